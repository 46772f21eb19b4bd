//! The tuner: past forecasts' starts kept as cases, and rounds of candidate models scored against the
//! roll measured after each case (output error). A round evaluates the centre and one step along each
//! parameter, one candidate per call (the daemon spreads a round over its ticks), then takes a
//! Gauss-Newton step, bounded and drawn toward the model as built by a weak prior.

use std::collections::VecDeque;
use std::sync::Arc;

use nalgebra::{DMatrix, DVector};

use super::{RollRow, RollTuning, bounds, changes, roll_rows};
use crate::radiation::history::Memory;
use crate::rom::{ForecastRequest, Forecaster, TimeModel, Track};
use crate::waves::WaveComponent;

/// A case is kept from a forecast every this many seconds, s.
pub const CASE_EVERY_S: f64 = 15.0;
/// Each case is re-run and scored over this many seconds after its start, s.
pub const CASE_LEAD_S: f64 = 60.0;
/// The newest this many scored cases make a round (two minutes of starts).
pub const MAX_CASES: usize = 8;
/// A round needs at least this many cases whose lead has passed.
pub const MIN_CASES: usize = 5;
/// A vessel whose measured roll's standard deviation is below this is not excited enough to tune, rad.
pub const MIN_ROLL_SIGMA_RAD: f64 = 0.0017;
/// Each parameter's finite-difference step, as a share of its bounds' width.
const STEP_SHARE: f64 = 0.05;
/// A round moves each parameter by at most this share of its bounds' width: one round's cases are two
/// minutes of one sea, and a small move per round averages the rounds' answers over the last minutes
/// (a round's own optimum over-fits its cases).
const MAX_MOVE_SHARE: f64 = 0.05;
/// ... and by this share of the step its Gauss-Newton solution asks.
const STEP_GAIN: f64 = 0.5;
/// Weight of the prior (the model as built) against the roll's normalized squared error: a move over
/// a parameter's whole width costs this much, so the data decide wherever they tell anything.
const PRIOR_WEIGHT: f64 = 0.01;
/// Levenberg-Marquardt damping of the normal equations' diagonal.
const LM_DAMPING: f64 = 0.1;
/// The tuning in force is the rounds' parameters averaged over about this many rounds (exponentially;
/// half a minute at the daemon's pace). A round's answer follows its two minutes of sea, and that
/// tracks the next minutes' best better than a longer average does (two-ship demo, roll correlation
/// at 30 s: 0.885 / 0.865 over 15 rounds, 0.889 / 0.873 over two; docs/tuning.md).
const SMOOTHING_ROUNDS: f64 = 2.0;
/// Rounds in a row that moved no parameter of the tuning in force by more than [`CONVERGED_SHARE`] of
/// its width: converged.
const CONVERGED_ROUNDS: usize = 3;
const CONVERGED_SHARE: f64 = 0.01;
/// A converged tuning is reset when a vessel's measured roll changes by more than this factor (the sea
/// or the loading changed beyond what was identified).
pub const SEA_CHANGE_FACTOR: f64 = 2.0;

/// A past forecast's start: what the model is re-run from (active rows, as the forecast had them).
#[derive(Debug, Clone)]
pub struct Case {
    pub t0_s: f64,
    pub x0: Vec<f64>,
    pub v0: Vec<f64>,
    pub velocities: Vec<Vec<f64>>,
    pub waves: Vec<WaveComponent>,
    pub track: Option<Track>,
}

/// A kept case and what every candidate model shares of its re-run (the wave force and the radiation
/// memory depend on the excitation and the kernel, which the tuning leaves alone).
#[derive(Debug)]
struct Kept {
    case: Case,
    shared: std::sync::OnceLock<Option<(Vec<f64>, Memory)>>,
}

/// A round in progress: its cases, the candidates and their residuals so far.
#[derive(Debug, Clone)]
pub struct Round {
    cases: Vec<Arc<Kept>>,
    /// The measured roll's standard deviation per row over the cases, rad.
    sigma: Vec<f64>,
    /// Which parameters move (those of excited vessels).
    free: Vec<usize>,
    candidates: Vec<Vec<f64>>,
    residuals: Vec<Vec<f64>>,
}

