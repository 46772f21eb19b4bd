//! The motion state estimator (pure): a vessel's IMU samples in, the state at a forecast's start and
//! the velocity history behind it out, with what is physically impossible kept out.
//!
//! Conventions (DESIGN.md section 1): DOFs surge, sway, heave (m), roll, pitch, yaw (rad) about the
//! body's reference point; velocities in m/s and rad/s; times are the samples' stamps, s.
//!
//! The choice, and why:
//! - One Kalman filter per DOF on a kinematic process, state (displacement, velocity), driven by
//!   white acceleration (the "nearly constant velocity" model), measuring both displacement and
//!   velocity, as a motion reference unit reports them. A kinematic process needs no knowledge of the
//!   waves: the excitation is what the forecast is for, and a model-based process would need it to
//!   predict. The acceleration's spectral density is set from the measurement noise so that the
//!   filter passes the whole band of the database (its bandwidth `BANDWIDTH_FACTOR` times the
//!   database's highest frequency): the estimate follows the wave motion and takes noise out above it.
//! - A Rauch-Tung-Striebel smoother over the kept window: the history the radiation memory reads uses
//!   the samples after each one as well as before. Between samples, and across a gap up to
//!   `forecast.max_gap_s`, the state is the cubic Hermite curve through the smoothed displacements
//!   and velocities at both ends (the smoother's mean of this process between two known states),
//!   its velocity that curve's slope.
//! - Physically impossible samples are refused before they reach the filter: a displacement, velocity
//!   or acceleration beyond bounds from the system (`Bounds::from_system`), or a change since the last
//!   estimate that no acceleration within the bound could make over the time between them (beyond
//!   `gate_sigma` standard deviations of the noise and the estimate's own uncertainty), or a stalled
//!   sensor: every value the same as in the two samples before, once the vessel has been seen moving
//!   (the stall's first two outputs are taken back). A refused sample never enters the filter, the
//!   smoother or the radiation history.
//! - A real jump (a sensor re-zeroed) is told from a spike by persistence: `reset_samples` refused
//!   samples in a row that agree with each other restart the estimate from them. The estimate before
//!   is kept for [`REVERT_WINDOW_S`]: a sample the new one refuses but the old one takes shows the
//!   run was a burst of spikes, and the old estimate comes back without it. A restarted estimate is
//!   settling ([`Estimator::settling`]) until its new offset is averaged (a fifth of `bias_time_s`):
//!   its start may be off by the jump, which its start's variance holds.
//! - Sensor bias: the displacement of a DOF with hydrostatic restoring (heave, roll, pitch) has zero
//!   mean about the equilibrium in linear waves, so its long average (time constant `bias_time_s`,
//!   each sample counting for the time since the one before, at most `BIAS_MAX_INTERVAL_S`) is
//!   the sensor's bias (or a static heel or trim: the two cannot be told apart from the motion alone;
//!   the status reports the estimate). It is taken off the initial displacement once it has averaged
//!   over a fifth of that time: the model starts from its own mean in waves (a moored vessel's heel
//!   from its lines and fenders, `Engine::learn_model_mean`), and its forecast of roll and pitch is
//!   shifted back to the measured mean (a heel the model does not know is kept;
//!   `MEASURED_MEAN_DOFS`). The velocity history is not affected by
//!   a constant bias. DOFs without restoring have no observable bias.

use std::cell::{Ref, RefCell};
use std::collections::VecDeque;

/// The filter passes motion up to this many times the database's highest frequency.
pub const BANDWIDTH_FACTOR: f64 = 4.0;

/// A restarted estimate's predecessor is kept this long after the restart, s: a sample that the new
/// estimate refuses and the old takes within it takes the restart back (a burst of spikes).
pub const REVERT_WINDOW_S: f64 = 2.0;

/// Samples closer than this to the newest taken are refused as duplicates: the kept window holds at
/// most 1000 samples a second, whatever a sensor sends.
pub const MIN_SAMPLE_INTERVAL_S: f64 = 1e-3;

/// The smoother's pass back from a new sample stops where it changes an earlier sample's smoothed
/// displacement and velocity by no more than this (m, rad; m/s, rad/s): the change only shrinks further
/// back (the smoother's gain is a contraction), so the states kept from the pass before are the whole
/// pass's to this.
pub const SMOOTHED_SETTLED: f64 = 1e-12;

/// A sample repeating every value of the one before this many times in a row is a stalled sensor.
pub const STALL_REPEATS: usize = 2;
/// In the bias average a sample counts for the time since the one before, at most this, s.
pub const BIAS_MAX_INTERVAL_S: f64 = 1.0;

/// Half the window of the centred average that tells, in hindsight, the sensor's offset at a past
/// instant, s: a Hann window of +-60 s passes under 1e-4 of a 20 s swell's amplitude, and a drift of
/// correlation time 10 min changes by a few percent of its spread across it.
pub const HINDSIGHT_HALF_WINDOW_S: f64 = 60.0;
/// Half the span of the quadratic fit that tells, in hindsight, the motion at that instant without
/// the sensor's noise, s: +-1 s holds 21 samples at 10 Hz (the noise falls to a third) and a wave of
/// 6 s period is still a parabola to within a millimetre per metre over it.
pub const HINDSIGHT_FIT_HALF_S: f64 = 1.0;
/// A hindsight check of the start opens this often, s.
pub const HINDSIGHT_EVERY_S: f64 = 10.0;
/// A check counts if its fit holds this many samples (a parabola through three is no fit: at least
/// two more to average the noise; a sensor of 2 Hz or less never has them) ...
pub const HINDSIGHT_MIN_FIT_SAMPLES: f64 = 5.0;
/// ... and its samples weigh at least this share of a whole window's (gaps leave the average lopsided).
pub const HINDSIGHT_MIN_COVER: f64 = 0.5;
/// The configured figure ([`Estimator::start_var`]'s prior) weighs as much as this many
/// `bias_time_s` of hindsight checks: within the half hour the sensor's own record outweighs it.
pub const HINDSIGHT_PRIOR_BIAS_TIMES: f64 = 1.0;
/// The hindsight checks are averaged over this many `drift_time_s` (a drift that changes character
/// is followed).
pub const HINDSIGHT_MEMORY_DRIFT_TIMES: f64 = 4.0;

/// How a vessel's samples become its state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Method {
    /// The Kalman filter and smoother with gating and bias (the default).
    Kalman,
    /// The samples as they come, resampled linearly (no gating, no bias): for comparison.
    Raw,
}

/// Per-DOF physical bounds of a vessel's motion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bounds {
    pub max_x: [f64; 6],
    pub max_v: [f64; 6],
    pub max_a: [f64; 6],
}

impl Bounds {
    /// Bounds from the system: translations accelerate at most `max_acceleration_g` g; rotations at
    /// most that over the body's radius of gyration about the axis (at least 1 m); no motion is slower
    /// than the database's lowest frequency `omega_min_rad_s`, so velocity and displacement are bounded
    /// by the acceleration over it and its square; roll and pitch never beyond 90 deg, yaw 180 deg.
    pub fn from_system(
        mass: &nalgebra::Matrix6<f64>,
        g_m_s2: f64,
        max_acceleration_g: f64,
        omega_min_rad_s: f64,
    ) -> Bounds {
        let a_t = max_acceleration_g * g_m_s2;
        let m = mass[(0, 0)].max(f64::MIN_POSITIVE);
        let w = omega_min_rad_s.max(1e-3);
        let mut b = Bounds {
            max_x: [0.0; 6],
            max_v: [0.0; 6],
            max_a: [0.0; 6],
        };
        for d in 0..6 {
            let a = if d < 3 {
                a_t
            } else {
                let r_m = (mass[(d, d)] / m).sqrt();
                a_t / if r_m.is_finite() { r_m.max(1.0) } else { 1.0 }
            };
            b.max_a[d] = a;
            b.max_v[d] = a / w;
            b.max_x[d] = a / (w * w);
        }
        b.max_x[3] = b.max_x[3].min(std::f64::consts::FRAC_PI_2);
        b.max_x[4] = b.max_x[4].min(std::f64::consts::FRAC_PI_2);
        b.max_x[5] = b.max_x[5].min(std::f64::consts::PI);
        b
    }
}

/// Everything the estimator of one vessel is set with.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spec {
    pub method: Method,
    /// Measurement noise (standard deviation) per DOF: displacement (m, rad), velocity (m/s, rad/s).
    pub noise_x: [f64; 6],
    pub noise_v: [f64; 6],
    /// Spectral density of the process's acceleration per DOF, m^2/s^3 (rad^2/s^3).
    pub q: [f64; 6],
    pub bounds: Bounds,
    /// DOFs whose bias is estimated (hydrostatic restoring).
    pub restored: [bool; 6],
    /// DOFs whose start's error is learned in hindsight ([`Estimator::start_var`]): restored, and
    /// their measured mean the sensor's alone (heave; roll and pitch may heel).
    pub learned: [bool; 6],
    pub bias_time_s: f64,
    /// The sensor's drift per DOF (standard deviation, m or rad) and its correlation time, s: what
    /// the bias average does not take off is part of a start's error ([`Estimator::start_var`]).
    pub drift: [f64; 6],
    pub drift_time_s: f64,
    pub gate_sigma: f64,
    pub reset_samples: usize,
}

