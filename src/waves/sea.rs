//! Sea states and their random-phase realizations (pure, reproducible from a seed).
//!
//! Spectra (one-sided, m^2 s/rad, w in rad/s): Pierson-Moskowitz in Hs/Tp form,
//!   S_PM(w) = 5/16 Hs^2 wp^4 w^-5 exp(-5/4 (wp/w)^4),
//! and JONSWAP, S_J = (1 - 0.287 ln gamma) S_PM gamma^exp(-(w - wp)^2 / (2 sigma^2 wp^2)), sigma = 0.07
//! below wp and 0.09 above (DNV-RP-C205 3.5.5). Directional spreading cos-2s: D(b) ~ cos^2s((b - b0)/2).
//! Discretization: equal-width frequency bins with one component at a random frequency inside each bin
//! (no common period, so the realization does not repeat), amplitude sqrt(2 S(w) dw), uniform random phase.

use super::WaveComponent;
use num_complex::Complex64;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::PI;

/// A sea state relative to a vessel (headings in its seakeeping frame).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SeaState {
    /// Significant wave height, m.
    pub hs_m: f64,
    /// Peak period, s.
    pub tp_s: f64,
    /// JONSWAP peak enhancement (1 = Pierson-Moskowitz).
    pub gamma: f64,
    /// Mean direction the waves travel to, relative to the vessel's +x, rad.
    pub heading_rad: f64,
    /// Directional spreading about the mean heading.
    pub spreading: Spreading,
    /// Number of components.
    pub components: usize,
    /// Frequency band, rad/s.
    pub omega_min_rad_s: f64,
    pub omega_max_rad_s: f64,
    /// Seed of the phases, frequencies and directions.
    pub seed: u64,
}

/// Directional spreading about a mean direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Spreading {
    LongCrested,
    /// cos^2s((theta - theta0) / 2) over the circle.
    Cos2s(f64),
    /// cos^2(theta - theta0) over |theta - theta0| < pi / 2.
    Cos2,
}

impl Spreading {
    /// Unnormalized weight of a direction offset `d` (rad) from the mean.
    pub fn weight(self, d: f64) -> f64 {
        let d = (d + PI).rem_euclid(2.0 * PI) - PI;
        match self {
            Spreading::LongCrested => {
                if d == 0.0 {
                    1.0
                } else {
                    0.0
                }
            }
            Spreading::Cos2s(s) => (0.5 * d).cos().abs().powf(2.0 * s),
            Spreading::Cos2 => {
                if d.abs() < 0.5 * PI {
                    d.cos().powi(2)
                } else {
                    0.0
                }
            }
        }
    }
}

/// JONSWAP (gamma = 1: Pierson-Moskowitz) spectral density at w, m^2 s/rad.
pub fn jonswap(hs_m: f64, tp_s: f64, gamma: f64, omega_rad_s: f64) -> f64 {
    if omega_rad_s <= 0.0 {
        return 0.0;
    }
    let wp = 2.0 * PI / tp_s;
    let pm = 5.0 / 16.0 * hs_m * hs_m * wp.powi(4) * omega_rad_s.powi(-5) * (-1.25 * (wp / omega_rad_s).powi(4)).exp();
    if gamma == 1.0 {
        return pm;
    }
    let sigma = if omega_rad_s <= wp { 0.07 } else { 0.09 };
    let r = (-(omega_rad_s - wp).powi(2) / (2.0 * sigma * sigma * wp * wp)).exp();
    (1.0 - 0.287 * gamma.ln()) * pm * gamma.powf(r)
}

/// Checks a sea state; the message names the field.
pub fn validate(sea: &SeaState) -> Result<(), String> {
    let pos = |v: f64, name: &str| {
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            Err(format!("{name} must be positive, found {v}"))
        }
    };
    pos(sea.hs_m, "hs_m")?;
    pos(sea.tp_s, "tp_s")?;
    pos(sea.gamma, "gamma")?;
    pos(sea.omega_min_rad_s, "omega_min_rad_s")?;
    if sea.omega_max_rad_s.is_nan() || sea.omega_max_rad_s <= sea.omega_min_rad_s {
        return Err("omega_max_rad_s must exceed omega_min_rad_s".into());
    }
    if sea.components == 0 || sea.components > 100_000 {
        return Err(format!("components must be in 1..=100000, found {}", sea.components));
    }
    if !sea.heading_rad.is_finite() {
        return Err("heading must be finite".into());
    }
    if let Spreading::Cos2s(s) = sea.spreading {
        pos(s, "spreading_s")?;
    }
    Ok(())
}

