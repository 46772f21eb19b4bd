//! What a coupled vessel's unknown start adds to the others' band (pure).
//!
//! Conventions (DESIGN.md section 1): series are 6 per vessel (surge, sway, heave in m; roll, pitch,
//! yaw in rad), each `steps + 1` values of lead, series-major.
//!
//! A vessel whose motion is missing (the other ship's, when the link is down) is started from rest at
//! the model's mean: its start errs by its whole motion. Through the lines, fenders and the water
//! between the hulls that error reaches the vessels coupled to it, as the model's free response to it.
//! The model is run, with no waves, after each of the vessel's rows has moved as a sinusoid at the
//! sea's mean frequency with that row's motion's standard deviation, in two phases (at t0 displaced
//! and still; at the mean and moving), its radiation memory holding that past ([`free_responses`]):
//! the start and the history the forecast lacks, at the motion's own size, so that fenders that only
//! touch in waves answer as they do. The response less the run from rest is what that row's unknown
//! motion does to every series; for a motion of random phase the variance is the sum of the two
//! phases' squares, and the band of the others holds its sum over the rows ([`coupled_var`]; the
//! rows taken as independent). The runs are kept while the motion's
//! size stays within [`PROBE_TOLERANCE`] of theirs ([`CouplingResponse::serves`]).

use crate::radiation::history::Memory;
use crate::rom::{ForecastRequest, Forecaster, TimeModel};

/// A response made with start errors within this factor of the ones wanted serves.
pub const PROBE_TOLERANCE: f64 = 1.25;

/// The free response of every series to one vessel's start errors, row by row.
#[derive(Debug, Clone, PartialEq)]
pub struct CouplingResponse {
    /// The vessel whose start errs.
    pub vessel: usize,
    /// The displacement error per DOF of the vessel's (m, rad) and the velocity error's frequency
    /// (rad/s) the runs were made with.
    pub probe: [f64; 6],
    pub omega_rad_s: f64,
    /// Per row of the vessel's moving: the response to its past motion in the two phases (displaced,
    /// moving at t0), series-major (`6 * n_bodies` series of `steps + 1`).
    pub rows: Vec<(Vec<f64>, Vec<f64>)>,
    pub steps: usize,
}

impl CouplingResponse {
    /// Whether these runs serve start errors `probe` at `omega_rad_s` over `steps`: each within
    /// [`PROBE_TOLERANCE`] (both below the floor of [`significant`]: the same).
    pub fn serves(&self, probe: &[f64; 6], omega_rad_s: f64, steps: usize) -> bool {
        let near =
            |a: f64, b: f64| (a <= 0.0 && b <= 0.0) || (a > 0.0 && b > 0.0 && (a / b).max(b / a) <= PROBE_TOLERANCE);
        self.steps == steps && near(self.omega_rad_s, omega_rad_s) && (0..6).all(|d| near(self.probe[d], probe[d]))
    }
}

/// The start errors of vessel `vessel`'s rows: the motion's standard deviation per DOF from
/// `motion_sigma` (per series), 0 where it is below [`super::SIGNIFICANT_DOF`] (nothing to carry).
pub fn significant(motion_sigma: &[f64], vessel: usize) -> [f64; 6] {
    std::array::from_fn(|d| {
        let s = motion_sigma.get(6 * vessel + d).copied().unwrap_or(0.0);
        if s.is_finite() && s >= super::SIGNIFICANT_DOF[d] {
            s
        } else {
            0.0
        }
    })
}

