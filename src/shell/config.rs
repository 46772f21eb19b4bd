//! Loading `config/shipcast.toml` (shell): read with the `config` crate (the TOML file, then
//! `SHIPCAST_<SECTION>__<KEY>` environment variables over it) and validated with messages that name
//! the key. The values themselves are [`crate::settings`]' (re-exported here).

pub use crate::settings::*;
use std::path::Path;

/// Fault injection for the tests of the daemon's liveness: `SHIPCAST_FAULT=compute-panic` makes the
/// daemon's compute thread panic on its first job (the daemon ends with an error),
/// `SHIPCAST_FAULT=compute-hang` makes it never finish its first job (the watchdog stops being fed).
pub const FAULT_ENV: &str = "SHIPCAST_FAULT";

/// The environment variables that overlay the file: `SHIPCAST_<SECTION>__<KEY>` (e.g.
/// `SHIPCAST_FORECAST__PERIOD_S=0.5`). `SHIPCAST_CONFIG` (the file's path, read by the CLI),
/// `SHIPCAST_LOG` and [`FAULT_ENV`] are not keys and are left out.
pub const ENV_PREFIX: &str = "SHIPCAST_";
const ENV_NOT_KEYS: [&str; 3] = ["SHIPCAST_CONFIG", "SHIPCAST_LOG", FAULT_ENV];

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
    // the file with the TOML types as written first (the `config` crate coerces types, a boolean
    // where a number is expected is 0 or 1, and names neither the key nor the line of a number
    // beyond a float's range), and no boolean in a variable for a numeric key
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
    let mut cfg = build(&[]).map_err(|msg| Error::Read {
        file: file.clone(),
        msg,
    })?;
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
    validate(&cfg).map_err(|(key, msg)| {
        // a value an environment variable set is the variable's, not the file's
        let from_env = vars
            .iter()
            .find(|(k, _)| k[ENV_PREFIX.len()..].to_ascii_lowercase().replace("__", ".") == key);
        Error::Key {
            file: from_env.map_or_else(
                || file.clone(),
                |(k, v)| format!("environment variable {k}={v:?} (overlaying {file})"),
            ),
            key,
            msg,
        }
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
    // two tell opposite directions apart; two minutes of 2 s scans fill a 400 m blind zone at the
    // slowest groups of a sea
    closed("forecast.radar_snapshots", 2.0, 64.0, ""),
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
    positive("state.every_s", DAY_S, "s"),
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

/// A numeric key of the table: (bound key, key as named, value; `None`: not set).
type Number = (&'static str, String, Option<f64>);

/// A key named as its bound, set to `v`.
fn one(k: &'static str, v: f64) -> Number {
    (k, k.to_string(), Some(v))
}

/// Every numeric key of the table with its value (`None`: not set), as (bound key, key as named).
fn numbers(c: &ShipcastConfig) -> Vec<(&'static str, String, Option<f64>)> {
    let mut out = site_and_forecast_numbers(c);
    out.extend(estimator_link_record_numbers(c));
    out.extend(simulate_numbers(c));
    out.extend(simulate_sensor_numbers(c));
    out.extend(operation_console_numbers(c));
    out
}

/// The numeric keys of `[site]` and `[forecast]`, in the table's order.
fn site_and_forecast_numbers(c: &ShipcastConfig) -> Vec<Number> {
    let f = &c.forecast;
    vec![
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
    ]
}

/// The numeric keys of `[estimator]`, `[link]` and `[record]`, in the table's order.
fn estimator_link_record_numbers(c: &ShipcastConfig) -> Vec<Number> {
    vec![
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
        one("state.every_s", c.state.every_s),
    ]
}

/// The numeric keys of `[simulate]` itself and of `[simulate.sea]`, in the table's order.
fn simulate_numbers(c: &ShipcastConfig) -> Vec<Number> {
    let s = &c.simulate;
    vec![
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
    ]
}

/// The numeric keys of the simulated sensors and track (`[simulate.radar]`, `.imu`, `.track`,
/// `.navigation`), in the table's order.
fn simulate_sensor_numbers(c: &ShipcastConfig) -> Vec<Number> {
    let s = &c.simulate;
    vec![
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
    ]
}

/// The numeric keys of `[operation]` and `[console]`, then each operation channel's limit, in the
/// table's order.
fn operation_console_numbers(c: &ShipcastConfig) -> Vec<Number> {
    let mut out = vec![
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
    check_bounds(c)?;
    check_forecast(c)?;
    check_simulate_radar(c)?;
    check_log_and_ipc(c)?;
    check_link(c)?;
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

/// Every numeric key that is set is within its bound ([`BOUNDS`]); the error names the first that is not.
fn check_bounds(c: &ShipcastConfig) -> Result<(), (String, String)> {
    for (bkey, key, v) in numbers(c) {
        let (Some(v), Some(b)) = (v, bound(bkey)) else {
            continue;
        };
        if !b.contains(v) {
            return Err((key, format!("must be in {}, found {v:?}", b.range())));
        }
    }
    Ok(())
}

/// `[forecast]`: the model's options, the number of steps of the horizon, the wave ages' order and
/// the radiation's name.
fn check_forecast(c: &ShipcastConfig) -> Result<(), (String, String)> {
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
    Ok(())
}

/// `[simulate.radar]`: the output's name and the masked sector's bearings.
fn check_simulate_radar(c: &ShipcastConfig) -> Result<(), (String, String)> {
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
    Ok(())
}

/// `[log]`'s format and level, and `[ipc]`'s service prefix.
fn check_log_and_ipc(c: &ShipcastConfig) -> Result<(), (String, String)> {
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
    Ok(())
}

/// `[link]`: its name and namespace, the other ship's prefix (not this ship's) and this ship's vessels.
fn check_link(c: &ShipcastConfig) -> Result<(), (String, String)> {
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
        .find(|v| **v as usize >= crate::shell::ipc::wire::MAX_VESSELS)
    {
        return Err((
            "link.own_vessels".into(),
            format!("vessel {v}: indices 0..{}", crate::shell::ipc::wire::MAX_VESSELS),
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
