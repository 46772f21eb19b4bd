//! In-situ tuning of roll (pure): the seed paper's viscous roll coefficients, which "must be tuned
//! using model test data and/or full scale results", identified on board from the daemon's own past
//! forecasts. Each vessel's roll gets an added linear damping, a quadratic damping and a correction of
//! its natural frequency, bounded, chosen so that the model re-run from the measured starts of the
//! last minutes with the wave fields it had then ([`Case`]) follows the roll that was measured
//! (output error, Gauss-Newton over rounds of candidate models: [`Tuner`]).
//!
//! Conventions (DESIGN.md section 1): roll is DOF 3 of each vessel, rad, positive starboard down;
//! the parameters are dimensionless:
//! - `damping_fraction`: added linear roll damping as a fraction of critical, 2 sqrt(C44 (M + A_inf)44);
//! - `quadratic_fraction`: added B_Q such that at a roll amplitude of [`PHI_REF_RAD`] at the natural
//!   frequency it equals this fraction of critical: B_Q = q B_crit / (w_n PHI_REF);
//! - `frequency_correction`: the natural frequency scaled by (1 + f) through the roll restoring,
//!   C44 (1 + f)^2.

mod solve;

pub use solve::{CASE_EVERY_S, CASE_LEAD_S, Case, MAX_CASES, MIN_CASES, Round, Tuner, TunerReport};

use crate::rom::TimeModel;
use crate::rom::adjust::RowChange;

/// The roll amplitude at which the quadratic fraction reads as a fraction of critical, rad (3 deg).
pub const PHI_REF_RAD: f64 = 0.05236;
/// Bounds of the parameters (the linear fraction's lower bound is also the model's own viscous
/// damping: it never goes below none).
pub const DAMPING_FRACTION_BOUNDS: (f64, f64) = (-0.10, 0.20);
pub const QUADRATIC_FRACTION_BOUNDS: (f64, f64) = (0.0, 0.30);
pub const FREQUENCY_CORRECTION_BOUNDS: (f64, f64) = (-0.10, 0.10);

/// One vessel's tuned roll.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct RollTuning {
    pub damping_fraction: f64,
    pub quadratic_fraction: f64,
    pub frequency_correction: f64,
}

impl RollTuning {
    pub fn as_array(&self) -> [f64; 3] {
        [
            self.damping_fraction,
            self.quadratic_fraction,
            self.frequency_correction,
        ]
    }

    pub fn from_slice(p: &[f64]) -> RollTuning {
        RollTuning {
            damping_fraction: p[0],
            quadratic_fraction: p[1],
            frequency_correction: p[2],
        }
    }
}

/// A vessel's roll row in a model: the scales its tuning is read against.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RollRow {
    pub vessel: usize,
    /// Index into the model's active states.
    pub row: usize,
    /// Global mode index (6 vessel + 3).
    pub mode: usize,
    /// 2 sqrt(C44 (M + A_inf)44), N m s/rad.
    pub critical_damping: f64,
    /// sqrt(C44 / (M + A_inf)44), rad/s.
    pub omega_n_rad_s: f64,
    /// C44 with the lines and fenders linearized, N m/rad.
    pub stiffness: f64,
    /// The model's own viscous (linear) roll damping as a fraction of critical.
    pub own_damping_fraction: f64,
}

/// The roll rows of a model's vessels that can be tuned: roll active with positive restoring.
pub fn roll_rows(model: &TimeModel) -> Vec<RollRow> {
    let n_bodies = model.n_modes / 6;
    model
        .active
        .iter()
        .enumerate()
        .filter(|&(row, &i)| i < 6 * n_bodies && i % 6 == 3 && row < model.n_hydro)
        .filter_map(|(row, &i)| {
            let c = model.stiffness_linearized[(row, row)];
            let m = model.mass[(row, row)];
            (c > 0.0 && m > 0.0 && c.is_finite() && m.is_finite()).then(|| {
                let critical = 2.0 * (c * m).sqrt();
                RollRow {
                    vessel: i / 6,
                    row,
                    mode: i,
                    critical_damping: critical,
                    omega_n_rad_s: (c / m).sqrt(),
                    stiffness: c,
                    own_damping_fraction: model.damping[(row, row)] / critical,
                }
            })
        })
        .collect()
}

/// Each parameter's bounds for a roll row: `[(lo, hi); 3]` in [`RollTuning`]'s order.
pub fn bounds(row: &RollRow) -> [(f64, f64); 3] {
    [
        (
            DAMPING_FRACTION_BOUNDS.0.max(-row.own_damping_fraction),
            DAMPING_FRACTION_BOUNDS.1,
        ),
        QUADRATIC_FRACTION_BOUNDS,
        FREQUENCY_CORRECTION_BOUNDS,
    ]
}

/// The model changes a vessel's tuning stands for.
pub fn changes(rows: &[RollRow], tuning: &[RollTuning]) -> Vec<RowChange> {
    rows.iter()
        .zip(tuning)
        .map(|(r, t)| {
            let f = 1.0 + t.frequency_correction;
            RowChange {
                row: r.row,
                damping: t.damping_fraction * r.critical_damping,
                quadratic: t.quadratic_fraction * r.critical_damping / (r.omega_n_rad_s * PHI_REF_RAD),
                stiffness: (f * f - 1.0) * r.stiffness,
            }
        })
        .collect()
}
