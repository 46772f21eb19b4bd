//! The forecasting daemon (shell): configuration, motion history, cadence, health, shutdown.
//!
//! [`Engine`] holds the state and makes every decision (what to drop, when a forecast is possible, its
//! flags and horizon, the status) against a clock it is given; [`Computer`] runs a forecast job. The
//! live daemon ([`run`]) feeds them from iceoryx2 and a wall-clock cadence; replay feeds the same two from
//! a log's clock: one code path.
//!
//! Threads: the tokio runtime owns the state (histories, the newest wave field, counters) and the
//! cadence; the iceoryx2 input and output threads ([`crate::ipc`]) bridge to it with channels; the
//! forecast itself runs on a compute thread of its own so a slow forecast never blocks the ports. A
//! forecast that is still running when the next tick comes is counted as an overrun and that tick is
//! skipped (no pile-up). Every tick publishes a status; a forecast is published only when the inputs
//! allow one (see [`crate::ipc::wire::flags`]).

pub mod clock;
pub mod config;
pub mod estimator;
pub mod navigation;

use crate::hydro::VesselSystem;
use crate::ipc::wire::{ForecastHeader, MAX_VESSELS, MotionSample, SCHEMA_VERSION, Status, flags, link_state};
use crate::ipc::{self, Input, Names, Output};
use crate::rom::spread::{self, ResponseTable, SpreadOptions};
use crate::rom::{ForecastRequest, Forecaster, Memory, RadiationMethod, RomOptions, TimeModel, Track};
use crate::waves::field::{WaveField, heading_from_compass_deg};
use crate::waves::horizon;
use config::ShipcastConfig;
use estimator::{Estimator, Refusal, Taken};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

pub type Error = Box<dyn std::error::Error + Send + Sync>;

/// Wall clock, UNIX seconds.
pub fn wall_s() -> f64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map(|d| d.as_secs_f64())
        .unwrap_or(0.0)
}

/// The model options a configuration asks for, for this system: the step is `forecast.dt_s`, or when
/// that is not set the one chosen from the system's natural periods ([`crate::rom::step`]).
pub fn rom_options(cfg: &ShipcastConfig, sys: &VesselSystem) -> RomOptions {
    options_at(
        cfg,
        cfg.forecast
            .dt_s
            .unwrap_or_else(|| crate::rom::step::default_step(sys).dt_s),
    )
}

/// The solver step in words: the configured one, or the one chosen and why.
pub fn describe_step(cfg: &ShipcastConfig, sys: &VesselSystem) -> String {
    match cfg.forecast.dt_s {
        Some(dt) => format!("{dt} s (forecast.dt_s)"),
        None => crate::rom::step::default_step(sys).describe(sys),
    }
}

/// The model options of a configuration at step `dt_s`.
pub fn options_at(cfg: &ShipcastConfig, dt_s: f64) -> RomOptions {
    RomOptions {
        dt_s,
        radiation: if cfg.forecast.radiation == "state-space" {
            RadiationMethod::StateSpace
        } else {
            RadiationMethod::Convolution
        },
        memory_s: cfg.forecast.memory_s,
        ..RomOptions::default()
    }
}

/// With the state-space radiation (whose modal states carry the memory), the measured history each
/// forecast starts from when `forecast.memory_s` is not set, s.
pub const STATE_SPACE_HISTORY_S: f64 = 120.0;

/// How much measured motion a forecast wants behind it, s: the radiation memory (convolution) or the
/// history the modal states are started from (state space). Until the history is this long, forecasts
/// carry `history_short` (the missing past taken as at rest).
pub fn history_wanted_s(cfg: &ShipcastConfig, sys: &VesselSystem) -> f64 {
    match (cfg.forecast.memory_s, cfg.forecast.radiation.as_str()) {
        (Some(m), _) => m,
        (None, "state-space") => STATE_SPACE_HISTORY_S,
        (None, _) => crate::hydro::memory::memory_duration_s(sys),
    }
}

/// Earth position (east, north) of each body's reference point and the system's heading (rad,
/// counterclockwise from east).
pub fn vessel_positions(cfg: &ShipcastConfig, sys: &VesselSystem) -> (Vec<[f64; 2]>, f64) {
    let h = heading_from_compass_deg(cfg.site.heading_deg);
    let (s, c) = h.sin_cos();
    let o = [cfg.site.origin_east_m, cfg.site.origin_north_m];
    let pos = sys
        .spec
        .bodies
        .iter()
        .map(|b| {
            let (x, y) = (b.position_m.x, b.position_m.y);
            [o[0] + c * x - s * y, o[1] + s * x + c * y]
        })
        .collect();
    (pos, h)
}

/// One forecast job.
#[derive(Debug, Clone)]
pub struct Job {
    t0_s: f64,
    x0: Vec<f64>,
    v0: Vec<f64>,
    velocities: Vec<Vec<f64>>,
    /// How many of `velocities` (the newest) were measured, fewest over the vessels.
    known: usize,
    waves: Vec<crate::waves::WaveComponent>,
    /// Per vessel, per component of `waves`, the leads (s from t0) over which it is known
    /// (`horizon::known_leads`; none when the field cannot be trusted).
    known_leads: Vec<Vec<[f64; 2]>>,
    /// Whether the field can be trusted at all (located, navigation fresh).
    trustworthy: bool,
    /// The model error of each series against lead, as a fraction of its motion
    /// ([`spread::ModelError`]).
    model_error: spread::ModelErrorCurve,
    /// Per series, the variance of the start's random error and its expected error
    /// ([`spread::SpreadOptions`]; the estimator's `start_var` and, for roll and pitch,
    /// [`spread::heel_split`]).
    start_var: Vec<f64>,
    start_offset: Vec<f64>,
    /// Per series, the estimate's own error variance (`estimator::Estimator::estimate_var`).
    check_var: Vec<f64>,
    /// The frame's track from t0 (speed and turn from navigation; None: keeping station).
    track: Option<Track>,
    header: ForecastHeader,
}

/// A job's result.
#[derive(Debug, Clone)]
pub struct Done {
    pub header: ForecastHeader,
    pub values: Option<Vec<f64>>,
    pub compute_ms: f64,
    pub error: Option<String>,
    /// Share of the wave variance the forecast left out (outside the database), 0..1.
    pub dropped_wave_share: f64,
    /// Each series' motion standard deviation by the band's model, and the model error the band took.
    pub motion_sigma: Vec<f64>,
    pub model_error: spread::ModelErrorCurve,
    /// Per series, the variance of the start's random error (the band's floor) and of the estimate's
    /// own error (the filter's: what a check against a later estimate differs by beside the motion;
    /// the sensor's drift, slow, the two share).
    pub start_var: Vec<f64>,
    pub check_var: Vec<f64>,
    /// The forecast may teach the model error: its waves were trusted and its band known (a forecast
    /// with no trusted span teaches all the same: its error is the model's).
    pub teaches: bool,
}

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

/// A forecast's leads from this one on are settled (past a roll's decay, 1 / (zeta w_n) = 47 s at 5 %
/// of critical and 0.43 rad/s): their mean is the model's own mean in waves, s.
pub const SETTLED_LEAD_S: f64 = 60.0;

/// The speed steps the compute thread rebuilds a speed-dependent model at, m/s: the forward speed from
/// navigation is rounded to it (B_U U and C_UQ U^2 then within 0.125 m/s of the speed's).
pub const MODEL_SPEED_STEP_M_S: f64 = 0.25;
/// ... and rebuilds only when the speed is more than this many steps from the model's: a speed near
/// the middle between two steps does not rebuild the model on every forecast.
pub const MODEL_SPEED_HYSTERESIS: f64 = 0.6;

