//! Subcommands of the `shipcast` binary that have grown past a few lines, and the replay report's
//! plots (shell: wiring and files only).

pub mod console;
pub mod daemon;
pub mod forecast;
pub mod horizon;
pub mod link;
pub mod plot;
pub mod rao;
pub mod replay;

use anyhow::{Context, Result, bail};
use shipcast::settings::ShipcastConfig;
use std::path::PathBuf;

/// `--config FILE`, shared by every subcommand that reads the daemon's configuration.
#[derive(clap::Args, Debug, Clone)]
pub struct ConfigArg {
    /// The configuration file (every key documented in config/shipcast.toml). Default: the file named
    /// by $SHIPCAST_CONFIG, else config/shipcast.toml in the working directory when it exists, else
    /// /etc/shipcast/shipcast.toml (the service's, README "Install as a service").
    #[arg(long = "config", value_name = "FILE")]
    file: Option<PathBuf>,
}

/// Where the configuration is looked for when `--config` is not given, after $SHIPCAST_CONFIG.
pub const CONFIG_SEARCH: [&str; 2] = ["config/shipcast.toml", "/etc/shipcast/shipcast.toml"];

impl ConfigArg {
    /// The file to read: `--config`, else $SHIPCAST_CONFIG, else the first of [`CONFIG_SEARCH`] that
    /// exists (the last one when none does, so that the error names it).
    pub fn path(&self) -> PathBuf {
        if let Some(f) = &self.file {
            return f.clone();
        }
        if let Some(f) = std::env::var_os("SHIPCAST_CONFIG").filter(|f| !f.is_empty()) {
            return PathBuf::from(f);
        }
        CONFIG_SEARCH
            .iter()
            .map(PathBuf::from)
            .find(|p| p.exists())
            .unwrap_or_else(|| PathBuf::from(CONFIG_SEARCH[CONFIG_SEARCH.len() - 1]))
    }
}

/// A data-clock time for people: UTC to the tenth of a second (`2026-12-01 17:40:12.3 UTC`) when it is
/// a UNIX time (after 1973), else seconds (`t 123.4 s`: a simulation or log clock from zero).
pub fn utc(unix_s: f64) -> String {
    const PLAUSIBLY_UNIX_S: f64 = 1e8;
    let t = match time::OffsetDateTime::from_unix_timestamp_nanos((unix_s * 1e9) as i128) {
        Ok(t) if unix_s.is_finite() && unix_s >= PLAUSIBLY_UNIX_S => t,
        _ => return format!("t {unix_s:.1} s"),
    };
    format!(
        "{:04}-{:02}-{:02} {:02}:{:02}:{:02}.{} UTC",
        t.year(),
        u8::from(t.month()),
        t.day(),
        t.hour(),
        t.minute(),
        t.second(),
        t.millisecond() / 100
    )
}

/// `--radiation`: the radiation memory of the time-domain model.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Radiation {
    /// Direct convolution of the impulse response with the velocity history.
    Convolution,
    /// The passive state-space fit.
    StateSpace,
}

impl From<Radiation> for shipcast::rom::RadiationMethod {
    fn from(r: Radiation) -> Self {
        use shipcast::rom::RadiationMethod;
        match r {
            Radiation::Convolution => RadiationMethod::Convolution,
            Radiation::StateSpace => RadiationMethod::StateSpace,
        }
    }
}

/// The configuration `--config` names (or the default one), loaded.
pub fn load_config(arg: &ConfigArg) -> Result<ShipcastConfig> {
    let path = arg.path();
    if !path.exists() {
        bail!(
            "{}: no such configuration file (give --config FILE or set SHIPCAST_CONFIG; without them shipcast looks for {})",
            path.display(),
            CONFIG_SEARCH.join(" and ")
        );
    }
    Ok(shipcast::shell::config::load(&path)?)
}

/// The system file a configuration names.
pub fn system_path(cfg: &ShipcastConfig) -> PathBuf {
    cfg.dir.join(&cfg.system.file)
}

/// The config's vessel system; an error names the config file and its `[system] file` key.
pub fn load_system(cfg: &ShipcastConfig) -> Result<shipcast::hydro::VesselSystem> {
    shipcast::shell::files::load_system(&system_path(cfg))
        .map(|l| l.system)
        .with_context(|| format!("{}: [system] file = {:?}", cfg.path.display(), cfg.system.file))
}

#[cfg(test)]
mod tests {
    #[test]
    fn utc_prints_unix_times_as_dates_and_small_times_as_seconds() {
        assert_eq!(super::utc(1_700_000_000.25), "2023-11-14 22:13:20.2 UTC");
        assert_eq!(super::utc(123.45), "t 123.5 s");
        assert_eq!(super::utc(f64::INFINITY), "t inf s");
    }
}
