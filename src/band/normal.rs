//! The normal distribution's tails: its cumulative probability, a band's exceedance and half-width.

/// The bracket [lo, hi] around where `below` turns false, halved `steps` times (`below` true at lo,
/// false at hi: an increasing function under its target).
pub(super) fn bisect(mut lo: f64, mut hi: f64, steps: usize, below: impl Fn(f64) -> bool) -> (f64, f64) {
    for _ in 0..steps {
        let mid = 0.5 * (lo + hi);
        if below(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    (lo, hi)
}

/// The standard normal distribution's cumulative probability.
pub fn normal_cdf(z: f64) -> f64 {
    0.5 * libm::erfc(-z / std::f64::consts::SQRT_2)
}

/// The probability that a normal variable of mean `mean` and standard deviation `sigma` lies outside
/// [-limit, limit] (0 or 1 for sigma 0).
pub fn exceedance(mean: f64, sigma: f64, limit: f64) -> f64 {
    if sigma.is_nan() || sigma <= 0.0 {
        return if mean.abs() > limit { 1.0 } else { 0.0 };
    }
    normal_cdf((-limit - mean) / sigma) + normal_cdf((mean - limit) / sigma)
}

/// The half-width of a two-sided band holding `probability` of a normal variable, in standard
/// deviations (1.645 for 0.9), by bisection on [`normal_cdf`].
pub fn band_z(probability: f64) -> f64 {
    let target = 0.5 + 0.5 * probability.clamp(0.0, 1.0 - 1e-12);
    let (lo, hi) = bisect(0.0, 10.0, 80, |z| normal_cdf(z) < target);
    0.5 * (lo + hi)
}