/// Runs jobs: the model and a reusable forecaster (the compute thread live, inline in replay).
pub struct Computer {
    model: TimeModel,
    /// The model's response for the band (None: it could not be made; nothing is trusted then).
    table: Option<ResponseTable>,
    trusted_nrmse: f64,
    /// The system and options to rebuild the model at another speed, when the system file has speed
    /// terms (`speed_damping` B_U, `speed_restoring` C_UQ) or databases at several speeds (interpolated:
    /// `VesselSystem::at_speed`); None: one model serves every speed (the speed then enters through the
    /// encounter frequency only).
    rebuild: Option<(Box<VesselSystem>, RomOptions)>,
    /// The speed step a rebuild failed at (not tried again until the speed moves).
    failed_speed: Option<f64>,
    fc: Forecaster,
    n_bodies: usize,
    /// Forecast length, s.
    length_s: f64,
    /// `forecast.drift_window_s` (0: no drift estimate).
    drift_window_s: f64,
}

impl Computer {
    pub fn new(model: TimeModel, sys: &VesselSystem, cfg: &ShipcastConfig) -> Computer {
        let speed_terms = !sys.speed_dbs.is_empty()
            || sys.spec.bodies.iter().any(|b| {
                b.speed_damping
                    .iter()
                    .chain(b.speed_restoring.iter())
                    .any(|v| *v != 0.0)
            });
        let n_bodies = sys.spec.bodies.len();
        Computer {
            rebuild: speed_terms.then(|| (Box::new(sys.clone()), model.opts)),
            failed_speed: None,
            table: response_table(&model),
            trusted_nrmse: cfg.forecast.trusted_nrmse,
            model,
            fc: Forecaster::new(),
            n_bodies,
            length_s: cfg.forecast.horizon_s,
            drift_window_s: cfg.forecast.drift_window_s,
        }
    }

    /// The model at the speed a job's track asks for, rebuilt when the system has speed terms and the
    /// speed moved to another step of [`MODEL_SPEED_STEP_M_S`]. An error (a speed beyond the databases')
    /// keeps the model it had, and is reported once per speed step.
    fn at_speed(&mut self, track: Option<Track>) -> Result<(), String> {
        let Some((sys, opts)) = &self.rebuild else {
            return Ok(());
        };
        let want = (track.map_or(0.0, |t| t.speed_m_s) / MODEL_SPEED_STEP_M_S).round() * MODEL_SPEED_STEP_M_S;
        // a speed between two steps keeps the model it has (no rebuild per forecast on noise)
        let speed = track.map_or(0.0, |t| t.speed_m_s);
        let near = (speed - self.model.opts.speed_m_s).abs() <= MODEL_SPEED_HYSTERESIS * MODEL_SPEED_STEP_M_S;
        if near || (want - self.model.opts.speed_m_s).abs() < 1e-9 || self.failed_speed == Some(want) {
            return Ok(());
        }
        // tried once per speed step: an error is logged once, the model kept
        self.failed_speed = Some(want);
        let at = sys
            .at_speed(want)
            .map_err(|e| format!("the database at {want} m/s: {e}"))?;
        let model = TimeModel::new(
            &at,
            RomOptions {
                speed_m_s: want,
                ..*opts
            },
        )
        .map_err(|e| format!("the model at {want} m/s: {e}"))?;
        tracing::info!(
            speed_m_s = want,
            "model rebuilt for the forward speed (its speed terms)"
        );
        self.table = response_table(&model);
        self.model = model;
        self.failed_speed = None;
        // its workspace holds the old model's kernel spectra
        self.fc = Forecaster::new();
        Ok(())
    }

    /// Runs one job; `elapsed_ms` measures its compute time (the shell passes a clock).
    pub fn run(&mut self, job: Job, elapsed_ms: impl Fn() -> f64) -> Done {
        if let Err(e) = self.at_speed(job.track) {
            tracing::warn!("{e}");
        }
        let (model, n_bodies) = (&self.model, self.n_bodies);
        let fc = &mut self.fc;
        let drift = (self.drift_window_s > 0.0)
            .then(|| {
                crate::rom::drift::slow_velocity(
                    &job.velocities,
                    job.known,
                    &job.v0,
                    model.opts.dt_s,
                    self.drift_window_s,
                )
            })
            .flatten();
        let result = Memory::from_history(model, &job.velocities).and_then(|memory| {
            let req = ForecastRequest {
                x0: &job.x0,
                v0: &job.v0,
                memory: &memory,
                waves: &job.waves,
                length_s: self.length_s,
                ramp_s: 0.0,
                drift_velocity: drift.as_deref(),
                track: job.track,
            };
            fc.forecast(model, &req).map(|f| {
                let mut values = Vec::with_capacity(6 * n_bodies * (f.steps + 1));
                for i in 0..6 * n_bodies {
                    values.extend((0..=f.steps).map(|k| f.at(k, i)));
                }
                (values, f.steps, f.skipped_variance_fraction, f.quasi_static_components)
            })
        });
        // the band and the trusted span (nothing trusted without the response table)
        let opts = SpreadOptions {
            model_error: job.model_error.clone(),
            trusted_nrmse: self.trusted_nrmse,
            start_var: job.start_var.clone(),
            start_offset: job.start_offset.clone(),
        };
        let result = result.map(|(values, steps, dropped, quasi_static)| {
            let spread = self.table.as_ref().map(|table| {
                spread::spread(
                    table,
                    &job.waves,
                    &job.known_leads,
                    n_bodies,
                    job.track.map_or(0.0, |t| t.speed_m_s),
                    model.g_m_s2,
                    model.water_depth_m,
                    steps,
                    model.opts.dt_s,
                    &opts,
                )
            });
            (values, steps, dropped, quasi_static, spread)
        });
        let compute_ms = elapsed_ms();
        let mut header = job.header;
        header.compute_ms = compute_ms;
        header.issue_time_s = job.t0_s;
        match result {
            Ok((mut values, steps, dropped_wave_share, quasi_static, spread)) => {
                header.steps = steps as u32;
                let mut motion_sigma = vec![];
                match spread {
                    Some(s) => {
                        values.extend_from_slice(&s.sigma);
                        for b in 0..n_bodies.min(MAX_VESSELS) {
                            let ok = job.trustworthy && s.to_s[b] > 0.0;
                            header.horizon_s[b] = if ok { s.to_s[b] } else { 0.0 };
                            header.trusted_from_s[b] = if ok { s.from_s[b] } else { 0.0 };
                        }
                        motion_sigma = s.motion_sigma;
                    }
                    None => {
                        // no band known: not a band of zero
                        values.extend(std::iter::repeat_n(f64::NAN, 6 * n_bodies * (steps + 1)));
                        header.horizon_s = [0.0; MAX_VESSELS];
                        header.trusted_from_s = [0.0; MAX_VESSELS];
                    }
                }
                if quasi_static > 0 {
                    header.flags |= flags::QUASI_STATIC_WAVES;
                }
                Done {
                    header,
                    values: Some(values),
                    compute_ms,
                    error: None,
                    dropped_wave_share,
                    teaches: job.trustworthy && !motion_sigma.is_empty(),
                    motion_sigma,
                    model_error: job.model_error,
                    start_var: job.start_var,
                    check_var: job.check_var,
                }
            }
            Err(e) => Done {
                header,
                values: None,
                compute_ms,
                error: Some(e.to_string()),
                dropped_wave_share: 0.0,
                motion_sigma: vec![],
                model_error: job.model_error,
                start_var: job.start_var,
                check_var: job.check_var,
                teaches: false,
            },
        }
    }
}

/// The model's response table for the band, or None (logged) where its equations are singular.
fn response_table(model: &TimeModel) -> Option<ResponseTable> {
    ResponseTable::of(model)
        .map_err(|e| tracing::warn!("no band for the forecasts (nothing will be trusted): {e}"))
        .ok()
}

