//! The time-domain floor (pure): the frequency-domain response of a time-domain model's own A(w) and
//! B(w) (those its radiation memory implies, with its A_inf), which a time-domain run converges to as
//! dt -> 0, and how far it is from the database's frequency domain.
//!
//! A database whose A(w), B(w) and A_inf are not Kramers-Kronig consistent cannot be matched exactly by
//! any causal time-domain model: the floor shows by how much, per radiation method, in RAO terms.
//!
//! Conventions: RAO tables are indexed `[heading][frequency][state]` (6N body modes then the tanks,
//! inactive states zero), exp(+i w t), per metre of wave amplitude (DESIGN.md section 1).
//!
//! The metric (the validation's and the integration tests'): for each (state, heading) curve, the worst
//! |test - reference| over the frequencies divided by that curve's reference peak; a curve whose peak is
//! below [`SMALL_CURVE`] of the same state's largest peak over every heading (it vanishes by symmetry,
//! like pitch in beam seas) is divided by that largest peak instead.

use super::{Result, TimeModel};
use num_complex::Complex64;

/// RAO of every state at every (heading, frequency): `table[heading][omega][state]`.
pub type RaoTable = Vec<Vec<Vec<Complex64>>>;

/// A curve whose peak is below this fraction of its state's largest peak is judged against that
/// largest peak (its own is round-off or mesh asymmetry: 1e-3 for pitch in beam seas on the ship demo).
pub const SMALL_CURVE: f64 = 0.1;

/// Where two RAO tables differ most, by the module's metric.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurveError {
    /// |test - reference| / the curve's scale.
    pub fraction: f64,
    /// Global state index (0-based).
    pub state: usize,
    /// Indices into the tables' headings and frequencies.
    pub heading: usize,
    pub omega: usize,
}

/// The worst difference of `test` against `reference` (same shape) by the module's metric; `None`
/// when every reference curve is zero (or the tables are empty or of different shapes).
pub fn worst_curve_error(test: &RaoTable, reference: &RaoTable) -> Option<CurveError> {
    let same_shape = test.len() == reference.len()
        && test
            .iter()
            .zip(reference)
            .all(|(a, b)| a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.len() == y.len()));
    if !same_shape {
        return None;
    }
    let states = reference.first()?.first()?.len();
    // curve_peak[h][s], and each state's largest over the headings
    let curve_peak: Vec<Vec<f64>> = reference
        .iter()
        .map(|rows| {
            (0..states)
                .map(|s| rows.iter().map(|row| row[s].norm()).fold(0.0, f64::max))
                .collect()
        })
        .collect();
    let state_peak: Vec<f64> = (0..states)
        .map(|s| curve_peak.iter().map(|p| p[s]).fold(0.0, f64::max))
        .collect();
    let mut worst: Option<CurveError> = None;
    for (h, rows) in reference.iter().enumerate() {
        for s in 0..states {
            let peak = curve_peak[h][s];
            let scale = if peak >= SMALL_CURVE * state_peak[s] {
                peak
            } else {
                state_peak[s]
            };
            if scale.is_nan() || scale <= 0.0 {
                continue;
            }
            for (k, row) in rows.iter().enumerate() {
                let fraction = (test[h][k][s] - row[s]).norm() / scale;
                if worst.is_none_or(|w| fraction > w.fraction) {
                    worst = Some(CurveError {
                        fraction,
                        state: s,
                        heading: h,
                        omega: k,
                    });
                }
            }
        }
    }
    worst
}

/// The floor of `model`: its implied RAO ([`TimeModel::implied_rao_with`]) at every heading and
/// frequency, the kernels computed once for every heading.
pub fn implied_table(model: &TimeModel, omegas_rad_s: &[f64], headings_rad: &[f64]) -> Result<RaoTable> {
    let kernels = model.kernels_at(omegas_rad_s);
    headings_rad
        .iter()
        .map(|&h| {
            omegas_rad_s
                .iter()
                .zip(&kernels)
                .map(|(&w, k)| {
                    model.implied_rao_with(k, w, h).map_err(|e| {
                        super::Error::Input(format!("omega {w} rad/s, heading {} deg: {e}", h.to_degrees()))
                    })
                })
                .collect()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(f: impl Fn(usize, usize, usize) -> f64) -> RaoTable {
        (0..2)
            .map(|h| {
                (0..3)
                    .map(|k| (0..2).map(|s| Complex64::new(f(h, k, s), 0.0)).collect())
                    .collect()
            })
            .collect()
    }

    #[test]
    fn the_error_is_relative_to_the_curve_peak_or_the_state_peak_for_a_small_curve() {
        // state 0: heading 0 peaks at 2, heading 1 at 1 (not small); state 1: heading 1 peaks at
        // 0.01 (small: below 0.1 of its state's peak 1)
        let reference = table(|h, k, s| match (h, s) {
            (0, 0) => [1.0, 2.0, 1.0][k],
            (1, 0) => [0.5, 1.0, 0.5][k],
            (0, 1) => 1.0,
            _ => 0.01,
        });
        // 0.1 off at (heading 1, omega 2, state 0): 0.1 / 1 = 10 %
        let test = table(|h, k, s| reference[h][k][s].re + if (h, k, s) == (1, 2, 0) { 0.1 } else { 0.0 });
        let e = worst_curve_error(&test, &reference).unwrap();
        assert_eq!((e.state, e.heading, e.omega), (0, 1, 2));
        assert!((e.fraction - 0.1).abs() < 1e-12, "{e:?}");
        // 0.005 off on the small curve: against its state's peak 1 (0.5 %), not its own 0.01 (50 %)
        let test = table(|h, k, s| reference[h][k][s].re + if (h, k, s) == (1, 0, 1) { 0.005 } else { 0.0 });
        let e = worst_curve_error(&test, &reference).unwrap();
        assert_eq!((e.state, e.heading, e.omega), (1, 1, 0));
        assert!((e.fraction - 0.005).abs() < 1e-12, "{e:?}");
    }

    #[test]
    fn tables_of_different_shapes_or_all_zero_give_no_error() {
        let a = table(|_, _, _| 1.0);
        let mut b = a.clone();
        b[1].pop();
        assert!(worst_curve_error(&a, &b).is_none());
        let z = table(|_, _, _| 0.0);
        assert!(worst_curve_error(&a, &z).is_none());
        assert_eq!(worst_curve_error(&a, &a).map(|e| e.fraction), Some(0.0));
    }
}
