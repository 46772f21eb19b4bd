//! The daemon's decision core (pure: no tokio, iceoryx2, files or clocks). [`Engine`] holds the
//! daemon's state and makes every decision against a clock the caller supplies (monotonic wall time
//! live, the log's time in replay): which inputs to take ([`input`](Engine::input)), when a forecast
//! can run and from what ([`tick`](Engine::tick) builds a [`Job`]), what a finished job publishes and
//! teaches ([`done`](Engine::done)), and the status. [`Computer`] runs a job: the model, the
//! forecaster and the band. [`message`] holds the plain values it takes and gives.
//!
//! Conventions as in DESIGN.md section 1: SI units, the data clock's seconds, DOFs surge..yaw per
//! vessel (series s = 6 v + d).

pub mod clock;
pub mod estimator;
pub mod message;
pub mod navigation;

mod input;
mod job;
pub mod latency;
mod publish;
mod setup;
pub mod state;
mod tick;
mod tune;

pub use job::{Computer, Done, Job};
pub use setup::{
    STATE_SPACE_HISTORY_S, describe_step, estimator_spec, fits_the_wire, history_wanted_s, options_at, rom_options,
    vessel_positions, watchdog_fits,
};

use crate::band;
use crate::hydro::VesselSystem;
use crate::rom::TimeModel;
use crate::settings::{self, ShipcastConfig};
use crate::waves::field::WaveField;
use estimator::Estimator;
use message::{MAX_VESSELS, flags};

/// The link is down when its process has said nothing for this long, s (three of its health
/// messages missed: `link::HEALTH_PERIOD_S`).
pub const LINK_SILENT_S: f64 = 3.0;

/// The DOFs (roll, pitch) whose forecast keeps the measured mean (the estimator's bias) where it is
/// further from the model's own mean in waves than the sensor's bias can be
/// (`estimator.angle_bias_rad`): a motion sensor's angles are gravity-referenced, so their long mean
/// is a real heel or trim (its bias an installation misalignment of hundredths of a degree), which
/// the model may not know; its heave is integrated acceleration, whose long mean is drift.
pub const MEASURED_MEAN_DOFS: [usize; 2] = [3, 4];

/// What of `x` lies beyond +-`bound` (0 within it).
fn beyond(x: f64, bound: f64) -> f64 {
    x.signum() * (x.abs() - bound).max(0.0)
}

/// How many `bias_time_s` the mean square of the measured mean's offset is taken over
/// (`Engine::heel_square`): several correlation times of an MRU's drift (600 s) at the default 300 s.
pub const HEEL_MEMORY_BIAS_TIMES: f64 = 3.0;

/// Every vessel's newest motion sample in ([`Engine::motion_complete`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotionSet {
    /// The newest stamp of all, s (data clock).
    pub stamp_s: f64,
    /// Half the longest sample interval: what the stamps may jitter by, s.
    pub jitter_s: f64,
    /// When the last of them arrived, s (engine clock).
    pub arrival_s: f64,
}

/// A forecast's leads from this one on are settled (past a roll's decay, 1 / (zeta w_n) = 47 s at 5 %
/// of critical and 0.43 rad/s): their mean is the model's own mean in waves, s.
pub const SETTLED_LEAD_S: f64 = 60.0;

/// The speed steps the compute thread rebuilds a speed-dependent model at, m/s: the forward speed from
/// navigation is rounded to it (B_U U and C_UQ U^2 then within 0.125 m/s of the speed's).
pub const MODEL_SPEED_STEP_M_S: f64 = 0.25;

/// ... and rebuilds only when the speed is more than this many steps from the model's: a speed near
/// the middle between two steps does not rebuild the model on every forecast.
pub const MODEL_SPEED_HYSTERESIS: f64 = 0.6;

#[derive(Debug, Clone, Default)]
pub struct Counters {
    pub forecasts: u64,
    pub overruns: u64,
    pub samples: u64,
    pub wave_fields: u64,
    pub nonfinite: u64,
    pub late: u64,
    pub duplicate: u64,
    pub rejected: u64,
    /// Refused for a stamp ahead of / behind their source's clock (`clock`).
    pub future: u64,
    pub past: u64,
    pub clock_steps: u64,
    /// Refused by the motion estimator as physically impossible, and its restarts after a real jump.
    pub implausible: u64,
    pub motion_restarts: u64,
    /// Navigation fixes received.
    pub navigation: u64,
}

