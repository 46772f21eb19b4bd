//! The messages the engine takes and gives: plain Rust values, `#[repr(C)]` so that the wire
//! ([`crate::shell::ipc::wire`], the one place that marks them for iceoryx2 and names their stable type names)
//! sends them as they are, and a C, C++ or Python subscriber declares the same layout field by field.
//!
//! Conventions: units SI; times are seconds on the sensors' clock (the data clock: UNIX seconds for
//! live sensors); frames as in DESIGN.md section 1 (earth: x east, y north; directions
//! counterclockwise from east, travel-to; body: x forward, y port, z up; DOFs surge, sway, heave,
//! roll, pitch, yaw). A reader checks `schema_version` first and refuses what it does not know.

use crate::waves::field::WaveField;

/// Schema version of the motion, navigation and elevation payloads.
pub const SCHEMA_VERSION: u32 = 1;
/// Schema version of the waves payload (2: the radar's blind zone and coverage).
pub const WAVES_SCHEMA_VERSION: u32 = 2;
/// Schema version of the forecast payload (2: the standard deviations after the displacements, the
/// start of each vessel's trusted span; 3: each series' own trusted span).
pub const FORECAST_SCHEMA_VERSION: u32 = 3;
/// Schema version of [`Status`] (2: the drop counters by reason and the clock steps; 3: the motion
/// estimator's refusals, restarts and bias).
pub const STATUS_SCHEMA_VERSION: u32 = 6;
/// Vessels a forecast or status can describe.
pub const MAX_VESSELS: usize = 4;
/// The most components a wave field may carry: the wavenumber bins of a 256 x 256 radar grid. A field
/// with more is refused (each component is a sinusoid in every forecast's wave force, and the
/// forecaster's buffers grow to the largest field seen).
pub const MAX_WAVE_COMPONENTS: usize = 65_536;

/// The one check of a wave field's size, for the decoder (before it allocates) and the engine (fields
/// from a log).
pub fn check_wave_components(n: usize) -> Result<(), String> {
    if n > MAX_WAVE_COMPONENTS {
        return Err(format!(
            "wave field of {n} components, more than {MAX_WAVE_COMPONENTS} (a 256 x 256 radar grid's wavenumber bins)"
        ));
    }
    Ok(())
}