impl Spec {
    /// The process noise that gives a filter of bandwidth `bandwidth_rad_s` on displacement noise
    /// `noise_x` (the white-acceleration filter's bandwidth is (q / r)^(1/4)).
    pub fn process_noise(noise_x: f64, bandwidth_rad_s: f64) -> f64 {
        bandwidth_rad_s.powi(4) * noise_x.max(1e-9).powi(2)
    }
}

/// Why a sample was refused.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Refusal {
    NonFinite,
    Late,
    /// The same stamp as the newest taken, or less than [`MIN_SAMPLE_INTERVAL_S`] after it.
    Duplicate,
    /// The same values as the two samples before, once the vessel has been seen moving: a stalled
    /// sensor repeating its last output (or zeros, an empty field read as 0).
    Frozen,
    /// Beyond a bound: the DOF, what (displacement, velocity), the value and the bound.
    Bound {
        dof: usize,
        what: &'static str,
        value: f64,
        bound: f64,
    },
    /// Nearer a run of refused samples than the estimate (which the gate's growth over the run would
    /// let take it): the run goes on, until `reset_samples` restart the estimate from it.
    InRun,
    /// A change since the last estimate no allowed acceleration makes: the DOF, what, the change and
    /// the largest allowed.
    Jump {
        dof: usize,
        what: &'static str,
        change: f64,
        allowed: f64,
    },
}

/// What became of a sample that was taken.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Taken {
    Accepted,
    /// The estimate restarted from a run of refused samples that agree (a real jump).
    Restarted,
    /// A restart taken back: the sample agrees with the estimate before it, and the run it restarted
    /// from (a burst of spikes) is dropped.
    Reverted,
}

/// One DOF's Gaussian: mean (displacement, velocity) and covariance (pp, pv, vv).
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
struct Gauss {
    m: [f64; 2],
    p: [f64; 3],
}

impl Gauss {
    fn predict(&self, dt: f64, q: f64) -> Gauss {
        let [pp, pv, vv] = self.p;
        Gauss {
            m: [self.m[0] + dt * self.m[1], self.m[1]],
            p: [
                pp + 2.0 * dt * pv + dt * dt * vv + q * dt.powi(3) / 3.0,
                pv + dt * vv + q * dt * dt / 2.0,
                vv + q * dt,
            ],
        }
    }

    /// The update with a measurement of both (variances rx, rv).
    fn update(&self, z: [f64; 2], rx: f64, rv: f64) -> Gauss {
        let [pp, pv, vv] = self.p;
        // K = P S^-1 (S = P + R is positive definite: the noise variances are positive)
        let Some([k00, k01, k10, k11]) = times_inverse([pp, pv, pv, vv], [pp + rx, pv, vv + rv]) else {
            return *self;
        };
        let (n0, n1) = (z[0] - self.m[0], z[1] - self.m[1]);
        // P - K P (symmetric up to rounding: the symmetric part kept)
        let q00 = pp - (k00 * pp + k01 * pv);
        let q01 = pv - 0.5 * ((k00 * pv + k01 * vv) + (k10 * pp + k11 * pv));
        let q11 = vv - (k10 * pv + k11 * vv);
        Gauss {
            m: [self.m[0] + k00 * n0 + k01 * n1, self.m[1] + k10 * n0 + k11 * n1],
            p: [q00.max(0.0), q01, q11.max(0.0)],
        }
    }
}

/// A S^-1 for a 2 x 2 `a` (row-major) and a symmetric `s` (s00, s01, s11); None unless S is positive
/// definite (the Kalman gain and the smoother's gain).
fn times_inverse(a: [f64; 4], s: [f64; 3]) -> Option<[f64; 4]> {
    let [s00, s01, s11] = s;
    let det = s00 * s11 - s01 * s01;
    if !(det.is_finite() && det > 0.0) {
        return None;
    }
    let (i00, i01, i11) = (s11 / det, -s01 / det, s00 / det);
    let [a00, a01, a10, a11] = a;
    Some([
        a00 * i00 + a01 * i01,
        a00 * i01 + a01 * i11,
        a10 * i00 + a11 * i01,
        a10 * i01 + a11 * i11,
    ])
}

/// One sample the filter took.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
struct Entry {
    time_s: f64,
    /// The measurement (for the raw method and the bias).
    x: [f64; 6],
    v: [f64; 6],
    /// Filtered, and predicted from the entry before (the smoother's inputs).
    filtered: [Gauss; 6],
    predicted: [Gauss; 6],
}

/// The state at a forecast's start and the velocities before it.
#[derive(Debug, Clone, PartialEq)]
pub struct Resampled {
    pub x0: [f64; 6],
    pub v0: [f64; 6],
    /// Velocities at t0 - n dt .. t0 - dt (oldest first).
    pub velocities: Vec<[f64; 6]>,
    /// Part of the requested history was not there (taken as at rest).
    pub short: bool,
    /// A gap was bridged.
    pub gap: bool,
    /// How many of `velocities`, counted from the newest, were measured (the rest are the rest).
    pub known: usize,
}

/// A running mean of 6 DOFs over the last `tau_s` of what it was given (over all of it until then):
/// each value counts for the time since the one before. The estimator's bias; the engine's mean of
/// its model's own forecasts.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct RunningMean {
    pub value: [f64; 6],
    /// The time the mean has been taken over, s.
    pub span_s: f64,
}

impl RunningMean {
    /// Takes in `x`, counting for `dt_s` (the first value: all of the mean); non-finite DOFs are left
    /// as they were.
    pub fn add(&mut self, dt_s: f64, x: &[f64; 6], tau_s: f64) {
        self.span_s += dt_s;
        let w = if self.span_s <= 0.0 {
            1.0
        } else {
            (dt_s / tau_s.min(self.span_s)).min(1.0)
        };
        for (m, xd) in self.value.iter_mut().zip(x) {
            if xd.is_finite() {
                *m += w * (xd - *m);
            }
        }
    }
}

/// A hindsight check of the start at one instant ([`Estimator::start_var`]): the Hann-weighted sums
/// of the samples within [`HINDSIGHT_HALF_WINDOW_S`] of it, the sums of a quadratic fit to those
/// within [`HINDSIGHT_FIT_HALF_S`], and the start the estimator took at the first sample from it.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
struct Check {
    centre_s: f64,
    weight: f64,
    weighted: [f64; 6],
    /// sum u^k (k = 0..4) and sum x u^k (k = 0..2) over the fit's samples, u = t - centre
    powers: [f64; 5],
    moments: [[f64; 3]; 6],
    /// (u of the sample, its start less the bias)
    start: Option<(f64, [f64; 6])>,
}

impl Check {
    fn new(centre_s: f64) -> Check {
        Check {
            centre_s,
            weight: 0.0,
            weighted: [0.0; 6],
            powers: [0.0; 5],
            moments: [[0.0; 3]; 6],
            start: None,
        }
    }

    fn add(&mut self, t: f64, dt_s: f64, x: &[f64; 6]) {
        let u = t - self.centre_s;
        if u.abs() < HINDSIGHT_HALF_WINDOW_S {
            let w = (std::f64::consts::FRAC_PI_2 * u / HINDSIGHT_HALF_WINDOW_S)
                .cos()
                .powi(2)
                * dt_s;
            self.weight += w;
            for (s, xd) in self.weighted.iter_mut().zip(x) {
                *s += w * xd;
            }
        }
        if u.abs() <= HINDSIGHT_FIT_HALF_S {
            for (k, p) in self.powers.iter_mut().enumerate() {
                *p += u.powi(k as i32);
            }
            for (m, xd) in self.moments.iter_mut().zip(x) {
                for (k, mk) in m.iter_mut().enumerate() {
                    *mk += xd * u.powi(k as i32);
                }
            }
        }
    }

    /// Per DOF, the square of the start's error less the fit's own noise variance there (NaN where
    /// not `learned`); None if the window was not covered (a gap, the start not taken) or the fit
    /// is singular.
    fn error_square(&self, noise_x: &[f64; 6], learned: &[bool; 6]) -> Option<[f64; 6]> {
        let (u, start) = self.start?;
        // a whole window's Hann weights sum to its half width
        if self.weight < HINDSIGHT_MIN_COVER * HINDSIGHT_HALF_WINDOW_S || self.powers[0] < HINDSIGHT_MIN_FIT_SAMPLES {
            return None;
        }
        let p = &self.powers;
        let normal = nalgebra::Matrix3::new(p[0], p[1], p[2], p[1], p[2], p[3], p[2], p[3], p[4]);
        let inverse = normal.try_inverse()?;
        let g = nalgebra::Vector3::new(1.0, u, u * u);
        let gain = (g.transpose() * inverse * g)[(0, 0)];
        if !gain.is_finite() {
            return None;
        }
        Some(std::array::from_fn(|d| {
            if !learned[d] {
                return f64::NAN;
            }
            let a = inverse * nalgebra::Vector3::from(self.moments[d]);
            let motion = a.dot(&g) - self.weighted[d] / self.weight;
            let error = start[d] - motion;
            error * error - gain * noise_x[d] * noise_x[d]
        }))
    }
}