/// Logs the first of a kind of event, then every time its count reaches a power of ten, so that a
/// flood of bad input is visible in the log without filling it.
fn log_count(count: u64, what: &str) {
    if count == 1 || (count >= 10 && power_of_ten(count)) {
        tracing::warn!(count, "{what}");
    }
}

fn power_of_ten(mut n: u64) -> bool {
    while n >= 10 && n.is_multiple_of(10) {
        n /= 10;
    }
    n == 1
}

/// Flags of events, kept in the state until the next status reports them.
const ONE_SHOT_FLAGS: u32 = flags::NUMERICAL
    | flags::CLOCK_STEP
    | flags::MOTION_IMPLAUSIBLE
    | flags::MOTION_RESTARTED
    | flags::WAVES_IMPLAUSIBLE;

/// The daemon's state and decisions, driven by a clock the caller supplies (seconds: monotonic wall
/// time live, the log's time in replay): the same code for both.
pub struct Engine {
    cfg: settings::ForecastConfig,
    /// The model's step, s.
    dt_s: f64,
    origin_m: [f64; 2],
    n_bodies: usize,
    taps: usize,
    active: Vec<usize>,
    n_active: usize,
    /// The `[site]` frame's heading (the fallback; its origin is `origin_m`).
    heading: f64,
    /// Each body's reference point in the system frame, m.
    body_xy_m: Vec<[f64; 2]>,
    /// Each vessel's navigation fixes, and their clocks.
    nav: Vec<navigation::NavTrack>,
    nav_clock: Vec<clock::SourceClock>,
    /// The last pose taken from navigation: (system heading, system origin, vessel velocity over
    /// ground), kept for when navigation goes stale.
    last_frame: Option<(f64, [f64; 2], [f64; 2])>,
    /// The newest radar scans of one grid (at most `forecast.radar_snapshots`), how many of the newest
    /// the next inversion takes (`waves::window::window_scans` of the last field), and how they are
    /// inverted (the database's frequency band); the last inversion's fit, which the next starts from.
    scans: std::collections::VecDeque<message::Scan>,
    radar_window: usize,
    radar_fit: Option<crate::waves::observe::ScanFit>,
    radar_options: crate::waves::observe::GridOptions,
    /// Each vessel's motion estimator (its kept window of samples).
    hist: Vec<Estimator>,
    /// Clock time of each vessel's newest accepted sample.
    arrival: Vec<Option<f64>>,
    field: Option<WaveField>,
    /// Each vessel's motion stream's clock, and the radar's.
    motion_clock: Vec<clock::SourceClock>,
    wave_clock: clock::SourceClock,
    clock_rules: clock::ClockRules,
    /// Share of the last forecast's wave variance outside the database.
    dropped_wave_share: f64,
    /// Whether the last tick could forecast (for the log line when that changes).
    forecasting: Option<bool>,
    pub counters: Counters,
    busy: bool,
    last_forecast_time: f64,
    last_compute_ms: f64,
    /// Where the forecasts' time goes ([`latency`]), and where the running job's started.
    latency: latency::Latency,
    job_start: Option<latency::JobStart>,
    last_horizon: [f64; MAX_VESSELS],
    /// The newest wave field or radar scan repeated the one before at a later stamp (refused: a frozen
    /// processor).
    waves_frozen: bool,
    /// The variances of the last fields taken, m^2 (what the next is judged against).
    recent_variance_m2: std::collections::VecDeque<f64>,
    /// The ship-to-ship link's newest health, and the engine clock it arrived at.
    link: Option<(message::LinkStatus, f64)>,
    state_flags: u32,
    /// The model error learnt from past forecasts against the motion that followed, and the checks
    /// at 30 s when it was last logged.
    model_error: band::ModelError,
    model_error_logged: usize,
    /// The model's own mean displacement in waves per vessel and DOF (heave, roll, pitch), and when it
    /// was last learnt (`learn_model_mean`).
    model_mean: Vec<estimator::RunningMean>,
    model_mean_time_s: Option<f64>,
    /// Per vessel, the running mean square of roll's and pitch's measured mean offset from the
    /// model's (over [`HEEL_MEMORY_BIAS_TIMES`] `bias_time_s`), and when it was last taken in: what
    /// the sensor's drift does not explain of it is heel ([`band::heel_split`]).
    heel_square: Vec<estimator::RunningMean>,
    heel_time_s: Option<f64>,
    bias_time_s: f64,
    /// `estimator.drift_time_s`.
    drift_time_s: f64,
    /// `estimator.angle_bias_rad`.
    angle_bias_rad: f64,
    /// Per vessel and DOF, what the running job's forecast is shifted by when done: for
    /// [`MEASURED_MEAN_DOFS`], the measured mean (the estimator's bias) less the model's own (the
    /// model forecasts the motion about its mean, the mean is as measured).
    job_offset: Vec<[f64; 6]>,
    /// Per vessel, whether the running job started it from rest for want of fresh motion.
    job_unknown: Vec<bool>,
    /// Per vessel, whether the running job's start of it, or of a vessel coupled to it, is settling
    /// after a restart (`Estimator::settling`): trusted nowhere, nothing learnt.
    job_withdrawn: Vec<bool>,
    /// Which vessels the model couples ([`setup::coupled_vessels`]).
    coupled: Vec<Vec<bool>>,
    /// The model's inertia (M + A_inf) diagonal, for [`Engine::fingerprint`].
    inertia_digest: String,
    /// The measured trace the in-situ roll tuning scores its cases against (time, every series).
    trace: std::collections::VecDeque<(f64, Vec<f64>)>,
    /// Per vessel, the roll tuning in force (damping, quadratic, frequency; [`crate::tuning`]), and
    /// whether it converged.
    roll_tuning: [[f64; 3]; MAX_VESSELS],
    roll_tuning_converged: bool,
}

