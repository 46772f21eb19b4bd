//! `shipcast console` against the running daemon, in tmux (issue 8): it shows a verdict once
//! forecasts flow, says the daemon is gone within two forecast periods of a crash and of a clean
//! stop, reconnects when the daemon comes back, and degrades to text in a tiny terminal.

use crate::daemon::{bin, config, daemon, simulator};
use crate::util::scratch_dir;
use std::process::Command;
use std::time::{Duration, Instant};

/// The test config's forecast period (tests/daemon.rs `config`).
const PERIOD_S: f64 = 0.5;
/// The bar: the display says the daemon stopped within two forecast periods.
const MAX_NOTICE_S: f64 = 2.0 * PERIOD_S;

struct Tmux(String);

impl Tmux {
    fn new(name: &str, cmd: &str) -> Tmux {
        let s = format!("shipcast-test-{}-{name}", std::process::id());
        let ok = Command::new("tmux")
            .args(["new-session", "-d", "-s", &s, "-x", "120", "-y", "36", cmd])
            .status()
            .expect("tmux is installed (.ci/run installs it)");
        assert!(ok.success());
        Tmux(s)
    }

    fn screen(&self) -> String {
        let o = Command::new("tmux")
            .args(["capture-pane", "-p", "-t", &self.0])
            .output()
            .unwrap();
        String::from_utf8_lossy(&o.stdout).into_owned()
    }

    /// Seconds until the screen satisfies `f` (polled every 20 ms), or None after `secs`.
    fn until(&self, secs: f64, f: impl Fn(&str) -> bool) -> Option<f64> {
        let t = Instant::now();
        while t.elapsed().as_secs_f64() < secs {
            if f(&self.screen()) {
                return Some(t.elapsed().as_secs_f64());
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        None
    }
}

impl Drop for Tmux {
    fn drop(&mut self) {
        let _ = Command::new("tmux")
            .args(["kill-session", "-t", &self.0])
            .stderr(std::process::Stdio::null())
            .status();
    }
}

fn verdict(s: &str) -> bool {
    s.contains("│GO (") || s.contains("│NO-GO (") || s.contains("│CAN'T TELL")
}

#[test]
fn console_shows_forecasts_notices_a_stopped_daemon_and_reconnects() {
    let dir = scratch_dir("console");
    let cfg = config(&dir, "console", "[operation]\nduration_s = 20.0\n");
    let tmux = Tmux::new("console", &format!("{} console --config {}", bin(), cfg.display()));
    assert!(
        tmux.until(10.0, |s| s.contains("Waiting for shipcast")).is_some(),
        "{}",
        tmux.screen()
    );
    let mut d = daemon(&cfg);
    let _sim = simulator(&cfg, "600", &[]);
    assert!(tmux.until(60.0, verdict).is_some(), "no verdict: {}", tmux.screen());
    let s = tmux.screen();
    assert!(
        s.contains("carrier.heave (m) limit ±1") && s.contains("Quiet windows ≥ 20 s"),
        "{s}"
    );
    assert!(s.contains("carrier IMU:") && s.contains("Radar: data"), "{s}");

    // a crash: nothing more arrives
    d.kill();
    let crash = tmux
        .until(5.0, |s| s.contains("NOT RESPONDING"))
        .expect("the crash is noticed");
    let s = tmux.screen();
    assert!(s.contains("STALE") && s.contains("no current forecast"), "{s}");
    eprintln!("crash noticed {crash:.2} s after SIGKILL (period {PERIOD_S} s)");
    assert!(crash <= MAX_NOTICE_S, "{crash} s");

    // back again: the console picks it up by itself
    let d = daemon(&cfg);
    let back = tmux.until(30.0, verdict).expect("reconnected");
    eprintln!("forecasts shown again {back:.1} s after the restarted daemon's ports were up");

    // a clean stop (SIGINT): its last status says so
    drop(d);
    let stop = tmux
        .until(8.0, |s| s.contains("STOPPED") || s.contains("NOT RESPONDING"))
        .expect("stop noticed");
    eprintln!("clean stop noticed {stop:.2} s after SIGINT was sent");
    assert!(
        stop <= MAX_NOTICE_S + 0.5,
        "{stop} s (the daemon takes a moment to finish its job)"
    );

    // a tiny terminal: text, no frames
    Command::new("tmux")
        .args(["resize-window", "-t", &tmux.0, "-x", "50", "-y", "10"])
        .status()
        .unwrap();
    assert!(
        tmux.until(3.0, |s| !s.contains('┌') && s.contains("shipcast"))
            .is_some(),
        "{}",
        tmux.screen()
    );
    // q quits
    Command::new("tmux")
        .args(["send-keys", "-t", &tmux.0, "q"])
        .status()
        .unwrap();
    let gone = (0..50).any(|_| {
        std::thread::sleep(Duration::from_millis(100));
        !Command::new("tmux")
            .args(["has-session", "-t", &tmux.0])
            .status()
            .unwrap()
            .success()
    });
    assert!(gone, "q ends the console");
}

#[test]
fn a_bad_channel_or_colour_is_named_before_the_screen_opens() {
    let dir = scratch_dir("console-bad");
    let run = |extra: &str| {
        let cfg = config(&dir, "console-bad", extra);
        let o = Command::new(bin())
            .args(["console", "--config", cfg.to_str().unwrap()])
            .output()
            .unwrap();
        assert!(!o.status.success());
        String::from_utf8_lossy(&o.stderr).into_owned()
    };
    let e = run("[operation]\nchannels = [{ name = \"carrier.heav\", limit = 1.0 }]\n");
    assert!(
        e.contains("operation.channels[0].name") && e.contains("unknown DOF \"heav\""),
        "{e}"
    );
    let e = run("[operation]\nchannels = [{ name = \"crane.z\", limit = 1.0 }]\n");
    assert!(
        e.contains("no vessel, point or relative motion \"crane\" (known: carrier)"),
        "{e}"
    );
    let e = run("[operation]\nchannels = [{ name = \"carrier.roll\", limit = -2.0 }]\n");
    assert!(
        e.contains("operation.channels[0].limit") && e.contains("must be in (0, ") && e.contains("-2"),
        "{e}"
    );
    let e = run("[console.colours]\nforecast = \"blurple\"\n");
    assert!(e.contains("console.colours.forecast") && e.contains("blurple"), "{e}");
}

/// Was: `shipcast demo` printed plain lines in a terminal too; the console was a separate command.
/// Now in a terminal it opens the console on the demo, which says in words how long the warm-up lasts.
#[test]
fn demo_in_a_terminal_opens_the_console_and_says_when_the_warm_up_ends() {
    let dir = scratch_dir("console-demo");
    let cfg = config(&dir, "console-demo", "");
    let tmux = Tmux::new(
        "console-demo",
        &format!("{} demo --config {} --seconds 40", bin(), cfg.display()),
    );
    let warm = |s: &str| s.contains("Warming up:") && s.contains("motion memory");
    assert!(tmux.until(30.0, warm).is_some(), "{}", tmux.screen());
    assert!(tmux.screen().contains("shipcast console"), "{}", tmux.screen());
    Command::new("tmux")
        .args(["send-keys", "-t", &tmux.0, "q"])
        .status()
        .unwrap();
}
