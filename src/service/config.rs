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
    pub estimator: EstimatorConfig,
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
    #[serde(default)]
    pub link: LinkConfig,
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
    /// Solver step, s (None: chosen from the system's shortest natural period, `rom::step`).
    pub dt_s: Option<f64>,
    /// "convolution" or "state-space".
    pub radiation: String,
    /// Radiation memory, s (default: the database's).
    pub memory_s: Option<f64>,
    /// A wave field older than this (data clock) is flagged stale, s.
    pub max_wave_age_s: f64,
    /// ... and beyond this no forecast is published (status only), s.
    pub suppress_wave_age_s: f64,
    /// A vessel without a motion sample for this long (wall clock) is stale: forecast from rest and
    /// trusted nowhere (flag `stale_motion`); every vessel stale: no forecast, s.
    pub max_motion_age_s: f64,
    /// Gaps in the motion history up to this long are bridged (by the estimator's curve through both
    /// ends); a longer one ends the history (what is before it counts as at rest), s.
    pub max_gap_s: f64,
    /// The modes without restoring (a free vessel's surge, sway, yaw) drift at the mean velocity
    /// measured over this much of the history (`rom::drift`); 0: at the last sample's velocity, s.
    pub drift_window_s: f64,
    /// Motion samples kept per vessel beyond the radiation memory, s.
    pub history_margin_s: f64,
    /// Of a received wave field, the largest components holding this fraction of its variance are kept
    /// (a radar inversion has one per wavenumber bin, mostly noise; the cost is linear in their number).
    pub wave_variance_kept: f64,
    /// A sample or wave field stamped more than this ahead of its source's clock (as tracked by the
    /// engine) is refused as from the future, s (`engine::clock`).
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
    /// A vessel's navigation older than this (its newest fix before the motion's time) is stale: the
    /// system's pose falls back (flag `navigation_fallback`), s.
    pub max_navigation_age_s: f64,
    /// The pose at a forecast's start is a straight line through this much of the newest fixes, s.
    pub navigation_window_s: f64,
    /// Radar scans (`<prefix>/elevation`) of one grid inverted together into a field.
    pub radar_snapshots: u32,
    /// The model's error, as a fraction of each motion's standard deviation, until the daemon has
    /// learnt it from its own forecasts (`rom::spread::ModelError`): the floor of the forecast's band,
    /// growing in proportion to the lead beyond 30 s.
    pub model_error: f64,
    /// A lead is trusted while the forecast's expected normalized RMS error (its band's standard
    /// deviation over the motion's) is at most this, for heave, roll and pitch of the vessel.
    pub trusted_nrmse: f64,
}

impl Default for ForecastConfig {
    fn default() -> Self {
        ForecastConfig {
            period_s: 1.0,
            horizon_s: 120.0,
            dt_s: None,
            radiation: "convolution".into(),
            memory_s: None,
            max_wave_age_s: 10.0,
            suppress_wave_age_s: 30.0,
            max_motion_age_s: 2.0,
            max_gap_s: 2.0,
            drift_window_s: crate::rom::drift::DRIFT_WINDOW_S,
            history_margin_s: 10.0,
            wave_variance_kept: 0.995,
            max_clock_skew_s: 1.0,
            max_clock_lag_s: 30.0,
            clock_resync_samples: 5,
            max_clock_rate: None,
            max_dropped_wave_share: 0.1,
            max_navigation_age_s: 5.0,
            navigation_window_s: 30.0,
            radar_snapshots: 3,
            model_error: 0.15,
            trusted_nrmse: 0.6,
        }
    }
}

/// The motion state estimator ([`crate::engine::estimator`]): how IMU samples become the state a
/// forecast starts from.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct EstimatorConfig {
    /// "kalman" (filter, smoother, gating, bias) or "raw" (the samples as they come, for comparison).
    pub method: crate::engine::estimator::Method,
    /// The motion sensor's noise (standard deviation): displacements, m and rad; velocities, m/s and
    /// rad/s.
    pub noise_m: f64,
    pub noise_rad: f64,
    pub velocity_noise_m_s: f64,
    pub velocity_noise_rad_s: f64,
    /// The largest acceleration of a translation, in g (rotations: over the radius of gyration).
    pub max_acceleration_g: f64,
    /// A change since the last estimate is allowed this many standard deviations beyond what the
    /// largest acceleration makes.
    pub gate_sigma: f64,
    /// This many refused samples in a row that agree are a real jump: the estimate restarts from them.
    pub reset_samples: u32,
    /// Time constant of the bias average (heave, roll, pitch), s.
    pub bias_time_s: f64,
    /// The largest bias the motion sensor's roll and pitch may have (installation misalignment and
    /// drift), rad: a measured mean heel or trim beyond the model's own by more is real, and the
    /// forecast keeps it less this.
    pub angle_bias_rad: f64,
    /// The motion sensor's drift: a bias that wanders (first-order Gauss-Markov), its standard
    /// deviation (translations m, rotations rad) and correlation time, s. What the bias average leaves
    /// of it widens the band at a forecast's start; what the average holds is how large a roll or
    /// pitch offset the sensor's bias may make (`rom::spread::heel_split`).
    pub drift_m: f64,
    pub drift_rad: f64,
    pub drift_time_s: f64,
}