/// A vessel's estimator: the kept window of filtered samples, the bias, and a run of refused samples
/// that may turn out to be a real jump.
#[derive(Debug, Clone)]
pub struct Estimator {
    spec: Spec,
    keep_s: f64,
    entries: VecDeque<Entry>,
    bias: RunningMean,
    /// Running means of the innovations' products per DOF (displacement^2, displacement x velocity,
    /// velocity^2; over `bias_time_s`): what the filter's prediction actually errs by, its noise
    /// added ([`Estimator::start_var`]).
    innovation: [RunningMean; 3],
    /// Open hindsight checks of the start, oldest first, and when the next opens.
    checks: VecDeque<Check>,
    next_check_s: Option<f64>,
    /// The mean square of the start's error the closed checks found per DOF, their fit's own noise
    /// off (m^2, rad^2; [`Estimator::start_var`]).
    learned: RunningMean,
    /// Refused samples in a row that agree with each other, filtered from the first of them.
    candidate: Vec<Entry>,
    /// The values of the last sample received (taken or not), and how many received in a row
    /// before it had the same.
    last_received: Option<([f64; 6], [f64; 6])>,
    repeats: usize,
    /// A taken sample has differed from the one before it (kept across a restart: the sensor has
    /// been seen moving).
    moved: bool,
    /// The last restart from a jump while its new offset is not yet averaged
    /// ([`Estimator::settling`]).
    jump: Option<Jump>,
    /// Counts the changes to `entries` other than a sample taken at the back or dropped from the
    /// front: the smoothed states of another count are of other samples.
    rewrites: u64,
    /// The kept samples' smoothed states as last asked for ([`Estimator::smoothed`]).
    smoothed: RefCell<Smoothed>,
}

/// A kept sample's time and its smoothed displacement and velocity.
type Point = (f64, [f64; 6], [f64; 6]);

/// The smoothed states of the oldest `points.len()` kept samples of `rewrites`, as smoothed back from
/// the newest of them.
#[derive(Debug, Clone, Default)]
struct Smoothed {
    rewrites: u64,
    points: VecDeque<Point>,
}

/// What an estimator keeps across a restart of the daemon ([`Estimator::state`]).
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct EstimatorState {
    learnt: Learnt,
    learned: RunningMean,
    moved: bool,
}

/// A restart from a jump: when, how far the first sample of the run was from the old estimate's
/// prediction per DOF, and (for [`REVERT_WINDOW_S`]) the estimate before it.
#[derive(Debug, Clone)]
struct Jump {
    at_s: f64,
    size: [f64; 6],
    before: Option<Box<Learnt>>,
}

/// What an estimate has learnt from its samples: what a restart forgets and a revert restores.
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
struct Learnt {
    entries: VecDeque<Entry>,
    bias: RunningMean,
    innovation: [RunningMean; 3],
    checks: VecDeque<Check>,
    next_check_s: Option<f64>,
}

impl Estimator {
    /// Keeps samples spanning `keep_s` seconds behind the newest.
    pub fn new(spec: Spec, keep_s: f64) -> Estimator {
        Estimator {
            spec,
            keep_s,
            entries: VecDeque::new(),
            bias: RunningMean::default(),
            innovation: Default::default(),
            checks: VecDeque::new(),
            next_check_s: None,
            learned: RunningMean::default(),
            candidate: vec![],
            last_received: None,
            repeats: 0,
            moved: false,
            jump: None,
            rewrites: 0,
            smoothed: RefCell::default(),
        }
    }

    /// Forgets every sample (a step of the source's clock): the bias is the sensor's and stays.
    pub fn restart(&mut self) {
        self.entries.clear();
        self.rewrites += 1;
        self.candidate.clear();
        self.checks.clear();
        self.next_check_s = None;
        if let Some(j) = &mut self.jump {
            j.before = None;
        }
    }

    /// What the estimate has learnt, to be kept across a restart of the daemon
    /// ([`Estimator::restore`]): the kept samples, the bias, the innovations, the hindsight checks and
    /// what they learnt (a run of refused samples and a restart's settling are not kept).
    pub fn state(&self) -> EstimatorState {
        EstimatorState {
            learnt: Learnt {
                entries: self.entries.clone(),
                bias: self.bias,
                innovation: self.innovation,
                checks: self.checks.clone(),
                next_check_s: self.next_check_s,
            },
            learned: self.learned,
            moved: self.moved,
        }
    }

    /// Takes back what [`Estimator::state`] kept (samples older than the kept window go).
    pub fn restore(&mut self, s: EstimatorState) {
        self.put_learnt(s.learnt);
        self.learned = s.learned;
        self.moved = s.moved;
        if let Some(t) = self.newest_time_s() {
            while self.entries.front().is_some_and(|f| t - f.time_s > self.keep_s) && self.entries.len() > 2 {
                self.entries.pop_front();
            }
        }
    }

    /// Whether the estimate restarted from a jump and its new offset is not yet averaged (a fifth of
    /// `bias_time_s`): its start may be off by as much as the jump.
    pub fn settling(&self) -> bool {
        self.jump.is_some()
    }

    pub fn newest_time_s(&self) -> Option<f64> {
        self.entries.back().map(|e| e.time_s)
    }

    pub fn len(&self) -> usize {
        self.entries.len()
    }

    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// Sample rate over the kept samples, Hz.
    pub fn rate_hz(&self) -> f64 {
        match (self.entries.front(), self.entries.back()) {
            (Some(a), Some(b)) if b.time_s > a.time_s => (self.entries.len() - 1) as f64 / (b.time_s - a.time_s),
            _ => 0.0,
        }
    }

    /// The bias estimate taken off the initial displacement (0 for DOFs without restoring, and until
    /// the average spans a fifth of `bias_time_s`).
    pub fn bias(&self) -> [f64; 6] {
        std::array::from_fn(|d| if self.bias_taken(d) { self.bias.value[d] } else { 0.0 })
    }

    /// Whether DOF d's bias is taken off: it has restoring, and the Kalman method's average spans a
    /// fifth of `bias_time_s`.
    fn bias_taken(&self, d: usize) -> bool {
        self.spec.method == Method::Kalman && self.bias.span_s >= 0.2 * self.spec.bias_time_s && self.spec.restored[d]
    }

    /// The variance of the error of the displacement a forecast starting at `t0_s` takes (the bias
    /// off), per DOF (m^2, rad^2): the filter's at the newest sample up to t0 (the smoother's is
    /// smaller: a bound), and the sensor's drift the bias average leaves. The filter's is what its
    /// gain K makes of the error its predictions actually show, (I - K) A (I - K)^T + K R K^T with A
    /// the innovations' covariance less the noise's R (the innovation is the prediction's error plus
    /// a noise independent of it): its own variance assumes an acceleration as wide as its bandwidth
    /// and is far larger than its error on a ship's smooth motion. Until the innovations have been
    /// averaged over a fifth of `bias_time_s`, the filter's own variance. A first-order
    /// Gauss-Markov drift of variance s^2 and correlation time tau, averaged over the last T, leaves
    /// s^2 T / (tau + T) (the average follows the drift less the longer it is; the rest,
    /// [`Estimator::drift_in_bias_var`], is in the bias taken off); a DOF whose bias is not taken off
    /// (no restoring, or not yet averaged) keeps all of it. The raw method's is the sensor's noise and
    /// its drift. None before any sample.
    ///
    /// Where the start's error is learned (`Spec::learned`: heave), that figure is the prior of what
    /// the sensor's own record shows in hindsight: once a sample is a minute old, the motion at it
    /// (a quadratic fit to the samples about it) less the centred average about it (the sensor's
    /// offset then: the motion's mean is nought) is what a start there should have been, and the
    /// start actually taken there (the filtered displacement, the bias off) errs from it by what a
    /// forecast's start errs by from the motion, the model's mean aside. The mean square of those
    /// errors (the fit's own noise off) and the prior weigh by the time they span, the prior as
    /// [`HINDSIGHT_PRIOR_BIAS_TIMES`] bias averages; the configured figure stays the least: hindsight
    /// sees neither the model's mean nor the motion's slow wander, so what it shows is a part of the
    /// error, and a sensor drifting less than its stated accuracy is not taken to.
    pub fn start_var(&self, t0_s: f64) -> Option<[f64; 6]> {
        let estimate = self.estimate_var(t0_s)?;
        let held = self.drift_in_bias_var();
        let prior_s = HINDSIGHT_PRIOR_BIAS_TIMES * self.spec.bias_time_s;
        let learned_s = self.learned.span_s.min(self.hindsight_memory_s());
        let jump = self.jump.as_ref().map_or([0.0; 6], |j| j.size);
        Some(std::array::from_fn(|d| {
            let s2 = self.spec.drift[d] * self.spec.drift[d];
            let prior = estimate[d] + (s2 - held[d]).max(0.0) + jump[d] * jump[d];
            if self.spec.learned[d] && self.bias_taken(d) && learned_s > 0.0 {
                let learned = (prior_s * prior + learned_s * self.learned.value[d].max(0.0)) / (prior_s + learned_s);
                learned.max(prior)
            } else {
                prior
            }
        }))
    }

    fn hindsight_memory_s(&self) -> f64 {
        HINDSIGHT_MEMORY_DRIFT_TIMES * self.spec.drift_time_s
    }

