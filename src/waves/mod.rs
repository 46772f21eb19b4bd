//! Phase-resolved wave fields (pure): components in a vessel's frame ([`WaveComponent`]), the dispersion
//! relation, earth-frame fields ([`field`]), measured inputs turned into fields ([`observe`]: radar
//! grids, probe records), sea states and their realizations ([`sea`]), the predictable horizon
//! ([`horizon`]), the radar window's length ([`window`]).
//!
//! Conventions (DESIGN.md section 1): a component is eta(x, y, t) = Re{ a exp(i(w t - k (x cos b +
//! y sin b))) } with a complex (m), w > 0 the absolute frequency (rad/s), b the direction the wave travels
//! to, counterclockwise from the frame's +x axis (rad), k from the dispersion relation.

use num_complex::Complex64;

/// Standard gravity used when a system gives none, m/s^2.
pub const G_STANDARD_M_S2: f64 = 9.80665;

/// One regular wave component, in a vessel's seakeeping frame: `amplitude_m` is the complex amplitude of
/// the elevation at the frame's origin at the forecast's start time t0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WaveComponent {
    /// Absolute wave frequency, rad/s.
    pub omega_rad_s: f64,
    /// Direction of travel relative to the vessel's +x, counterclockwise, rad (pi = head seas).
    pub heading_rad: f64,
    /// Complex amplitude at the origin at t0, m.
    pub amplitude_m: Complex64,
}

/// Wave number k (rad/m) of frequency w (rad/s): deep water k = w^2 / g; finite depth h solves
/// w^2 = g k tanh(k h) by Newton's method from a Fenton-McKee start.
pub fn wave_number(omega_rad_s: f64, g_m_s2: f64, depth_m: Option<f64>) -> f64 {
    let k_deep = omega_rad_s * omega_rad_s / g_m_s2;
    let Some(h) = depth_m else { return k_deep };
    if !(h.is_finite() && h > 0.0) || k_deep * h > 20.0 {
        return k_deep;
    }
    // Fenton & McKee (1990) explicit approximation, then Newton
    let mut k = k_deep / (k_deep * h).powf(0.75).tanh().powf(2.0 / 3.0);
    for _ in 0..20 {
        let t = (k * h).tanh();
        let f = g_m_s2 * k * t - omega_rad_s * omega_rad_s;
        let df = g_m_s2 * (t + k * h * (1.0 - t * t));
        let dk = f / df;
        k -= dk;
        if dk.abs() < 1e-14 * k {
            break;
        }
    }
    k
}

/// Encounter frequency w_e = w - k U cos(b) of a component met by a vessel at speed U (m/s) along its +x;
/// b relative to the vessel's x axis. Negative when a following wave is overtaken.
pub fn encounter_frequency(omega_rad_s: f64, k_rad_m: f64, speed_m_s: f64, heading_rad: f64) -> f64 {
    omega_rad_s - k_rad_m * speed_m_s * heading_rad.cos()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dispersion_limits() {
        let w = 0.8;
        assert_eq!(wave_number(w, 9.81, None), w * w / 9.81);
        // deep enough depth gives the deep-water value
        assert!((wave_number(w, 9.81, Some(1000.0)) - w * w / 9.81).abs() < 1e-12);
        // shallow water: k h small, w ~ k sqrt(g h)
        let k = wave_number(0.05, 9.81, Some(10.0));
        assert!((0.05 / k - (9.81f64 * 10.0).sqrt()).abs() / (9.81f64 * 10.0).sqrt() < 1e-3);
        // the relation holds
        let k = wave_number(0.6, 9.81, Some(30.0));
        assert!((9.81 * k * (k * 30.0).tanh() - 0.36).abs() < 1e-12);
    }

    #[test]
    fn encounter_frequency_head_and_following() {
        let (w, k) = (0.6, 0.6 * 0.6 / 9.81);
        assert!(encounter_frequency(w, k, 5.0, std::f64::consts::PI) > w);
        assert!(encounter_frequency(w, k, 5.0, 0.0) < w);
        assert!((encounter_frequency(w, k, 5.0, std::f64::consts::FRAC_PI_2) - w).abs() < 1e-15);
    }
}

pub mod field;
pub mod horizon;
pub mod observe;
pub mod sea;
pub mod window;
