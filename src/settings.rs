//! The configuration's values (pure): `config/shipcast.toml`'s sections as plain serde types with their
//! defaults, the daemon's, the simulator's and the watcher's. Reading them from the file and the
//! environment, and checking every key's bounds, is the shell's ([`crate::shell::config`]). Every key,
//! its unit and default: `config/shipcast.toml`.

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
    pub state: StateConfig,
    #[serde(default)]
    pub simulate: SimulateConfig,
    #[serde(default)]
    pub operation: OperationConfig,
    #[serde(default)]
    pub console: ConsoleConfig,
    #[serde(default)]
    pub link: LinkConfig,
    /// Directory of the config file (relative paths are resolved against it); set by [`crate::shell::config::load`].
    #[serde(skip)]
    pub dir: PathBuf,
    /// The config file itself, as given; set by [`crate::shell::config::load`] (for messages that name it).
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
    /// Tune each vessel's roll damping and natural frequency in situ from the daemon's own past
    /// forecasts against the measured roll ([`crate::tuning`]).
    pub tune_roll: bool,
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
    /// The most radar scans (`<prefix>/elevation`) of one grid inverted together into a field: the
    /// window takes as many of the newest as the blind zone needs (`waves::window::window_scans`).
    pub radar_snapshots: u32,
    /// The model's error, as a fraction of each motion's standard deviation, until the daemon has
    /// learnt it from its own forecasts (`band::ModelError`): the floor of the forecast's band,
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
            radar_snapshots: 48,
            tune_roll: true,
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
    /// pitch offset the sensor's bias may make (`band::heel_split`).
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

/// What the daemon keeps of its learnt state across a restart ([`crate::engine::state`]).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct StateConfig {
    /// Directory of the state file (relative to the config file); empty: systemd's
    /// `STATE_DIRECTORY` when it sets one, else none is kept.
    pub dir: String,
    /// The state is written this often, s (and at a clean stop).
    pub every_s: f64,
}

impl Default for StateConfig {
    fn default() -> Self {
        StateConfig {
            dir: String::new(),
            every_s: 60.0,
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
            snapshots: 48,
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
pub fn check_key_chunk(what: &str) -> Result<(), String> {
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