/// `SHIPCAST_FAULT=compute-panic` makes the compute thread panic on its first job: fault injection for
/// the test of the daemon's liveness (a panic there ends the daemon with an error).
pub const FAULT_ENV: &str = "SHIPCAST_FAULT";

fn compute_thread(
    mut computer: Computer,
    jobs: std::sync::mpsc::Receiver<Job>,
    done: tokio::sync::mpsc::Sender<Done>,
    inject_panic: bool,
) -> std::thread::JoinHandle<()> {
    std::thread::Builder::new()
        .name("shipcast-compute".into())
        .spawn(move || {
            while let Ok(job) = jobs.recv() {
                if inject_panic {
                    panic!("{FAULT_ENV}=compute-panic: the compute thread panics on its first job");
                }
                let t = Instant::now();
                let msg = computer.run(job, || t.elapsed().as_secs_f64() * 1e3);
                if done.blocking_send(msg).is_err() {
                    break;
                }
            }
        })
        .expect("spawning the compute thread")
}

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

/// A stamp judged by its source's clock, counted and logged: None if refused, else whether the source's
/// clock stepped (and re-synchronized) with it.
fn judge(
    source: &mut clock::SourceClock,
    c: &mut Counters,
    what: &str,
    stamp_s: f64,
    clock_s: f64,
    rules: &clock::ClockRules,
) -> Option<bool> {
    match source.judge(stamp_s, clock_s, rules) {
        clock::Stamp::Accepted => Some(false),
        clock::Stamp::Stepped { step_s } => {
            c.clock_steps += 1;
            tracing::warn!(
                step_s,
                "{what}: the source's clock stepped: re-synchronized, its history restarts"
            );
            Some(true)
        }
        clock::Stamp::NonFinite => {
            c.nonfinite += 1;
            log_count(c.nonfinite, &format!("{what} with a non-finite stamp refused"));
            None
        }
        clock::Stamp::Future { ahead_s } => {
            c.future += 1;
            log_count(
                c.future,
                &format!("{what} stamped {ahead_s:.3} s ahead of its clock refused"),
            );
            None
        }
        clock::Stamp::Past { behind_s } => {
            c.past += 1;
            log_count(
                c.past,
                &format!("{what} stamped {behind_s:.3} s behind its clock refused"),
            );
            None
        }
    }
}

/// A vessel's sample (`what`: a motion sample, a navigation fix) of (schema version, vessel index,
/// stamp): the schema and the index checked against `clocks` (one per vessel), the stamp judged by
/// the vessel's clock of that kind. None: refused (counted, logged); else the vessel and whether its
/// clock stepped.
fn vessel_sample(
    c: &mut Counters,
    clocks: &mut [clock::SourceClock],
    what: &str,
    (schema_version, vessel, stamp_s): (u32, u32, f64),
    clock_s: f64,
    rules: &clock::ClockRules,
) -> Option<(usize, bool)> {
    let b = vessel as usize;
    if schema_version != SCHEMA_VERSION || b >= clocks.len() {
        c.rejected += 1;
        log_count(
            c.rejected,
            &format!(
                "{what} refused: schema version {schema_version} (this daemon reads {SCHEMA_VERSION}), vessel {vessel} of {}",
                clocks.len()
            ),
        );
        return None;
    }
    judge(
        &mut clocks[b],
        c,
        &format!("vessel {b}: {what}"),
        stamp_s,
        clock_s,
        rules,
    )
    .map(|stepped| (b, stepped))
}

/// Flags of events, kept in the state until the next status reports them.
const ONE_SHOT_FLAGS: u32 = flags::NUMERICAL | flags::CLOCK_STEP | flags::MOTION_IMPLAUSIBLE | flags::MOTION_RESTARTED;

/// A refusal in words, with the DOF's name and units.
fn refusal_text(why: &Refusal) -> String {
    let name = |d: usize| crate::hydro::Dof::of_index(d).output_name();
    let show = |d: usize, v: f64| crate::hydro::Dof::of_index(d).to_output(v);
    match *why {
        Refusal::Bound {
            dof,
            what,
            value,
            bound,
        } => {
            format!(
                "{} {what} {:.4e} beyond +-{:.4e}",
                name(dof),
                show(dof, value),
                show(dof, bound)
            )
        }
        Refusal::Jump {
            dof,
            what,
            change,
            allowed,
        } => format!(
            "{} {what} changed by {:.4e} since the estimate, at most {:.4e} possible",
            name(dof),
            show(dof, change),
            show(dof, allowed)
        ),
        Refusal::Frozen => "the same values as the sample before while the vessel moves (a stalled sensor)".into(),
        Refusal::NonFinite | Refusal::Late | Refusal::Duplicate => format!("{why:?}"),
    }
}

/// The estimator of vessel `b`: the configured sensor and gate, bounds from the body and the
/// database, the bandwidth from the database's highest frequency, the bias on the DOFs with
/// hydrostatic restoring.
pub fn estimator_spec(cfg: &ShipcastConfig, sys: &VesselSystem, model: &TimeModel, b: usize) -> estimator::Spec {
    let e = &cfg.estimator;
    let (omega_min, omega_max) = model.db.omega_range();
    let mut spec = estimator::Spec {
        method: e.method,
        noise_x: [e.noise_m, e.noise_m, e.noise_m, e.noise_rad, e.noise_rad, e.noise_rad],
        noise_v: [
            e.velocity_noise_m_s,
            e.velocity_noise_m_s,
            e.velocity_noise_m_s,
            e.velocity_noise_rad_s,
            e.velocity_noise_rad_s,
            e.velocity_noise_rad_s,
        ],
        q: [0.0; 6],
        bounds: estimator::Bounds::from_system(
            &sys.spec.bodies[b].mass,
            sys.spec.g_m_s2,
            e.max_acceleration_g,
            omega_min,
        ),
        restored: [false; 6],
        learned: [false; 6],
        bias_time_s: e.bias_time_s,
        drift: [e.drift_m, e.drift_m, e.drift_m, e.drift_rad, e.drift_rad, e.drift_rad],
        drift_time_s: e.drift_time_s,
        gate_sigma: e.gate_sigma,
        reset_samples: e.reset_samples as usize,
    };
    for d in 0..6 {
        spec.q[d] = estimator::Spec::process_noise(spec.noise_x[d], estimator::BANDWIDTH_FACTOR * omega_max);
        if (2..5).contains(&d)
            && let Some(row) = model.active.iter().position(|&i| i == 6 * b + d)
        {
            spec.restored[d] = model.stiffness[(row, row)] > 0.0;
            spec.learned[d] = spec.restored[d] && !MEASURED_MEAN_DOFS.contains(&d);
        }
    }
    spec
}

fn power_of_ten(mut n: u64) -> bool {
    while n >= 10 && n.is_multiple_of(10) {
        n /= 10;
    }
    n == 1
}

/// The daemon's state and decisions, driven by a clock the caller supplies (seconds: monotonic wall
/// time live, the log's time in replay): the same code for both.
pub struct Engine {
    cfg: config::ForecastConfig,
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
    /// The newest radar scans of one grid (at most `forecast.radar_snapshots`), and how they are
    /// inverted (the database's frequency band).
    scans: std::collections::VecDeque<crate::ipc::Scan>,
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
    last_horizon: [f64; MAX_VESSELS],
    /// The ship-to-ship link's newest health, and the engine clock it arrived at.
    link: Option<(crate::ipc::wire::LinkStatus, f64)>,
    state_flags: u32,
    /// The model error learnt from past forecasts against the motion that followed, and the checks
    /// at 30 s when it was last logged.
    model_error: spread::ModelError,
    model_error_logged: usize,
    /// The model's own mean displacement in waves per vessel and DOF (heave, roll, pitch), and when it
    /// was last learnt (`learn_model_mean`).
    model_mean: Vec<estimator::RunningMean>,
    model_mean_time_s: Option<f64>,
    /// Per vessel, the running mean square of roll's and pitch's measured mean offset from the
    /// model's (over [`HEEL_MEMORY_BIAS_TIMES`] `bias_time_s`), and when it was last taken in: what
    /// the sensor's drift does not explain of it is heel ([`spread::heel_split`]).
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
}

