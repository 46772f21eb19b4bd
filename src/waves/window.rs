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
//! A map that re-centres on a moving ship keeps its window: an older scan on the same lattice (the
//! same spacing and orientation, origins a whole number of cells apart) is moved onto the new grid
//! ([`regrid`]).
//!
//! Frames and units: earth frame, m, s, rad/s (DESIGN.md section 1).

use super::field::{Region, WaveField, group_velocity};
use super::horizon::UNKNOWN_FRACTION;
use super::observe::{Grid, GridFrame};

/// How far from a whole number of cells two grids' offset may be and still be one lattice, in cells.
const LATTICE_TOLERANCE_CELLS: f64 = 1e-3;

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

/// An older scan moved onto another grid of the same lattice, so that a window of scans survives a map
/// that re-centres on a moving ship: `old` (in `old_frame`) on the cells `x_m` x `y_m` of `frame`, NaN
/// where it did not reach. None when the two are not one lattice: another orientation, another
/// spacing, or origins not a whole number of cells apart.
pub fn regrid(old: &Grid, old_frame: GridFrame, x_m: &[f64], y_m: &[f64], frame: GridFrame) -> Option<Grid> {
    let spacing = |v: &[f64]| (v.len() >= 2).then(|| (v[v.len() - 1] - v[0]) / (v.len() - 1) as f64);
    let (dx, dy) = (spacing(x_m)?, spacing(y_m)?);
    let same = |a: Option<f64>, b: f64| a.is_some_and(|a| (a - b).abs() <= LATTICE_TOLERANCE_CELLS * b.abs());
    if !(same(spacing(&old.x_m), dx) && same(spacing(&old.y_m), dy))
        || (old_frame.orientation_rad - frame.orientation_rad).abs() > 1e-9
        || old.values.len() != old.x_m.len() * old.y_m.len()
    {
        return None;
    }
    // the old grid's first cell in the new grid's axes, in cells
    let p = old_frame.to_earth(old.x_m[0], old.y_m[0]);
    let q = frame.to_earth(x_m[0], y_m[0]);
    let (s, c) = frame.orientation_rad.sin_cos();
    let (ex, ey) = (p[0] - q[0], p[1] - q[1]);
    let (sx, sy) = ((c * ex + s * ey) / dx, (-s * ex + c * ey) / dy);
    if (sx - sx.round()).abs() > LATTICE_TOLERANCE_CELLS || (sy - sy.round()).abs() > LATTICE_TOLERANCE_CELLS {
        return None;
    }
    let (sx, sy) = (sx.round() as i64, sy.round() as i64);
    let (onx, ony) = (old.x_m.len() as i64, old.y_m.len() as i64);
    let mut values = Vec::with_capacity(x_m.len() * y_m.len());
    for iy in 0..y_m.len() as i64 {
        for ix in 0..x_m.len() as i64 {
            let (ox, oy) = (ix - sx, iy - sy);
            values.push(if (0..onx).contains(&ox) && (0..ony).contains(&oy) {
                old.values[(oy * onx + ox) as usize]
            } else {
                f64::NAN
            });
        }
    }
    Some(Grid {
        x_m: x_m.to_vec(),
        y_m: y_m.to_vec(),
        time_s: old.time_s,
        values,
    })
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
    fn a_scan_moves_onto_a_grid_of_its_lattice_and_not_onto_another() {
        let grid = |x0: f64, y0: f64| Grid {
            x_m: (0..4).map(|i| x0 + 10.0 * i as f64).collect(),
            y_m: (0..3).map(|i| y0 + 10.0 * i as f64).collect(),
            time_s: 5.0,
            values: (0..12).map(|i| i as f64).collect(),
        };
        let at = |x: f64, y: f64, turn: f64| GridFrame {
            origin_m: [x, y],
            orientation_rad: turn,
        };
        let old = grid(0.0, 0.0);
        // the map moved one cell east and one north: the old cell (1, 1) is the new (0, 0)
        let new = grid(0.0, 0.0);
        let moved = regrid(&old, at(100.0, 50.0, 0.0), &new.x_m, &new.y_m, at(110.0, 60.0, 0.0)).unwrap();
        assert_eq!(moved.time_s, 5.0);
        assert_eq!(moved.values[0], old.values[4 + 1]);
        assert_eq!(moved.values[4 + 2], old.values[2 * 4 + 3]);
        // what the old grid did not reach is not seen
        assert!(moved.values[3].is_nan() && moved.values[2 * 4].is_nan());
        // the same map, offset in its own coordinates instead of its frame
        let same = regrid(
            &grid(-10.0, -10.0),
            at(110.0, 60.0, 0.0),
            &new.x_m,
            &new.y_m,
            at(110.0, 60.0, 0.0),
        )
        .unwrap();
        assert_eq!(same.values[0], old.values[4 + 1]);
        // half a cell apart, turned, or another spacing: another lattice
        assert!(regrid(&old, at(105.0, 50.0, 0.0), &new.x_m, &new.y_m, at(100.0, 50.0, 0.0)).is_none());
        assert!(regrid(&old, at(100.0, 50.0, 0.1), &new.x_m, &new.y_m, at(100.0, 50.0, 0.0)).is_none());
        let coarse: Vec<f64> = (0..4).map(|i| 20.0 * i as f64).collect();
        assert!(regrid(&old, at(0.0, 0.0, 0.0), &coarse, &new.y_m, at(0.0, 0.0, 0.0)).is_none());
    }

    #[test]
    fn a_field_without_waves_or_a_period_asks_for_the_most() {
        assert_eq!(window_scans(&field(200.0, &[]), 2.0, 40), 40);
        assert_eq!(window_scans(&field(200.0, &[0.7]), 0.0, 40), 40);
        assert_eq!(window_scans(&field(200.0, &[0.7]), f64::NAN, 40), 40);
    }
}
