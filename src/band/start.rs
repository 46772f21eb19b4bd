//! The error of a forecast's start: a heel or the sensor's bias, and the start's band.

use super::*;

/// The variance of a heel (rad^2), from the running mean square `mean_square` of a DOF's measured mean
/// offset over `memory_s`, of which the sensor's drift (variance `held`, correlation `drift_time_s`)
/// explains `held`: what is left is heel, counted only beyond one standard error of that mean square
/// (held sqrt(drift_time_s / memory_s): a few draws of the drift are all `memory_s` holds; `memory_s`
/// taken as at least one `drift_time_s`, as one draw is), so that a large draw of the drift is not
/// taken for heel. Infinite (nothing known) where `memory_s` is not positive; 0 where `mean_square`
/// is not finite; a `held` or `drift_time_s` that is negative or not a number counts as 0.
pub fn heel_var(mean_square: f64, held: f64, drift_time_s: f64, memory_s: f64) -> f64 {
    if memory_s.is_nan() || memory_s <= 0.0 {
        return f64::INFINITY;
    }
    let held = held.max(0.0);
    let drift_time_s = drift_time_s.max(0.0);
    let se = held * (drift_time_s / memory_s.max(drift_time_s)).sqrt();
    let v = (mean_square - held - se).max(0.0);
    if v.is_finite() { v } else { 0.0 }
}

/// The expected error of a forecast's start and the variance of what is unknown of it, for a DOF whose
/// measured mean is `measured` (rad) off the model's and of which the forecast leaves `left` out as
/// the sensor's bias: the measured offset is heel H plus the sensor's bias average S, independent,
/// of variances `heel_var` (infinite: nothing known of it, all taken for heel) and `bias_var` (the
/// sensor's drift the average holds). The start errs by left - S (truth less forecast); given the
/// measured offset, S is normal about k measured with variance k heel_var, where k is bias_var over
/// (bias_var + heel_var). So (left - k measured, k heel_var); (left - measured, 0) where no heel is
/// known, and (left, bias_var) where nothing is.
pub fn heel_split(measured: f64, left: f64, bias_var: f64, heel_var: f64) -> (f64, f64) {
    let bias_var = bias_var.max(0.0);
    if !(measured.is_finite() && left.is_finite() && bias_var.is_finite()) || heel_var.is_nan() {
        return (0.0, 0.0);
    }
    if heel_var.is_infinite() {
        return (left, bias_var);
    }
    let sum = bias_var + heel_var.max(0.0);
    if sum <= 0.0 {
        return (left - measured, 0.0);
    }
    let k = bias_var / sum;
    (left - k * measured, k * heel_var.max(0.0))
}

/// The standard deviation of a 90 % band at a forecast's start whose error is `offset_m` (m or rad)
/// plus a normal error of variance `var`: such that |offset + N(0, var)| falls inside it
/// [`BAND_QUANTILE`] of the time (`var` alone: its own standard deviation).
pub fn start_sigma(offset: f64, var: f64) -> f64 {
    let (e, s) = (offset.abs(), var.max(0.0).sqrt());
    if !(e.is_finite() && s.is_finite()) {
        return f64::NAN;
    }
    if e == 0.0 {
        return s;
    }
    if s == 0.0 {
        return e / Z90;
    }
    let covered = |h: f64| normal_cdf((h - e) / s) - normal_cdf((-h - e) / s);
    let (_, hi) = bisect(0.0, e + 5.0 * s, 60, |h| covered(h) < BAND_QUANTILE);
    (hi / Z90).max(s)
}