impl Engine {
    pub fn new(cfg: &ShipcastConfig, sys: &VesselSystem, model: &TimeModel) -> Engine {
        let n_bodies = sys.spec.bodies.len();
        let taps = match &model.kernel {
            crate::rom::model::Kernel::Convolution { taps, .. } => *taps,
            crate::rom::model::Kernel::StateSpace { .. } => {
                (cfg.forecast.memory_s.unwrap_or(STATE_SPACE_HISTORY_S) / model.opts.dt_s).round() as usize
            }
        };
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
            last_horizon: [0.0; MAX_VESSELS],
            link: None,
            state_flags: 0,
            model_error_logged: 0,
            model_mean: vec![Default::default(); n_bodies],
            model_mean_time_s: None,
            heel_square: vec![Default::default(); n_bodies],
            heel_time_s: None,
            job_offset: vec![[0.0; 6]; n_bodies],
            job_unknown: vec![false; n_bodies],
            bias_time_s: cfg.estimator.bias_time_s,
            drift_time_s: cfg.estimator.drift_time_s,
            angle_bias_rad: cfg.estimator.angle_bias_rad,
            model_error: spread::ModelError::new(
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

    /// Radiation memory the engine keeps, s.
    pub fn memory_s(&self) -> f64 {
        self.taps as f64 * self.dt_s
    }

    /// One input that arrived at `clock_s` (engine clock). Every stamp is judged against its source's
    /// clock first ([`clock`]): refused samples never reach the history.
    pub fn input(&mut self, msg: Input, clock_s: f64) {
        let rules = self.clock_rules;
        let c = &mut self.counters;
        match msg {
            Input::Motion(m) => {
                c.samples += 1;
                let sample = (m.schema_version, m.vessel, m.time_s);
                let Some((b, stepped)) =
                    vessel_sample(c, &mut self.motion_clock, "motion sample", sample, clock_s, &rules)
                else {
                    return;
                };
                if stepped {
                    self.state_flags |= flags::CLOCK_STEP;
                    self.hist[b].restart();
                }
                match self.hist[b].push(m.time_s, m.x, m.v) {
                    Ok(taken) => {
                        self.arrival[b] = Some(clock_s);
                        if taken == Taken::Restarted {
                            c.motion_restarts += 1;
                            self.state_flags |= flags::MOTION_RESTARTED;
                            tracing::warn!(
                                vessel = b,
                                "motion samples that agree with each other but not with the estimate: a real jump, the estimate restarts from them"
                            );
                        }
                    }
                    Err(Refusal::NonFinite) => {
                        c.nonfinite += 1;
                        log_count(
                            c.nonfinite,
                            &format!("vessel {b}: motion sample with a non-finite value refused"),
                        );
                    }
                    Err(Refusal::Late) => {
                        c.late += 1;
                        log_count(
                            c.late,
                            &format!("vessel {b}: motion sample older than the newest refused"),
                        );
                    }
                    Err(Refusal::Duplicate) => c.duplicate += 1,
                    Err(why) => {
                        c.implausible += 1;
                        self.state_flags |= flags::MOTION_IMPLAUSIBLE;
                        log_count(
                            c.implausible,
                            &format!(
                                "vessel {b}: motion sample refused as physically impossible: {}",
                                refusal_text(&why)
                            ),
                        );
                    }
                }
            }
            Input::Navigation(n) => {
                c.navigation += 1;
                let sample = (n.schema_version, n.vessel, n.time_s);
                let Some((b, stepped)) =
                    vessel_sample(c, &mut self.nav_clock, "navigation fix", sample, clock_s, &rules)
                else {
                    return;
                };
                if stepped {
                    self.state_flags |= flags::CLOCK_STEP;
                    self.nav[b].restart();
                }
                match self.nav[b].push(&n, self.cfg.navigation_window_s) {
                    Ok(()) => {}
                    Err(navigation::NavRefusal::NonFinite) => {
                        c.nonfinite += 1;
                        log_count(
                            c.nonfinite,
                            &format!("vessel {b}: navigation fix with a non-finite value refused"),
                        );
                    }
                    Err(navigation::NavRefusal::Late) => {
                        c.late += 1;
                        log_count(
                            c.late,
                            &format!("vessel {b}: navigation fix not newer than the newest refused"),
                        );
                    }
                    Err(navigation::NavRefusal::Implausible(what)) => {
                        c.rejected += 1;
                        log_count(
                            c.rejected,
                            &format!("vessel {b}: navigation fix refused: its {what} is beyond what a ship does"),
                        );
                    }
                }
            }
            Input::Elevation(scan) => {
                c.wave_fields += 1;
                let Some(stepped) = judge(&mut self.wave_clock, c, "radar scan", scan.grid.time_s, clock_s, &rules)
                else {
                    return;
                };
                if stepped {
                    self.state_flags |= flags::CLOCK_STEP;
                    self.scans.clear();
                }
                // a sequence shares one grid at increasing times: another grid starts it again
                if self.scans.back().is_some_and(|last| {
                    last.frame != scan.frame
                        || last.grid.x_m != scan.grid.x_m
                        || last.grid.y_m != scan.grid.y_m
                        || last.grid.time_s >= scan.grid.time_s
                }) {
                    self.scans.clear();
                }
                self.scans.push_back(*scan);
                while self.scans.len() > self.cfg.radar_snapshots as usize {
                    self.scans.pop_front();
                }
                if self.scans.len() < self.cfg.radar_snapshots as usize {
                    return;
                }
                let grids: Vec<crate::waves::observe::Grid> = self.scans.iter().map(|s| s.grid.clone()).collect();
                let frame = self
                    .scans
                    .back()
                    .map(|s| s.frame)
                    .unwrap_or(crate::waves::observe::GridFrame {
                        origin_m: [0.0, 0.0],
                        orientation_rad: 0.0,
                    });
                match crate::waves::observe::from_scans(&grids, frame, &self.radar_options) {
                    Ok(f) => {
                        let f = f.pruned(self.cfg.wave_variance_kept);
                        if stepped || self.field.as_ref().is_none_or(|old| f.time_s > old.time_s) {
                            self.field = Some(f);
                        }
                    }
                    Err(e) => {
                        c.rejected += 1;
                        log_count(c.rejected, &format!("radar scans not inverted: {e}"));
                    }
                }
            }
            Input::Waves(f) => {
                c.wave_fields += 1;
                if let Err(why) = crate::ipc::wire::check_wave_components(f.components.len()) {
                    c.rejected += 1;
                    log_count(c.rejected, &format!("{why}: refused"));
                    return;
                }
                let Some(stepped) = judge(&mut self.wave_clock, c, "wave field", f.time_s, clock_s, &rules) else {
                    return;
                };
                if stepped {
                    self.state_flags |= flags::CLOCK_STEP;
                }
                let f = f.pruned(self.cfg.wave_variance_kept);
                if stepped || self.field.as_ref().is_none_or(|old| f.time_s > old.time_s) {
                    self.field = Some(f);
                }
            }
            Input::Link(l) => {
                if l.schema_version == crate::ipc::wire::LINK_SCHEMA_VERSION {
                    self.link = Some((l, clock_s));
                } else {
                    c.rejected += 1;
                    log_count(
                        c.rejected,
                        &format!("link status of schema version {}: refused", l.schema_version),
                    );
                }
            }
            Input::Rejected(why) => {
                c.rejected += 1;
                tracing::warn!("input rejected: {why}");
            }
        }
    }

    /// One cadence tick at `clock_s`: the flags of the moment and, when the inputs allow and no
    /// forecast is running, the job to run (a tick while one runs is an overrun).
    pub fn tick(&mut self, clock_s: f64) -> Option<Job> {
        let cfg = &self.cfg;
        let n_bodies = self.n_bodies;
        let mut fl = 0u32;
        let motion_ok: Vec<bool> = (0..n_bodies)
            .map(|b| self.arrival[b].is_some_and(|a| clock_s - a <= cfg.max_motion_age_s))
            .collect();
        if self.arrival.iter().any(|a| a.is_none()) {
            fl |= flags::NO_MOTION;
        }
        if motion_ok.iter().any(|ok| !ok) {
            fl |= flags::STALE_MOTION;
        }
        // a vessel whose motion is stale or missing (the other ship's, when the link between them is
        // down) does not stop the others' forecasts: the model starts it from rest at its mean in
        // waves, it is trusted nowhere and its band is the motion's own, and its error reaches the
        // fresh vessels through the coupling (lines, fenders, the water between them)
        let motion_fresh: Vec<bool> = (0..n_bodies)
            .map(|b| motion_ok[b] && self.hist[b].newest_time_s().is_some())
            .collect();
        let (t0, newest) = self.newest_motion_of(&motion_fresh);
        // the sources' clocks must agree: vessels' newest motion within the staleness and the skew of
        // each other, and no wave field from after the motion beyond the skew
        let mut disagree = newest - t0 > cfg.max_motion_age_s + cfg.max_clock_skew_s;
        if let Some(f) = &self.field
            && f.time_s - t0 > cfg.max_clock_skew_s
        {
            disagree = true;
        }
        if disagree {
            fl |= flags::CLOCKS_DISAGREE;
        }
        // ages are never negative: a field stamped a little after the newest motion (within the
        // clocks' skew) is taken as current
        match self.field.as_ref().map(|f| (t0 - f.time_s).max(0.0)) {
            None => fl |= flags::NO_WAVES,
            Some(a) if a.is_nan() || a > cfg.suppress_wave_age_s => fl |= flags::NO_WAVES | flags::STALE_WAVES,
            Some(a) if a > cfg.max_wave_age_s => fl |= flags::STALE_WAVES,
            _ => {}
        }
        let can =
            fl & (flags::NO_WAVES | flags::CLOCKS_DISAGREE) == 0 && motion_fresh.iter().any(|f| *f) && t0.is_finite();
        if self.forecasting != Some(can) {
            let why = flags::names(fl).join(", ");
            match (self.forecasting, can) {
                (_, true) => tracing::info!("forecasting"),
                (Some(true), false) => tracing::warn!(flags = %why, "forecasting stopped: status only"),
                (None, false) => tracing::info!(flags = %why, "waiting for inputs: status only"),
                _ => {}
            }
            self.forecasting = Some(can);
        }
        let mut job = None;
        if can && self.busy {
            self.counters.overruns += 1;
        } else if can && let Some(f) = &self.field {
            let dt = self.dt_s;
            let n_hist = self.taps.saturating_sub(1);
            let mut x0 = vec![0.0; self.n_active];
            let mut v0 = vec![0.0; self.n_active];
            let mut velocities = vec![vec![0.0; self.n_active]; n_hist];
            let mut known_history = n_hist;
            let mut offset = vec![[0.0; 6]; n_bodies];
            // the start's error per series: a vessel without fresh motion is bounded apart
            // (`unknown_start`), so its share here is the sensor's noise
            let mut start_var: Vec<f64> = self.model_error.noise_var().to_vec();
            let mut start_offset = vec![0.0; 6 * n_bodies];
            let mut check_var = start_var.clone();
            let heel_dt = match self.heel_time_s {
                Some(t) => (t0 - t).max(0.0),
                None => 0.0,
            };
            self.heel_time_s = Some(t0);
            let mut ok = true;
            for b in 0..n_bodies {
                if !motion_fresh[b] {
                    // at rest at the model's own mean in waves, no history
                    for (row, &i) in self.active.iter().enumerate() {
                        if i / 6 == b && i < 6 * n_bodies {
                            x0[row] = self.model_mean[b].value[i % 6];
                        }
                    }
                    continue;
                }
                let Some(r) = self.hist[b].resample(t0, dt, n_hist, cfg.max_gap_s) else {
                    ok = false;
                    break;
                };
                if r.short {
                    fl |= flags::HISTORY_SHORT;
                }
                if r.gap {
                    fl |= flags::HISTORY_GAP;
                }
                known_history = known_history.min(r.known);
                // the estimator takes its bias off (the sensor's and a mean heel alike); the model
                // starts from its own mean in waves, and the forecast of roll and pitch is shifted
                // toward the measured mean when done: beyond what the sensor's bias can be, a heel or
                // trim the model does not know (angles are gravity-referenced; heave is integrated
                // acceleration, whose mean is drift: heave keeps the model's)
                let bias = self.hist[b].bias();
                for (row, &i) in self.active.iter().enumerate() {
                    if i / 6 == b && i < 6 * n_bodies {
                        let d = i % 6;
                        if bias[d] != 0.0 && MEASURED_MEAN_DOFS.contains(&d) {
                            offset[b][d] = beyond(bias[d] - self.model_mean[b].value[d], self.angle_bias_rad);
                        }
                        x0[row] = r.x0[d]
                            + if bias[d] != 0.0 {
                                self.model_mean[b].value[d]
                            } else {
                                0.0
                            };
                        v0[row] = r.v0[i % 6];
                        for (m, v) in r.velocities.iter().enumerate() {
                            velocities[m][row] = v[i % 6];
                        }
                    }
                }
                if let Some(v) = self.hist[b].start_var(t0) {
                    start_var[6 * b..6 * b + 6].copy_from_slice(&v);
                }
                if let Some(v) = self.hist[b].estimate_var(t0) {
                    check_var[6 * b..6 * b + 6].copy_from_slice(&v);
                }
                // roll and pitch: what the forecast leaves out of the measured mean's offset from the
                // model's (within angle_bias_rad) is the sensor's bias or a heel, which no sample
                // tells apart; the band holds either, as likely as the sensor's drift and the
                // offsets seen so far make them (`spread::heel_split`)
                let held = self.hist[b].drift_in_bias_var();
                let heel_memory_s = HEEL_MEMORY_BIAS_TIMES * self.bias_time_s;
                let mut square = [f64::NAN; 6];
                for d in MEASURED_MEAN_DOFS {
                    if bias[d] != 0.0 {
                        let m = bias[d] - self.model_mean[b].value[d];
                        square[d] = m * m;
                        let heel_var = spread::heel_var(
                            self.heel_square[b].value[d],
                            held[d],
                            self.drift_time_s,
                            self.heel_square[b].span_s.min(heel_memory_s),
                        );
                        let (mean, var) = spread::heel_split(m, m - offset[b][d], held[d], heel_var);
                        start_offset[6 * b + d] = mean;
                        start_var[6 * b + d] += var;
                    }
                }
                self.heel_square[b].add(heel_dt, &square, heel_memory_s);
            }
            if ok {
                // past forecasts against the motion that followed them, as measured, with the sensor's
                // bias off as the forecast takes it: about the model's own mean where the measured
                // mean is taken for the sensor's (heave's drift; roll and pitch within the bias the
                // sensor may have: how much of that may be heel is in the band at the start,
                // `spread::heel_split`), with the measured mean where roll or pitch keeps a heel
                // (gravity-referenced: part of what the forecast leaves out of it as bias may be
                // heel, and a forecast settles to the model's equilibrium whatever its start)
                let hist = &self.hist;
                let model_mean = &self.model_mean;
                let angle_bias_rad = self.angle_bias_rad;
                self.model_error.observe(t0, |t| {
                    let mut x = vec![0.0; 6 * n_bodies];
                    for (b, h) in hist.iter().enumerate() {
                        let r = h.resample(t, dt, 0, cfg.max_gap_s)?;
                        let bias = h.bias();
                        for d in 0..6 {
                            let mean = model_mean[b].value[d];
                            let heel = MEASURED_MEAN_DOFS.contains(&d) && beyond(bias[d] - mean, angle_bias_rad) != 0.0;
                            x[6 * b + d] = r.x0[d]
                                + match (bias[d] != 0.0, heel) {
                                    (false, _) => 0.0,
                                    (true, true) => bias[d],
                                    (true, false) => mean,
                                };
                        }
                    }
                    Some(x)
                });
                // the learnt model error in the log: when first learnt, then every CHECK_MEMORY checks
                let c30 = self.model_error.checks()[4];
                if c30 != self.model_error_logged && (c30 == 60 || c30.is_multiple_of(600)) && c30 > 0 {
                    self.model_error_logged = c30;
                    let curve = self.model_error.curve();
                    let at = |i: usize| {
                        let m = curve.motion_var[i];
                        format!("{:.3}", (curve.at(i, 30.0, m) / m).sqrt())
                    };
                    tracing::info!(
                        checks = c30,
                        "model error at 30 s lead (fraction of each measured motion; heave, roll, pitch per vessel): {}",
                        (0..n_bodies)
                            .map(|b| format!("[{} {} {}]", at(6 * b + 2), at(6 * b + 3), at(6 * b + 4)))
                            .collect::<Vec<_>>()
                            .join(" ")
                    );
                }
                let mut header = ForecastHeader {
                    schema_version: crate::ipc::wire::FORECAST_SCHEMA_VERSION,
                    n_vessels: n_bodies as u32,
                    dt_s: dt,
                    n_series: (6 * n_bodies) as u32,
                    flags: fl,
                    wave_time_s: f.time_s,
                    motion_time_s: t0,
                    ..ForecastHeader::default()
                };
                // the system frame at t0: from the first vessel with fresh navigation, else the last
                // pose navigation gave (stale: not trusted), else `[site]` (keeping station)
                let fresh = (0..n_bodies).find_map(|b| {
                    let newest = self.nav[b].newest_time_s()?;
                    if t0 - newest > cfg.max_navigation_age_s {
                        return None;
                    }
                    self.nav[b].pose_at(t0, cfg.navigation_window_s).map(|p| (b, p))
                });
                let mut untrusted = false;
                let (heading, origin, velocity, track) = match fresh {
                    Some((b, p)) => {
                        let (s, c) = p.heading_rad.sin_cos();
                        let r = self.body_xy_m[b];
                        let origin = [
                            p.position_m[0] - (c * r[0] - s * r[1]),
                            p.position_m[1] - (s * r[0] + c * r[1]),
                        ];
                        self.last_frame = Some((p.heading_rad, origin, p.velocity_m_s));
                        let track = Track {
                            speed_m_s: p
                                .speed_m_s
                                .clamp(-crate::rom::model::MAX_SPEED_M_S, crate::rom::model::MAX_SPEED_M_S),
                            turn_rate_rad_s: p.turn_rate_rad_s.clamp(
                                -crate::rom::forecast::MAX_TURN_RATE_RAD_S,
                                crate::rom::forecast::MAX_TURN_RATE_RAD_S,
                            ),
                            turn_start_s: 0.0,
                            piece_rad: crate::rom::forecast::TURN_PIECE_RAD,
                        };
                        (p.heading_rad, origin, p.velocity_m_s, Some(track))
                    }
                    None => {
                        header.flags |= flags::NAVIGATION_FALLBACK;
                        match self.last_frame {
                            Some((h, o, _)) => {
                                untrusted = true;
                                (h, o, [0.0, 0.0], None)
                            }
                            None => (self.heading, self.origin_m, [0.0, 0.0], None),
                        }
                    }
                };
                let waves = f.for_vessel(origin, heading, t0);
                // what the field says about where it was observed decides how far it is trusted (and
                // the variance the forecast leaves out, in `done`)
                let located = match f.region {
                    _ if f.components.is_empty() => {
                        header.flags |= flags::NO_WAVE_COMPONENTS;
                        false
                    }
                    crate::waves::field::Region::Everywhere => {
                        header.flags |= flags::WAVE_REGION_UNKNOWN;
                        false
                    }
                    _ => true,
                };
                // each component's known leads at each vessel, from t0 (the field is that much older);
                // a field that cannot be trusted (no region, stale navigation) tells none of them
                let trustworthy = located && !untrusted;
                let (s, c) = heading.sin_cos();
                let age_s = (t0 - f.time_s).max(0.0);
                let known_leads: Vec<Vec<[f64; 2]>> = self
                    .body_xy_m
                    .iter()
                    .map(|r| {
                        if !trustworthy {
                            return vec![[0.0, 0.0]; f.components.len()];
                        }
                        let p = [origin[0] + c * r[0] - s * r[1], origin[1] + s * r[0] + c * r[1]];
                        horizon::known_leads(f, p, velocity)
                            .into_iter()
                            .map(|[a, b]| [a - age_s, b - age_s])
                            .collect()
                    })
                    .collect();
                let model_error = self.model_error.curve();
                if model_error.checked_to_s <= 0.0 {
                    header.flags |= flags::MODEL_ERROR_UNCHECKED;
                }
                fl = header.flags;
                self.busy = true;
                self.job_offset = offset;
                self.job_unknown = motion_fresh.iter().map(|f| !f).collect();
                job = Some(Job {
                    t0_s: t0,
                    x0,
                    v0,
                    velocities,
                    known: known_history,
                    waves,
                    known_leads,
                    trustworthy,
                    model_error,
                    start_var,
                    start_offset,
                    check_var,
                    track,
                    header,
                });
            }
        }
        self.state_flags = fl | (self.state_flags & ONE_SHOT_FLAGS);
        job
    }

    /// A finished job: the forecast to publish, if it succeeded.
    pub fn done(&mut self, d: Done) -> Option<Output> {
        self.busy = false;
        self.last_compute_ms = d.compute_ms;
        match (d.values, d.error) {
            (Some(values), _) => {
                let mut header = d.header;
                self.dropped_wave_share = d.dropped_wave_share;
                if d.dropped_wave_share > 0.0 {
                    header.flags |= flags::WAVES_DROPPED;
                }
                if d.dropped_wave_share > self.cfg.max_dropped_wave_share {
                    header.horizon_s = [0.0; MAX_VESSELS];
                    header.trusted_from_s = [0.0; MAX_VESSELS];
                }
                self.counters.forecasts += 1;
                self.last_forecast_time = header.issue_time_s;
                // only forecasts whose waves the daemon trusts teach it the model's error (an
                // untrusted field's error is its waves'), with or without a trusted span
                let n = (header.steps as usize + 1) * header.n_series as usize;
                let unknown = self.job_unknown.iter().any(|u| *u);
                let trusted = d.teaches && d.dropped_wave_share <= self.cfg.max_dropped_wave_share && !unknown;
                let mut values = values;
                if unknown {
                    self.unknown_start(&mut header, &mut values, &d.motion_sigma);
                }
                if values.len() == 2 * n {
                    self.learn_model_mean(&header, &values[..n]);
                    self.shift_to_measured_mean(&header, &mut values[..n]);
                }
                if values.len() == 2 * n && trusted {
                    self.model_error.record(
                        header.issue_time_s,
                        header.dt_s,
                        (&values[..n], &values[n..]),
                        &d.motion_sigma,
                        &d.model_error,
                        (&d.start_var, &d.check_var),
                    );
                }
                self.last_horizon = header.horizon_s;
                Some(Output::Forecast(header, values))
            }
            (None, e) => {
                self.state_flags |= flags::NUMERICAL;
                tracing::warn!("forecast abandoned: {}", e.unwrap_or_default());
                None
            }
        }
    }

    /// The model's own mean displacement in waves (heave, roll, pitch), from a forecast's settled leads
    /// (at least [`SETTLED_LEAD_S`]): averaged over [`crate::service::config::EstimatorConfig`]'s
    /// `bias_time_s`, as the estimator averages the measured motion. Lines and fenders give a moored
    /// vessel a mean heel in waves; the model starts from its own, and its forecast of roll and pitch
    /// is shifted to the measured one ([`MEASURED_MEAN_DOFS`]).
    fn learn_model_mean(&mut self, header: &ForecastHeader, values: &[f64]) {
        let steps = header.steps as usize;
        let first = (SETTLED_LEAD_S / header.dt_s).ceil() as usize;
        if first > steps || values.len() != (steps + 1) * 6 * self.n_bodies {
            return;
        }
        let dt = match self.model_mean_time_s {
            Some(t) => (header.issue_time_s - t).max(0.0),
            None => 0.0,
        };
        self.model_mean_time_s = Some(header.issue_time_s);
        for (b, m) in self.model_mean.iter_mut().enumerate() {
            // heave, roll and pitch (the DOFs with a bias); the others stay 0
            let mut mean = [f64::NAN; 6];
            for d in 2..5 {
                let series = &values[(6 * b + d) * (steps + 1) + first..(6 * b + d + 1) * (steps + 1)];
                mean[d] = series.iter().sum::<f64>() / series.len() as f64;
            }
            m.add(dt, &mean, self.bias_time_s);
        }
    }

    /// A forecast that started vessels from rest for want of their motion: nothing of theirs is trusted
    /// (horizon 0), and their band is at least the error of a guess unrelated to the motion, twice
    /// its variance (`motion_sigma`: the model's response to the whole sea), as for unknown waves.
    fn unknown_start(&self, header: &mut ForecastHeader, values: &mut [f64], motion_sigma: &[f64]) {
        let per = header.steps as usize + 1;
        let n = per * header.n_series as usize;
        for (b, _) in self.job_unknown.iter().enumerate().filter(|(_, u)| **u) {
            if b < MAX_VESSELS {
                header.horizon_s[b] = 0.0;
                header.trusted_from_s[b] = 0.0;
            }
            if values.len() != 2 * n {
                continue;
            }
            for i in 6 * b..(6 * b + 6).min(header.n_series as usize) {
                let floor = std::f64::consts::SQRT_2 * motion_sigma.get(i).copied().unwrap_or(f64::NAN);
                for s in &mut values[n + i * per..n + (i + 1) * per] {
                    // NaN (no band known) stays NaN
                    if floor.is_finite() && *s < floor {
                        *s = floor;
                    }
                }
            }
        }
    }

    /// Shifts a forecast's values (the model's motion about its own mean) by the job's offsets: the
    /// measured mean less the model's, per vessel and DOF.
    fn shift_to_measured_mean(&self, header: &ForecastHeader, values: &mut [f64]) {
        let per = header.steps as usize + 1;
        if values.len() != per * 6 * self.n_bodies {
            return;
        }
        for (b, o) in self.job_offset.iter().enumerate().take(self.n_bodies) {
            for (d, od) in o.iter().enumerate() {
                if *od != 0.0 && od.is_finite() {
                    let i = 6 * b + d;
                    values[i * per..(i + 1) * per].iter_mut().for_each(|v| *v += od);
                }
            }
        }
    }

    /// The status at `clock_s` (`wall_s`: the wall clock to stamp it with); clears the one-shot flags.
    pub fn status(&mut self, clock_s: f64, wall_s: f64, running: bool) -> Status {
        let now_data = self.newest_motion_s().1;
        let c = &self.counters;
        let waves_dropped = if self.dropped_wave_share > 0.0 {
            flags::WAVES_DROPPED
        } else {
            0
        };
        let mut s = Status {
            schema_version: crate::ipc::wire::STATUS_SCHEMA_VERSION,
            flags: self.state_flags | waves_dropped,
            time_s: if now_data.is_finite() { now_data } else { -1.0 },
            wall_time_s: wall_s,
            wave_age_s: match &self.field {
                Some(f) if now_data.is_finite() => (now_data - f.time_s).max(0.0),
                _ => -1.0,
            },
            last_forecast_time_s: self.last_forecast_time,
            last_compute_ms: self.last_compute_ms,
            horizon_s: self.last_horizon,
            forecasts: c.forecasts,
            overruns: c.overruns,
            samples: c.samples,
            wave_fields: c.wave_fields,
            dropped_nonfinite: c.nonfinite,
            dropped_late: c.late,
            dropped_duplicate: c.duplicate,
            dropped_future: c.future,
            dropped_past: c.past,
            dropped_rejected: c.rejected,
            clock_steps: c.clock_steps,
            dropped_wave_share: self.dropped_wave_share,
            dropped_implausible: c.implausible,
            motion_restarts: c.motion_restarts,
            running: running as u32,
            ..Status::default()
        };
        (s.link_state, s.link_latency_ms, s.link_loss, s.link_age_s) = match self.link {
            None => (link_state::NONE, -1.0, -1.0, -1.0),
            Some((l, at)) => {
                let since = (clock_s - at).max(0.0);
                let up = l.up == 1 && since <= LINK_SILENT_S;
                (
                    if up { link_state::UP } else { link_state::DOWN },
                    l.latency_ms,
                    l.loss,
                    if l.last_message_age_s >= 0.0 {
                        l.last_message_age_s + since
                    } else {
                        -1.0
                    },
                )
            }
        };
        for (b, h) in self.hist.iter().enumerate() {
            s.motion_age_s[b] = self.arrival[b].map(|a| clock_s - a).unwrap_or(-1.0);
            s.motion_rate_hz[b] = h.rate_hz();
            let bias = h.bias();
            s.motion_bias[b] = [bias[2], bias[3], bias[4]];
        }
        self.state_flags &= !ONE_SHOT_FLAGS;
        s
    }
}

/// The model and the engine of a configuration, built and logged.
fn build(cfg: &ShipcastConfig, sys: &VesselSystem) -> Result<(TimeModel, Engine), Error> {
    let t_build = Instant::now();
    let model = TimeModel::new(sys, rom_options(cfg, sys))?;
    let engine = Engine::new(cfg, sys, &model);
    tracing::info!(
        vessels = sys.spec.bodies.len(),
        active_dofs = model.n(),
        memory_s = engine.memory_s(),
        step = %describe_step(cfg, sys),
        build_s = t_build.elapsed().as_secs_f64(),
        "model ready"
    );
    Ok((model, engine))
}

/// The daemon's recorder (`[record]`), or None when it records nothing or cannot (logged).
fn open_recorder(cfg: &ShipcastConfig, sys: &VesselSystem) -> Option<crate::record::RotatingRecorder> {
    if cfg.record.dir.is_empty() {
        return None;
    }
    let dir = cfg.dir.join(&cfg.record.dir);
    match crate::record::RotatingRecorder::new(
        &dir,
        cfg.record.rotate_mb,
        cfg.record.rotate_s,
        crate::record::LogInfo::of(cfg, &cfg.system.file, sys, "daemon"),
    ) {
        Ok(r) => Some(r),
        Err(e) => {
            tracing::error!("recording disabled: {e}");
            None
        }
    }
}

/// One record into the recording; a write error ends the recording (logged), never the daemon.
fn record(recorder: &mut Option<crate::record::RotatingRecorder>, t: f64, r: crate::record::Record) {
    if let Some(rec) = recorder.as_mut()
        && let Err(e) = rec.record(t, &r)
    {
        tracing::error!("recording stopped: {e}");
        *recorder = None;
    }
}

/// An input as it arrived, into the recording.
fn record_input(recorder: &mut Option<crate::record::RotatingRecorder>, t: f64, msg: &Input) {
    use crate::record::{MotionRecord, Record, WavesRecord};
    if recorder.is_none() {
        return;
    }
    match msg {
        Input::Motion(m) => record(
            recorder,
            t,
            Record::Motion(MotionRecord {
                vessel: m.vessel,
                time_s: m.time_s,
                x: m.x,
                v: m.v,
            }),
        ),
        Input::Waves(f) => record(recorder, t, Record::Waves(WavesRecord::of(f))),
        Input::Navigation(n) => record(recorder, t, Record::Navigation(crate::record::NavigationRecord::of(n))),
        Input::Elevation(scan) => record(
            recorder,
            t,
            Record::Elevation(Box::new(crate::record::GridRecord::of_scan(scan))),
        ),
        // the link's health changes no forecast
        Input::Rejected(_) | Input::Link(_) => {}
    }
}

/// The daemon (and a replay of its log) forecasts at most [`MAX_VESSELS`] vessels: the forecast and
/// status payloads carry no more.
pub fn fits_the_wire(sys: &VesselSystem) -> Result<(), String> {
    let n = sys.spec.bodies.len();
    if n > MAX_VESSELS {
        return Err(format!(
            "the system file has {n} vessels: the daemon's forecasts and status carry at most {MAX_VESSELS}"
        ));
    }
    Ok(())
}

/// The daemon pings systemd's watchdog once per forecast period: a `WatchdogSec` shorter than two periods
/// would have systemd kill a healthy daemon. `watchdog_s` is the unit's interval (None: no watchdog).
pub fn watchdog_fits(period_s: f64, watchdog_s: Option<f64>) -> Result<(), String> {
    match watchdog_s {
        Some(w) if 2.0 * period_s > w => Err(format!(
            "forecast.period_s = {period_s} s, but the unit's WatchdogSec is {w} s: the daemon pings the watchdog once \
             a period, so WatchdogSec must be at least twice forecast.period_s ({} s)",
            2.0 * period_s
        )),
        _ => Ok(()),
    }
}

/// Runs the daemon until SIGINT, SIGTERM or SIGHUP (each a clean stop: a last status with
/// `running = 0`, exit 0). Ends with an error (a non-zero exit: systemd restarts it) if
/// the compute thread dies.
pub async fn run(cfg: ShipcastConfig, sys: VesselSystem, stop: Arc<AtomicBool>) -> Result<(), Error> {
    let mut watchdog_usec = 0u64;
    let watchdog = sd_notify::watchdog_enabled(false, &mut watchdog_usec);
    watchdog_fits(cfg.forecast.period_s, watchdog.then_some(watchdog_usec as f64 / 1e6))?;
    fits_the_wire(&sys)?;
    let (model, mut engine) = build(&cfg, &sys)?;
    let names = Names {
        prefix: cfg.ipc.service_prefix.clone(),
    };
    let (in_tx, mut in_rx) = tokio::sync::mpsc::channel::<Input>(8192);
    let (out_tx, out_rx) = std::sync::mpsc::channel::<Output>();
    let (ready_tx, ready_rx) = std::sync::mpsc::channel();
    let input = ipc::spawn_input(names.clone(), in_tx, stop.clone(), ready_tx.clone());
    let output = ipc::spawn_output(names.clone(), out_rx, ready_tx);
    for _ in 0..2 {
        ready_rx
            .recv()
            .map_err(|_| "an iceoryx2 thread ended before it was ready")??;
    }
    let (job_tx, job_rx) = std::sync::mpsc::channel::<Job>();
    let (done_tx, mut done_rx) = tokio::sync::mpsc::channel::<Done>(4);
    let inject_panic = std::env::var(FAULT_ENV).is_ok_and(|v| v == "compute-panic");
    let compute = compute_thread(Computer::new(model, &sys, &cfg), job_rx, done_tx, inject_panic);
    let _ = sd_notify::notify(false, &[sd_notify::NotifyState::Ready]);
    tracing::info!(prefix = %names.prefix, period_s = cfg.forecast.period_s, "shipcast running");
    let mut tick = tokio::time::interval(Duration::from_secs_f64(cfg.forecast.period_s));
    tick.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Skip);
    let mut sigterm = tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate())?;
    // SIGHUP (a closed terminal or SSH session): a clean stop with a final status, as SIGTERM; the
    // configuration is read at start only, so a restart is how it is reloaded
    let mut sighup = tokio::signal::unix::signal(tokio::signal::unix::SignalKind::hangup())?;
    let start = Instant::now();
    // the engine's clock: monotonic, in UNIX seconds from the wall clock at the start (a recording's
    // log times are this clock, so they line up with the ship's other logs)
    let clock_anchor_s = wall_s();
    let clock = || clock_anchor_s + start.elapsed().as_secs_f64();
    // recording: inputs, ticks and forecasts, log time = the engine's clock (replay retakes every
    // decision); a write error is logged and ends the recording, never the daemon
    let mut recorder = open_recorder(&cfg, &sys);
    let mut failure: Option<&str> = None;
    loop {
        tokio::select! {
            _ = tokio::signal::ctrl_c() => { tracing::info!("SIGINT: stopping"); break; }
            _ = sigterm.recv() => { tracing::info!("SIGTERM: stopping"); break; }
            _ = sighup.recv() => { tracing::info!("SIGHUP: stopping (restart shipcast to reload its configuration)"); break; }
            msg = in_rx.recv() => {
                let Some(msg) = msg else { break };
                let t = clock();
                record_input(&mut recorder, t, &msg);
                engine.input(msg, t);
            }
            done = done_rx.recv() => {
                let Some(d) = done else {
                    tracing::error!("the compute thread has ended (a panic): stopping, with an error, so that systemd restarts shipcast");
                    failure = Some("the compute thread ended unexpectedly");
                    break;
                };
                if let Some(out) = engine.done(d) {
                    if let Output::Forecast(h, v) = &out {
                        let rec = crate::record::Record::Forecast(crate::record::ForecastRecord::of(h, v));
                        record(&mut recorder, clock(), rec);
                    }
                    let _ = out_tx.send(out);
                }
            }
            _ = tick.tick() => {
                if compute.is_finished() {
                    tracing::error!("the compute thread has ended (a panic): stopping, with an error, so that systemd restarts shipcast");
                    failure = Some("the compute thread ended unexpectedly");
                    break;
                }
                if watchdog {
                    let _ = sd_notify::notify(false, &[sd_notify::NotifyState::Watchdog]);
                }
                let t = clock();
                record(&mut recorder, t, crate::record::Record::Tick(crate::record::TickRecord { clock_s: t }));
                if let Some(job) = engine.tick(t) {
                    let _ = job_tx.send(job);
                }
                let _ = out_tx.send(Output::Status(engine.status(clock(), wall_s(), true)));
            }
        }
    }
    // clean shutdown: the last status says so, then the ports go
    stop.store(true, Ordering::Relaxed);
    let _ = out_tx.send(Output::Status(engine.status(clock(), wall_s(), false)));
    drop(out_tx);
    drop(job_tx);
    drop(in_rx);
    if let Some(r) = recorder
        && let Err(e) = r.finish()
    {
        tracing::error!("closing the recording: {e}");
    }
    let _ = sd_notify::notify(false, &[sd_notify::NotifyState::Stopping]);
    let _ = output.join();
    let _ = input.join();
    let _ = compute.join();
    let c = &engine.counters;
    tracing::info!(
        forecasts = c.forecasts,
        overruns = c.overruns,
        samples = c.samples,
        "shipcast stopped"
    );
    match failure {
        Some(why) => Err(why.to_string().into()),
        None => Ok(()),
    }
}

/// A motion sample on the wire from the simulator's.
pub fn to_wire(s: &crate::sim::ImuSample) -> MotionSample {
    MotionSample {
        schema_version: SCHEMA_VERSION,
        vessel: s.vessel as u32,
        time_s: s.time_s,
        x: s.x,
        v: s.v,
    }
}
