//! Slow drift of the modes without restoring (pure).
//!
//! A mode with no restoring (surge, sway and yaw of a free vessel; the common surge, sway and yaw of two
//! hulls moored to each other) turns any error in its initial velocity into a displacement error growing
//! linearly over the whole forecast: the velocity noise of a motion sensor, 0.01 m/s, is 1.2 m at 120 s.
//! Linear (first-order) wave forces have zero mean, so the only secular motion of such a mode is its slow
//! drift, which the measured history knows far better than the last sample does. A forecast therefore
//! takes the drift of these modes from the history and the wave-frequency motion from the model:
//! - drift modes: the mass-orthonormal modes of (M + A_inf, C) (C with the lines and fenders linearized,
//!   symmetric part) whose natural frequency w_n makes w_n L < [`DRIFT_OMEGA_LENGTH`] for a forecast of
//!   length L (over the forecast they move within 10 % of a free mode);
//! - the drift velocity: the Hann-weighted mean of the measured velocity over the last
//!   [`DRIFT_WINDOW_S`] of history ([`slow_velocity`]; the window's sidelobes leave 1e-4 of a 9 s
//!   wave's velocity amplitude in it);
//! - the forecast of each drift mode keeps its displacement at t0 and its wave-frequency motion, and its
//!   mean velocity over the forecast (Hann-weighted) is set to the drift velocity's ([`apply`]).
//!
//! Units: SI; vectors over the model's active states (`TimeModel::active` order).

use nalgebra::DMatrix;

/// Largest w_n L for a mode to count as drift in a forecast of length L: sin(w L) / (w L) >= 0.9, a
/// velocity error moves it within 10 % of how it moves a free mode.
pub const DRIFT_OMEGA_LENGTH: f64 = 0.78;

/// Modes with a natural period below this are never drift (a cheap bound on what is kept), s.
pub const DRIFT_MIN_PERIOD_S: f64 = 100.0;

/// Measured history the drift velocity is averaged over, s: 13 periods of a 9 s sea.
pub const DRIFT_WINDOW_S: f64 = 120.0;

/// One mode without (much) restoring.
#[derive(Debug, Clone, PartialEq)]
pub struct DriftMode {
    /// Natural frequency, rad/s (0 for no restoring at all).
    pub omega_rad_s: f64,
    /// Mode shape phi over the active states, phi^T M phi = 1.
    pub shape: Vec<f64>,
    /// M phi: the modal coordinate of a state x is (M phi)^T x.
    pub mass_shape: Vec<f64>,
}

/// The modes of (M, C) with natural periods above [`DRIFT_MIN_PERIOD_S`]; M symmetric positive definite
/// (the model checks it), C's symmetric part taken.
pub fn drift_modes(mass: &DMatrix<f64>, stiffness: &DMatrix<f64>) -> Vec<DriftMode> {
    let n = mass.nrows();
    let Some(chol) = mass.clone().cholesky() else {
        return vec![];
    };
    let l = chol.l();
    let Some(l_inv) = l.clone().try_inverse() else {
        return vec![];
    };
    let c_sym = (stiffness + stiffness.transpose()) * 0.5;
    let s = &l_inv * c_sym * l_inv.transpose();
    let s = (&s + s.transpose()) * 0.5;
    let eig = s.symmetric_eigen();
    let omega_max = 2.0 * std::f64::consts::PI / DRIFT_MIN_PERIOD_S;
    let mut out = vec![];
    for j in 0..n {
        let lambda = eig.eigenvalues[j];
        if !lambda.is_finite() || lambda.abs() >= omega_max * omega_max {
            continue;
        }
        let phi = l_inv.transpose() * eig.eigenvectors.column(j);
        let m_phi = mass * &phi;
        out.push(DriftMode {
            omega_rad_s: lambda.abs().sqrt(),
            shape: phi.iter().copied().collect(),
            mass_shape: m_phi.iter().copied().collect(),
        });
    }
    out
}

/// Hann weights w_k = sin^2(pi (k + 1) / (n + 1)), k = 0..n-1: none zero, symmetric.
fn hann(n: usize) -> impl Iterator<Item = f64> {
    (0..n).map(move |k| (std::f64::consts::PI * (k + 1) as f64 / (n + 1) as f64).sin().powi(2))
}

/// The drift velocity: the Hann-weighted mean of the last `window_s` of velocities (`history` at step
/// `dt_s`, oldest first, `known` of them at its end measured, then `v0` at t0), or of as much as is
/// known when that is less (right after a start: the mean then holds some of the waves' velocity, less
/// than the last sample does). None with fewer than 3 samples.
pub fn slow_velocity(history: &[Vec<f64>], known: usize, v0: &[f64], dt_s: f64, window_s: f64) -> Option<Vec<f64>> {
    let want = (window_s / dt_s).round() as usize;
    let have = known.min(history.len()) + 1;
    if dt_s.is_nan() || dt_s <= 0.0 || have < 3 {
        return None;
    }
    let n = have.min(want);
    let tail = history[history.len() + 1 - n..]
        .iter()
        .map(|v| v.as_slice())
        .chain([v0]);
    let mut sum = vec![0.0; v0.len()];
    let mut wsum = 0.0;
    for (w, v) in hann(n).zip(tail) {
        for (s, x) in sum.iter_mut().zip(v) {
            *s += w * x;
        }
        wsum += w;
    }
    sum.iter_mut().for_each(|s| *s /= wsum);
    Some(sum)
}

