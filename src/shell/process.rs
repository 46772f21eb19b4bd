//! Child processes that stop politely (shell): `shipcast demo` and the daemon tests start the daemon
//! and the simulator as children and must never leave one running.

use std::time::{Duration, Instant};

/// Grace period between SIGINT and SIGKILL.
const GRACE: Duration = Duration::from_secs(5);

/// A child process that, when dropped, gets SIGINT (so it shuts down as on Ctrl-C: ports closed,
/// logs finished), then SIGKILL if it has not ended within 5 s, and is always reaped.
pub struct Interrupting(pub std::process::Child);

impl Interrupting {
    /// SIGKILL now and reap (a crash, as tests simulate one).
    pub fn kill(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

impl Drop for Interrupting {
    fn drop(&mut self) {
        if let Ok(Some(_)) = self.0.try_wait() {
            return;
        }
        if let Ok(pid) = i32::try_from(self.0.id()) {
            let _ = nix::sys::signal::kill(nix::unistd::Pid::from_raw(pid), nix::sys::signal::Signal::SIGINT);
        }
        let t = Instant::now();
        while t.elapsed() < GRACE {
            if let Ok(Some(_)) = self.0.try_wait() {
                return;
            }
            std::thread::sleep(Duration::from_millis(50));
        }
        self.kill();
    }
}
