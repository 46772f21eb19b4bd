//! How many radar scans the inversion's window holds (pure): enough that the water inside the radar's
//! blind zone now was outside it, and seen, at the window's oldest scan.
//!
//! Water travels with the groups: the wave energy that reaches a vessel at the blind zone's centre at
//! lead 0 crossed the zone's edge `inner_m / c_g` earlier. The slowest groups that matter are those of
//! the highest frequency below which all but [`crate::waves::horizon::UNKNOWN_FRACTION`] of the field's
//! variance lies, so a window of `inner_m / c_g(w_slow)` seconds saw all but that share of the water the
//! next seconds bring. The window is fitted by least squares over its scans (`observe::from_scans`),
//! which also sharpens the dispersion filter: the longer the window, the less of the blind zone's and
//! the shadows' leakage passes as waves.
//!
//! Frames and units: earth frame, m, s, rad/s (DESIGN.md section 1).

use super::field::{Region, WaveField, group_velocity};
use super::horizon::UNKNOWN_FRACTION;

/// The window's length in crossings of the blind zone at the slowest group speed that matters. One
/// crossing has seen the water the blind zone holds; more resolve the blind zone's own leakage (a hole
/// of radius R spreads each wave's energy over wavenumbers +-pi / R around its own, frequencies
/// +-c_g pi / R off the dispersion shell, which a least-squares fit over 2 R / c_g tells from the
/// wave), but fit each wavenumber bin's frequency (the grid's, not the wave's: a 2 km map's bins are
/// 0.003 rad/m apart) over longer and carry the bin's frequency error further. The one-ship demo
/// (900 s, docs/skill.md) put the balance here: one crossing, heave correlation 0.95 at 15 s lead
/// and 0.96 at 60 s; two, 0.96 and 0.88; one and a half, 0.96 and 0.92.
pub const WINDOW_CROSSINGS: f64 = 1.5;

/// The fewest scans a window is inverted from: two tell opposite directions apart, a third keeps the
/// separation well conditioned over most of the band (`observe::SEPARATION_FLOOR`).
pub const MIN_WINDOW_SCANS: usize = 3;

/// The scans, `period_s` apart, a window needs to have seen the water in `field`'s blind zone (its
/// region's `inner_m`; none: [`MIN_WINDOW_SCANS`]), at least [`MIN_WINDOW_SCANS`] and at most
/// `max_scans` (which wins when smaller). A field without waves or a period that is not a positive
/// number asks for `max_scans`.
pub fn window_scans(field: &WaveField, period_s: f64, max_scans: usize) -> usize {
    let inner_m = match field.region {
        Region::Coverage { inner_m, .. } if inner_m.is_finite() => inner_m.max(0.0),
        _ => 0.0,
    };
    let bounded = |n: usize| n.max(MIN_WINDOW_SCANS).min(max_scans);
    if inner_m == 0.0 {
        return bounded(MIN_WINDOW_SCANS);
    }
    let Some(omega_slow) = slow_frequency(field) else {
        return max_scans;
    };
    if !(period_s.is_finite() && period_s > 0.0) {
        return max_scans;
    }
    let cg = group_velocity(omega_slow, field.g_m_s2, field.depth_m);
    let window_s = WINDOW_CROSSINGS * inner_m / cg;
    let n = (window_s / period_s).ceil();
    if !n.is_finite() || n >= max_scans as f64 {
        return max_scans;
    }
    bounded(n as usize + 1)
}

/// The frequency below which all but [`UNKNOWN_FRACTION`] of the field's variance lies (None: no
/// variance).
fn slow_frequency(field: &WaveField) -> Option<f64> {
    let mut parts: Vec<(f64, f64)> = field
        .components
        .iter()
        .map(|c| (c.omega_rad_s, c.amplitude_m.norm_sqr()))
        .filter(|(w, v)| w.is_finite() && *w > 0.0 && v.is_finite())
        .collect();
    let total: f64 = parts.iter().map(|p| p.1).sum();
    if !(total > 0.0 && total.is_finite()) {
        return None;
    }
    parts.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut acc = 0.0;
    for (w, v) in &parts {
        acc += v;
        if acc >= (1.0 - UNKNOWN_FRACTION) * total {
            return Some(*w);
        }
    }
    parts.last().map(|p| p.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::waves::field::{COVERAGE_SECTORS, FieldComponent};
    use num_complex::Complex64;

    fn field(inner_m: f64, omegas: &[f64]) -> WaveField {
        WaveField {
            components: omegas
                .iter()
                .map(|w| FieldComponent {
                    omega_rad_s: *w,
                    direction_rad: 0.0,
                    amplitude_m: Complex64::new(0.5, 0.0),
                })
                .collect(),
            reference_m: [0.0, 0.0],
            time_s: 0.0,
            g_m_s2: 9.81,
            depth_m: None,
            region: Region::Coverage {
                centre_m: [0.0, 0.0],
                inner_m,
                ranges_m: [1000.0; COVERAGE_SECTORS],
                window_s: 0.0,
            },
        }
    }

    #[test]
    fn the_window_spans_the_blind_zone_at_the_slowest_group_that_matters() {
        // one frequency, 0.7 rad/s: c_g = 9.81 / 1.4 = 7.0 m/s, 200 m in 28.5 s, 1.5 crossings in
        // 42.8 s: 22 scans 2 s apart and the newest
        let cg = 9.81 / 1.4;
        let n = window_scans(&field(200.0, &[0.7]), 2.0, 64);
        assert_eq!(n, (WINDOW_CROSSINGS * 200.0 / cg / 2.0f64).ceil() as usize + 1);
        assert_eq!(n, 23);
        // slower groups need a longer window; a larger blind zone too
        assert!(window_scans(&field(200.0, &[1.2]), 2.0, 64) > n);
        assert!(window_scans(&field(400.0, &[0.7]), 2.0, 64) > n);
        // the cap wins; no blind zone needs no more than the fewest
        assert_eq!(window_scans(&field(200.0, &[1.2]), 2.0, 8), 8);
        assert_eq!(window_scans(&field(0.0, &[0.7]), 2.0, 64), MIN_WINDOW_SCANS);
        assert_eq!(window_scans(&field(0.0, &[0.7]), 2.0, 2), 2);
    }

    #[test]
    fn a_field_without_waves_or_a_period_asks_for_the_most() {
        assert_eq!(window_scans(&field(200.0, &[]), 2.0, 40), 40);
        assert_eq!(window_scans(&field(200.0, &[0.7]), 0.0, 40), 40);
        assert_eq!(window_scans(&field(200.0, &[0.7]), f64::NAN, 40), 40);
    }
}