/// Quality flags of forecasts and status (bits).
pub mod flags {
    /// The newest wave field is older than `max_wave_age_s`.
    pub const STALE_WAVES: u32 = 1;
    /// A vessel's newest motion sample is older than `max_motion_age_s` (the status's `motion_age_s`
    /// says which): a forecast starts it from rest and trusts it nowhere (its horizon 0).
    pub const STALE_MOTION: u32 = 2;
    /// Less motion history than the radiation memory: the oldest part is taken as at rest.
    pub const HISTORY_SHORT: u32 = 4;
    /// The model diverged: no forecast this cycle.
    pub const NUMERICAL: u32 = 8;
    /// No wave field yet, or suppressed for age: no forecast.
    pub const NO_WAVES: u32 = 16;
    /// A gap in the motion history was bridged by interpolation.
    pub const HISTORY_GAP: u32 = 32;
    /// No motion for a vessel: no forecast.
    pub const NO_MOTION: u32 = 64;
    /// The wave field says nothing about where it was observed (radius 0): trusted horizon 0.
    pub const WAVE_REGION_UNKNOWN: u32 = 128;
    /// The wave field has no components: a wave-free forecast, trusted horizon 0.
    pub const NO_WAVE_COMPONENTS: u32 = 256;
    /// Wave components outside the database's frequencies or headings were left out of the forecast;
    /// beyond `forecast.max_dropped_wave_share` of the variance the trusted horizon is 0.
    pub const WAVES_DROPPED: u32 = 512;
    /// A source's clock stepped and it was re-synchronized (status only, for the period it happened).
    pub const CLOCK_STEP: u32 = 1024;
    /// The sources' clocks disagree (a wave field newer than the motion, or vessels' motion apart, by
    /// more than the clocks' skew allows): no forecast.
    pub const CLOCKS_DISAGREE: u32 = 2048;
    /// A motion sample was refused as physically impossible (beyond the bounds, a jump no acceleration
    /// makes, or a stalled sensor repeating itself) since the last status (status only).
    pub const MOTION_IMPLAUSIBLE: u32 = 4096;
    /// A vessel's motion estimate restarted from a run of refused samples that agree (a real jump),
    /// since the last status (status only): its history restarts.
    pub const MOTION_RESTARTED: u32 = 8192;
    /// The system's heading and position are not from navigation: no vessel has published any (the
    /// `[site]` heading and origin, a vessel keeping station), or it went stale beyond
    /// `forecast.max_navigation_age_s` (the last known pose, trusted horizon 0).
    pub const NAVIGATION_FALLBACK: u32 = 16384;
    /// Wave components meet the vessel at an encounter frequency below one cycle over the forecast
    /// (following seas at speed): kept, their force quasi-static.
    pub const QUASI_STATIC_WAVES: u32 = 32768;
    /// No forecast has yet been checked against the motion that followed at any lead past 0 (the
    /// first minute or so of a run): the model error is the configured prior's, and no lead is
    /// trusted (horizon 0) until it has been checked.
    pub const MODEL_ERROR_UNCHECKED: u32 = 65536;
    /// The wave processor repeats its last field (or the radar its last scan) at later stamps: a frozen
    /// processor. The repeats are refused; the forecasts take the last field that differed, at its own
    /// age (stale, then suppressed, as it grows old).
    pub const WAVES_FROZEN: u32 = 131_072;
    /// A wave field was refused as not a sea since the last status (status only): more than the
    /// highest seas, a component steeper than a wave can be, or a jump over the last fields no sea
    /// makes. The forecasts keep the last field taken.
    pub const WAVES_IMPLAUSIBLE: u32 = 262_144;
    /// The model could not be rebuilt for the forward speed (a speed beyond the databases'): the
    /// forecast is the model's at the speed it was built for, and nothing is trusted.
    pub const MODEL_SPEED_MISMATCH: u32 = 524_288;
    /// A vessel's motion estimate restarted from a jump (a sensor re-zeroed) and its new offset is not
    /// yet averaged (`estimator.bias_time_s` / 5): its start may be off by the jump, so that vessel
    /// and every vessel coupled to it are trusted nowhere, and nothing is learnt from the forecast.
    pub const MOTION_SETTLING: u32 = 1_048_576;
    /// A vessel's motion is stamped apart from the radar's clock (behind the newest field beyond the
    /// clocks' skew, or ahead of it beyond `forecast.suppress_wave_age_s`) while another vessel's agrees:
    /// that vessel alone is forecast from rest and trusted nowhere (the other ship's clock, over the
    /// link); the others go on. With no vessel agreeing, `clocks_disagree`.
    pub const MOTION_CLOCK_APART: u32 = 2_097_152;

    /// Names of the set bits.
    pub fn names(f: u32) -> Vec<&'static str> {
        [
            (STALE_WAVES, "stale_waves"),
            (STALE_MOTION, "stale_motion"),
            (HISTORY_SHORT, "history_short"),
            (NUMERICAL, "numerical_trouble"),
            (NO_WAVES, "no_waves"),
            (HISTORY_GAP, "history_gap"),
            (NO_MOTION, "no_motion"),
            (WAVE_REGION_UNKNOWN, "wave_region_unknown"),
            (NO_WAVE_COMPONENTS, "no_wave_components"),
            (WAVES_DROPPED, "waves_dropped"),
            (CLOCK_STEP, "clock_step"),
            (CLOCKS_DISAGREE, "clocks_disagree"),
            (MOTION_IMPLAUSIBLE, "motion_implausible"),
            (MOTION_RESTARTED, "motion_restarted"),
            (NAVIGATION_FALLBACK, "navigation_fallback"),
            (QUASI_STATIC_WAVES, "quasi_static_waves"),
            (MODEL_ERROR_UNCHECKED, "model_error_unchecked"),
            (WAVES_FROZEN, "waves_frozen"),
            (WAVES_IMPLAUSIBLE, "waves_implausible"),
            (MODEL_SPEED_MISMATCH, "model_speed_mismatch"),
            (MOTION_SETTLING, "motion_settling"),
            (MOTION_CLOCK_APART, "motion_clock_apart"),
        ]
        .iter()
        .filter(|(b, _)| f & b != 0)
        .map(|(_, n)| *n)
        .collect()
    }
}