/// Several sea states superposed (swell + wind sea): their realizations concatenated.
pub fn realize_all(seas: &[SeaState]) -> Vec<WaveComponent> {
    seas.iter().flat_map(realize).collect()
}

/// A random-phase realization: amplitudes at the origin at t = 0. Frequencies are drawn at random
/// within equal bins (no common period: a realization does not repeat), directions from the
/// spreading function by rejection, phases uniform; all from `seed` (reproducible).
pub fn realize(sea: &SeaState) -> Vec<WaveComponent> {
    let mut rng = ChaCha8Rng::seed_from_u64(sea.seed);
    let n = sea.components;
    let dw = (sea.omega_max_rad_s - sea.omega_min_rad_s) / n as f64;
    (0..n)
        .map(|k| {
            let w = sea.omega_min_rad_s + (k as f64 + rng.random::<f64>()) * dw;
            let amp = (2.0 * jonswap(sea.hs_m, sea.tp_s, sea.gamma, w) * dw).sqrt();
            let phase = 2.0 * PI * rng.random::<f64>();
            let dir = match sea.spreading {
                Spreading::LongCrested => sea.heading_rad,
                s => {
                    // rejection sampling of the spreading function on (-pi, pi] (its peak weight is 1)
                    loop {
                        let d = PI * (2.0 * rng.random::<f64>() - 1.0);
                        if rng.random::<f64>() <= s.weight(d) {
                            break sea.heading_rad + d;
                        }
                    }
                }
            };
            WaveComponent {
                omega_rad_s: w,
                heading_rad: dir,
                amplitude_m: Complex64::from_polar(amp, phase),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spectrum_integrates_to_hs() {
        // m0 = Hs^2 / 16 for PM and (nearly, DNV's normalization) JONSWAP
        for gamma in [1.0, 3.3] {
            let dw = 1e-4;
            let m0: f64 = (1..40000).map(|k| jonswap(2.5, 9.0, gamma, k as f64 * dw) * dw).sum();
            assert!((m0 - 2.5f64.powi(2) / 16.0).abs() < 0.02 * m0, "gamma {gamma}: m0 {m0}");
        }
    }

    #[test]
    fn realization_is_reproducible_and_has_the_variance() {
        let sea = SeaState {
            hs_m: 2.0,
            tp_s: 8.0,
            gamma: 3.3,
            heading_rad: PI,
            spreading: Spreading::Cos2s(10.0),
            components: 2000,
            omega_min_rad_s: 0.2,
            omega_max_rad_s: 3.0,
            seed: 7,
        };
        let a = realize(&sea);
        assert_eq!(a, realize(&sea));
        let var: f64 = a.iter().map(|c| 0.5 * c.amplitude_m.norm_sqr()).sum();
        assert!((var - 0.25).abs() < 0.02 * 0.25, "variance {var}");
    }

    #[test]
    fn cos2_spreading_stays_within_90_degrees_and_swell_adds_up() {
        let wind = SeaState {
            hs_m: 2.0,
            tp_s: 8.0,
            gamma: 3.3,
            heading_rad: 0.5,
            spreading: Spreading::Cos2,
            components: 500,
            omega_min_rad_s: 0.2,
            omega_max_rad_s: 3.0,
            seed: 1,
        };
        let a = realize(&wind);
        assert!(a.iter().all(|c| (c.heading_rad - 0.5).abs() < 0.5 * PI));
        let swell = SeaState {
            hs_m: 1.0,
            tp_s: 14.0,
            gamma: 1.0,
            spreading: Spreading::LongCrested,
            omega_min_rad_s: 0.2,
            omega_max_rad_s: 1.0,
            ..wind
        };
        let both = realize_all(&[wind, swell]);
        assert_eq!(both.len(), 1000);
        let var: f64 = both.iter().map(|c| 0.5 * c.amplitude_m.norm_sqr()).sum();
        // m0 = (Hs1^2 + Hs2^2) / 16, within the finite bands
        assert!((var - (4.0 + 1.0) / 16.0).abs() < 0.04 * var, "{var}");
        assert_eq!(Spreading::Cos2.weight(0.6 * PI), 0.0);
        assert!((Spreading::Cos2s(2.0).weight(0.0) - 1.0).abs() < 1e-15);
    }
}