/// What a finished round did.
#[derive(Debug, Clone, PartialEq)]
pub struct TunerReport {
    /// Vessel index of each tuned row, and its tuning after the round.
    pub vessels: Vec<usize>,
    pub tuning: Vec<RollTuning>,
    /// Normalized squared roll error (mean over the cases' leads, per the roll's variance) of the model
    /// as built and of the tuning in force over the round's cases (NaN until [`Tuner::score`]d).
    pub cost_untuned: f64,
    pub cost: f64,
    pub cases: usize,
    pub converged: bool,
    /// Why the tuning was set back to the model as built, if it was.
    pub reset: Option<String>,
    /// Whether the model forecasts run with took it (set by the caller).
    pub applied: bool,
}

/// The in-situ roll tuner of one model.
pub struct Tuner {
    rows: Vec<RollRow>,
    cases: VecDeque<Arc<Kept>>,
    /// The parameters the rounds move (three per tuned vessel), and their average over the last
    /// [`SMOOTHING_ROUNDS`]: the tuning in force.
    center: Vec<f64>,
    smoothed: Vec<f64>,
    round: Option<Round>,
    fc: Forecaster,
    quiet_rounds: usize,
    converged_sigma: Option<Vec<f64>>,
    /// The last finished round's cases and roll scales ([`Tuner::score`]).
    last_round: Option<(Vec<Arc<Kept>>, Vec<f64>)>,
}

impl Tuner {
    /// A tuner for `model`'s vessels whose roll can be tuned (None: none can).
    pub fn new(model: &TimeModel) -> Option<Tuner> {
        let rows = roll_rows(model);
        (!rows.is_empty()).then(|| Tuner {
            center: vec![0.0; 3 * rows.len()],
            smoothed: vec![0.0; 3 * rows.len()],
            rows,
            cases: VecDeque::new(),
            round: None,
            fc: Forecaster::new(),
            quiet_rounds: 0,
            converged_sigma: None,
            last_round: None,
        })
    }

    /// The tuning now, per tuned vessel.
    pub fn tuning(&self) -> Vec<(usize, RollTuning)> {
        self.rows
            .iter()
            .enumerate()
            .map(|(k, r)| (r.vessel, RollTuning::from_slice(&self.smoothed[3 * k..3 * k + 3])))
            .collect()
    }

    /// Starts from a tuning kept across a restart of the daemon (damping, quadratic, frequency per
    /// vessel, by the vessel's index): the tuning in force and the rounds' centre. Vessels it does not
    /// tune, and values that are not finite, are passed over.
    pub fn resume(&mut self, kept: &[[f64; 3]]) {
        for (k, r) in self.rows.iter().enumerate() {
            if let Some(p) = kept.get(r.vessel).filter(|p| p.iter().all(|v| v.is_finite())) {
                self.center[3 * k..3 * k + 3].copy_from_slice(p);
                self.smoothed[3 * k..3 * k + 3].copy_from_slice(p);
            }
        }
    }

    /// The model as built with the tuning now.
    pub fn apply(&self, base: &TimeModel) -> crate::rom::Result<TimeModel> {
        base.adjusted(&changes(&self.rows, &params(&self.smoothed)))
    }

    /// Back to a new model as built (the forward speed moved): its cases are made again.
    pub fn reset(&mut self, model: &TimeModel) {
        self.cases.clear();
        self.rows = roll_rows(model);
        self.center = vec![0.0; 3 * self.rows.len()];
        self.smoothed = self.center.clone();
        self.round = None;
        self.quiet_rounds = 0;
        self.converged_sigma = None;
        self.last_round = None;
    }