/// One motion/navigation sample of one vessel. 112 bytes.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[repr(C)]
pub struct MotionSample {
    pub schema_version: u32,
    /// Index of the vessel (its body in the system file, 0-based).
    pub vessel: u32,
    /// Sample time, s (data clock).
    pub time_s: f64,
    /// Displacement of surge..yaw about the mean position (m, rad), body frame.
    pub x: [f64; 6],
    /// Velocity (m/s, rad/s).
    pub v: [f64; 6],
}

/// One navigation fix of one vessel (a GNSS receiver and a gyro compass, fused or not). 80 bytes.
/// Marine conventions at this edge: compass angles in degrees clockwise from true north, rate of turn
/// positive to starboard; the daemon converts them once, on arrival, to its earth frame (x east, y
/// north, angles counterclockwise from east, rad). Optional values are marked in `valid`.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[repr(C)]
pub struct NavigationSample {
    pub schema_version: u32,
    /// Index of the vessel (its body in the system file, 0-based).
    pub vessel: u32,
    /// Fix time, s (data clock).
    pub time_s: f64,
    /// Position of the vessel's reference point in the site's tangent plane (`[site]`'s east-north
    /// frame), m east and m north.
    pub east_m: f64,
    pub north_m: f64,
    /// True heading of the vessel's +x axis, deg clockwise from north.
    pub heading_deg: f64,
    /// Speed over ground, m/s.
    pub sog_m_s: f64,
    /// Course over ground, deg clockwise from north.
    pub cog_deg: f64,
    /// Speed through the water, m/s (when `valid` has [`nav_valid::STW`]).
    pub stw_m_s: f64,
    /// Rate of turn, deg/s, positive to starboard (when `valid` has [`nav_valid::ROT`]).
    pub rot_deg_s: f64,
    /// Which optional values are given: [`nav_valid`] bits.
    pub valid: u32,
    pub reserved: u32,
}

/// Bits of [`NavigationSample::valid`]: the values a sensor gives beyond time, position, heading and
/// speed and course over ground (always required).
pub mod nav_valid {
    /// `stw_m_s` is given.
    pub const STW: u32 = 1;
    /// `rot_deg_s` is given.
    pub const ROT: u32 = 2;
}

/// Header of a forecast sample. 512 bytes; `schema_version` = [`FORECAST_SCHEMA_VERSION`].
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[repr(C)]
pub struct ForecastHeader {
    pub schema_version: u32,
    pub n_vessels: u32,
    /// t0 of the forecast (the motion state it starts from), s.
    pub issue_time_s: f64,
    pub dt_s: f64,
    /// Values per series: steps + 1.
    pub steps: u32,
    /// Number of series (6 per vessel).
    pub n_series: u32,
    /// [`flags`] bits.
    pub flags: u32,
    pub reserved: u32,
    /// Time of the wave field used, s.
    pub wave_time_s: f64,
    /// Newest motion sample used, s.
    pub motion_time_s: f64,
    /// Wall-clock compute time of this forecast, ms.
    pub compute_ms: f64,
    /// End of each vessel's trusted span, s of lead (beyond it the forecast is not to be trusted; 0:
    /// not trusted at all).
    pub horizon_s: [f64; MAX_VESSELS],
    /// Start of each vessel's trusted span, s of lead (before it the waves that move the vessel have
    /// not been observed yet: a probe far up-wave).
    pub trusted_from_s: [f64; MAX_VESSELS],
    /// Each series' own trusted span (6 per vessel in DOF order, the first `n_series`), s of lead:
    /// heave may be trusted a minute ahead while roll is not. Its end (0: not trusted at all) ...
    pub series_horizon_s: [f64; 6 * MAX_VESSELS],
    /// ... and its start. A vessel's span (`horizon_s`, `trusted_from_s`) is where every DOF that
    /// moves enough to matter is trusted.
    pub series_trusted_from_s: [f64; 6 * MAX_VESSELS],
}

