//! The ship-to-ship link (`shipcast link`, the `link` feature): two iceoryx2 domains (two service
//! prefixes on one host) bridged over Zenoh on loopback, the link cut and restored.
//!
//! Domain A is the carrier's host: the simulator's carrier motion and radar, the daemon. Domain B is
//! the lighter's: the simulator's lighter motion (`--vessel-prefix 1=B`), and a subscriber of the
//! carrier's forecasts. B's link connects to A's through a TCP relay in this test, which the test
//! cuts (every connection closed, none accepted) for [`CUT_S`] and restores: a radio link lost and
//! back, both link processes running.

use crate::util::{median, repo};
use shipcast::shell::ipc::wire::{Status, flags, link_state};
use shipcast::shell::ipc::{ForecastSubscriber, Names, Received};
use shipcast::shell::process::Interrupting;
use std::io::{Read, Write};
use std::net::{Shutdown, TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// The outage, s (the issue's).
const CUT_S: f64 = 20.0;
/// After the link is restored, the lighter's motion is fresh again within this, s: Zenoh's connect
/// retry (at most 1 s apart), its session setup and the daemon's next period (1 s), with margin.
const BACK_WITHIN_S: f64 = 6.0;
/// The median latency of a message across the link on loopback (the sending link's stamp to the
/// receiving link's receipt: one Zenoh hop, TCP, express) is at most this, ms, on a loaded 2-core
/// machine; measured 0.4-0.9 ms.
const MAX_MEDIAN_LATENCY_MS: f64 = 50.0;

fn bin() -> &'static str {
    env!("CARGO_BIN_EXE_shipcast")
}

fn free_port() -> u16 {
    TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port()
}

/// A TCP relay from `listen` to `to` that can be cut (every connection closed, none accepted) and
/// restored: the radio between the ships.
struct Relay {
    up: Arc<AtomicBool>,
    conns: Arc<std::sync::Mutex<Vec<TcpStream>>>,
}

impl Relay {
    fn start(listen: u16, to: u16) -> Relay {
        let up = Arc::new(AtomicBool::new(true));
        let conns: Arc<std::sync::Mutex<Vec<TcpStream>>> = Arc::default();
        let l = TcpListener::bind(("127.0.0.1", listen)).unwrap();
        let (up2, conns2) = (up.clone(), conns.clone());
        std::thread::spawn(move || {
            for c in l.incoming() {
                let Ok(a) = c else { continue };
                if !up2.load(Ordering::SeqCst) {
                    let _ = a.shutdown(Shutdown::Both);
                    continue;
                }
                let Ok(b) = TcpStream::connect(("127.0.0.1", to)) else {
                    let _ = a.shutdown(Shutdown::Both);
                    continue;
                };
                let _ = a.set_nodelay(true);
                let _ = b.set_nodelay(true);
                conns2
                    .lock()
                    .unwrap()
                    .extend([a.try_clone().unwrap(), b.try_clone().unwrap()]);
                for (mut from, mut into) in [(a.try_clone().unwrap(), b.try_clone().unwrap()), (b, a)] {
                    std::thread::spawn(move || {
                        let mut buf = [0u8; 65536];
                        while let Ok(n) = from.read(&mut buf) {
                            if n == 0 || into.write_all(&buf[..n]).is_err() {
                                break;
                            }
                        }
                        let _ = into.shutdown(Shutdown::Both);
                        let _ = from.shutdown(Shutdown::Both);
                    });
                }
            }
        });
        Relay { up, conns }
    }

    fn cut(&self) {
        self.up.store(false, Ordering::SeqCst);
        for c in self.conns.lock().unwrap().drain(..) {
            let _ = c.shutdown(Shutdown::Both);
        }
    }

    fn restore(&self) {
        self.up.store(true, Ordering::SeqCst);
    }
}

/// A config of the moored pair in domain `prefix` (the twin sea: the link is the subject, not the
/// sensors), with a `[link]` section.
fn config(dir: &Path, name: &str, prefix: &str, link: &str) -> PathBuf {
    let system = repo("config/vessels/pair/moored.toml");
    let text = format!(
        r#"
[ipc]
service_prefix = "{prefix}"
[system]
file = "{system}"
[forecast]
horizon_s = 120.0
# the history the test waits for to refill after the outage (the pair's own memory is longer)
memory_s = 15.0
[log]
level = "info"
[simulate]
speed = 1.0
seed = 5
ramp_s = 10.0
[simulate.sea]
hs_m = 2.0
tp_s = 9.0
towards_deg = 0.0
components = 120
bound_waves = false
[simulate.imu]
drift_m = 0.0
drift_rad = 0.0
[simulate.radar]
radius_m = 1000.0
cells = 128
blind_radius_m = 0.0
antenna_height_m = 0.0
[link]
{link}
"#,
        system = system.display()
    );
    let p = dir.join(format!("{name}.toml"));
    std::fs::write(&p, text).unwrap();
    p
}