impl Default for EstimatorConfig {
    fn default() -> Self {
        EstimatorConfig {
            method: crate::engine::estimator::Method::Kalman,
            noise_m: 0.01,
            noise_rad: 0.0005,
            velocity_noise_m_s: 0.01,
            velocity_noise_rad_s: 0.0005,
            max_acceleration_g: 2.0,
            gate_sigma: 5.0,
            reset_samples: 5,
            bias_time_s: 300.0,
            angle_bias_rad: 0.001,
            drift_m: 0.02,
            drift_rad: 0.0003,
            drift_time_s: 600.0,
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
    /// The truth's vessel system file (another database of the same bodies, its own damping), relative
    /// to the config file; None: the model's own (`[system] file`).
    pub truth_system: Option<String>,
    pub ramp_s: f64,
    /// The data clock at the start, UNIX seconds (None: the wall clock at the start).
    pub start_unix_s: Option<f64>,
    pub sea: SeaConfig,
    pub radar: RadarConfig,
    pub imu: ImuConfig,
    pub track: TrackConfig,
    pub navigation: NavigationConfig,
}

/// The simulated ships' track (`[simulate.track]`).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TrackConfig {
    /// Forward speed, m/s (default 0: keeping station).
    pub speed_m_s: f64,
    /// Compass heading of the system's +x at the start, deg (default: `[site]`'s).
    pub heading_deg: Option<f64>,
    /// Steady rate of turn, deg/s, positive to starboard (default 0).
    pub turn_deg_s: f64,
    /// The turn starts this long after the start, s (default 0).
    pub turn_start_s: f64,
}

impl Default for TrackConfig {
    fn default() -> Self {
        TrackConfig {
            speed_m_s: 0.0,
            heading_deg: None,
            turn_deg_s: 0.0,
            turn_start_s: 0.0,
        }
    }
}

/// The simulated navigation sensors (`[simulate.navigation]`).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct NavigationConfig {
    /// Fixes per second per vessel (0: none published).
    pub rate_hz: f64,
    /// Heading noise, deg (standard deviation).
    pub heading_noise_deg: f64,
    /// Position noise, m (standard deviation, each axis).
    pub position_noise_m: f64,
}

impl Default for NavigationConfig {
    fn default() -> Self {
        NavigationConfig {
            rate_hz: 1.0,
            heading_noise_deg: 0.1,
            position_noise_m: 1.0,
        }
    }
}