    /// Keeps a forecast's start as a case, at most one every [`CASE_EVERY_S`]; cases too old to be in
    /// the next round are dropped.
    pub fn offer(&mut self, case: impl FnOnce() -> Case, t0_s: f64) {
        if self.cases.back().is_some_and(|c| t0_s - c.case.t0_s < CASE_EVERY_S) {
            return;
        }
        self.cases.push_back(Arc::new(Kept {
            case: case(),
            shared: std::sync::OnceLock::new(),
        }));
        let oldest = t0_s - CASE_LEAD_S - (MAX_CASES as f64 + 1.0) * CASE_EVERY_S;
        while self.cases.front().is_some_and(|c| c.case.t0_s < oldest) {
            self.cases.pop_front();
        }
    }

    /// One step of work: start a round (when enough cases have been measured over their lead in
    /// `trace`: (time, every series' measured value)), or score its next candidate; a finished round
    /// moves the tuning and is reported.
    pub fn work(&mut self, base: &TimeModel, trace: &[(f64, Vec<f64>)]) -> Option<TunerReport> {
        if self.round.is_none() {
            self.round = self.start_round(trace);
            return None;
        }
        let round = self.round.as_mut()?;
        let k = round.residuals.len();
        let p = params(&round.candidates[k]);
        match residuals(&self.rows, base, &p, &round.cases, &round.sigma, trace, &mut self.fc) {
            Some(r) if k == 0 || r.len() == round.residuals[0].len() => round.residuals.push(r),
            None if k == 0 => {
                // the centre itself does not run: back to the model as built
                self.center.iter_mut().for_each(|v| *v = 0.0);
                self.smoothed.iter_mut().for_each(|v| *v = 0.0);
                self.round = None;
                return Some(self.report(Some("the tuned model failed to run".into())));
            }
            // a step that does not run (or the trace moved under it): that parameter stays this round
            _ => round.residuals.push(round.residuals[0].clone()),
        }
        if round.residuals.len() < round.candidates.len() {
            return None;
        }
        let round = self.round.take()?;
        Some(self.finish(round))
    }

    /// A round over the newest scored cases, or None while too few have been measured.
    fn start_round(&self, trace: &[(f64, Vec<f64>)]) -> Option<Round> {
        let newest = trace.last()?.0;
        let cases: Vec<Arc<Kept>> = self
            .cases
            .iter()
            .rev()
            .filter(|c| c.case.t0_s + CASE_LEAD_S <= newest && trace[0].0 <= c.case.t0_s)
            .take(MAX_CASES)
            .cloned()
            .collect();
        if cases.len() < MIN_CASES {
            return None;
        }
        let sigma = self
            .rows
            .iter()
            .map(|r| measured_sigma(trace, &cases, r.mode))
            .collect::<Vec<_>>();
        let free: Vec<usize> = (0..self.center.len())
            .filter(|&i| sigma[i / 3] >= MIN_ROLL_SIGMA_RAD)
            .collect();
        if free.is_empty() {
            return None;
        }
        let mut candidates = vec![self.center.clone()];
        for &i in &free {
            let (lo, hi) = bounds(&self.rows[i / 3])[i % 3];
            let h = STEP_SHARE * (hi - lo);
            let mut c = self.center.clone();
            c[i] = if c[i] + h <= hi { c[i] + h } else { c[i] - h };
            candidates.push(c);
        }
        Some(Round {
            cases,
            sigma,
            free,
            candidates,
            residuals: vec![],
        })
    }

