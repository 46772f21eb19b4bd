//! The default solver step (pure): chosen from the system's shortest natural period, so that a
//! user who sets no step gets one the time domain is accurate at.
//!
//! Why this many steps: the Newmark average-acceleration step (`rom::stepper`) keeps amplitude but
//! lengthens a period T by about (w dt)^2 / 12 at step dt; near a lightly damped resonance that moves
//! the response by several times as much. [`STEPS_PER_PERIOD`] steps keep the step's own error well
//! below 1 % of a curve's peak (docs/validation.md has the measured error against the step).

use crate::hydro::VesselSystem;

/// Steps in the shortest natural period at the default step.
pub const STEPS_PER_PERIOD: f64 = 100.0;
/// The default step is never longer than this, s (the forecasts' output sampling).
pub const MAX_DEFAULT_DT_S: f64 = 0.1;
/// ... and is a whole number of 1 / this, s (a tidy output grid: 0.005 s).
pub const DT_QUANTA_PER_S: f64 = 200.0;

/// The default step and why.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepChoice {
    pub dt_s: f64,
    /// The shortest natural period and its global mode index (None: no DOF with restoring, or none
    /// shorter than `STEPS_PER_PERIOD` x [`MAX_DEFAULT_DT_S`]).
    pub shortest: Option<(usize, f64)>,
}

impl StepChoice {
    /// The choice in words, for the daemon's log and `db check`.
    pub fn describe(&self, sys: &VesselSystem) -> String {
        match self.shortest {
            Some((i, t)) => format!(
                "{} s: {STEPS_PER_PERIOD:.0} steps in the shortest natural period ({} {t:.2} s), in whole {} s",
                self.dt_s,
                crate::hydro::mode_label(sys, i),
                1.0 / DT_QUANTA_PER_S
            ),
            None => format!(
                "{} s: the longest default step (no natural period shorter than {:.0} s)",
                self.dt_s,
                STEPS_PER_PERIOD * MAX_DEFAULT_DT_S
            ),
        }
    }
}

/// The step a run gets when none is set: the shortest natural period over [`STEPS_PER_PERIOD`],
/// rounded down to whole 1 / [`DT_QUANTA_PER_S`], at most [`MAX_DEFAULT_DT_S`].
pub fn default_step(sys: &VesselSystem) -> StepChoice {
    let shortest = sys
        .natural_periods_s()
        .into_iter()
        .filter(|(_, t)| t.is_finite() && *t > 0.0)
        .min_by(|a, b| a.1.total_cmp(&b.1));
    match shortest {
        Some((i, t)) if t / STEPS_PER_PERIOD < MAX_DEFAULT_DT_S => StepChoice {
            dt_s: (t / STEPS_PER_PERIOD * DT_QUANTA_PER_S).floor().max(1.0) / DT_QUANTA_PER_S,
            shortest: Some((i, t)),
        },
        _ => StepChoice {
            dt_s: MAX_DEFAULT_DT_S,
            shortest: None,
        },
    }
}