impl Default for SimulateConfig {
    fn default() -> Self {
        SimulateConfig {
            duration_s: 3600.0,
            speed: 1.0,
            seed: 1,
            damping_factor: 1.0,
            truth_system: None,
            ramp_s: 30.0,
            start_unix_s: None,
            sea: SeaConfig::default(),
            radar: RadarConfig::default(),
            imu: ImuConfig::default(),
            track: TrackConfig::default(),
            navigation: NavigationConfig::default(),
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
    /// The radar sees the second-order bound waves too.
    pub bound_waves: bool,
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
            bound_waves: true,
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
    /// What the simulated processor publishes: "components" (a wave field on `<prefix>/waves`) or
    /// "grid" (each scan on `<prefix>/elevation`, inverted by the daemon).
    pub output: String,
    /// No echo within this range of the antenna, m.
    pub blind_radius_m: f64,
    /// A sector masked by the superstructure: relative bearings [from, to], deg clockwise from the bow.
    pub masked_sector_deg: Option<[f64; 2]>,
    /// The antenna's height above the water, m: cells behind crests are shadowed (0: no shadowing).
    pub antenna_height_m: f64,
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
            output: "components".into(),
            blind_radius_m: 200.0,
            masked_sector_deg: None,
            antenna_height_m: 30.0,
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
    /// A wandering bias (first-order Gauss-Markov): standard deviations and correlation time.
    pub drift_m: f64,
    pub drift_rad: f64,
    pub drift_time_s: f64,
}

impl Default for ImuConfig {
    fn default() -> Self {
        ImuConfig {
            rate_hz: 10.0,
            noise_m: 0.01,
            noise_rad: 0.0005,
            bias_m: 0.0,
            bias_rad: 0.0,
            drift_m: 0.02,
            drift_rad: 0.0003,
            drift_time_s: 600.0,
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
    /// The confidence of a go: a step is inside its limits when, by the forecast's band, the
    /// probability that every channel is inside is at least this (0..1).
    pub confidence: f64,
}

impl Default for OperationConfig {
    fn default() -> Self {
        OperationConfig {
            duration_s: 60.0,
            channels: vec![],
            confidence: 0.9,
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

/// The ship-to-ship link (`shipcast link`): this host's iceoryx2 services bridged to the other ship's
/// over Zenoh.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LinkConfig {
    /// This ship's name on the link (unique among the operation's participants).
    pub name: String,
    /// The operation: Zenoh keys are `shipcast/<namespace>/<name>/<kind>`; links of another namespace
    /// see nothing of this one.
    pub namespace: String,
    /// Zenoh endpoints to listen on (`tcp/0.0.0.0:7447`).
    pub listen: Vec<String>,
    /// Zenoh endpoints of the other ship's link to connect to (`tcp/10.0.0.2:7447`); retried while
    /// it is away.
    pub connect: Vec<String>,
    /// The vessels (indices of the system file) whose motion and navigation are measured on this
    /// ship: sent out; the others' are taken in.
    pub own_vessels: Vec<u32>,
    /// Send this ship's forecasts and status.
    pub forecasts_out: bool,
    /// The iceoryx2 prefix the other ship's forecasts and status are published under here (default
    /// `<ipc.service_prefix>/peer`).
    pub peer_prefix: String,
    /// No message from the other ship for this long: the link is down, s.
    pub stale_s: f64,
    /// Latency and loss are over this window, s.
    pub window_s: f64,
}

impl Default for LinkConfig {
    fn default() -> Self {
        LinkConfig {
            name: "ship".into(),
            namespace: "shipcast".into(),
            listen: vec![],
            connect: vec![],
            own_vessels: vec![0],
            forecasts_out: true,
            peer_prefix: String::new(),
            stale_s: 2.0,
            window_s: 30.0,
        }
    }
}

impl LinkConfig {
    /// The prefix of the other ship's forecasts and status here.
    pub fn peer_prefix_of(&self, ipc: &IpcConfig) -> String {
        if self.peer_prefix.is_empty() {
            format!("{}/peer", ipc.service_prefix)
        } else {
            self.peer_prefix.clone()
        }
    }
}

/// A Zenoh key chunk: not empty, no `/`, `*`, `$`, `?`, `#` (they mean something in key expressions).
fn check_key_chunk(what: &str) -> Result<(), String> {
    if what.is_empty() || what.len() > 100 || what.chars().any(|c| "/*$?#".contains(c) || c.is_whitespace()) {
        return Err(format!(
            "\"{what}\" is not a Zenoh key chunk: 1..100 characters, none of / * $ ? # or spaces"
        ));
    }
    Ok(())
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
const ENV_NOT_KEYS: [&str; 3] = ["SHIPCAST_CONFIG", "SHIPCAST_LOG", crate::service::FAULT_ENV];

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
    // the `config` crate coerces types (a boolean where a number is expected is 0 or 1): the file
    // again with the TOML types as written, and no boolean in a variable for a numeric key
    let text = std::fs::read_to_string(path).map_err(|e| Error::Read {
        file: file.clone(),
        msg: e.to_string(),
    })?;
    if let Err(e) = toml::from_str::<ShipcastConfig>(&text) {
        let (key, line) = toml_key_at(&text, e.span().map_or(0, |s| s.start));
        return Err(Error::Key {
            file: format!("{file}:{line}"),
            key,
            msg: e.message().to_string(),
        });
    }
    for (k, v) in &vars {
        let key = k[ENV_PREFIX.len()..].to_ascii_lowercase().replace("__", ".");
        let word = v.trim().to_ascii_lowercase();
        if is_numeric_key(&key) && ["true", "false", "yes", "no", "on", "off"].contains(&word.as_str()) {
            return Err(Error::Key {
                file: format!("environment variable {k}={v:?}"),
                key,
                msg: format!("expected a number, found the boolean `{v}`"),
            });
        }
    }
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

/// A numeric key's accepted range: a finite number from `min` (excluded when `open`) to `max`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bound {
    pub key: &'static str,
    pub min: f64,
    pub open: bool,
    pub max: f64,
    pub unit: &'static str,
}

const fn closed(key: &'static str, min: f64, max: f64, unit: &'static str) -> Bound {
    Bound {
        key,
        min,
        open: false,
        max,
        unit,
    }
}

const fn positive(key: &'static str, max: f64, unit: &'static str) -> Bound {
    Bound {
        key,
        min: 0.0,
        open: true,
        max,
        unit,
    }
}

impl Bound {
    pub fn contains(&self, v: f64) -> bool {
        v.is_finite() && (v > self.min || (!self.open && v == self.min)) && v <= self.max
    }

    /// `[min, max] unit` or `(min, max] unit`.
    pub fn range(&self) -> String {
        let unit = if self.unit.is_empty() {
            String::new()
        } else {
            format!(" {}", self.unit)
        };
        format!("{}{}, {}]{unit}", if self.open { "(" } else { "[" }, self.min, self.max)
    }
}

/// One day, s.
const DAY_S: f64 = 86_400.0;

/// Every numeric key but `forecast.dt_s` and `forecast.memory_s` (checked by
/// [`crate::rom::RomOptions::validate`], the same check as the CLI's) and `simulate.seed` (any u64), with
/// why its range is what it is. `config/shipcast.toml` repeats each range beside its key.
pub const BOUNDS: &[Bound] = &[
    // half the earth's circumference: any place on it
    closed("site.origin_east_m", -2.0e7, 2.0e7, "m"),
    closed("site.origin_north_m", -2.0e7, 2.0e7, "m"),
    // a compass angle, one turn either way
    closed("site.heading_deg", -360.0, 360.0, "deg"),
    // 20 forecasts a second at most (the tick, the IPC and the compute thread); a minute at least
    closed("forecast.period_s", 0.05, 60.0, "s"),
    // a forecast's buffers are steps x states: rom::forecast::MAX_FORECAST_LENGTH_S
    positive("forecast.horizon_s", crate::rom::forecast::MAX_FORECAST_LENGTH_S, "s"),
    // an hour-old sea is no sea: and the ages are compared with the data clock, not sized
    positive("forecast.max_wave_age_s", 3600.0, "s"),
    positive("forecast.suppress_wave_age_s", 3600.0, "s"),
    positive("forecast.max_motion_age_s", 3600.0, "s"),
    // a bridged gap is a curve through the motion at both ends: longer than a minute, it is invented
    positive("forecast.max_gap_s", 60.0, "s"),
    // the drift's mean velocity: over an hour it is no longer the present drift
    closed("forecast.drift_window_s", 0.0, 3600.0, "s"),
    // samples kept beyond the memory: sizes the history (rate x time per vessel)
    closed("forecast.history_margin_s", 0.0, 3600.0, "s"),
    closed("forecast.wave_variance_kept", 1e-6, 1.0, ""),
    // clock offsets between sources and the daemon: stamps an hour off are not a skew but a wrong clock
    positive("forecast.max_clock_skew_s", 3600.0, "s"),
    positive("forecast.max_clock_lag_s", 3600.0, "s"),
    // refused samples in a row before a clock step is believed: a few seconds of motion at 1000 Hz
    closed("forecast.clock_resync_samples", 1.0, 1000.0, ""),
    // how much faster than the daemon's a source's clock may run: a simulator at its speed
    closed("forecast.max_clock_rate", 1.0, 1000.0, ""),
    closed("forecast.max_dropped_wave_share", 0.0, 1.0, ""),
    // a fix is 0.1-1 s apart; an hour-old pose is no pose
    positive("forecast.max_navigation_age_s", 3600.0, "s"),
    // at least a few fixes, at most ten minutes of a turn
    closed("forecast.navigation_window_s", 1.0, 600.0, "s"),
    // two tell opposite directions apart; more than a minute of 2 s scans adds nothing
    closed("forecast.radar_snapshots", 2.0, 32.0, ""),
    // a model off by its own motion is no model
    closed("forecast.model_error", 0.0, 1.0, ""),
    // an expected error as large as the motion itself is no forecast
    positive("forecast.trusted_nrmse", 1.0, ""),
    // a sensor's noise: beyond these it measures nothing of a ship's motion
    positive("estimator.noise_m", 10.0, "m"),
    positive("estimator.noise_rad", 1.0, "rad"),
    positive("estimator.velocity_noise_m_s", 10.0, "m/s"),
    positive("estimator.velocity_noise_rad_s", 1.0, "rad/s"),
    // a tenth of g would refuse a ship's own motion in a storm; beyond 100 g is a crash, not a sea
    closed("estimator.max_acceleration_g", 0.1, 100.0, "g"),
    closed("estimator.gate_sigma", 1.0, 100.0, ""),
    // refused samples in a row before a jump is believed: a few seconds of motion at 1000 Hz
    closed("estimator.reset_samples", 1.0, 1000.0, ""),
    positive("estimator.bias_time_s", DAY_S, "s"),
    // a radio link's outage is told from its jitter in a second or two; an hour is no link
    positive("link.stale_s", 3600.0, "s"),
    positive("link.window_s", DAY_S, "s"),
    closed("estimator.angle_bias_rad", 0.0, 0.1, "rad"),
    closed("estimator.drift_m", 0.0, 10.0, "m"),
    closed("estimator.drift_rad", 0.0, 1.0, "rad"),
    positive("estimator.drift_time_s", DAY_S, "s"),
    // a terabyte of messages per file at most
    positive("record.rotate_mb", 1.0e6, "MB"),
    positive("record.rotate_s", 30.0 * DAY_S, "s"),
    // the simulation's truth is kept whole: a week at 10 Hz is about 6 million samples per DOF
    positive("simulate.duration_s", 7.0 * DAY_S, "s"),
    positive("simulate.speed", 1000.0, ""),
    positive("simulate.damping_factor", 100.0, ""),
    closed("simulate.ramp_s", 0.0, 3600.0, "s"),
    // UNIX time from 1970 to the year 2286 (f64 seconds keep microseconds there)
    positive("simulate.start_unix_s", 1.0e10, "s"),
    // the highest wave ever measured is about 30 m
    positive("simulate.sea.hs_m", 30.0, "m"),
    closed("simulate.sea.tp_s", 1.0, 30.0, "s"),
    // JONSWAP's peak enhancement: 1 (Pierson-Moskowitz) to 10, beyond any fitted sea
    closed("simulate.sea.gamma", 1.0, 10.0, ""),
    closed("simulate.sea.towards_deg", -360.0, 360.0, "deg"),
    positive("simulate.sea.spreading_s", 100.0, ""),
    // each component is a sinusoid in every force evaluation and on the wire
    closed("simulate.sea.components", 1.0, 10_000.0, ""),
    positive("simulate.sea.omega_min_rad_s", 10.0, "rad/s"),
    positive("simulate.sea.omega_max_rad_s", 10.0, "rad/s"),
    positive("simulate.radar.radius_m", 20_000.0, "m"),
    // cells x cells grid per snapshot, FFT-inverted
    closed("simulate.radar.cells", 8.0, 1024.0, ""),
    closed("simulate.radar.period_s", 0.1, 60.0, "s"),
    closed("simulate.radar.noise_m", 0.0, 10.0, "m"),
    closed("simulate.radar.snapshots", 1.0, 64.0, ""),
    // 0: no grid recorded; a recorded grid is cells x cells floats
    closed("simulate.radar.record_grid_every", 0.0, 1.0e6, ""),
    // a motion sample per IMU tick goes through the IPC and the history
    positive("simulate.imu.rate_hz", 1000.0, "Hz"),
    closed("simulate.imu.noise_m", 0.0, 10.0, "m"),
    closed("simulate.imu.noise_rad", 0.0, 1.0, "rad"),
    closed("simulate.imu.bias_m", -10.0, 10.0, "m"),
    closed("simulate.imu.bias_rad", -1.0, 1.0, "rad"),
    closed("simulate.imu.drift_m", 0.0, 10.0, "m"),
    closed("simulate.imu.drift_rad", 0.0, 1.0, "rad"),
    positive("simulate.imu.drift_time_s", 86_400.0, "s"),
    closed("simulate.radar.antenna_height_m", 0.0, 200.0, "m"),
    // the radar's range at most (simulate.radar.radius_m's bound)
    closed("simulate.radar.blind_radius_m", 0.0, 20000.0, "m"),
    // rom::model::MAX_SPEED_M_S (50 knots); astern allowed
    closed("simulate.track.speed_m_s", -25.0, 25.0, "m/s"),
    closed("simulate.track.heading_deg", -360.0, 360.0, "deg"),
    // rom::forecast::MAX_TURN_RATE_RAD_S
    closed("simulate.track.turn_deg_s", -10.0, 10.0, "deg/s"),
    closed("simulate.track.turn_start_s", 0.0, DAY_S, "s"),
    // a GNSS/gyro gives 1-10 Hz; 0: no navigation stream
    closed("simulate.navigation.rate_hz", 0.0, 100.0, "Hz"),
    closed("simulate.navigation.heading_noise_deg", 0.0, 10.0, "deg"),
    closed("simulate.navigation.position_noise_m", 0.0, 100.0, "m"),
    positive("operation.duration_s", DAY_S, "s"),
    // a probability: 0.5 is a coin, 0.999 asks the band for more than its calibration gives
    closed("operation.confidence", 0.5, 0.999, ""),
    // m, or deg for rotations: beyond this every motion is inside
    positive("operation.channels.limit", 1.0e4, "m or deg"),
    positive("console.history_s", 3600.0, "s"),
];

/// The bound of a key.
pub fn bound(key: &str) -> Option<&'static Bound> {
    BOUNDS.iter().find(|b| b.key == key)
}

/// Every numeric key of the table with its value (`None`: not set), as (bound key, key as named).
fn numbers(c: &ShipcastConfig) -> Vec<(&'static str, String, Option<f64>)> {
    let f = &c.forecast;
    let s = &c.simulate;
    let one = |k: &'static str, v: f64| (k, k.to_string(), Some(v));
    let mut out = vec![
        one("site.origin_east_m", c.site.origin_east_m),
        one("site.origin_north_m", c.site.origin_north_m),
        one("site.heading_deg", c.site.heading_deg),
        one("forecast.period_s", f.period_s),
        one("forecast.horizon_s", f.horizon_s),
        one("forecast.max_wave_age_s", f.max_wave_age_s),
        one("forecast.suppress_wave_age_s", f.suppress_wave_age_s),
        one("forecast.max_motion_age_s", f.max_motion_age_s),
        one("forecast.max_gap_s", f.max_gap_s),
        one("forecast.drift_window_s", f.drift_window_s),
        one("forecast.history_margin_s", f.history_margin_s),
        one("forecast.wave_variance_kept", f.wave_variance_kept),
        one("forecast.max_clock_skew_s", f.max_clock_skew_s),
        one("forecast.max_clock_lag_s", f.max_clock_lag_s),
        one("forecast.clock_resync_samples", f.clock_resync_samples as f64),
        (
            "forecast.max_clock_rate",
            "forecast.max_clock_rate".to_string(),
            f.max_clock_rate,
        ),
        one("forecast.max_dropped_wave_share", f.max_dropped_wave_share),
        one("forecast.max_navigation_age_s", f.max_navigation_age_s),
        one("forecast.navigation_window_s", f.navigation_window_s),
        one("forecast.radar_snapshots", f.radar_snapshots as f64),
        one("forecast.model_error", f.model_error),
        one("forecast.trusted_nrmse", f.trusted_nrmse),
        one("estimator.noise_m", c.estimator.noise_m),
        one("estimator.noise_rad", c.estimator.noise_rad),
        one("estimator.velocity_noise_m_s", c.estimator.velocity_noise_m_s),
        one("estimator.velocity_noise_rad_s", c.estimator.velocity_noise_rad_s),
        one("estimator.max_acceleration_g", c.estimator.max_acceleration_g),
        one("estimator.gate_sigma", c.estimator.gate_sigma),
        one("estimator.reset_samples", c.estimator.reset_samples as f64),
        one("estimator.bias_time_s", c.estimator.bias_time_s),
        one("link.stale_s", c.link.stale_s),
        one("link.window_s", c.link.window_s),
        one("estimator.angle_bias_rad", c.estimator.angle_bias_rad),
        one("estimator.drift_m", c.estimator.drift_m),
        one("estimator.drift_rad", c.estimator.drift_rad),
        one("estimator.drift_time_s", c.estimator.drift_time_s),
        one("record.rotate_mb", c.record.rotate_mb),
        ("record.rotate_s", "record.rotate_s".into(), c.record.rotate_s),
        one("simulate.duration_s", s.duration_s),
        one("simulate.speed", s.speed),
        one("simulate.damping_factor", s.damping_factor),
        one("simulate.ramp_s", s.ramp_s),
        ("simulate.start_unix_s", "simulate.start_unix_s".into(), s.start_unix_s),
        one("simulate.sea.hs_m", s.sea.hs_m),
        one("simulate.sea.tp_s", s.sea.tp_s),
        one("simulate.sea.gamma", s.sea.gamma),
        one("simulate.sea.towards_deg", s.sea.towards_deg),
        (
            "simulate.sea.spreading_s",
            "simulate.sea.spreading_s".into(),
            s.sea.spreading_s,
        ),
        one("simulate.sea.components", s.sea.components as f64),
        one("simulate.sea.omega_min_rad_s", s.sea.omega_min_rad_s),
        one("simulate.sea.omega_max_rad_s", s.sea.omega_max_rad_s),
        one("simulate.radar.radius_m", s.radar.radius_m),
        one("simulate.radar.cells", s.radar.cells as f64),
        one("simulate.radar.period_s", s.radar.period_s),
        one("simulate.radar.noise_m", s.radar.noise_m),
        one("simulate.radar.snapshots", s.radar.snapshots as f64),
        one("simulate.radar.record_grid_every", s.radar.record_grid_every as f64),
        one("simulate.imu.rate_hz", s.imu.rate_hz),
        one("simulate.imu.noise_m", s.imu.noise_m),
        one("simulate.imu.noise_rad", s.imu.noise_rad),
        one("simulate.imu.bias_m", s.imu.bias_m),
        one("simulate.imu.bias_rad", s.imu.bias_rad),
        one("simulate.imu.drift_m", s.imu.drift_m),
        one("simulate.imu.drift_rad", s.imu.drift_rad),
        one("simulate.imu.drift_time_s", s.imu.drift_time_s),
        one("simulate.radar.antenna_height_m", s.radar.antenna_height_m),
        one("simulate.radar.blind_radius_m", s.radar.blind_radius_m),
        one("simulate.track.speed_m_s", s.track.speed_m_s),
        (
            "simulate.track.heading_deg",
            "simulate.track.heading_deg".into(),
            s.track.heading_deg,
        ),
        one("simulate.track.turn_deg_s", s.track.turn_deg_s),
        one("simulate.track.turn_start_s", s.track.turn_start_s),
        one("simulate.navigation.rate_hz", s.navigation.rate_hz),
        one("simulate.navigation.heading_noise_deg", s.navigation.heading_noise_deg),
        one("simulate.navigation.position_noise_m", s.navigation.position_noise_m),
        one("operation.duration_s", c.operation.duration_s),
        one("operation.confidence", c.operation.confidence),
        one("console.history_s", c.console.history_s),
    ];
    for (i, ch) in c.operation.channels.iter().enumerate() {
        out.push((
            "operation.channels.limit",
            format!("operation.channels[{i}].limit"),
            Some(ch.limit),
        ));
    }
    out
}

/// Keys whose value is a number (a boolean there is an error, not 0 or 1).
fn is_numeric_key(key: &str) -> bool {
    bound(key).is_some() || ["forecast.dt_s", "forecast.memory_s", "simulate.seed"].contains(&key)
}

/// Level names `log.level` takes alone or beside `target=level` directives.
const LOG_LEVELS: [&str; 6] = ["trace", "debug", "info", "warn", "error", "off"];

/// `log.level`: level names and `target=level` directives, comma-separated, as tracing's EnvFilter reads
/// them; a bare word must be a level name (EnvFilter would take it for a target and log nothing else).
fn check_log_level(level: &str) -> Result<(), String> {
    for part in level.split(',') {
        let p = part.trim();
        if !p.contains('=') && !LOG_LEVELS.contains(&p.to_ascii_lowercase().as_str()) {
            return Err(format!(
                "`{p}` is not a level: expected one of {} or `target=level` directives, found \"{level}\"",
                LOG_LEVELS.join(", ")
            ));
        }
    }
    tracing_subscriber::EnvFilter::try_new(level)
        .map(|_| ())
        .map_err(|e| format!("not a log filter: \"{level}\": {e}"))
}

/// The service names the prefix makes, as iceoryx2 parses them.
fn check_service_prefix(prefix: &str) -> Result<(), String> {
    for kind in ["motion", "waves", "forecast", "status"] {
        let name = format!("{prefix}/{kind}");
        if let Err(e) = iceoryx2::prelude::ServiceName::new(&name) {
            return Err(format!(
                "\"{prefix}\" does not make an iceoryx2 service name (`{name}`: {e:?}; ASCII without NUL, at most {} bytes, not starting with `iox2://`)",
                iceoryx2::constants::MAX_SERVICE_NAME_LENGTH
            ));
        }
    }
    Ok(())
}

/// The key and line (1-based) of a byte offset of a TOML text: `section.key` from the last table
/// header before it and the key on its line.
fn toml_key_at(text: &str, offset: usize) -> (String, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let mut section = String::new();
    for l in before.lines() {
        let l = l.trim();
        if l.starts_with('[') && !l.starts_with("[[") {
            section = l.trim_matches(|ch| ch == '[' || ch == ']').trim().to_string();
        }
    }
    let this = text.lines().nth(line - 1).unwrap_or("");
    let key = this.split('=').next().unwrap_or("").trim();
    let full = match (section.is_empty(), key.is_empty()) {
        (_, true) => section,
        (true, false) => key.to_string(),
        (false, false) => format!("{section}.{key}"),
    };
    (full, line)
}

fn validate(c: &ShipcastConfig) -> Result<(), (String, String)> {
    for (bkey, key, v) in numbers(c) {
        let (Some(v), Some(b)) = (v, bound(bkey)) else {
            continue;
        };
        if !b.contains(v) {
            return Err((key, format!("must be in {}, found {v:?}", b.range())));
        }
    }
    let f = &c.forecast;
    // the default step is the system's (known once it is loaded): the longest it can be stands in
    crate::engine::options_at(c, f.dt_s.unwrap_or(crate::rom::step::MAX_DEFAULT_DT_S))
        .validate()
        .map_err(|e| (format!("forecast.{}", e.field), e.msg))?;
    let dt_s = f.dt_s.unwrap_or(crate::rom::step::MAX_DEFAULT_DT_S);
    let steps = f.horizon_s / dt_s;
    if steps > crate::rom::forecast::MAX_FORECAST_STEPS as f64 {
        return Err((
            "forecast.horizon_s".into(),
            format!(
                "{} s at forecast.dt_s = {} s is {steps:.0} steps, more than {}",
                f.horizon_s,
                dt_s,
                crate::rom::forecast::MAX_FORECAST_STEPS
            ),
        ));
    }
    if f.suppress_wave_age_s < f.max_wave_age_s {
        return Err((
            "forecast.suppress_wave_age_s".into(),
            format!(
                "must be at least forecast.max_wave_age_s ({} s), found {}",
                f.max_wave_age_s, f.suppress_wave_age_s
            ),
        ));
    }
    if !["convolution", "state-space"].contains(&f.radiation.as_str()) {
        return Err((
            "forecast.radiation".into(),
            format!("expected \"convolution\" or \"state-space\", found \"{}\"", f.radiation),
        ));
    }
    if !["components", "grid"].contains(&c.simulate.radar.output.as_str()) {
        return Err((
            "simulate.radar.output".into(),
            format!(
                "expected \"components\" or \"grid\", found \"{}\"",
                c.simulate.radar.output
            ),
        ));
    }
    if let Some(m) = c.simulate.radar.masked_sector_deg
        && m.iter().any(|v| !(v.is_finite() && v.abs() <= 360.0))
    {
        return Err((
            "simulate.radar.masked_sector_deg".into(),
            format!("two relative bearings in [-360, 360] deg, found {m:?}"),
        ));
    }
    if !["human", "json"].contains(&c.log.format.as_str()) {
        return Err((
            "log.format".into(),
            format!("expected \"human\" or \"json\", found \"{}\"", c.log.format),
        ));
    }
    check_log_level(&c.log.level).map_err(|m| ("log.level".to_string(), m))?;
    if c.ipc.service_prefix.is_empty() || c.ipc.service_prefix.len() > 200 {
        return Err(("ipc.service_prefix".into(), "must be 1..200 characters".into()));
    }
    check_service_prefix(&c.ipc.service_prefix).map_err(|m| ("ipc.service_prefix".to_string(), m))?;
    check_key_chunk(&c.link.name).map_err(|m| ("link.name".to_string(), m))?;
    check_key_chunk(&c.link.namespace).map_err(|m| ("link.namespace".to_string(), m))?;
    if !c.link.peer_prefix.is_empty() {
        check_service_prefix(&c.link.peer_prefix).map_err(|m| ("link.peer_prefix".to_string(), m))?;
        if c.link.peer_prefix == c.ipc.service_prefix {
            return Err((
                "link.peer_prefix".into(),
                format!(
                    "\"{}\" is ipc.service_prefix: the other ship's forecasts would be taken for this ship's and sent back",
                    c.link.peer_prefix
                ),
            ));
        }
    }
    if let Some(v) = c
        .link
        .own_vessels
        .iter()
        .find(|v| **v as usize >= crate::ipc::wire::MAX_VESSELS)
    {
        return Err((
            "link.own_vessels".into(),
            format!("vessel {v}: indices 0..{}", crate::ipc::wire::MAX_VESSELS),
        ));
    }
    c.console.colours.parse()?;
    let sea = &c.simulate.sea;
    if sea.omega_min_rad_s >= sea.omega_max_rad_s {
        return Err((
            "simulate.sea.omega_max_rad_s".into(),
            format!(
                "must be above simulate.sea.omega_min_rad_s ({} rad/s), found {}",
                sea.omega_min_rad_s, sea.omega_max_rad_s
            ),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every key of the table is checked, and every checked key has a bound.
    #[test]
    fn every_numeric_key_has_one_bound() {
        let mut c: ShipcastConfig = toml::from_str("[system]\nfile = \"s.toml\"\n").unwrap();
        c.operation.channels.push(ChannelConfig {
            name: "a.heave".into(),
            limit: 1.0,
        });
        c.record.rotate_s = Some(1.0);
        c.simulate.sea.spreading_s = Some(1.0);
        c.simulate.start_unix_s = Some(1.75e9);
        let keys: Vec<&str> = numbers(&c).iter().map(|n| n.0).collect();
        for b in BOUNDS {
            assert_eq!(keys.iter().filter(|k| **k == b.key).count(), 1, "{}", b.key);
        }
        for k in keys {
            assert!(bound(k).is_some(), "{k}");
        }
        validate(&c).unwrap();
    }

    #[test]
    fn log_levels() {
        for ok in ["info", "WARN", "shipcast=debug,warn", "off"] {
            check_log_level(ok).unwrap();
        }
        for bad in ["loud", "info,loud", "shipcast=loud"] {
            assert!(check_log_level(bad).is_err(), "{bad}");
        }
    }
}