/// Health of the daemon, published every cycle. 560 bytes; `schema_version` = [`STATUS_SCHEMA_VERSION`].
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[repr(C)]
pub struct Status {
    pub schema_version: u32,
    /// [`flags`] bits of the current state.
    pub flags: u32,
    /// Newest data-clock time seen, s.
    pub time_s: f64,
    /// Wall-clock time of this status (UNIX s).
    pub wall_time_s: f64,
    /// Age of the newest wave field on the data clock, s (-1: none yet).
    pub wave_age_s: f64,
    /// Age of each vessel's newest motion sample, s (-1: none yet).
    pub motion_age_s: [f64; MAX_VESSELS],
    /// Measured sample rate of each vessel's motion stream, Hz.
    pub motion_rate_hz: [f64; MAX_VESSELS],
    /// Issue time of the last forecast published, s (-1: none).
    pub last_forecast_time_s: f64,
    pub last_compute_ms: f64,
    pub horizon_s: [f64; MAX_VESSELS],
    pub forecasts: u64,
    /// Forecasts that ran past their period.
    pub overruns: u64,
    pub samples: u64,
    pub wave_fields: u64,
    pub dropped_nonfinite: u64,
    pub dropped_late: u64,
    pub dropped_duplicate: u64,
    /// Samples and fields refused for a stamp beyond `forecast.max_clock_skew_s` ahead of their source.
    pub dropped_future: u64,
    /// ... or beyond `forecast.max_clock_lag_s` behind it.
    pub dropped_past: u64,
    /// Samples refused for an unknown schema version or a vessel index out of range, and wave fields
    /// of more than [`MAX_WAVE_COMPONENTS`] components.
    pub dropped_rejected: u64,
    /// Steps of a source's clock detected (the source re-synchronized).
    pub clock_steps: u64,
    /// Share of the last forecast's wave variance outside the database (left out), 0..1.
    pub dropped_wave_share: f64,
    /// Motion samples refused by the estimator as physically impossible (flag `motion_implausible`).
    pub dropped_implausible: u64,
    /// Restarts of a vessel's motion estimate after a real jump (flag `motion_restarted`).
    pub motion_restarts: u64,
    /// Each vessel's estimated sensor bias taken off the initial state: heave (m), roll, pitch (rad)
    /// (0 until it has averaged long enough; `estimator.method = "raw"`: 0).
    pub motion_bias: [[f64; 3]; MAX_VESSELS],
    /// 1 while running, 0 in the last status before a clean shutdown.
    pub running: u32,
    /// The ship-to-ship link (`shipcast link`, its [`LinkStatus`] on `<prefix>/link`): 0 none heard
    /// of, 1 up, 2 down (no message from the other ship lately, or the link process itself silent).
    pub link_state: u32,
    /// The link's median latency over its window, ms (-1: none measured).
    pub link_latency_ms: f64,
    /// The link's share of messages lost over its window, 0..1 (-1: none heard of).
    pub link_loss: f64,
    /// Age of the newest message from the other ship, s (-1: none yet).
    pub link_age_s: f64,
    /// Each vessel's in-situ roll tuning in force ([`crate::tuning`]): the added linear roll damping
    /// and the quadratic one (fractions of critical, the quadratic's at a 3 deg roll) and the
    /// correction of the roll natural frequency (a fraction); zeros: the model as built.
    pub roll_tuning: [[f64; 3]; MAX_VESSELS],
    /// 1 once the roll tuning has converged (its last rounds moved no parameter), else 0.
    pub roll_tuning_converged: u32,
    pub reserved: u32,
    /// Where the last forecast's time went, ms, from the newest motion sample's stamp to its
    /// hand-over for publishing, by stage ([`crate::engine::latency::STAGE_NAMES`]: received, waited,
    /// built, queued, forecast, band, handed); zeros before the first.
    pub latency_ms: [f64; 7],
    /// The median and the 99th percentile of that total over the newest
    /// [`crate::engine::latency::LATENCY_WINDOW`] forecasts, ms (-1: none yet).
    pub latency_p50_ms: f64,
    pub latency_p99_ms: f64,
}