/// Sets the mean velocity of every drift mode of a forecast (x, v over `n_modes` states per step,
/// `active` mapping active rows to states) to that of `drift_velocity`, keeping the displacement at
/// t0: x_k -= phi c t_k, v_k -= phi c with c the forecast's Hann-weighted mean modal velocity less the
/// drift's.
pub fn apply(
    modes: &[DriftMode],
    drift_velocity: &[f64],
    active: &[usize],
    n_modes: usize,
    dt_s: f64,
    x: &mut [f64],
    v: &mut [f64],
) {
    let steps = x.len() / n_modes.max(1);
    if steps < 3 {
        return;
    }
    let length_s = (steps - 1) as f64 * dt_s;
    for m in modes.iter().filter(|m| m.omega_rad_s * length_s < DRIFT_OMEGA_LENGTH) {
        let target: f64 = m.mass_shape.iter().zip(drift_velocity).map(|(a, b)| a * b).sum();
        let (mut mean, mut wsum) = (0.0, 0.0);
        for (k, w) in hann(steps).enumerate() {
            let q: f64 = m
                .mass_shape
                .iter()
                .zip(active)
                .map(|(a, &i)| a * v[k * n_modes + i])
                .sum();
            mean += w * q;
            wsum += w;
        }
        let c = mean / wsum - target;
        for k in 0..steps {
            let t = k as f64 * dt_s;
            for (p, &i) in m.shape.iter().zip(active) {
                x[k * n_modes + i] -= p * c * t;
                v[k * n_modes + i] -= p * c;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two masses joined by a spring, free as a pair: one drift mode (the common translation).
    fn pair() -> (DMatrix<f64>, DMatrix<f64>) {
        let m = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![2.0, 1.0]));
        let k = 5.0;
        let c = DMatrix::from_row_slice(2, 2, &[k, -k, -k, k]);
        (m, c)
    }

    #[test]
    fn the_common_translation_of_a_free_pair_is_its_one_drift_mode() {
        let (m, c) = pair();
        let modes = drift_modes(&m, &c);
        assert_eq!(modes.len(), 1);
        let d = &modes[0];
        assert!(d.omega_rad_s < 1e-6, "{}", d.omega_rad_s);
        assert!(
            (d.shape[0] - d.shape[1]).abs() < 1e-12 * d.shape[0].abs(),
            "{:?}",
            d.shape
        );
        // mass-normalized
        let norm: f64 = d.shape.iter().zip(&d.mass_shape).map(|(a, b)| a * b).sum();
        assert!((norm - 1.0).abs() < 1e-12);
        // with a spring to the earth nothing drifts
        let mut grounded = c.clone();
        grounded[(0, 0)] += 1.0;
        assert!(drift_modes(&m, &grounded).is_empty());
    }

    #[test]
    fn the_slow_velocity_is_the_mean_and_leaves_the_waves_out() {
        let dt = 0.1;
        let n = 2000;
        let w = 2.0 * std::f64::consts::PI / 9.0;
        let v = |k: usize| 0.3 + 0.7 * (w * k as f64 * dt + 0.4).cos();
        let history: Vec<Vec<f64>> = (0..n).map(|k| vec![v(k)]).collect();
        let got = slow_velocity(&history, n, &[v(n)], dt, DRIFT_WINDOW_S).unwrap()[0];
        // Hann sidelobes at 13 bins: well under 1e-3 of the 0.7 m/s wave velocity
        assert!((got - 0.3).abs() < 1e-3 * 0.7, "{got}");
        // what is known is used
        let short = slow_velocity(&history, 100, &[v(n)], dt, DRIFT_WINDOW_S).unwrap()[0];
        assert!((short - 0.3).abs() < 0.7, "{short}");
        assert!(slow_velocity(&history, 1, &[v(n)], dt, DRIFT_WINDOW_S).is_none());
    }

    #[test]
    fn a_forecast_keeps_its_start_and_waves_and_takes_the_drift_velocity() {
        let (m, c) = pair();
        let modes = drift_modes(&m, &c);
        let (dt, steps) = (0.1, 1201);
        let w = 1.0;
        // a forecast whose common mode drifts at 0.05 m/s (a noisy start) on top of an oscillation
        let (mut x, mut v) = (vec![0.0; 2 * steps], vec![0.0; 2 * steps]);
        for k in 0..steps {
            let t = k as f64 * dt;
            for i in 0..2 {
                x[2 * k + i] = 1.0 + 0.05 * t + 0.2 * (w * t).sin();
                v[2 * k + i] = 0.05 + 0.2 * w * (w * t).cos();
            }
        }
        apply(&modes, &[0.01, 0.01], &[0, 1], 2, dt, &mut x, &mut v);
        for i in 0..2 {
            assert!((x[i] - 1.0).abs() < 1e-12, "start kept");
            let t = (steps - 1) as f64 * dt;
            let want = 1.0 + 0.01 * t + 0.2 * (w * t).sin();
            assert!(
                (x[2 * (steps - 1) + i] - want).abs() < 0.01,
                "{} vs {want}",
                x[2 * (steps - 1) + i]
            );
        }
    }
}