    /// Feeds the newest taken sample to the open hindsight checks, closes those a half window old
    /// and opens the next on its cadence (Kalman method only: the raw method takes no bias off).
    /// Checks open once the bias is taken off (it stays so until a restart of the samples, which
    /// drops the open checks): a start with the bias on is not a forecast's.
    fn check_start(&mut self, dt_s: f64) {
        let Some(d) = self.spec.learned.iter().position(|&l| l) else {
            return;
        };
        if !self.bias_taken(d) {
            return;
        }
        let Some(e) = self.entries.back() else { return };
        let (t, x) = (e.time_s, e.x);
        let start: [f64; 6] = std::array::from_fn(|d| e.filtered[d].m[0]);
        let next = *self.next_check_s.get_or_insert(t);
        if t >= next {
            self.checks.push_back(Check::new(t + HINDSIGHT_HALF_WINDOW_S));
            self.next_check_s = Some(next + HINDSIGHT_EVERY_S * (((t - next) / HINDSIGHT_EVERY_S).floor() + 1.0));
        }
        let bias = self.bias();
        for c in self.checks.iter_mut() {
            c.add(t, dt_s, &x);
            if c.start.is_none() && t >= c.centre_s {
                c.start = Some((t - c.centre_s, std::array::from_fn(|d| start[d] - bias[d])));
            }
        }
        while self
            .checks
            .front()
            .is_some_and(|c| t >= c.centre_s + HINDSIGHT_HALF_WINDOW_S)
        {
            let Some(c) = self.checks.pop_front() else { break };
            let Some(square) = c.error_square(&self.spec.noise_x, &self.spec.learned) else {
                continue;
            };
            let memory_s = self.hindsight_memory_s();
            self.learned.add(HINDSIGHT_EVERY_S, &square, memory_s);
        }
    }

    /// The estimate's own error variance at `t0_s` per DOF (m^2, rad^2; [`Estimator::start_var`]
    /// without the drift): the filter's as its innovations show it. Between a forecast and its check
    /// at a later lead this is what the two estimates differ by beside the motion; the drift, slow,
    /// they share. None before any sample.
    pub fn estimate_var(&self, t0_s: f64) -> Option<[f64; 6]> {
        let j = self.entries.partition_point(|e| e.time_s <= t0_s);
        let e = self.entries.get(j.saturating_sub(1))?;
        Some(std::array::from_fn(|d| match self.spec.method {
            Method::Kalman if self.innovation[0].span_s >= 0.2 * self.spec.bias_time_s => {
                self.filtered_error_var(e, d).unwrap_or(e.filtered[d].p[0])
            }
            Method::Kalman => e.filtered[d].p[0],
            Method::Raw => self.spec.noise_x[d] * self.spec.noise_x[d],
        }))
    }

    /// The variance of the sensor's drift that the bias average holds, per DOF (m^2, rad^2): s^2 tau /
    /// (tau + T) for a first-order Gauss-Markov drift averaged over the last T (0 where no bias is
    /// taken off). The measured mean's offset from the model's holds it: of such an offset, this much
    /// is the sensor's, not the motion's.
    pub fn drift_in_bias_var(&self) -> [f64; 6] {
        let span = self.bias.span_s.min(self.spec.bias_time_s);
        std::array::from_fn(|d| {
            if self.bias_taken(d) && span > 0.0 {
                let s2 = self.spec.drift[d] * self.spec.drift[d];
                s2 * self.spec.drift_time_s / (self.spec.drift_time_s + span)
            } else {
                0.0
            }
        })
    }

    /// The displacement error variance of DOF d's filtered estimate at entry `e`, from the actual
    /// error of the predictions (the innovations less the noise): (I - K) A (I - K)^T + K R K^T.
    fn filtered_error_var(&self, e: &Entry, d: usize) -> Option<f64> {
        let (rx, rv) = (self.spec.noise_x[d].powi(2), self.spec.noise_v[d].powi(2));
        let [pp, pv, vv] = e.predicted[d].p;
        let [k00, k01, _, _] = times_inverse([pp, pv, pv, vv], [pp + rx, pv, vv + rv])?;
        let a00 = (self.innovation[0].value[d] - rx).max(0.0);
        let a11 = (self.innovation[2].value[d] - rv).max(0.0);
        let bound = (a00 * a11).sqrt();
        let a01 = self.innovation[1].value[d].clamp(-bound, bound);
        // row 0 of (I - K): (1 - k00, -k01); of K: (k00, k01)
        let (i0, i1) = (1.0 - k00, -k01);
        let v = i0 * i0 * a00 + 2.0 * i0 * i1 * a01 + i1 * i1 * a11 + k00 * k00 * rx + k01 * k01 * rv;
        v.is_finite().then_some(v.max(0.0))
    }

    fn first(&self, time_s: f64, x: [f64; 6], v: [f64; 6]) -> Entry {
        let mut g = [Gauss::default(); 6];
        for d in 0..6 {
            g[d] = Gauss {
                m: [x[d], v[d]],
                p: [self.spec.noise_x[d].powi(2), 0.0, self.spec.noise_v[d].powi(2)],
            };
        }
        Entry {
            time_s,
            x,
            v,
            filtered: g,
            predicted: g,
        }
    }

    /// The largest change of DOF d's displacement and velocity from the prediction `pred` over `dt`
    /// the gate allows: what the bound's acceleration makes, and `gate_sigma` standard deviations of
    /// the prediction and the noise.
    fn allowed(&self, pred: &Gauss, d: usize, dt: f64) -> (f64, f64) {
        let s = &self.spec;
        let (rx, rv) = (s.noise_x[d].powi(2), s.noise_v[d].powi(2));
        let a = s.bounds.max_a[d];
        (
            0.5 * a * dt * dt + s.gate_sigma * (pred.p[0] + rx).sqrt(),
            a * dt + s.gate_sigma * (pred.p[2] + rv).sqrt(),
        )
    }

    /// The sample filtered after `prev`, or why it cannot follow it.
    fn follow(&self, prev: &Entry, time_s: f64, x: [f64; 6], v: [f64; 6]) -> Result<Entry, Refusal> {
        let s = &self.spec;
        let dt = time_s - prev.time_s;
        let mut e = Entry {
            time_s,
            x,
            v,
            filtered: [Gauss::default(); 6],
            predicted: [Gauss::default(); 6],
        };
        for d in 0..6 {
            let pred = prev.filtered[d].predict(dt, s.q[d]);
            let (rx, rv) = (s.noise_x[d].powi(2), s.noise_v[d].powi(2));
            if s.method == Method::Kalman {
                let (allowed_x, allowed_v) = self.allowed(&pred, d, dt);
                let (cx, cv) = ((x[d] - pred.m[0]).abs(), (v[d] - pred.m[1]).abs());
                if cx > allowed_x {
                    return Err(Refusal::Jump {
                        dof: d,
                        what: "displacement",
                        change: cx,
                        allowed: allowed_x,
                    });
                }
                if cv > allowed_v {
                    return Err(Refusal::Jump {
                        dof: d,
                        what: "velocity",
                        change: cv,
                        allowed: allowed_v,
                    });
                }
            }
            e.predicted[d] = pred;
            e.filtered[d] = pred.update([x[d], v[d]], rx, rv);
        }
        Ok(e)
    }

    /// Takes one sample, or says why not.
    pub fn push(&mut self, time_s: f64, x: [f64; 6], v: [f64; 6]) -> Result<Taken, Refusal> {
        if !(time_s.is_finite() && x.iter().chain(&v).all(|v| v.is_finite())) {
            return Err(Refusal::NonFinite);
        }
        if let Some(last) = self.entries.back() {
            if time_s < last.time_s {
                return Err(Refusal::Late);
            }
            if time_s - last.time_s < MIN_SAMPLE_INTERVAL_S {
                return Err(Refusal::Duplicate);
            }
        }
        self.repeats = if self.last_received == Some((x, v)) {
            self.repeats + 1
        } else {
            0
        };
        self.last_received = Some((x, v));
        if self.spec.method == Method::Kalman && self.repeats >= STALL_REPEATS && self.moved {
            // a sensor's noise never repeats all its values three times: a stalled sensor (a
            // sensor that sends each value twice is not one). Its first outputs, taken before they
            // repeated, are taken back. A vessel never seen moving (at rest, noise-free) is not stalled.
            if self.repeats == STALL_REPEATS {
                for _ in 0..STALL_REPEATS {
                    if self.entries.len() > 2 && self.entries.back().is_some_and(|e| e.x == x && e.v == v) {
                        self.entries.pop_back();
                        self.rewrites += 1;
                    }
                }
            }
            return Err(Refusal::Frozen);
        }
        if self.spec.method == Method::Kalman {
            let b = &self.spec.bounds;
            for d in 0..6 {
                if x[d].abs() > b.max_x[d] {
                    return Err(Refusal::Bound {
                        dof: d,
                        what: "displacement",
                        value: x[d],
                        bound: b.max_x[d],
                    });
                }
                if v[d].abs() > b.max_v[d] {
                    return Err(Refusal::Bound {
                        dof: d,
                        what: "velocity",
                        value: v[d],
                        bound: b.max_v[d],
                    });
                }
            }
        }
        let entry = match self.entries.back() {
            None => self.first(time_s, x, v),
            Some(prev) => match self.follow(prev, time_s, x, v) {
                // the estimate's gate widens with the time since the last sample it took: a sample
                // closer to a run of refused samples than to the estimate continues the run (a jump
                // smaller than the gate grown over the run is not taken for motion)
                Ok(_) if self.continues_run(prev, time_s, x, v) => {
                    return self.refused(Refusal::InRun, time_s, x, v);
                }
                Ok(e) => e,
                Err(why) => {
                    if self.revert(time_s, x, v) {
                        return Ok(Taken::Reverted);
                    }
                    return self.refused(why, time_s, x, v);
                }
            },
        };
        self.candidate.clear();
        self.take(entry);
        Ok(Taken::Accepted)
    }