/// Vessel `vessel`'s [`CouplingResponse`] over `length_s` to its rows' past motion of amplitude
/// `probe` at `omega_rad_s` (two phases), from `model` with `history` velocity rows of memory.
#[allow(clippy::too_many_arguments)]
pub fn free_responses(
    model: &TimeModel,
    fc: &mut Forecaster,
    vessel: usize,
    n_bodies: usize,
    length_s: f64,
    history: usize,
    probe: [f64; 6],
    omega_rad_s: f64,
) -> crate::rom::Result<CouplingResponse> {
    let n = model.n();
    let dt = model.opts.dt_s;
    // the memory of a row that has moved as cos(w t + phase) x `amplitude` (velocity) up to t0
    let memory = |moving: Option<(usize, f64, f64)>| -> crate::rom::Result<Memory> {
        let velocities: Vec<Vec<f64>> = (0..history)
            .map(|m| {
                let t = -((history - 1 - m) as f64) * dt;
                let mut v = vec![0.0; n];
                if let Some((row, amplitude, phase)) = moving {
                    v[row] = amplitude * (omega_rad_s * t + phase).cos();
                }
                v
            })
            .collect();
        Memory::from_history(model, &velocities)
    };
    let mut run = |x0: &[f64], v0: &[f64], memory: &Memory| -> crate::rom::Result<(usize, Vec<f64>)> {
        let req = ForecastRequest {
            x0,
            v0,
            memory,
            waves: &[],
            length_s,
            ramp_s: 0.0,
            drift_velocity: None,
            track: None,
        };
        let f = fc.forecast(model, &req)?;
        let mut out = Vec::with_capacity(6 * n_bodies * (f.steps + 1));
        for i in 0..6 * n_bodies {
            out.extend((0..=f.steps).map(|k| f.at(k, i)));
        }
        Ok((f.steps, out))
    };
    let zero = vec![0.0; n];
    let (steps, rest) = run(&zero, &zero, &memory(None)?)?;
    let less_rest = |r: Vec<f64>| -> Vec<f64> { r.iter().zip(&rest).map(|(a, b)| a - b).collect() };
    let mut rows = vec![];
    for (row, &i) in model.active.iter().enumerate() {
        let d = i % 6;
        if i / 6 != vessel || i >= 6 * n_bodies || probe[d] <= 0.0 {
            continue;
        }
        let speed = probe[d] * omega_rad_s;
        // x = probe cos(w t): at t0 displaced, still
        let mut x0 = zero.clone();
        x0[row] = probe[d];
        let (_, displaced) = run(&x0, &zero, &memory(Some((row, speed, std::f64::consts::FRAC_PI_2)))?)?;
        // x = probe sin(w t): at t0 at the mean, moving
        let mut v0 = zero.clone();
        v0[row] = speed;
        let (_, moving) = run(&zero, &v0, &memory(Some((row, speed, 0.0)))?)?;
        rows.push((less_rest(displaced), less_rest(moving)));
    }
    Ok(CouplingResponse {
        vessel,
        probe,
        omega_rad_s,
        rows,
        steps,
    })
}

/// The variance the unknown starts of `responses`' vessels add to every series at every lead
/// (series-major, `6 * n_bodies` of `steps + 1`; 0 for the unknown vessels' own series, whose band
/// holds their whole motion).
pub fn coupled_var(responses: &[&CouplingResponse], n_bodies: usize, steps: usize) -> Vec<f64> {
    let n = steps + 1;
    let mut var = vec![0.0; 6 * n_bodies * n];
    for r in responses.iter().filter(|r| r.steps == steps) {
        for (displaced, moving) in &r.rows {
            for i in (0..6 * n_bodies).filter(|i| i / 6 != r.vessel) {
                for k in 0..n {
                    let j = i * n + k;
                    var[j] += displaced[j].powi(2) + moving[j].powi(2);
                }
            }
        }
    }
    for r in responses {
        for i in 6 * r.vessel..(6 * r.vessel + 6).min(6 * n_bodies) {
            var[i * n..(i + 1) * n].iter_mut().for_each(|v| *v = 0.0);
        }
    }
    var.iter_mut().filter(|v| !v.is_finite()).for_each(|v| *v = 0.0);
    var
}

/// The waves' mean frequency, weighted by each component's variance (rad/s; 0 without waves).
pub fn mean_omega_rad_s(waves: &[crate::waves::WaveComponent]) -> f64 {
    let (mut sum, mut weight) = (0.0, 0.0);
    for w in waves {
        let v = w.amplitude_m.norm_sqr();
        sum += w.omega_rad_s * v;
        weight += v;
    }
    if weight > 0.0 { sum / weight } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_coupled_variance_spares_the_unknown_vessel_and_adds_the_rows_squares() {
        let n = 3;
        let mut displaced = vec![0.0; 12 * n];
        let mut moving = vec![0.0; 12 * n];
        // vessel 0's heave (series 2) answers vessel 1's roll error
        displaced[2 * n + 1] = 0.05;
        moving[2 * n + 1] = 0.01;
        displaced[(6 + 3) * n + 1] = 0.1;
        let r = CouplingResponse {
            vessel: 1,
            probe: [0.0, 0.0, 0.0, 0.1, 0.0, 0.0],
            omega_rad_s: 0.5,
            rows: vec![(displaced, moving)],
            steps: n - 1,
        };
        let v = coupled_var(&[&r], 2, n - 1);
        let want = 0.05f64.powi(2) + 0.01f64.powi(2);
        assert!((v[2 * n + 1] - want).abs() < 1e-15, "{}", v[2 * n + 1]);
        assert_eq!(v[(6 + 3) * n + 1], 0.0, "the unknown vessel's own series");
        assert_eq!(v.iter().filter(|x| **x != 0.0).count(), 1);
        assert!(r.serves(&[0.0, 0.0, 0.0, 0.11, 0.0, 0.0], 0.55, n - 1));
        assert!(!r.serves(&[0.0, 0.0, 0.0, 0.2, 0.0, 0.0], 0.5, n - 1));
        assert!(!r.serves(&[0.0, 0.0, 0.01, 0.1, 0.0, 0.0], 0.5, n - 1));
    }
}