/// The link's state (`link_state` of [`Status`]).
pub mod link_state {
    pub const NONE: u32 = 0;
    pub const UP: u32 = 1;
    pub const DOWN: u32 = 2;
}

/// Schema version of [`LinkStatus`].
pub const LINK_SCHEMA_VERSION: u32 = 1;

/// Health of the ship-to-ship link, published by `shipcast link` every second (`link::HEALTH_PERIOD_S`) on
/// `<prefix>/link`. 64 bytes.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
#[repr(C)]
pub struct LinkStatus {
    pub schema_version: u32,
    /// 1 while messages from the other ship arrive (the newest within `link.stale_s`), else 0.
    pub up: u32,
    /// Wall-clock time of this status (UNIX s).
    pub wall_time_s: f64,
    /// Median latency of the messages received over the window, ms: receipt less the sender's stamp
    /// (both hosts' clocks: GNSS-disciplined on a ship; exact on one host). -1: none in the window.
    pub latency_ms: f64,
    /// Share of the messages lost over the window (gaps in each stream's sequence), 0..1 (-1: none
    /// received in it).
    pub loss: f64,
    /// Age of the newest message from the other ship, s (-1: none yet).
    pub last_message_age_s: f64,
    /// Messages received, lost and sent since the link started.
    pub received: u64,
    pub lost: u64,
    pub sent: u64,
}

impl MotionSample {
    /// The payload's stable type name on the wire (its layout's version: a new field is a new name).
    pub const TYPE_NAME: &'static str = "shipcast_MotionSample_v1";
}

impl NavigationSample {
    /// The payload's stable type name on the wire (its layout's version: a new field is a new name).
    pub const TYPE_NAME: &'static str = "shipcast_NavigationSample_v1";
}

impl ForecastHeader {
    /// The payload's stable type name on the wire (its layout's version: a new field is a new name).
    pub const TYPE_NAME: &'static str = "shipcast_ForecastHeader_v3";
}

impl Status {
    /// The payload's stable type name on the wire (its layout's version: a new field is a new name).
    pub const TYPE_NAME: &'static str = "shipcast_Status_v5";
}

impl LinkStatus {
    /// The payload's stable type name on the wire (its layout's version: a new field is a new name).
    pub const TYPE_NAME: &'static str = "shipcast_LinkStatus_v1";
}

impl ForecastHeader {
    /// Vessel `b`'s trusted span, from `from_s` to `to_s` of lead (both 0: not trusted at all); a
    /// vessel beyond the payload's [`MAX_VESSELS`] has none.
    pub fn set_span(&mut self, b: usize, from_s: f64, to_s: f64) {
        if b < MAX_VESSELS {
            self.trusted_from_s[b] = from_s;
            self.horizon_s[b] = to_s;
            if to_s <= 0.0 {
                for i in 6 * b..6 * b + 6 {
                    self.set_series_span(i, 0.0, 0.0);
                }
            }
        }
    }

