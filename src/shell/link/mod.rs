//! The ship-to-ship link (shell): this host's iceoryx2 services bridged to the other ship's over
//! Zenoh (`shipcast link`, the `link` cargo feature).
//!
//! iceoryx2 is shared memory: one host. Each ship runs its own daemon, sensors and consoles on its
//! own host, and one link process; the two links speak Zenoh (TCP) over the radio between the ships.
//! What crosses, per `[link]`:
//! - out: the motion and navigation of this ship's own vessels (`own_vessels`), and (with
//!   `forecasts_out`) this ship's forecasts and status, each on the Zenoh key
//!   `shipcast/<namespace>/<name>/<kind>`;
//! - in: the other ship's motion and navigation of the vessels that are not this ship's, into this
//!   host's `<prefix>/motion` and `<prefix>/navigation` (its daemon takes them as any sample, stamps
//!   and all: the clock rules judge them); the other ship's forecasts and status into
//!   `<peer_prefix>/forecast` and `/status` (a console watches them there).
//!
//! Nothing loops: a vessel's samples go out only from the ship that owns it and come in only on the
//! other, and the other ship's forecasts are published under their own prefix, which the link does
//! not read. Each message carries its stream's sequence number and the sender's wall-clock stamp;
//! the link's health (latency, loss, the newest message's age: [`health`]) goes out every
//! [`HEALTH_PERIOD_S`] on `<prefix>/link`, and the daemon carries it into its status.
//!
//! Why Zenoh directly, not iceoryx2's Zenoh link carrier (`iceoryx2-integrations-zenoh-link-carrier`,
//! a prototype in 0.10): the carrier mirrors services of the same name both ways, and both ships'
//! daemons publish `<prefix>/forecast`; the link must choose a direction per service and put the
//! other ship's forecasts under another name.

pub mod health;

#[cfg(feature = "link")]
mod bridge;
#[cfg(feature = "link")]
pub use bridge::{Envelope, Message, run};

/// The link publishes its health this often, s.
pub const HEALTH_PERIOD_S: f64 = 1.0;