fn spawn(args: &[&str], log: &Path) -> Interrupting {
    Interrupting(
        Command::new(bin())
            .args(args)
            .stdout(Stdio::null())
            .stderr(std::fs::File::create(log).unwrap())
            .spawn()
            .expect("shipcast starts"),
    )
}

#[test]
fn two_hosts_over_zenoh_survive_a_cut_link() {
    let dir = crate::util::scratch_dir("link");
    let pid = std::process::id();
    let (a_prefix, b_prefix) = (
        format!("shipcast-test-{pid}-link-a"),
        format!("shipcast-test-{pid}-link-b"),
    );
    let (port_a, port_relay) = (free_port(), free_port());
    let ns = format!("test{pid}");
    let cfg_a = config(
        &dir,
        "a",
        &a_prefix,
        &format!("name = \"carrier\"\nnamespace = \"{ns}\"\nlisten = [\"tcp/127.0.0.1:{port_a}\"]\nown_vessels = [0]"),
    );
    let cfg_b = config(
        &dir,
        "b",
        &b_prefix,
        &format!(
            "name = \"lighter\"\nnamespace = \"{ns}\"\nconnect = [\"tcp/127.0.0.1:{port_relay}\"]\nown_vessels = [1]\nforecasts_out = false"
        ),
    );
    let relay = Relay::start(port_relay, port_a);
    let a = |p: &PathBuf| p.to_str().unwrap().to_string();
    let mut link_a = spawn(&["link", "--config", &a(&cfg_a)], &dir.join("link-a.log"));
    let mut link_b = spawn(&["link", "--config", &a(&cfg_b)], &dir.join("link-b.log"));
    let mut daemon = spawn(&["run", "--config", &a(&cfg_a)], &dir.join("daemon-a.log"));
    std::thread::sleep(Duration::from_millis(1500));
    let sub_a = ForecastSubscriber::new(&Names {
        prefix: a_prefix.clone(),
    })
    .unwrap();
    let sub_b = ForecastSubscriber::new(&Names {
        prefix: format!("{b_prefix}/peer"),
    })
    .unwrap();
    let lighter = format!("1={b_prefix}");
    let _sim = spawn(
        &[
            "simulate",
            "--publish",
            "--config",
            &a(&cfg_a),
            "--duration",
            "200",
            "--vessel-prefix",
            &lighter,
        ],
        &dir.join("simulate.log"),
    );
    let start = Instant::now();
    let now = || start.elapsed().as_secs_f64();
    // (wall s since start, what A published) and what reached B
    let mut at_a: Vec<(f64, Received)> = vec![];
    let mut at_b: Vec<(f64, Received)> = vec![];
    let collect = |until_s: f64, at_a: &mut Vec<(f64, Received)>, at_b: &mut Vec<(f64, Received)>| {
        while now() < until_s {
            let mut got = vec![];
            sub_a.wait(Duration::from_millis(100), &mut got).unwrap();
            at_a.extend(got.drain(..).map(|r| (now(), r)));
            sub_b.drain(&mut got).unwrap();
            at_b.extend(got.drain(..).map(|r| (now(), r)));
        }
    };
    // warm-up: the memory fills (15 s), then a while of normal forecasts
    let cut_at = 32.0;
    collect(cut_at, &mut at_a, &mut at_b);
    relay.cut();
    let restore_at = cut_at + CUT_S;
    collect(restore_at, &mut at_a, &mut at_b);
    relay.restore();
    let end = restore_at + 26.0;
    collect(end, &mut at_a, &mut at_b);
    assert!(
        matches!(daemon.0.try_wait(), Ok(None))
            && matches!(link_a.0.try_wait(), Ok(None))
            && matches!(link_b.0.try_wait(), Ok(None)),
        "a process ended (logs in {})",
        dir.display()
    );

    let forecasts =
        |v: &[(f64, Received)], from: f64, to: f64| -> Vec<(f64, shipcast::shell::ipc::wire::ForecastHeader)> {
            v.iter()
                .filter_map(|(t, r)| match r {
                    Received::Forecast(h, _) if *t >= from && *t < to => Some((*t, *h)),
                    _ => None,
                })
                .collect()
        };
    let statuses = |v: &[(f64, Received)], from: f64, to: f64| -> Vec<(f64, Status)> {
        v.iter()
            .filter_map(|(t, r)| match r {
                Received::Status(s) if *t >= from && *t < to => Some((*t, *s)),
                _ => None,
            })
            .collect()
    };
    let stale = |h: &shipcast::shell::ipc::wire::ForecastHeader| h.flags & flags::STALE_MOTION != 0;

    // before the cut: the lighter's motion came from B, the forecasts reached B
    let before = forecasts(&at_a, 22.0, cut_at);
    let fresh_before = before.iter().filter(|(_, h)| !stale(h)).count();
    let at_b_before = forecasts(&at_b, 22.0, cut_at).len();
    let lat: Vec<f64> = statuses(&at_a, 10.0, cut_at)
        .iter()
        .filter(|(_, s)| s.link_state == link_state::UP && s.link_latency_ms >= 0.0)
        .map(|(_, s)| s.link_latency_ms)
        .collect();
    eprintln!(
        "before the cut: {} forecasts at A ({fresh_before} with both vessels fresh), {at_b_before} reached B; \
         median latency of the lighter's motion B -> A {:.2} ms",
        before.len(),
        if lat.is_empty() { f64::NAN } else { median(lat.clone()) }
    );
    assert!(before.len() >= 8 && fresh_before == before.len(), "{before:?}");
    assert!(
        at_b_before as f64 >= 0.8 * before.len() as f64,
        "{at_b_before} of {} reached B",
        before.len()
    );
    assert!(
        !lat.is_empty() && median(lat.clone()) <= MAX_MEDIAN_LATENCY_MS,
        "{lat:?}"
    );

    // the outage: forecasts go on for the carrier, flagged; nothing of the lighter's trusted
    let during = forecasts(&at_a, cut_at + 4.0, restore_at);
    let flagged = during.iter().filter(|(_, h)| stale(h)).count();
    let lighter_trusted = during.iter().filter(|(_, h)| h.horizon_s[1] > 0.0).count();
    let down = statuses(&at_a, cut_at + 4.0, restore_at)
        .iter()
        .filter(|(_, s)| s.link_state == link_state::DOWN)
        .count();
    let at_b_during = forecasts(&at_b, cut_at + 1.0, restore_at).len();
    eprintln!(
        "during the cut: {} forecasts at A, {flagged} flagged stale_motion, {lighter_trusted} trusting the lighter; \
         link down in {down} status; {at_b_during} reached B",
        during.len()
    );
    assert!(during.len() >= 10, "the carrier's forecasts stopped during the outage");
    assert_eq!(flagged, during.len());
    assert_eq!(lighter_trusted, 0);
    assert!(down >= 10);
    assert_eq!(at_b_during, 0);

    // restored: the lighter's motion fresh again, the link up, forecasts at B again
    let after = forecasts(&at_a, restore_at, end);
    let back = after.iter().find(|(_, h)| !stale(h)).map(|(t, _)| t - restore_at);
    let full = after
        .iter()
        .find(|(_, h)| h.flags & (flags::STALE_MOTION | flags::HISTORY_SHORT | flags::HISTORY_GAP) == 0)
        .map(|(t, _)| t - restore_at);
    let up = statuses(&at_a, restore_at, end)
        .iter()
        .find(|(_, s)| s.link_state == link_state::UP)
        .map(|(t, _)| t - restore_at);
    let at_b_after = forecasts(&at_b, restore_at, end).first().map(|(t, _)| t - restore_at);
    let stale_again = after
        .iter()
        .skip_while(|(_, h)| stale(h))
        .filter(|(_, h)| stale(h))
        .count();
    eprintln!(
        "after the link is back: the lighter's motion fresh in {back:?} s, the link up in {up:?} s, forecasts at B in \
         {at_b_after:?} s, the memory full again (no history flags) in {full:?} s; {stale_again} stale forecasts after"
    );
    assert!(back.is_some_and(|b| b <= BACK_WITHIN_S), "{back:?}");
    assert!(up.is_some_and(|b| b <= BACK_WITHIN_S), "{up:?}");
    assert!(at_b_after.is_some_and(|b| b <= BACK_WITHIN_S), "{at_b_after:?}");
    assert!(full.is_some_and(|f| f <= BACK_WITHIN_S + 15.0 + 2.0), "{full:?}");
    assert_eq!(stale_again, 0);
}