    /// Series `i`'s own trusted span (6 per vessel), s of lead (both 0: not trusted).
    pub fn set_series_span(&mut self, i: usize, from_s: f64, to_s: f64) {
        if i < 6 * MAX_VESSELS {
            self.series_trusted_from_s[i] = from_s;
            self.series_horizon_s[i] = to_s;
        }
    }

    /// Series `i`'s trusted span (from, to), s of lead ((0, 0): not trusted, or not sent).
    pub fn series_span(&self, i: usize) -> (f64, f64) {
        if i < 6 * MAX_VESSELS {
            (self.series_trusted_from_s[i], self.series_horizon_s[i])
        } else {
            (0.0, 0.0)
        }
    }

    /// No vessel trusted at any lead.
    pub fn untrust_all(&mut self) {
        for b in 0..MAX_VESSELS {
            self.set_span(b, 0.0, 0.0);
        }
    }
}

/// Checks a received forecast against its own header, as every consumer must before indexing it
/// (`ForecastSubscriber` does, for `watch`, `demo` and the console): the schema, the vessel count, the
/// series count and the payload's length (displacements and standard deviations), a positive step,
/// finite times and spans.
pub fn check_forecast(h: &ForecastHeader, payload_len: usize) -> Result<(), String> {
    let n_vessels = h.n_vessels as usize;
    if h.schema_version != FORECAST_SCHEMA_VERSION {
        return Err(format!(
            "forecast of schema version {} (this shipcast reads {FORECAST_SCHEMA_VERSION})",
            h.schema_version
        ));
    }
    if n_vessels == 0 || n_vessels > MAX_VESSELS {
        return Err(format!("forecast for {n_vessels} vessels (1..={MAX_VESSELS})"));
    }
    if h.n_series as usize != 6 * n_vessels {
        return Err(format!(
            "forecast with {} series for {n_vessels} vessels (6 each)",
            h.n_series
        ));
    }
    let values = (h.steps as usize + 1)
        .checked_mul(h.n_series as usize)
        .and_then(|v| v.checked_mul(2));
    if values != Some(payload_len) {
        return Err(format!(
            "forecast of {} steps x {} series (and their standard deviations) in {payload_len} values",
            h.steps, h.n_series
        ));
    }
    if !(h.dt_s.is_finite() && h.dt_s > 0.0 && h.issue_time_s.is_finite()) {
        return Err(format!(
            "forecast with dt_s {} and issue_time_s {}",
            h.dt_s, h.issue_time_s
        ));
    }
    if h.horizon_s[..n_vessels].iter().any(|x| !(x.is_finite() && *x >= 0.0)) {
        return Err(format!("forecast with horizons {:?}", &h.horizon_s[..n_vessels]));
    }
    if h.trusted_from_s[..n_vessels]
        .iter()
        .any(|x| !(x.is_finite() && *x >= 0.0))
    {
        return Err(format!(
            "forecast with trusted spans from {:?}",
            &h.trusted_from_s[..n_vessels]
        ));
    }
    let n_series = h.n_series as usize;
    let spans = h.series_trusted_from_s[..n_series]
        .iter()
        .zip(&h.series_horizon_s[..n_series]);
    if let Some((i, (from, to))) = spans
        .enumerate()
        .find(|(_, (f, t))| !(f.is_finite() && t.is_finite() && **f >= 0.0 && **t >= 0.0))
    {
        return Err(format!("forecast with series {i}'s trusted span {from} to {to} s"));
    }
    Ok(())
}

/// Checks a received status: its schema version.
pub fn check_status(s: &Status) -> Result<(), String> {
    if s.schema_version != STATUS_SCHEMA_VERSION {
        return Err(format!(
            "status of schema version {} (this shipcast reads {STATUS_SCHEMA_VERSION})",
            s.schema_version
        ));
    }
    Ok(())
}