    /// The Gauss-Newton step of a scored round, bounded; convergence and the sea's change judged.
    fn finish(&mut self, round: Round) -> TunerReport {
        let r0 = &round.residuals[0];
        let nf = round.free.len();
        let widths: Vec<f64> = round
            .free
            .iter()
            .map(|&i| {
                let (lo, hi) = bounds(&self.rows[i / 3])[i % 3];
                hi - lo
            })
            .collect();
        let mut jac = DMatrix::zeros(r0.len() + nf, nf);
        for (col, (&i, rk)) in round.free.iter().zip(&round.residuals[1..]).enumerate() {
            let h = round.candidates[col + 1][i] - self.center[i];
            for (row, (a, b)) in rk.iter().zip(r0).enumerate() {
                jac[(row, col)] = (a - b) / h;
            }
            jac[(r0.len() + col, col)] = PRIOR_WEIGHT.sqrt() / widths[col];
        }
        let mut res = DVector::zeros(r0.len() + nf);
        res.rows_mut(0, r0.len()).copy_from_slice(r0);
        for (col, &i) in round.free.iter().enumerate() {
            res[r0.len() + col] = PRIOR_WEIGHT.sqrt() * self.center[i] / widths[col];
        }
        let jtj = jac.transpose() * &jac;
        let mut lhs = jtj.clone();
        for c in 0..nf {
            lhs[(c, c)] += LM_DAMPING * jtj[(c, c)] + 1e-12;
        }
        let rhs = -(jac.transpose() * res);
        let step = lhs.lu().solve(&rhs).unwrap_or_else(|| DVector::zeros(nf));
        for (col, &i) in round.free.iter().enumerate() {
            let (lo, hi) = bounds(&self.rows[i / 3])[i % 3];
            let s = if step[col].is_finite() {
                STEP_GAIN * step[col]
            } else {
                0.0
            };
            let s = s.clamp(-MAX_MOVE_SHARE * widths[col], MAX_MOVE_SHARE * widths[col]);
            self.center[i] = (self.center[i] + s).clamp(lo, hi);
        }
        let mut largest_move = 0.0f64;
        for (col, &i) in round.free.iter().enumerate() {
            let m = (self.center[i] - self.smoothed[i]) / SMOOTHING_ROUNDS;
            self.smoothed[i] += m;
            largest_move = largest_move.max(m.abs() / widths[col]);
        }
        self.quiet_rounds = if largest_move < CONVERGED_SHARE {
            self.quiet_rounds + 1
        } else {
            0
        };
        let converged = self.quiet_rounds >= CONVERGED_ROUNDS;
        let mut reset = None;
        match &self.converged_sigma {
            Some(s) if changed(s, &round.sigma) => {
                reset = Some("the measured roll changed beyond what was identified".to_string());
                self.center.iter_mut().for_each(|v| *v = 0.0);
                self.smoothed.iter_mut().for_each(|v| *v = 0.0);
                self.quiet_rounds = 0;
                self.converged_sigma = None;
            }
            None if converged => self.converged_sigma = Some(round.sigma.clone()),
            _ => {}
        }
        let mut report = self.report(reset);
        report.cases = round.cases.len();
        self.last_round = Some((round.cases, round.sigma));
        report
    }

    /// The roll error (normalized as [`TunerReport::cost`]) of the model as built and of the tuning
    /// in force, over the last round's cases: two re-runs of each (the caller asks when it logs).
    pub fn score(&mut self, base: &TimeModel, trace: &[(f64, Vec<f64>)]) -> Option<(f64, f64)> {
        let (cases, sigma) = self.last_round.as_ref()?;
        let mut cost = |p: &[f64]| {
            residuals(&self.rows, base, &params(p), cases, sigma, trace, &mut self.fc)
                .map(|r| r.iter().map(|v| v * v).sum::<f64>())
        };
        let untuned = cost(&vec![0.0; self.smoothed.len()])?;
        Some((untuned, cost(&self.smoothed.clone())?))
    }

    fn report(&self, reset: Option<String>) -> TunerReport {
        let t = self.tuning();
        TunerReport {
            vessels: t.iter().map(|(v, _)| *v).collect(),
            tuning: t.iter().map(|(_, t)| *t).collect(),
            cost_untuned: f64::NAN,
            cost: f64::NAN,
            cases: 0,
            converged: self.quiet_rounds >= CONVERGED_ROUNDS && reset.is_none(),
            reset,
            applied: false,
        }
    }
}

/// Each vessel's tuning from the parameter vector (three per tuned vessel).
fn params(v: &[f64]) -> Vec<RollTuning> {
    v.chunks(3).map(RollTuning::from_slice).collect()
}

