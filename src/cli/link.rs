//! `shipcast link`: the ship-to-ship link's process (`shipcast::shell::link`).

use anyhow::Result;
use clap::Args;
use shipcast::shell::config::ShipcastConfig;

#[derive(Args, Debug)]
pub struct LinkArgs {
    #[command(flatten)]
    pub config: super::ConfigArg,
}

/// Runs the link until SIGINT or SIGTERM.
#[cfg(feature = "link")]
pub fn run(cfg: ShipcastConfig) -> Result<()> {
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    super::daemon::ctrlc_flag(stop.clone())?;
    shipcast::shell::link::run(&cfg, stop)
}

#[cfg(not(feature = "link"))]
pub fn run(cfg: ShipcastConfig) -> Result<()> {
    anyhow::bail!(
        "{}: this shipcast was built without the ship-to-ship link (Zenoh): build it with `cargo build --release --features link`",
        cfg.path.display()
    )
}