/// A radar scan decoded from the wire: the grid (its axes' coordinates from the frame's origin; NaN
/// cells invalid) and where it lies.
#[derive(Debug, Clone, PartialEq)]
pub struct Scan {
    pub grid: crate::waves::observe::Grid,
    pub frame: crate::waves::observe::GridFrame,
}

/// One input to the engine, decoded from the wire or a log.
#[derive(Debug, Clone)]
// a wave field (its region included) a scan period: a box would be an allocation for nothing
#[allow(clippy::large_enum_variant)]
pub enum Input {
    Motion(MotionSample),
    Navigation(NavigationSample),
    /// A radar scan (boxed: a scan is up to 4 MB).
    Elevation(Box<Scan>),
    Waves(WaveField),
    /// The ship-to-ship link's health (`shipcast link`).
    Link(LinkStatus),
    /// A sample that could not be decoded (counted, logged).
    Rejected(String),
}

/// What the engine publishes.
#[derive(Debug, Clone)]
// one status a period: a box would be an allocation for nothing
#[allow(clippy::large_enum_variant)]
pub enum Output {
    Forecast(ForecastHeader, Vec<f64>),
    Status(Status),
}

#[cfg(test)]
mod tests {
    use super::*;

    fn good() -> ForecastHeader {
        ForecastHeader {
            schema_version: FORECAST_SCHEMA_VERSION,
            n_vessels: 2,
            dt_s: 0.1,
            steps: 10,
            n_series: 12,
            ..ForecastHeader::default()
        }
    }

    /// Was: `watch`, `demo` and the console indexed payloads by their header unchecked (`n_vessels` > 4,
    /// or `steps` larger than the payload, panicked).
    #[test]
    fn a_forecast_whose_header_does_not_fit_its_payload_is_refused() {
        assert_eq!(check_forecast(&good(), 22 * 12), Ok(()));
        let bad = [
            (
                ForecastHeader {
                    n_vessels: 5,
                    n_series: 30,
                    ..good()
                },
                22 * 30,
            ),
            (
                ForecastHeader {
                    n_vessels: 0,
                    n_series: 0,
                    ..good()
                },
                0,
            ),
            (ForecastHeader { steps: 1000, ..good() }, 22 * 12),
            (
                ForecastHeader {
                    steps: u32::MAX,
                    ..good()
                },
                22 * 12,
            ),
            (ForecastHeader { n_series: 6, ..good() }, 22 * 6),
            (ForecastHeader { dt_s: 0.0, ..good() }, 22 * 12),
            (
                ForecastHeader {
                    schema_version: 9,
                    ..good()
                },
                22 * 12,
            ),
            (
                ForecastHeader {
                    horizon_s: [f64::INFINITY, 0.0, 0.0, 0.0],
                    ..good()
                },
                22 * 12,
            ),
            (
                ForecastHeader {
                    trusted_from_s: [0.0, f64::NAN, 0.0, 0.0],
                    ..good()
                },
                22 * 12,
            ),
            (
                ForecastHeader {
                    series_horizon_s: std::array::from_fn(|i| if i == 9 { f64::NAN } else { 1.0 }),
                    ..good()
                },
                22 * 12,
            ),
            (
                ForecastHeader {
                    series_trusted_from_s: std::array::from_fn(|i| if i == 11 { -1.0 } else { 0.0 }),
                    ..good()
                },
                22 * 12,
            ),
            // the displacements without their standard deviations (a schema 1 payload)
            (good(), 11 * 12),
        ];
        for (h, len) in bad {
            assert!(check_forecast(&h, len).is_err(), "{h:?}");
        }
    }

    #[test]
    fn layouts_are_what_the_docs_say() {
        assert_eq!(std::mem::size_of::<MotionSample>(), 112);
        assert_eq!(std::mem::size_of::<NavigationSample>(), 80);
        assert_eq!(std::mem::size_of::<ForecastHeader>(), 512);
        assert_eq!(std::mem::size_of::<Status>(), 560);
        assert_eq!(std::mem::size_of::<LinkStatus>(), 64);
    }
}
