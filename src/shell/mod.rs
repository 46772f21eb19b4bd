//! The imperative shell: the only place that names tokio, iceoryx2, Zenoh, files, the environment,
//! clocks and systemd. The daemon's loop ([`daemon`]) around the engine, the iceoryx2 ports and the one
//! conversion between messages and wire payloads ([`ipc`]), MCAP logs ([`record`]) and their replay
//! through the engine ([`replay`]), the ship-to-ship link ([`link`]), reading configurations, systems
//! and scenarios from disk ([`config`], [`files`], [`scenario`]), `db check`'s report ([`report`]) and
//! child processes ([`process`]).

pub mod config;
pub mod daemon;
pub mod files;
pub mod ipc;
pub mod link;
pub mod process;
pub mod record;
pub mod replay;
pub mod report;
pub mod scenario;
pub mod state;
