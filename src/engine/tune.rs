//! The in-situ roll tuning's glue ([`crate::tuning`]): the engine keeps the measured trace and marks
//! the ticks whose start may be a case; the computer's [`Tuning`] keeps the cases and works a round's
//! candidates between jobs, and gives the tuned model the forecasts then run with.

use std::sync::Arc;

use super::message::flags;
use super::*;
use crate::tuning::{Case, Tuner, TunerReport};

/// The trace takes each series' measured value this long before the tick's start time, once the
/// estimator's smoother has seen the samples after it, s.
pub const TRACE_SETTLE_S: f64 = 1.0;
/// The trace keeps this much, s: every case of a round over its lead, and the round's own time.
pub const TRACE_KEEP_S: f64 = 300.0;
/// A tuning moves the model forecasts run with at most this often (each move rebuilds the band's
/// response table), s.
pub const APPLY_EVERY_S: f64 = 30.0;
/// The tuning scores at most one candidate per this many seconds of the data clock (a candidate is a
/// re-run of every case of its round: about a tenth of a core's second on the two-ship demo), s.
pub const WORK_EVERY_S: f64 = 3.0;
/// Flags that keep a tick's start out of the cases (its history is not what the vessel did).
const NOT_A_CASE: u32 = flags::HISTORY_SHORT | flags::HISTORY_GAP | flags::MOTION_RESTARTED;

/// What the tuning takes from a tick: the measured trace (time, every series) and whether the job's
/// start may be a case (its waves trusted, every vessel's motion fresh and whole).
#[derive(Debug, Clone)]
pub struct TuneInput {
    pub trace: Arc<Vec<(f64, Vec<f64>)>>,
    pub case: bool,
}

/// The computer's side: the tuner, the newest trace, a finished round's report not yet handed on.
pub struct Tuning {
    tuner: Option<Tuner>,
    trace: Arc<Vec<(f64, Vec<f64>)>>,
    report: Option<TunerReport>,
    now_s: f64,
    applied_s: f64,
    worked_s: f64,
}

impl Tuning {
    pub fn new(model: &TimeModel, cfg: &ShipcastConfig) -> Tuning {
        Tuning {
            tuner: if cfg.forecast.tune_roll {
                Tuner::new(model)
            } else {
                None
            },
            trace: Arc::new(vec![]),
            report: None,
            now_s: f64::NEG_INFINITY,
            applied_s: f64::NEG_INFINITY,
            worked_s: f64::NEG_INFINITY,
        }
    }

    /// Back to the model as built (a rebuild for the forward speed).
    pub fn reset(&mut self, model: &TimeModel) {
        if let Some(t) = &mut self.tuner {
            t.reset(model);
        }
    }

    /// Starts from a tuning kept across a restart ([`Tuner::resume`]): the model as built, `base`,
    /// with it (None: no tuning, or the model could not be made).
    pub fn resume(&mut self, base: &TimeModel, kept: &[[f64; 3]]) -> Option<TimeModel> {
        let tuner = self.tuner.as_mut()?;
        tuner.resume(kept);
        tuner
            .apply(base)
            .map_err(|e| tracing::warn!("the kept roll tuning could not be applied, the model as built kept: {e}"))
            .ok()
    }

    /// Takes a job's trace (at start time `t0_s`) and, when it may be one, its start as a case; hands
    /// on the report of a round finished since the last job.
    pub fn take(&mut self, t0_s: f64, input: Option<&TuneInput>, case: impl FnOnce() -> Case) -> Option<TunerReport> {
        if let (Some(t), Some(input)) = (&mut self.tuner, input) {
            self.trace = input.trace.clone();
            self.now_s = t0_s;
            if input.case {
                t.offer(case, t0_s);
            }
        }
        self.report.take()
    }

    /// One step of the tuning (a round's next candidate, at most every [`WORK_EVERY_S`]) on the model
    /// as built, `base`: a finished round's tuning, applied at most every [`APPLY_EVERY_S`], is the
    /// model returned (its report goes with the next job).
    pub fn work(&mut self, base: &TimeModel) -> Option<TimeModel> {
        let tuner = self.tuner.as_mut()?;
        if self.now_s - self.worked_s < WORK_EVERY_S {
            return None;
        }
        self.worked_s = self.now_s;
        let mut report = tuner.work(base, &self.trace)?;
        let mut tuned = None;
        if report.reset.is_some() || self.now_s - self.applied_s >= APPLY_EVERY_S {
            if let Some((untuned, cost)) = tuner.score(base, &self.trace) {
                (report.cost_untuned, report.cost) = (untuned, cost);
            }
            match tuner.apply(base) {
                Ok(model) => {
                    self.applied_s = self.now_s;
                    report.applied = true;
                    tuned = Some(model);
                }
                Err(e) => tracing::warn!("the tuned model could not be made, the model as built kept: {e}"),
            }
        }
        self.report = Some(report);
        tuned
    }
}

impl Engine {
    /// The tick's input to the tuning at start time `t0`: the trace extended by the measured values
    /// [`TRACE_SETTLE_S`] before it; `eligible` when its waves are trusted and every vessel's motion
    /// fresh (None: tuning is off).
    pub(super) fn tune_input(&mut self, t0: f64, eligible: bool, fl: u32) -> Option<TuneInput> {
        if !self.cfg.tune_roll {
            return None;
        }
        let t = t0 - TRACE_SETTLE_S;
        if self.trace.back().is_none_or(|(last, _)| t > *last)
            && let Some(x) = self.measured_at(t)
        {
            self.trace.push_back((t, x));
        }
        while self.trace.front().is_some_and(|(s, _)| *s < t - TRACE_KEEP_S) {
            self.trace.pop_front();
        }
        Some(TuneInput {
            trace: Arc::new(self.trace.iter().cloned().collect()),
            case: eligible && fl & NOT_A_CASE == 0,
        })
    }

    /// The roll tuning in force per vessel (damping, quadratic, frequency; the status's).
    pub fn roll_tuning(&self) -> &[[f64; 3]] {
        &self.roll_tuning[..self.n_bodies.min(MAX_VESSELS)]
    }

    /// A finished tuning round: logged, and its figures kept for the status.
    pub(super) fn tuned(&mut self, r: &TunerReport) {
        let per_vessel = r
            .vessels
            .iter()
            .zip(&r.tuning)
            .map(|(v, t)| {
                format!(
                    "vessel {v}: damping {:+.3}, quadratic {:.3}, frequency {:+.1} %",
                    t.damping_fraction,
                    t.quadratic_fraction,
                    100.0 * t.frequency_correction
                )
            })
            .collect::<Vec<_>>()
            .join("; ");
        if let Some(why) = &r.reset {
            tracing::warn!("roll tuning reset to the model as built: {why}");
        } else if r.applied {
            tracing::info!(
                cases = r.cases,
                error_untuned = r.cost_untuned,
                error_tuned = r.cost,
                converged = r.converged,
                "roll tuned in situ (fractions of critical damping; roll error normalized by its variance): {per_vessel}"
            );
        }
        for (v, t) in r.vessels.iter().zip(&r.tuning) {
            if let Some(slot) = self.roll_tuning.get_mut(*v) {
                *slot = t.as_array();
            }
        }
        self.roll_tuning_converged = r.converged;
    }
}
