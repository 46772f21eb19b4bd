//! `config/shipcast.toml`: the daemon's, the simulator's and the watcher's configuration, read with the
//! `config` crate (the TOML file, then `SHIPCAST_<SECTION>__<KEY>` environment variables over it) and
//! validated with messages that name the key. Every key, its unit and default: `config/shipcast.toml`.

use serde::Deserialize;
use std::path::{Path, PathBuf};

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShipcastConfig {
    #[serde(default)]
    pub ipc: IpcConfig,
    pub system: SystemConfig,
    #[serde(default)]
    pub site: SiteConfig,
    #[serde(default)]
    pub forecast: ForecastConfig,
    #[serde(default)]
    pub log: LogConfig,
    #[serde(default)]
    pub record: RecordConfig,
    #[serde(default)]
    pub simulate: SimulateConfig,
    #[serde(default)]
    pub operation: OperationConfig,
    #[serde(default)]
    pub console: ConsoleConfig,
    /// Directory of the config file (relative paths are resolved against it); set by [`load`].
    #[serde(skip)]
    pub dir: PathBuf,
    /// The config file itself, as given; set by [`load`] (for messages that name it).
    #[serde(skip)]
    pub path: PathBuf,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct IpcConfig {
    /// Service names are `<service_prefix>/motion|waves|forecast|status`.
    pub service_prefix: String,
}

impl Default for IpcConfig {
    fn default() -> Self {
        IpcConfig {
            service_prefix: "shipcast".into(),
        }
    }
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SystemConfig {
    /// The vessels' system file, relative to the config file.
    pub file: PathBuf,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SiteConfig {
    /// Earth position (east, north) of the system's origin, m.
    pub origin_east_m: f64,
    pub origin_north_m: f64,
    /// Compass heading of the system's +x axis (clockwise from north), deg.
    pub heading_deg: f64,
}

impl Default for SiteConfig {
    fn default() -> Self {
        SiteConfig {
            origin_east_m: 0.0,
            origin_north_m: 0.0,
            heading_deg: 90.0,
        }
    }
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ForecastConfig {
    /// A forecast every period, s.
    pub period_s: f64,
    /// Length of each forecast, s.
    pub horizon_s: f64,
    /// Solver step, s.
    pub dt_s: f64,
    /// "convolution" or "state-space".
    pub radiation: String,
    /// Radiation memory, s (default: the database's).
    pub memory_s: Option<f64>,
    /// A wave field older than this (data clock) is flagged stale, s.
    pub max_wave_age_s: f64,
    /// ... and beyond this no forecast is published (status only), s.
    pub suppress_wave_age_s: f64,
    /// No motion sample received for this long (wall clock): stale motion, no forecast, s.
    pub max_motion_age_s: f64,
    /// Gaps in the motion history up to this long are bridged linearly; a longer one ends the
    /// history (what is before it counts as at rest), s.
    pub max_gap_s: f64,
    /// Motion samples kept per vessel beyond the radiation memory, s.
    pub history_margin_s: f64,
    /// Of a received wave field, the largest components holding this fraction of its variance are kept
    /// (a radar inversion has one per wavenumber bin, mostly noise; the cost is linear in their number).
    pub wave_variance_kept: f64,
    /// A sample or wave field stamped more than this ahead of its source's clock (as tracked by the
    /// engine) is refused as from the future, s (`service::clock`).
    pub max_clock_skew_s: f64,
    /// ... or more than this behind it, as from the past, s.
    pub max_clock_lag_s: f64,
    /// This many refused samples in a row that agree are a step of the source's clock: it
    /// re-synchronizes to them (its history restarts).
    pub clock_resync_samples: u32,
    /// The fastest a source's clock may run against the daemon's, data s per s (default:
    /// `simulate.speed`, at least 1: live sensors run at 1; this config's simulator at its speed).
    pub max_clock_rate: Option<f64>,
    /// A forecast whose wave field lost more than this share of its variance (components outside the
    /// database's frequencies or headings) is not trusted (trusted horizon 0), 0..1.
    pub max_dropped_wave_share: f64,
}

impl Default for ForecastConfig {
    fn default() -> Self {
        ForecastConfig {
            period_s: 1.0,
            horizon_s: 120.0,
            dt_s: 0.1,
            radiation: "convolution".into(),
            memory_s: None,
            max_wave_age_s: 10.0,
            suppress_wave_age_s: 30.0,
            max_motion_age_s: 2.0,
            max_gap_s: 1.0,
            history_margin_s: 10.0,
            wave_variance_kept: 0.995,
            max_clock_skew_s: 1.0,
            max_clock_lag_s: 30.0,
            clock_resync_samples: 5,
            max_clock_rate: None,
            max_dropped_wave_share: 0.1,
        }
    }
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RecordConfig {
    /// Directory for the daemon's logs (relative to the config file); empty: no recording.
    pub dir: String,
    /// A new file once the current one holds this many megabytes (uncompressed message bytes).
    pub rotate_mb: f64,
    /// A new file every this many seconds of log time (default: by size only).
    pub rotate_s: Option<f64>,
}

impl Default for RecordConfig {
    fn default() -> Self {
        RecordConfig {
            dir: String::new(),
            rotate_mb: 256.0,
            rotate_s: None,
        }
    }
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LogConfig {
    /// "human" or "json".
    pub format: String,
    /// Default filter when RUST_LOG is not set.
    pub level: String,
}

impl Default for LogConfig {
    fn default() -> Self {
        LogConfig {
            format: "human".into(),
            level: "info".into(),
        }
    }
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SimulateConfig {
    pub duration_s: f64,
    /// Data-clock seconds per wall-clock second.
    pub speed: f64,
    pub seed: u64,
    /// Model error: the true linear damping is this factor times the model's.
    pub damping_factor: f64,
    pub ramp_s: f64,
    /// The data clock at the start, UNIX seconds (None: the wall clock at the start).
    pub start_unix_s: Option<f64>,
    pub sea: SeaConfig,
    pub radar: RadarConfig,
    pub imu: ImuConfig,
}

impl Default for SimulateConfig {
    fn default() -> Self {
        SimulateConfig {
            duration_s: 3600.0,
            speed: 1.0,
            seed: 1,
            damping_factor: 1.0,
            ramp_s: 30.0,
            start_unix_s: None,
            sea: SeaConfig::default(),
            radar: RadarConfig::default(),
            imu: ImuConfig::default(),
        }
    }
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SeaConfig {
    pub hs_m: f64,
    pub tp_s: f64,
    pub gamma: f64,
    /// Compass direction the waves travel towards (clockwise from north), deg.
    pub towards_deg: f64,
    /// cos-2s spreading exponent; absent: long-crested.
    pub spreading_s: Option<f64>,
    pub components: usize,
    pub omega_min_rad_s: f64,
    pub omega_max_rad_s: f64,
}

impl Default for SeaConfig {
    fn default() -> Self {
        SeaConfig {
            hs_m: 2.0,
            tp_s: 9.0,
            gamma: 3.3,
            towards_deg: 270.0,
            spreading_s: None,
            components: 200,
            omega_min_rad_s: 0.3,
            omega_max_rad_s: 1.4,
        }
    }
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RadarConfig {
    pub radius_m: f64,
    pub cells: usize,
    pub period_s: f64,
    pub noise_m: f64,
    pub snapshots: usize,
    /// A recording (`simulate --record`) writes one snapshot in this many to `/radar` (0: none).
    pub record_grid_every: u32,
}

impl Default for RadarConfig {
    fn default() -> Self {
        RadarConfig {
            radius_m: 1000.0,
            cells: 128,
            period_s: 2.0,
            noise_m: 0.05,
            snapshots: 3,
            record_grid_every: 15,
        }
    }
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ImuConfig {
    pub rate_hz: f64,
    pub noise_m: f64,
    pub noise_rad: f64,
    pub bias_m: f64,
    pub bias_rad: f64,
}

impl Default for ImuConfig {
    fn default() -> Self {
        ImuConfig {
            rate_hz: 10.0,
            noise_m: 0.01,
            noise_rad: 0.0005,
            bias_m: 0.0,
            bias_rad: 0.0,
        }
    }
}

/// The operation the console watches and replay scores windows for.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct OperationConfig {
    /// How long the operation needs quiet motion, s.
    pub duration_s: f64,
    /// Channels and limits; empty: heave (1 m) and roll (2 deg) of every vessel.
    pub channels: Vec<ChannelConfig>,
}

impl Default for OperationConfig {
    fn default() -> Self {
        OperationConfig {
            duration_s: 60.0,
            channels: vec![],
        }
    }
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ChannelConfig {
    /// `<vessel>.<dof>`, `<point>.<x|y|z>` or `<relative_motion>.<x|y|z>` (`crate::operation`).
    pub name: String,
    /// |value| <= limit is inside: m, or deg for rotations.
    pub limit: f64,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ConsoleConfig {
    /// Measured past shown before "now", s.
    pub history_s: f64,
    pub colours: ColourConfig,
}

impl Default for ConsoleConfig {
    fn default() -> Self {
        ConsoleConfig {
            history_s: 60.0,
            colours: ColourConfig::default(),
        }
    }
}

/// Colour names as ratatui reads them ("red", "lightcyan", "darkgray", "#ffaa00", "208").
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ColourConfig {
    pub measured: String,
    pub forecast: String,
    pub beyond_horizon: String,
    pub limit: String,
    pub go: String,
    pub no_go: String,
    pub caution: String,
}

impl Default for ColourConfig {
    fn default() -> Self {
        ColourConfig {
            measured: "white".into(),
            forecast: "cyan".into(),
            beyond_horizon: "darkgray".into(),
            limit: "red".into(),
            go: "green".into(),
            no_go: "red".into(),
            caution: "yellow".into(),
        }
    }
}

impl ColourConfig {
    /// The colours, or the key of the first that ratatui cannot read.
    pub fn parse(&self) -> Result<crate::console::Colours, (String, String)> {
        let c = |k: &str, v: &str| {
            v.parse::<ratatui::style::Color>()
                .map_err(|_| (format!("console.colours.{k}"), format!("not a colour: \"{v}\"")))
        };
        Ok(crate::console::Colours {
            measured: c("measured", &self.measured)?,
            forecast: c("forecast", &self.forecast)?,
            beyond_horizon: c("beyond_horizon", &self.beyond_horizon)?,
            limit: c("limit", &self.limit)?,
            go: c("go", &self.go)?,
            no_go: c("no_go", &self.no_go)?,
            caution: c("caution", &self.caution)?,
        })
    }
}

impl ShipcastConfig {
    /// The operation's channels resolved against the system (its vessels, points and relative
    /// motions); the error names the config file and the channel's key.
    pub fn operation_channels(
        &self,
        vessels: &[String],
        ext: &crate::hydro::external::External,
        file: &Path,
    ) -> Result<Vec<crate::operation::Channel>, Error> {
        use crate::operation::{Channel, resolve};
        if self.operation.channels.is_empty() {
            let mut out = vec![];
            for v in vessels {
                for (dof, limit) in [("heave", 1.0), ("roll", 2.0)] {
                    let name = format!("{v}.{dof}");
                    if let Ok(source) = resolve(&name, vessels, ext) {
                        out.push(Channel { name, source, limit });
                    }
                }
            }
            return Ok(out);
        }
        self.operation
            .channels
            .iter()
            .enumerate()
            .map(|(i, c)| {
                let source = resolve(&c.name, vessels, ext).map_err(|msg| Error::Key {
                    file: file.display().to_string(),
                    key: format!("operation.channels[{i}].name"),
                    msg,
                })?;
                Ok(Channel {
                    name: c.name.clone(),
                    source,
                    limit: c.limit,
                })
            })
            .collect()
    }
}

/// A configuration error: the file or the key, and why.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    #[error("{file}: {msg}")]
    Read { file: String, msg: String },
    #[error("{file}: {key}: {msg}")]
    Key { file: String, key: String, msg: String },
}

/// The environment variables that overlay the file: `SHIPCAST_<SECTION>__<KEY>` (e.g.
/// `SHIPCAST_FORECAST__PERIOD_S=0.5`). `SHIPCAST_CONFIG` (the file's path, read by the CLI) and
/// `SHIPCAST_LOG` are not keys and are left out.
pub const ENV_PREFIX: &str = "SHIPCAST_";
const ENV_NOT_KEYS: [&str; 2] = ["SHIPCAST_CONFIG", "SHIPCAST_LOG"];

/// Reads the file, overlays the `SHIPCAST_*` variables of `env` (name, value), validates. An error in
/// the file names the file; an error an environment variable brings in names that variable.
pub fn load_with_env(path: &Path, env: &[(String, String)]) -> Result<ShipcastConfig, Error> {
    let file = path.display().to_string();
    let vars: Vec<&(String, String)> = env
        .iter()
        .filter(|(k, _)| k.starts_with(ENV_PREFIX) && !ENV_NOT_KEYS.contains(&k.as_str()))
        .collect();
    let build = |vars: &[&(String, String)]| -> Result<ShipcastConfig, String> {
        let map: config::Map<String, String> = vars.iter().map(|(k, v)| (k.clone(), v.clone())).collect();
        config::Config::builder()
            .add_source(config::File::from(path).format(config::FileFormat::Toml).required(true))
            .add_source(
                config::Environment::with_prefix(ENV_PREFIX.trim_end_matches('_'))
                    .prefix_separator("_")
                    .separator("__")
                    .try_parsing(true)
                    .source(Some(map)),
            )
            .build()
            .and_then(|raw| raw.try_deserialize())
            .map_err(|e| e.to_string())
    };
    let mut cfg = build(&[]).map_err(|msg| Error::Read {
        file: file.clone(),
        msg,
    })?;
    if !vars.is_empty() {
        cfg = build(&vars).map_err(|msg| {
            // name the variable: the first that fails on its own, else all of them
            let culprit = vars
                .iter()
                .find(|v| build(&[**v]).is_err())
                .map(|(k, v)| format!("environment variable {k}={v:?}"))
                .unwrap_or_else(|| {
                    let names: Vec<&str> = vars.iter().map(|(k, _)| k.as_str()).collect();
                    format!("environment variables {}", names.join(", "))
                });
            Error::Read {
                file: culprit,
                msg: format!(
                    "{msg} (overlaying {file}; keys are SHIPCAST_<SECTION>__<KEY>, e.g. SHIPCAST_FORECAST__PERIOD_S)"
                ),
            }
        })?;
    }
    cfg.dir = path.parent().unwrap_or(Path::new(".")).to_path_buf();
    cfg.path = path.to_path_buf();
    validate(&cfg).map_err(|(key, msg)| Error::Key {
        file: file.clone(),
        key,
        msg,
    })?;
    Ok(cfg)
}

/// [`load_with_env`] with the process's environment.
pub fn load(path: &Path) -> Result<ShipcastConfig, Error> {
    let env: Vec<(String, String)> = std::env::vars().collect();
    load_with_env(path, &env)
}

fn validate(c: &ShipcastConfig) -> Result<(), (String, String)> {
    let pos = |k: &str, v: f64| {
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            Err((k.to_string(), format!("must be a positive number, found {v}")))
        }
    };
    let f = &c.forecast;
    pos("forecast.period_s", f.period_s)?;
    pos("forecast.horizon_s", f.horizon_s)?;
    pos("forecast.dt_s", f.dt_s)?;
    pos("forecast.max_wave_age_s", f.max_wave_age_s)?;
    pos("forecast.suppress_wave_age_s", f.suppress_wave_age_s)?;
    pos("forecast.max_motion_age_s", f.max_motion_age_s)?;
    pos("forecast.max_gap_s", f.max_gap_s)?;
    if !(f.wave_variance_kept > 0.0 && f.wave_variance_kept <= 1.0) {
        return Err((
            "forecast.wave_variance_kept".into(),
            format!("must be in (0, 1], found {}", f.wave_variance_kept),
        ));
    }
    pos("forecast.max_clock_skew_s", f.max_clock_skew_s)?;
    pos("forecast.max_clock_lag_s", f.max_clock_lag_s)?;
    if let Some(r) = f.max_clock_rate
        && !(r.is_finite() && (1.0..=1000.0).contains(&r))
    {
        return Err((
            "forecast.max_clock_rate".into(),
            format!("must be in [1, 1000], found {r}"),
        ));
    }
    if !(1..=1000).contains(&f.clock_resync_samples) {
        return Err((
            "forecast.clock_resync_samples".into(),
            format!("must be in 1..=1000, found {}", f.clock_resync_samples),
        ));
    }
    if !(0.0..=1.0).contains(&f.max_dropped_wave_share) {
        return Err((
            "forecast.max_dropped_wave_share".into(),
            format!("must be in [0, 1], found {}", f.max_dropped_wave_share),
        ));
    }
    if f.horizon_s > crate::rom::forecast::MAX_FORECAST_LENGTH_S {
        return Err((
            "forecast.horizon_s".into(),
            format!(
                "at most {} s, found {}",
                crate::rom::forecast::MAX_FORECAST_LENGTH_S,
                f.horizon_s
            ),
        ));
    }
    if !["convolution", "state-space"].contains(&f.radiation.as_str()) {
        return Err((
            "forecast.radiation".into(),
            format!("expected \"convolution\" or \"state-space\", found \"{}\"", f.radiation),
        ));
    }
    if !["human", "json"].contains(&c.log.format.as_str()) {
        return Err((
            "log.format".into(),
            format!("expected \"human\" or \"json\", found \"{}\"", c.log.format),
        ));
    }
    if c.ipc.service_prefix.is_empty() || c.ipc.service_prefix.len() > 200 {
        return Err(("ipc.service_prefix".into(), "must be 1..200 characters".into()));
    }
    if !(c.record.rotate_mb.is_finite() && c.record.rotate_mb > 0.0) {
        return Err((
            "record.rotate_mb".into(),
            format!("must be positive, found {}", c.record.rotate_mb),
        ));
    }
    if let Some(r) = c.record.rotate_s {
        pos("record.rotate_s", r)?;
    }
    pos("operation.duration_s", c.operation.duration_s)?;
    for (i, ch) in c.operation.channels.iter().enumerate() {
        pos(&format!("operation.channels[{i}].limit"), ch.limit)?;
    }
    pos("console.history_s", c.console.history_s)?;
    c.console.colours.parse()?;
    let s = &c.simulate;
    pos("simulate.duration_s", s.duration_s)?;
    pos("simulate.speed", s.speed)?;
    pos("simulate.damping_factor", s.damping_factor)?;
    pos("simulate.sea.hs_m", s.sea.hs_m)?;
    pos("simulate.sea.tp_s", s.sea.tp_s)?;
    pos("simulate.radar.radius_m", s.radar.radius_m)?;
    pos("simulate.radar.period_s", s.radar.period_s)?;
    pos("simulate.imu.rate_hz", s.imu.rate_hz)?;
    if let Some(t) = s.start_unix_s {
        pos("simulate.start_unix_s", t)?;
    }
    if !(8..=1024).contains(&s.radar.cells) {
        return Err((
            "simulate.radar.cells".into(),
            format!("must be in 8..=1024, found {}", s.radar.cells),
        ));
    }
    Ok(())
}