    /// Whether the sample, which the estimate at `prev` takes, is nearer the run of refused samples
    /// (as a share of what each allows) and the run takes it too.
    fn continues_run(&self, prev: &Entry, time_s: f64, x: [f64; 6], v: [f64; 6]) -> bool {
        let Some(last) = self
            .candidate
            .last()
            .filter(|c| time_s - c.time_s >= MIN_SAMPLE_INTERVAL_S)
        else {
            return false;
        };
        let run = self.reach(last, time_s, x, v);
        run <= 1.0 && run < self.reach(prev, time_s, x, v)
    }

    /// The largest share of the change the gate allows from `prev` that the sample takes, over the
    /// DOFs, displacement and velocity (above 1: refused).
    fn reach(&self, prev: &Entry, time_s: f64, x: [f64; 6], v: [f64; 6]) -> f64 {
        let s = &self.spec;
        let dt = time_s - prev.time_s;
        (0..6)
            .map(|d| {
                let pred = prev.filtered[d].predict(dt, s.q[d]);
                let (allowed_x, allowed_v) = self.allowed(&pred, d, dt);
                ((x[d] - pred.m[0]).abs() / allowed_x).max((v[d] - pred.m[1]).abs() / allowed_v)
            })
            .fold(0.0, f64::max)
    }

    /// Takes the last restart back if the sample, refused by the estimate since, agrees with the one
    /// before it within [`REVERT_WINDOW_S`] of the restart: the run restarted from was a burst of
    /// spikes. The sample is taken into the old estimate; the burst is dropped.
    fn revert(&mut self, time_s: f64, x: [f64; 6], v: [f64; 6]) -> bool {
        let Some(before) = self
            .jump
            .as_mut()
            .filter(|j| time_s - j.at_s <= REVERT_WINDOW_S)
            .and_then(|j| j.before.take())
        else {
            return false;
        };
        let followed = before
            .entries
            .back()
            .filter(|prev| time_s - prev.time_s >= MIN_SAMPLE_INTERVAL_S)
            .and_then(|prev| self.follow(prev, time_s, x, v).ok());
        let Some(e) = followed else {
            // not the old estimate's either: kept for the next sample
            if let Some(j) = &mut self.jump {
                j.before = Some(before);
            }
            return false;
        };
        self.put_learnt(*before);
        self.take(e);
        true
    }

    /// Puts `l` in place of what the estimate has learnt, with no run of refused samples and no
    /// restart settling (a revert, a restore).
    fn put_learnt(&mut self, l: Learnt) {
        self.entries = l.entries;
        self.rewrites += 1;
        self.bias = l.bias;
        self.innovation = l.innovation;
        self.checks = l.checks;
        self.next_check_s = l.next_check_s;
        self.candidate.clear();
        self.jump = None;
    }

    /// A sample refused by the gate: kept as a candidate jump; `reset_samples` in a row that agree
    /// restart the estimate from them.
    fn refused(&mut self, why: Refusal, time_s: f64, x: [f64; 6], v: [f64; 6]) -> Result<Taken, Refusal> {
        let next = match self.candidate.last() {
            Some(prev) if time_s - prev.time_s >= MIN_SAMPLE_INTERVAL_S => self.follow(prev, time_s, x, v).ok(),
            _ => None,
        };
        match next {
            Some(e) => self.candidate.push(e),
            None => self.candidate = vec![self.first(time_s, x, v)],
        }
        if self.candidate.len() < self.spec.reset_samples.max(1) {
            return Err(why);
        }
        // how far the run's first sample is from the estimate it leaves, predicted to it
        let first = &self.candidate[0];
        let size = match self.entries.back() {
            Some(prev) => std::array::from_fn(|d| {
                (first.x[d] - prev.filtered[d].predict(first.time_s - prev.time_s, self.spec.q[d]).m[0]).abs()
            }),
            None => [0.0; 6],
        };
        self.rewrites += 1;
        let before = Learnt {
            entries: std::mem::take(&mut self.entries),
            bias: std::mem::take(&mut self.bias),
            innovation: std::mem::take(&mut self.innovation),
            checks: std::mem::take(&mut self.checks),
            next_check_s: self.next_check_s.take(),
        };
        self.jump = Some(Jump {
            at_s: time_s,
            size,
            before: (!before.entries.is_empty()).then(|| Box::new(before)),
        });
        for e in std::mem::take(&mut self.candidate) {
            self.take(e);
        }
        Ok(Taken::Restarted)
    }

    fn take(&mut self, e: Entry) {
        // a sample after a gap counts for a second at most: one reading does not stand for the whole
        // silence; the first after a restart of the samples, for nothing (the bias is the sensor's)
        let interval_s = match self.entries.back() {
            Some(prev) => {
                self.moved |= prev.x != e.x || prev.v != e.v;
                e.time_s - prev.time_s
            }
            None => 0.0,
        };
        let dt = interval_s.min(BIAS_MAX_INTERVAL_S);
        self.bias.add(dt, &e.x, self.spec.bias_time_s);
        if let Some(j) = &mut self.jump {
            if e.time_s - j.at_s > REVERT_WINDOW_S {
                j.before = None;
            }
            // settled: the new offset is averaged as a first start's bias is
            if self.bias.span_s >= 0.2 * self.spec.bias_time_s {
                self.jump = None;
            }
        }
        // the innovations are the filter's errors from one sample to the next: a sample after a gap
        // (longer than a bias interval) was predicted across all of it, which tells nothing of them
        if self.entries.back().is_some() && dt > 0.0 && interval_s <= BIAS_MAX_INTERVAL_S {
            let n: [[f64; 2]; 6] =
                std::array::from_fn(|d| [e.x[d] - e.predicted[d].m[0], e.v[d] - e.predicted[d].m[1]]);
            let products = [[0, 0], [0, 1], [1, 1]];
            for (m, [a, b]) in self.innovation.iter_mut().zip(products) {
                m.add(dt, &std::array::from_fn(|d| n[d][a] * n[d][b]), self.spec.bias_time_s);
            }
        }
        let t = e.time_s;
        self.entries.push_back(e);
        self.check_start(dt);
        while let Some(f) = self.entries.front() {
            if t - f.time_s > self.keep_s && self.entries.len() > 2 {
                self.entries.pop_front();
            } else {
                break;
            }
        }
    }