impl Engine {
    pub fn new(cfg: &ShipcastConfig, sys: &VesselSystem, model: &TimeModel) -> Engine {
        let n_bodies = sys.spec.bodies.len();
        let taps = model.kernel.taps().unwrap_or_else(|| {
            (cfg.forecast.memory_s.unwrap_or(STATE_SPACE_HISTORY_S) / model.opts.dt_s).round() as usize
        });
        let keep_s = taps as f64 * model.opts.dt_s + cfg.forecast.history_margin_s;
        let (_, heading) = vessel_positions(cfg, sys);
        Engine {
            cfg: cfg.forecast.clone(),
            dt_s: model.opts.dt_s,
            origin_m: [cfg.site.origin_east_m, cfg.site.origin_north_m],
            n_bodies,
            taps,
            active: model.active.clone(),
            n_active: model.n(),
            heading,
            body_xy_m: sys.spec.reference_points_xy_m(),
            nav: vec![navigation::NavTrack::default(); n_bodies],
            nav_clock: vec![clock::SourceClock::default(); n_bodies],
            last_frame: None,
            scans: std::collections::VecDeque::new(),
            radar_window: cfg.forecast.radar_snapshots as usize,
            radar_fit: None,
            radar_options: {
                let (lo, hi) = model.db.omega_range();
                crate::waves::observe::GridOptions {
                    g_m_s2: sys.spec.g_m_s2,
                    depth_m: sys.spec.water_depth_m,
                    omega_min_rad_s: lo,
                    omega_max_rad_s: hi,
                    mean_direction_rad: None,
                    region: None,
                }
            },
            hist: (0..n_bodies)
                .map(|b| Estimator::new(estimator_spec(cfg, sys, model, b), keep_s))
                .collect(),
            arrival: vec![None; n_bodies],
            field: None,
            motion_clock: vec![clock::SourceClock::default(); n_bodies],
            wave_clock: clock::SourceClock::default(),
            clock_rules: clock::ClockRules {
                max_skew_s: cfg.forecast.max_clock_skew_s,
                max_lag_s: cfg.forecast.max_clock_lag_s,
                resync_samples: cfg.forecast.clock_resync_samples,
                max_rate: cfg.forecast.max_clock_rate.unwrap_or(cfg.simulate.speed).max(1.0),
            },
            dropped_wave_share: 0.0,
            forecasting: None,
            counters: Counters::default(),
            busy: false,
            last_forecast_time: -1.0,
            last_compute_ms: 0.0,
            latency: latency::Latency::default(),
            job_start: None,
            last_horizon: [0.0; MAX_VESSELS],
            link: None,
            waves_frozen: false,
            recent_variance_m2: std::collections::VecDeque::new(),
            state_flags: 0,
            model_error_logged: 0,
            model_mean: vec![Default::default(); n_bodies],
            model_mean_time_s: None,
            heel_square: vec![Default::default(); n_bodies],
            heel_time_s: None,
            job_offset: vec![[0.0; 6]; n_bodies],
            job_unknown: vec![false; n_bodies],
            job_withdrawn: vec![false; n_bodies],
            coupled: setup::coupled_vessels(model, n_bodies),
            inertia_digest: (0..model.mass.nrows())
                .map(|i| format!("{:.6e}", model.mass[(i, i)]))
                .collect::<Vec<_>>()
                .join(" "),
            trace: std::collections::VecDeque::new(),
            roll_tuning: [[0.0; 3]; MAX_VESSELS],
            roll_tuning_converged: false,
            bias_time_s: cfg.estimator.bias_time_s,
            drift_time_s: cfg.estimator.drift_time_s,
            angle_bias_rad: cfg.estimator.angle_bias_rad,
            model_error: band::ModelError::new(
                cfg.forecast.model_error,
                // the motion sensor's noise as the estimator is told it (translations, rotations)
                (0..6 * n_bodies)
                    .map(|i| {
                        let e = &cfg.estimator;
                        if i % 6 < 3 {
                            e.noise_m * e.noise_m
                        } else {
                            e.noise_rad * e.noise_rad
                        }
                    })
                    .collect(),
            ),
        }
    }