/// Whether any vessel's measured roll changed by more than [`SEA_CHANGE_FACTOR`].
fn changed(then: &[f64], now: &[f64]) -> bool {
    then.iter()
        .zip(now)
        .any(|(a, b)| *a > 0.0 && (b / a > SEA_CHANGE_FACTOR || a / b > SEA_CHANGE_FACTOR))
}

/// The trace's values of `mode` over each case's lead: (case, time, value) in order.
fn measured<'a>(trace: &'a [(f64, Vec<f64>)], case: &'a Case, mode: usize) -> impl Iterator<Item = (f64, f64)> + 'a {
    let from = trace.partition_point(|(t, _)| *t < case.t0_s);
    trace[from..]
        .iter()
        .take_while(move |(t, _)| *t <= case.t0_s + CASE_LEAD_S)
        .filter_map(move |(t, x)| x.get(mode).filter(|v| v.is_finite()).map(|v| (t - case.t0_s, *v)))
}

/// The standard deviation of `mode`'s measured values over the cases' leads.
fn measured_sigma(trace: &[(f64, Vec<f64>)], cases: &[Arc<Kept>], mode: usize) -> f64 {
    let (mut n, mut s, mut s2) = (0.0, 0.0, 0.0);
    for c in cases {
        for (_, v) in measured(trace, &c.case, mode) {
            n += 1.0;
            s += v;
            s2 += v * v;
        }
    }
    if n < 2.0 {
        return 0.0;
    }
    let mean = s / n;
    (s2 / n - mean * mean).max(0.0).sqrt()
}

/// The residuals of the model tuned by `p`, re-run from each case, against the measured roll: per
/// case and row, the forecast less the measurement with their mean difference off (a heel the
/// tuning cannot change), over the roll's standard deviation and the root of the count (their squares
/// sum to the mean normalized squared error). None when the model does not run.
fn residuals(
    rows: &[RollRow],
    base: &TimeModel,
    p: &[RollTuning],
    cases: &[Arc<Kept>],
    sigma: &[f64],
    trace: &[(f64, Vec<f64>)],
    fc: &mut Forecaster,
) -> Option<Vec<f64>> {
    let model = base.adjusted(&changes(rows, p)).ok()?;
    let mut out = vec![];
    let mut count = 0usize;
    for kept in cases {
        let case = &kept.case;
        let (force, memory) = kept.shared.get_or_init(|| shared(base, case, fc)).as_ref()?;
        let req = request(case, memory);
        let f = fc.forecast_forced(&model, &req, force).ok()?;
        for (r, s) in rows.iter().zip(sigma) {
            if *s < MIN_ROLL_SIGMA_RAD {
                continue;
            }
            let diffs: Vec<f64> = measured(trace, case, r.mode)
                .filter_map(|(lead, v)| {
                    let k = (lead / f.dt_s).round() as usize;
                    (k <= f.steps).then(|| f.at(k, r.mode) - v)
                })
                .collect();
            let mean = diffs.iter().sum::<f64>() / diffs.len().max(1) as f64;
            count += diffs.len();
            out.extend(diffs.iter().map(|d| (d - mean) / s));
        }
    }
    let norm = (count.max(1) as f64).sqrt();
    out.iter_mut().for_each(|v| *v /= norm);
    Some(out)
}

/// A case's re-run request over [`CASE_LEAD_S`].
fn request<'a>(case: &'a Case, memory: &'a Memory) -> ForecastRequest<'a> {
    ForecastRequest {
        x0: &case.x0,
        v0: &case.v0,
        memory,
        waves: &case.waves,
        length_s: CASE_LEAD_S,
        ramp_s: 0.0,
        drift_velocity: None,
        track: case.track,
    }
}

/// What every candidate shares of a case's re-run: its wave force and radiation memory on `model`
/// (None: they cannot be made, the case is not scored).
fn shared(model: &TimeModel, case: &Case, fc: &mut Forecaster) -> Option<(Vec<f64>, Memory)> {
    let memory = Memory::from_history(model, &case.velocities).ok()?;
    let force = fc.force_for(model, &request(case, &memory)).ok()?;
    Some((force, memory))
}