    /// Displacements and velocities at the kept samples: smoothed (Kalman), or as measured (raw).
    /// Kept between calls: a sample taken since is smoothed back only as far as it changes the states
    /// before it by more than [`SMOOTHED_SETTLED`], and a sample dropped from the front drops its state.
    fn smoothed(&self) -> Ref<'_, VecDeque<Point>> {
        {
            let mut c = self.smoothed.borrow_mut();
            if c.rewrites != self.rewrites {
                c.points.clear();
                c.rewrites = self.rewrites;
            }
            let first_s = self.entries.front().map_or(f64::INFINITY, |e| e.time_s);
            while c.points.front().is_some_and(|p| p.0 < first_s) {
                c.points.pop_front();
            }
            let aligned = c.points.len() <= self.entries.len()
                && c.points.front().is_none_or(|p| p.0 == first_s)
                && c.points
                    .back()
                    .is_none_or(|p| p.0 == self.entries[c.points.len() - 1].time_s);
            if !aligned {
                c.points.clear();
            }
            self.smooth_new(&mut c.points);
        }
        Ref::map(self.smoothed.borrow(), |c| &c.points)
    }

    /// Appends the states of the samples `points` does not have yet and smooths back from the newest
    /// (Rauch-Tung-Striebel) until the states before them settle.
    fn smooth_new(&self, points: &mut VecDeque<Point>) {
        let (known, n) = (points.len(), self.entries.len());
        if known == n {
            return;
        }
        points.extend(self.entries.range(known..).map(|e| (e.time_s, e.x, e.v)));
        if self.spec.method == Method::Raw {
            return;
        }
        for d in 0..6 {
            let mut ms = self.entries[n - 1].filtered[d].m;
            points[n - 1].1[d] = ms[0];
            points[n - 1].2[d] = ms[1];
            for k in (0..n - 1).rev() {
                let f = &self.entries[k].filtered[d];
                let next = &self.entries[k + 1];
                let pr = &next.predicted[d];
                let dt = next.time_s - self.entries[k].time_s;
                // C = P_k Phi^T Ppred^-1, Phi = [[1, dt], [0, 1]]
                let [pp, pv, vv] = f.p;
                let (a00, a01, a10, a11) = (pp + dt * pv, pv, pv + dt * vv, vv);
                match times_inverse([a00, a01, a10, a11], pr.p) {
                    None => ms = f.m,
                    Some([c00, c01, c10, c11]) => {
                        let (r0, r1) = (ms[0] - pr.m[0], ms[1] - pr.m[1]);
                        ms = [f.m[0] + c00 * r0 + c01 * r1, f.m[1] + c10 * r0 + c11 * r1];
                    }
                }
                let p = &mut points[k];
                let settled = k < known
                    && (ms[0] - p.1[d]).abs() <= SMOOTHED_SETTLED
                    && (ms[1] - p.2[d]).abs() <= SMOOTHED_SETTLED;
                p.1[d] = ms[0];
                p.2[d] = ms[1];
                if settled {
                    break;
                }
            }
        }
    }

    /// The state at `t0_s` and the `n` velocities before it at step `dt_s`; walking back from t0, a gap
    /// up to `max_gap_s` is bridged, a longer one is taken as at rest and the history before it kept
    /// (both flagged gap; `known` counts the velocities newer than the first long gap); before the
    /// oldest sample kept, at rest (flagged short). None if t0 is after the newest sample or inside a
    /// long gap, or fewer than two are kept. The bias is taken off the initial displacement.
    pub fn resample(&self, t0_s: f64, dt_s: f64, n: usize, max_gap_s: f64) -> Option<Resampled> {
        let last = self.entries.back()?;
        if t0_s > last.time_s + 1e-9 || self.entries.len() < 2 {
            return None;
        }
        let pts = self.smoothed();
        let hermite = self.spec.method == Method::Kalman;
        let nominal = {
            let r = self.rate_hz();
            if r > 0.0 { 1.0 / r } else { f64::INFINITY }
        };
        let mut out = Resampled {
            x0: [0.0; 6],
            v0: [0.0; 6],
            velocities: vec![[0.0; 6]; n],
            short: false,
            gap: false,
            known: 0,
        };
        // the newest point at or before t0 (the walk below goes back from it)
        let mut j = pts.partition_point(|p| p.0 <= t0_s).saturating_sub(1);
        let mut ended = false;
        // the state at t, or None where the history has ended; inside a gap longer than `max_gap_s`
        // (the sensor or the link away) nothing is known: at rest there, the history before it kept
        let mut at = |t: f64, out: &mut Resampled| -> Option<([f64; 6], [f64; 6])> {
            if ended {
                out.short = true;
                return None;
            }
            while j > 0 && pts[j].0 > t {
                j -= 1;
            }
            let a = pts[j];
            if a.0 > t {
                ended = true;
                out.short = true;
                return None;
            }
            let b = if j + 1 < pts.len() { pts[j + 1] } else { a };
            let h = b.0 - a.0;
            if h > max_gap_s {
                out.gap = true;
                return None;
            }
            if h > 2.5 * nominal {
                out.gap = true;
            }
            let s = if h > 0.0 { (t - a.0) / h } else { 0.0 };
            let (mut x, mut v) = ([0.0; 6], [0.0; 6]);
            for d in 0..6 {
                if hermite && h > 0.0 {
                    let (s2, s3) = (s * s, s * s * s);
                    x[d] = (2.0 * s3 - 3.0 * s2 + 1.0) * a.1[d]
                        + (s3 - 2.0 * s2 + s) * h * a.2[d]
                        + (-2.0 * s3 + 3.0 * s2) * b.1[d]
                        + (s3 - s2) * h * b.2[d];
                    v[d] = ((6.0 * s2 - 6.0 * s) * (a.1[d] - b.1[d])) / h
                        + (3.0 * s2 - 4.0 * s + 1.0) * a.2[d]
                        + (3.0 * s2 - 2.0 * s) * b.2[d];
                } else {
                    x[d] = a.1[d] + s * (b.1[d] - a.1[d]);
                    v[d] = a.2[d] + s * (b.2[d] - a.2[d]);
                }
            }
            Some((x, v))
        };
        match at(t0_s, &mut out) {
            Some((x, v)) => {
                let bias = self.bias();
                for d in 0..6 {
                    out.x0[d] = x[d] - bias[d];
                }
                out.v0 = v;
            }
            // t0 inside a long gap: no state
            None => return None,
        }
        // `known` counts the newest velocities up to the first long gap (what the drift estimate
        // reads); the history before the gap is kept for the radiation memory
        let mut unbroken = true;
        for m in 1..=n {
            match at(t0_s - m as f64 * dt_s, &mut out) {
                Some((_, v)) => {
                    out.velocities[n - m] = v;
                    if unbroken {
                        out.known = m;
                    }
                }
                None => unbroken = false,
            }
        }
        Some(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(method: Method) -> Spec {
        let noise_x = [0.01, 0.01, 0.01, 5e-4, 5e-4, 5e-4];
        let mut q = [0.0; 6];
        for d in 0..6 {
            q[d] = Spec::process_noise(noise_x[d], 10.0);
        }
        Spec {
            method,
            noise_x,
            noise_v: noise_x,
            q,
            bounds: Bounds::from_system(&nalgebra::Matrix6::from_diagonal_element(1e6), 9.81, 2.0, 0.2),
            restored: [false, false, true, true, true, false],
            learned: [false, false, true, false, false, false],
            bias_time_s: 100.0,
            drift: [0.0; 6],
            drift_time_s: 600.0,
            gate_sigma: 5.0,
            reset_samples: 5,
        }
    }

    /// A heave of 1 m at 0.6 rad/s sampled at 10 Hz with a 0.2 m bias (no noise).
    fn wave(t: f64) -> ([f64; 6], [f64; 6]) {
        let w = 0.6;
        let mut x = [0.0; 6];
        let mut v = [0.0; 6];
        x[2] = (w * t).sin() + 0.2;
        v[2] = w * (w * t).cos();
        (x, v)
    }

    /// [`wave`] as a sensor reads it: heave's displacement and velocity with uniform noise of
    /// standard deviation 0.01.
    fn noisy_wave(t: f64, rng: &mut impl rand::Rng) -> ([f64; 6], [f64; 6]) {
        let (mut x, mut v) = wave(t);
        x[2] += 0.01 * (rng.random::<f64>() - 0.5) * 12f64.sqrt();
        v[2] += 0.01 * (rng.random::<f64>() - 0.5) * 12f64.sqrt();
        (x, v)
    }

    fn fed(method: Method, until_s: f64, skip: impl Fn(f64) -> bool) -> Estimator {
        let mut e = Estimator::new(spec(method), 300.0);
        for k in 0..=(until_s * 10.0) as usize {
            let t = k as f64 * 0.1;
            if skip(t) {
                continue;
            }
            let (x, v) = wave(t);
            e.push(t, x, v).unwrap();
        }
        e
    }

    /// The pass stops where a change is below [`SMOOTHED_SETTLED`] and further back it shrinks: the
    /// states kept are the whole pass's to a thousand of it (a nanometre), whatever the calls between.
    const KEPT_SMOOTHED_TOL: f64 = 1e3 * SMOOTHED_SETTLED;

    /// The smoothed states as a pass over every kept sample gives them (nothing kept from before).
    fn smoothed_afresh(e: &Estimator) -> Vec<Point> {
        let fresh = Estimator {
            smoothed: RefCell::default(),
            ..e.clone()
        };
        fresh.smoothed().iter().copied().collect()
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(32))]
        /// The states kept between calls are the whole pass's, whatever the sensor did in between:
        /// spikes, a re-zeroed sensor (a restart), a burst taken back (a revert), a stall, gaps, the
        /// window's front dropping, a clock step.
        #[test]
        fn the_smoothed_states_kept_between_calls_are_the_whole_pass_s(
            events in proptest::collection::vec(0u8..12, 50..400),
            seed in 0u64..1000,
        ) {
            use rand::SeedableRng;
            let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
            let mut e = Estimator::new(spec(Method::Kalman), 20.0);
            let (mut t, mut offset) = (0.0, 0.0);
            for ev in events {
                let (mut x, v) = noisy_wave(t, &mut rng);
                x[2] += offset;
                match ev {
                    0 => x[2] += 50.0,
                    1 => offset += 2.0,
                    2 => t += 3.0,
                    3 => {
                        // a stall seen by a forecast before the third repeat takes it back
                        let _ = e.push(t, x, v);
                        let _ = e.push(t + 0.02, x, v);
                        let _ = e.smoothed();
                        t += 0.04;
                    }
                    4 => e.restart(),
                    _ => {}
                }
                let _ = e.push(t, x, v);
                t += 0.1;
                if ev >= 9 {
                    let kept: Vec<Point> = e.smoothed().iter().copied().collect();
                    let afresh = smoothed_afresh(&e);
                    proptest::prop_assert_eq!(kept.len(), afresh.len());
                    for (a, b) in kept.iter().zip(&afresh) {
                        proptest::prop_assert_eq!(a.0, b.0);
                        for d in 0..6 {
                            proptest::prop_assert!((a.1[d] - b.1[d]).abs() <= KEPT_SMOOTHED_TOL, "{a:?} {b:?}");
                            proptest::prop_assert!((a.2[d] - b.2[d]).abs() <= KEPT_SMOOTHED_TOL, "{a:?} {b:?}");
                        }
                    }
                }
            }
        }
    }

    /// After a gap longer than `max_gap_s` (a daemon restarted from a state kept a minute before its
    /// kill), the start's variance is what the filter errs by sample to sample, not the gap's
    /// extrapolation (it entered the innovation means with the whole gap's prediction error: 2.07 m^2
    /// against 3.1e-4 m^2 before).
    #[test]
    fn a_long_gap_does_not_inflate_the_start_s_variance() {
        let mut rng = <rand::rngs::StdRng as rand::SeedableRng>::seed_from_u64(7);
        let mut e = Estimator::new(spec(Method::Kalman), 600.0);
        let mut feed = |e: &mut Estimator, from_s: f64, to_s: f64| {
            for k in 0..((to_s - from_s) * 10.0) as usize {
                let t = from_s + k as f64 * 0.1;
                let (x, v) = noisy_wave(t, &mut rng);
                let _ = e.push(t, x, v);
            }
        };
        feed(&mut e, 0.0, 300.0);
        let before = e.start_var(299.9).unwrap()[2];
        feed(&mut e, 390.0, 400.0);
        let after = e.start_var(399.9).unwrap()[2];
        assert!(
            after <= 2.0 * before,
            "heave start variance {after} after a 90 s gap, {before} before"
        );
    }

    #[test]
    fn the_state_follows_the_motion_and_the_bias_comes_off() {
        let e = fed(Method::Kalman, 200.0, |_| false);
        let r = e.resample(200.0, 0.1, 100, 1.0).unwrap();
        let truth = (0.6f64 * 200.0).sin();
        assert!((r.x0[2] - truth).abs() < 0.02, "{} against {truth}", r.x0[2]);
        assert!((e.bias()[2] - 0.2).abs() < 0.02, "bias {}", e.bias()[2]);
        assert!(!r.short && !r.gap);
        // the raw method keeps the bias
        let raw = fed(Method::Raw, 200.0, |_| false)
            .resample(200.0, 0.1, 100, 1.0)
            .unwrap();
        assert!((raw.x0[2] - truth - 0.2).abs() < 1e-9);
    }

    #[test]
    fn a_gap_is_bridged_by_the_curve_through_both_ends() {
        // 1.9 s without samples before t0 = 100
        let e = fed(Method::Kalman, 100.0, |t| t > 98.05 && t < 99.95);
        let r = e.resample(99.0, 0.1, 10, 2.0).unwrap();
        let (x, v) = wave(99.0);
        assert!(
            (r.x0[2] + e.bias()[2] - x[2]).abs() < 0.01,
            "{} against {}",
            r.x0[2],
            x[2]
        );
        let (_, v_before) = wave(98.5);
        assert!((r.velocities[5][2] - v_before[2]).abs() < 0.01);
        assert!((r.v0[2] - v[2]).abs() < 0.01);
        assert!(r.gap && !r.short);
        // linear (raw) across the same gap is far off
        let raw = fed(Method::Raw, 100.0, |t| t > 98.05 && t < 99.95)
            .resample(99.0, 0.1, 10, 2.0)
            .unwrap();
        assert!((raw.v0[2] - v[2]).abs() > 0.05);
    }

    #[test]
    fn a_spike_is_refused_and_a_real_jump_restarts_the_estimate() {
        let mut e = fed(Method::Kalman, 50.0, |_| false);
        let (mut x, v) = wave(50.1);
        x[2] += 1e6;
        assert!(matches!(e.push(50.1, x, v), Err(Refusal::Bound { dof: 2, .. })));
        x[2] -= 1e6 - 1.0; // a metre off: within the bounds, not within reach in 0.1 s
        assert!(matches!(e.push(50.1, x, v), Err(Refusal::Jump { dof: 2, .. })));
        let (x, v) = wave(50.2);
        assert_eq!(e.push(50.2, x, v), Ok(Taken::Accepted));
        // a sensor re-zeroed 10 m away (further than 2 g moves it in half a second): refused four
        // times, then taken
        for k in 3..8 {
            let t = 50.0 + k as f64 * 0.1;
            let (mut x, v) = wave(t);
            x[2] += 10.0;
            let got = e.push(t, x, v);
            if k < 7 {
                assert!(matches!(got, Err(Refusal::Jump { .. })), "{k}: {got:?}");
            } else {
                assert_eq!(got, Ok(Taken::Restarted));
            }
        }
        assert_eq!(e.len(), 5);
    }

    #[test]
    fn a_restart_settles_until_its_offset_is_averaged_and_its_start_holds_the_jump() {
        let mut e = fed(Method::Kalman, 50.0, |_| false);
        let before = e.start_var(50.0).unwrap()[2];
        let mut taken = vec![];
        let mut t = 50.1;
        while t < 50.0 + 0.25 * e.spec.bias_time_s {
            let (mut x, v) = wave(t);
            x[2] += 2.0;
            taken.push(e.push(t, x, v));
            if taken.last() == Some(&Ok(Taken::Restarted)) {
                assert!(e.settling());
                let var = e.start_var(t).unwrap()[2];
                assert!(
                    var > before + 3.0 && var < before + 5.0,
                    "{before} then {var}: the jump's square is in it"
                );
            }
            t += 0.1;
        }
        assert_eq!(
            taken.iter().filter(|r| **r == Ok(Taken::Restarted)).count(),
            1,
            "{:?}",
            &taken[..10]
        );
        assert!(!e.settling(), "settled once the new offset is averaged");
        // the wave's own offset 0.2 and the sensor's 2
        assert!((e.bias()[2] - 2.2).abs() < 0.05, "the new offset {}", e.bias()[2]);
    }

    #[test]
    fn a_burst_of_spikes_the_motion_leaves_is_taken_back() {
        let mut e = fed(Method::Kalman, 50.0, |_| false);
        let n = e.len();
        for k in 1..=5 {
            let t = 50.0 + k as f64 * 0.1;
            let (mut x, v) = wave(t);
            x[2] += 50.0;
            let got = e.push(t, x, v);
            assert_eq!(got.is_ok(), k == 5, "{k}: {got:?}");
        }
        assert!(e.settling());
        let (x, v) = wave(50.6);
        assert_eq!(e.push(50.6, x, v), Ok(Taken::Reverted));
        assert!(!e.settling());
        assert_eq!(e.len(), n + 1, "the burst is gone, the old estimate goes on");
        let r = e.resample(50.6, 0.1, 10, 2.0).unwrap();
        let got = r.x0[2] + e.bias()[2];
        assert!((got - wave(50.6).0[2]).abs() < 0.05, "{got}");
    }

    #[test]
    fn the_smoother_takes_noise_out_of_the_displacement() {
        use rand::SeedableRng;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let mut e = Estimator::new(spec(Method::Kalman), 300.0);
        let mut raw = Estimator::new(spec(Method::Raw), 300.0);
        for k in 0..=600 {
            let t = k as f64 * 0.1;
            let (x, v) = noisy_wave(t, &mut rng);
            e.push(t, x, v).unwrap();
            raw.push(t, x, v).unwrap();
        }
        // displacements at the samples and velocities on the grid, against the truth
        let err = |est: &Estimator| {
            let r = est.resample(60.0, 0.1, 500, 1.0).unwrap();
            let v = (0..500)
                .map(|m| (r.velocities[m][2] - wave(60.0 - (500 - m) as f64 * 0.1).1[2]).powi(2))
                .sum::<f64>();
            let x = est
                .smoothed()
                .iter()
                .map(|(t, x, _)| (x[2] - wave(*t).0[2]).powi(2))
                .sum::<f64>();
            ((x / est.len() as f64).sqrt(), (v / 500.0).sqrt())
        };
        let (kalman, measured) = (err(&e), err(&raw));
        assert!(
            kalman.0 < 0.6 * measured.0,
            "displacement error {} smoothed, {} as measured",
            kalman.0,
            measured.0
        );
        assert!(
            kalman.1 <= measured.1,
            "velocity error {} smoothed, {} as measured",
            kalman.1,
            measured.1
        );
    }

    #[test]
    fn the_start_s_variance_is_the_error_the_filter_makes_as_its_innovations_show_it() {
        use rand::SeedableRng;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let mut spec = spec(Method::Kalman);
        spec.drift = [0.0, 0.0, 0.02, 0.0, 0.0, 0.0];
        spec.drift_time_s = 600.0;
        // the configured figure alone (the hindsight learning: below)
        spec.learned = [false; 6];
        let mut e = Estimator::new(spec, 300.0);
        let (mut square, mut count, mut own, mut start) = (0.0, 0.0, 0.0, 0.0);
        for k in 0..=4000 {
            let t = k as f64 * 0.1;
            let (x, v) = noisy_wave(t, &mut rng);
            e.push(t, x, v).unwrap();
            if t < 30.0 {
                // before the innovations have been averaged over a fifth of bias_time_s: the
                // filter's own variance, and all of the drift (no bias taken off yet)
                if k > 1 && t < 19.0 {
                    let f = e.entries.back().unwrap().filtered[2].p[0];
                    assert_eq!(e.start_var(t).unwrap()[2], f + 4e-4);
                }
                continue;
            }
            let newest = e.entries.back().unwrap().filtered[2];
            square += (newest.m[0] - wave(t).0[2]).powi(2);
            own += newest.p[0];
            // the drift the bias average leaves: 4e-4 x 100 / (600 + 100)
            start += e.start_var(t).unwrap()[2] - 4e-4 / 7.0;
            count += 1.0;
        }
        let (actual, own, start) = (square / count, own / count, start / count);
        // the filter's own variance takes the 0.6 rad/s wave for an acceleration as wide as its
        // bandwidth: more than the error it makes; the innovations tell that error
        assert!(own > actual, "own {own}, actual {actual}");
        assert!(
            start > 0.9 * actual && start < 1.1 * actual,
            "start {start}, actual {actual}, own {own}"
        );
        // the rest of the drift is in the bias taken off
        assert!((e.drift_in_bias_var()[2] - 4e-4 * 6.0 / 7.0).abs() < 1e-12);
    }

    /// Heave's start error in hindsight: a drift of 5 cm over 15 minutes that the configured figure
    /// (no drift) knows nothing of. Returns the mean square of the starts' actual error and the mean
    /// start variance over the second quarter hour.
    fn drifting_start(learned: bool) -> (f64, f64) {
        use rand::SeedableRng;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let mut spec = spec(Method::Kalman);
        spec.learned[2] = learned;
        let mut e = Estimator::new(spec, 300.0);
        let drift = |t: f64| 0.05 * (std::f64::consts::TAU * t / 900.0).sin();
        let (mut square, mut var, mut count) = (0.0, 0.0, 0.0);
        for k in 0..=18000 {
            let t = k as f64 * 0.1;
            let (mut x, v) = noisy_wave(t, &mut rng);
            x[2] += drift(t);
            e.push(t, x, v).unwrap();
            if t >= 900.0 && k % 10 == 0 {
                let r = e.resample(t, 0.1, 0, 1.0).unwrap();
                // the motion itself: the wave less its constant bias
                square += (r.x0[2] - (wave(t).0[2] - 0.2)).powi(2);
                var += e.start_var(t).unwrap()[2];
                count += 1.0;
            }
        }
        (square / count, var / count)
    }

    #[test]
    fn the_start_s_variance_learns_in_hindsight_what_the_sensor_s_drift_leaves() {
        // ratio of the learned variance to the actual mean square: the hindsight checks lag a minute
        // and more behind the drift, and the prior weighs a bias average's worth
        const LEARNED_RATIO: (f64, f64) = (0.7, 1.4);
        let (actual, learned) = drifting_start(true);
        assert!(
            learned > LEARNED_RATIO.0 * actual && learned < LEARNED_RATIO.1 * actual,
            "learned {learned}, actual {actual}"
        );
        // the configured figure alone is the filter's error: far short of it
        let (actual, configured) = drifting_start(false);
        assert!(configured < 0.3 * actual, "configured {configured}, actual {actual}");
    }

    #[test]
    fn hindsight_checks_count_only_starts_taken_with_the_bias_off() {
        // a bias average of 1000 s is taken off from 200 s: a check of a start before then would
        // count a start with the bias on (or none) and weigh the learned mean toward nought
        let mut spec = spec(Method::Kalman);
        spec.bias_time_s = 1000.0;
        let mut e = Estimator::new(spec, 300.0);
        for k in 0..=4000 {
            let t = k as f64 * 0.1;
            let (x, v) = wave(t);
            e.push(t, x, v).unwrap();
        }
        // checks open from 200 s, every 10 s; each closes 2 x 60 s later: those opened at 200-280 s
        let closed = ((400.0 - 200.0 - 2.0 * HINDSIGHT_HALF_WINDOW_S) / HINDSIGHT_EVERY_S).floor() + 1.0;
        assert_eq!(e.learned.span_s, closed * HINDSIGHT_EVERY_S);
    }

    #[test]
    fn a_stalled_sensor_repeating_itself_is_refused_and_bridged() {
        let mut e = fed(Method::Kalman, 50.0, |_| false);
        // zeros for 1.9 s: the first is a jump, the rest repeat it
        for k in 1..20 {
            let t = 50.0 + 0.1 * k as f64;
            let got = e.push(t, [0.0; 6], [0.0; 6]);
            assert!(
                matches!(got, Err(Refusal::Jump { .. } | Refusal::Frozen)),
                "{k}: {got:?}"
            );
        }
        let (x, v) = wave(52.0);
        assert_eq!(e.push(52.0, x, v), Ok(Taken::Accepted));
        let r = e.resample(51.0, 0.1, 5, 2.0).unwrap();
        assert!((r.x0[2] + e.bias()[2] - wave(51.0).0[2]).abs() < 0.01, "{}", r.x0[2]);
        // a small motion: the stall's first zero is within reach and taken, then taken back
        let mut e = Estimator::new(spec(Method::Kalman), 300.0);
        for k in 0..=500 {
            let t = k as f64 * 0.1;
            let (mut x, mut v) = wave(t);
            x[2] = 0.05 * (x[2] - 0.2);
            v[2] *= 0.05;
            e.push(t, x, v).unwrap();
        }
        assert_eq!(e.push(50.1, [0.0; 6], [0.0; 6]), Ok(Taken::Accepted));
        assert_eq!(e.push(50.2, [0.0; 6], [0.0; 6]), Ok(Taken::Accepted));
        assert_eq!(e.push(50.3, [0.0; 6], [0.0; 6]), Err(Refusal::Frozen));
        assert_eq!(e.newest_time_s(), Some(50.0));
        // ... and after a restart (a step of its clock) it is still a moving vessel's stall
        e.restart();
        for k in 0..3 {
            let _ = e.push(60.0 + 0.1 * k as f64, [0.0; 6], [0.0; 6]);
        }
        assert_eq!(e.push(60.3, [0.0; 6], [0.0; 6]), Err(Refusal::Frozen));
        // a sensor sending each value twice is not stalled
        let mut twice = Estimator::new(spec(Method::Kalman), 300.0);
        for k in 0..200 {
            let t = k as f64 * 0.05;
            let (x, v) = wave(0.1 * (k / 2) as f64);
            assert_eq!(twice.push(t, x, v), Ok(Taken::Accepted), "{k}");
        }
        // a vessel at rest, measured so, is not frozen
        let mut rest = Estimator::new(spec(Method::Kalman), 300.0);
        for k in 0..10 {
            assert_eq!(rest.push(k as f64 * 0.1, [0.0; 6], [0.0; 6]), Ok(Taken::Accepted));
        }
    }

    #[test]
    fn drops_are_counted_by_kind_and_raw_resampling_is_linear_with_the_gap_rule() {
        let s = |t: f64, v: f64| (t, [v; 6], [v; 6]);
        let mut h = Estimator::new(spec(Method::Raw), 100.0);
        let (t, x, v) = s(1.0, 0.0);
        assert!(h.push(t, x, v).is_ok());
        assert_eq!(h.push(t, x, v), Err(Refusal::Duplicate));
        assert_eq!(h.push(t + 0.5 * MIN_SAMPLE_INTERVAL_S, x, v), Err(Refusal::Duplicate));
        assert_eq!(h.push(0.5, x, v), Err(Refusal::Late));
        assert_eq!(h.push(2.0, [f64::NAN; 6], v), Err(Refusal::NonFinite));
        assert_eq!(h.len(), 1);
        let mut h = Estimator::new(spec(Method::Raw), 100.0);
        for k in 0..=100 {
            let t = k as f64 * 0.1;
            if (40..60).contains(&k) {
                continue; // a 2 s gap from 3.9 to 6.0
            }
            let (t, x, v) = s(t, t);
            h.push(t, x, v).unwrap();
        }
        let r = h.resample(10.0, 0.25, 8, 3.0).unwrap();
        assert!((r.x0[2] - 10.0).abs() < 1e-12 && (r.velocities[7][0] - 9.75).abs() < 1e-12);
        assert!(!r.short && !r.gap);
        // back across the gap: bridged with max_gap 3 s; with 1 s at rest inside it, the history
        // before it kept, `known` up to it
        let r = h.resample(10.0, 0.5, 16, 3.0).unwrap();
        assert!(r.gap && !r.short);
        assert!((r.velocities[0][0] - 2.0).abs() < 1e-12);
        assert_eq!(r.known, 16);
        let r = h.resample(10.0, 0.5, 16, 1.0).unwrap();
        assert!(r.gap && !r.short);
        // 10 - 0.5 m for m = 9..12 (5.5 .. 4.0) falls in the gap: at rest; 3.5 and 2.0 kept
        assert_eq!(r.velocities[16 - 9], [0.0; 6]);
        assert_eq!(r.velocities[16 - 12], [0.0; 6]);
        assert!((r.velocities[16 - 13][0] - 3.5).abs() < 1e-12);
        assert!((r.velocities[0][0] - 2.0).abs() < 1e-12);
        assert_eq!(r.known, 8);
        // t0 inside the long gap: no state
        assert!(h.resample(5.0, 0.5, 4, 1.0).is_none());
        // history longer than what is kept: short
        let r = h.resample(10.0, 1.0, 20, 3.0).unwrap();
        assert!(r.short);
        // t0 after the newest sample: nothing
        assert!(h.resample(10.5, 0.1, 5, 1.0).is_none());
    }
}