    /// The earliest and the latest of the vessels' newest motion stamps, s (+inf and -inf before any).
    fn newest_motion_s(&self) -> (f64, f64) {
        self.newest_motion_of(&vec![true; self.hist.len()])
    }

    /// [`Self::newest_motion_s`] over the vessels where `which` is true.
    fn newest_motion_of(&self, which: &[bool]) -> (f64, f64) {
        self.hist
            .iter()
            .zip(which)
            .filter(|(_, w)| **w)
            .filter_map(|(h, _)| h.newest_time_s())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), t| (lo.min(t), hi.max(t)))
    }

    /// When every vessel's newest motion sample is in: the newest stamp of all, half the longest sample
    /// interval (the stamps' jitter allowance) and the clock time the last of them arrived. Each vessel
    /// whose motion is not stale (within `forecast.max_motion_age_s` of the newest of all) has one
    /// within half its own sample interval of the newest of all (the daemon ticks on that: a forecast
    /// then starts from the newest motion, not from one up to a sample interval older). None before any
    /// motion, or while a vessel's sample is still to come.
    pub fn motion_complete(&self) -> Option<MotionSet> {
        let (_, hi) = self.newest_motion_s();
        if !hi.is_finite() {
            return None;
        }
        let mut set = MotionSet {
            stamp_s: hi,
            jitter_s: 0.0,
            arrival_s: f64::NEG_INFINITY,
        };
        for (h, arrival) in self.hist.iter().zip(&self.arrival) {
            match h.newest_time_s() {
                Some(t) if hi - t <= self.cfg.max_motion_age_s => {
                    let rate = h.rate_hz();
                    let half = if rate > 0.0 { 0.5 / rate } else { 0.0 };
                    if hi - t > half {
                        return None;
                    }
                    set.jitter_s = set.jitter_s.max(half);
                    set.arrival_s = set.arrival_s.max(arrival.unwrap_or(f64::NEG_INFINITY));
                }
                _ => {}
            }
        }
        Some(set)
    }

    /// Radiation memory the engine keeps, s.
    pub fn memory_s(&self) -> f64 {
        self.taps as f64 * self.dt_s
    }
}
