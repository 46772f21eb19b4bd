//! The predictable horizon (pure): how far ahead the waves reaching a vessel were inside the observed
//! region at the observation time (or, for a radar's window of scans, at one of its scans).
//!
//! A wave group of frequency w travelling along d reaches the vessel (moving at velocity u from its
//! position at t0) at lead time t only if it was inside the observed region at t0: at
//! p0 + (u - c_g(w) d) t, or, a scan tau earlier in the window, at p0 + (u - c_g(w) d) t - c_g(w) d tau. Each part of the field thus has a lead time t_c after which it is unknown;
//! the horizon is the lead time by which the unknown parts carry [`UNKNOWN_FRACTION`] of the variance
//! (long waves, the fastest groups, go first), less the non-causal reach of the force RAO (the force at t
//! depends on the waves up to that much later). For a disc of radius R around a stationary vessel and
//! long-crested waves this is R / c_g,max, c_g,max the group velocity at the frequency below which that
//! fraction of the energy lies.
//!
//! Frames: earth (x east, y north) for fields; for a sea state, directions relative to the vessel's +x,
//! travel-to, counterclockwise (DESIGN.md section 1).

use super::field::{Region, WaveField, group_velocity};
pub use super::sea::Spreading;
use super::sea::jonswap;
use std::f64::consts::PI;

/// Variance share allowed to be unknown at the horizon.
pub const UNKNOWN_FRACTION: f64 = 0.025;

/// The horizon and how it came about.
#[derive(Debug, Clone, PartialEq)]
pub struct Horizon {
    /// Lead time up to which the force is predictable, s (infinite for a field known everywhere).
    pub horizon_s: f64,
    /// The waves' horizon before the non-causal reach is taken off, s.
    pub wave_horizon_s: f64,
    /// The frequency and direction (rad) of the limiting part, and its group velocity (m/s).
    pub limiting_omega_rad_s: f64,
    pub limiting_direction_rad: f64,
    pub limiting_group_velocity_m_s: f64,
    pub noncausal_s: f64,
}

/// Steps of [`coverage_span`]'s march, m (longer on a region so large that it would take more than
/// [`COVERAGE_STEPS`]).
const COVERAGE_STEP_M: f64 = 10.0;
const COVERAGE_STEPS: f64 = 400.0;

/// The horizon from (weight, lead time, omega, direction, c_g) of every part of the field.
fn quantile(mut parts: Vec<(f64, f64, f64, f64, f64)>, noncausal_s: f64) -> Horizon {
    parts.sort_by(|a, b| a.1.total_cmp(&b.1));
    let total: f64 = parts.iter().map(|p| p.0).sum();
    let mut acc = 0.0;
    let mut pick = parts.last().copied().unwrap_or((0.0, f64::INFINITY, 0.0, 0.0, 0.0));
    for p in &parts {
        acc += p.0;
        if acc > UNKNOWN_FRACTION * total {
            pick = *p;
            break;
        }
    }
    Horizon {
        horizon_s: (pick.1 - noncausal_s).max(0.0),
        wave_horizon_s: pick.1,
        limiting_omega_rad_s: pick.2,
        limiting_direction_rad: pick.3,
        limiting_group_velocity_m_s: pick.4,
        noncausal_s,
    }
}

/// The horizon of an observed field for a vessel at `position_m` (earth) moving at `velocity_m_s`
/// (earth) from the field's time on.
pub fn of_field(field: &WaveField, position_m: [f64; 2], velocity_m_s: [f64; 2], noncausal_s: f64) -> Horizon {
    let parts = field
        .components
        .iter()
        .map(|c| {
            let cg = group_velocity(c.omega_rad_s, field.g_m_s2, field.depth_m);
            let d = [c.direction_rad.cos(), c.direction_rad.sin()];
            let rel = [velocity_m_s[0] - cg * d[0], velocity_m_s[1] - cg * d[1]];
            let t = match field.region {
                Region::Everywhere => f64::INFINITY,
                // the exit of the disc: the end of the span its water is inside it
                Region::Disc { centre_m, radius_m } => disc_span(
                    [position_m[0] - centre_m[0], position_m[1] - centre_m[1]],
                    radius_m,
                    rel,
                )[1],
                // the end of the span its water is inside it (behind a blind zone too)
                Region::Coverage { .. } => coverage_span(&field.region, position_m, rel, [-cg * d[0], -cg * d[1]])[1],
                Region::Point { at_m, .. } => {
                    // a probe: the group reaches the (stationary) vessel after travelling from it
                    let along = d[0] * (position_m[0] - at_m[0]) + d[1] * (position_m[1] - at_m[1]);
                    let closing = cg - (velocity_m_s[0] * d[0] + velocity_m_s[1] * d[1]);
                    if along > 0.0 && closing > 0.0 {
                        along / closing
                    } else {
                        0.0
                    }
                }
            };
            (0.5 * c.amplitude_m.norm_sqr(), t, c.omega_rad_s, c.direction_rad, cg)
        })
        .collect();
    quantile(parts, noncausal_s)
}

/// Lead times (s, from the field's time) between which the water that brings a group of frequency w
/// along d to a vessel at `position` (moving relative to the group at `rel`) had been inside a disc:
/// the roots of |offset + rel t| = R, the earlier one no sooner than 0 ([0, 0]: never inside).
fn disc_span(offset: [f64; 2], radius: f64, rel: [f64; 2]) -> [f64; 2] {
    let a = rel[0] * rel[0] + rel[1] * rel[1];
    let b = offset[0] * rel[0] + offset[1] * rel[1];
    let c = offset[0] * offset[0] + offset[1] * offset[1] - radius * radius;
    if a <= 0.0 {
        return if c <= 0.0 { [0.0, f64::INFINITY] } else { [0.0, 0.0] };
    }
    let disc = b * b - a * c;
    if disc < 0.0 {
        return [0.0, 0.0];
    }
    let (t0, t1) = ((-b - disc.sqrt()) / a, (-b + disc.sqrt()) / a);
    if t1 < 0.0 { [0.0, 0.0] } else { [t0.max(0.0), t1] }
}

/// How far a coverage's march from `position` goes (m), its step (m) and the window of scans (s, 0 when
/// not finite); None for another region.
fn coverage_march(region: &Region, position: [f64; 2]) -> Option<(f64, f64, f64)> {
    let Region::Coverage {
        ranges_m,
        centre_m,
        window_s,
        ..
    } = *region
    else {
        return None;
    };
    let far = ranges_m.iter().fold(0.0f64, |m, r| m.max(*r));
    let reach = (position[0] - centre_m[0]).hypot(position[1] - centre_m[1]) + 2.0 * far + COVERAGE_STEP_M;
    let step_m = COVERAGE_STEP_M.max(reach / COVERAGE_STEPS);
    let window_s = if window_s.is_finite() { window_s.max(0.0) } else { 0.0 };
    Some((reach, step_m, window_s))
}

/// [`disc_span`] for a coverage region, marched in steps of [`COVERAGE_STEP_M`] or more: the first step
/// seen, then the first not seen after it ([0, 0]: never seen within reach). The water at lead t is at
/// `position + rel t` at the field's time; a scan `tau` earlier (up to the region's `window_s`) saw it
/// at `position + rel t + back tau`, `back` the group's velocity reversed: a lead is seen when the
/// water was inside the coverage at the field's time or at an earlier scan of its window (the region
/// taken as it was at the field's time: the union of what the window's scans saw).
fn coverage_span(region: &Region, position: [f64; 2], rel: [f64; 2], back: [f64; 2]) -> [f64; 2] {
    let Some((reach, step_m, window_s)) = coverage_march(region, position) else {
        return [0.0, 0.0];
    };
    let back_speed = back[0].hypot(back[1]);
    let (taus, dtau) = if back_speed > 0.0 && window_s > 0.0 {
        let d = step_m / back_speed;
        (
            (window_s / d).ceil() as usize,
            window_s / (window_s / d).ceil().max(1.0),
        )
    } else {
        (0, 0.0)
    };
    let seen = |t: f64| {
        let p = [position[0] + rel[0] * t, position[1] + rel[1] * t];
        (0..=taus).any(|j| {
            let tau = j as f64 * dtau;
            region.contains([p[0] + back[0] * tau, p[1] + back[1] * tau])
        })
    };
    let speed = rel[0].hypot(rel[1]);
    if speed <= 0.0 {
        return if seen(0.0) { [0.0, f64::INFINITY] } else { [0.0, 0.0] };
    }
    let dt = step_m / speed;
    let mut t = 0.0;
    while !seen(t) {
        t += dt;
        if t * speed > reach {
            return [0.0, 0.0];
        }
    }
    let start = t;
    while t * speed <= reach && seen(t + dt) {
        t += dt;
    }
    [start, t]
}

/// [`coverage_span`] of every component for a vessel at rest, on the same steps. At rest the water a
/// group brings at lead t was, a scan tau earlier, at `position - c_g d (t + tau)`: on the ray from
/// the vessel against the group's direction, at c_g (t + tau) metres. A lead's window of scans is
/// then a stretch of that ray, read off running counts of its samples inside the region (one test per
/// sample, where the march tests each of the window's scans), and the ray is kept for the direction:
/// the frequencies that share it march no further than the farthest of them.
fn coverage_spans_at_rest(field: &WaveField, position: [f64; 2]) -> Vec<[f64; 2]> {
    let Some((reach, step_m, window_s)) = coverage_march(&field.region, position) else {
        return vec![[0.0, 0.0]; field.components.len()];
    };
    // per direction, the count of the ray's samples j' < j inside the region, for j = 0, 1, ...
    let mut rays: Vec<(f64, Vec<u32>)> = vec![];
    let mut ray_of: std::collections::HashMap<u64, usize> = std::collections::HashMap::new();
    field
        .components
        .iter()
        .map(|c| {
            let cg = group_velocity(c.omega_rad_s, field.g_m_s2, field.depth_m);
            if !(cg > 0.0 && cg.is_finite()) {
                let d = [c.direction_rad.cos(), c.direction_rad.sin()];
                let rel = [-cg * d[0], -cg * d[1]];
                return coverage_span(&field.region, position, rel, rel);
            }
            // the samples beyond a lead's that its window of scans saw (never past the window)
            let wide = (cg * window_s / step_m).floor() as usize;
            let at = *ray_of.entry(c.direction_rad.to_bits()).or_insert_with(|| {
                rays.push((c.direction_rad, vec![0]));
                rays.len() - 1
            });
            let (direction_rad, seen_before) = &mut rays[at];
            let back = [-direction_rad.cos(), -direction_rad.sin()];
            // lead step i is seen if a sample i..=i + wide of the ray is inside; the ray is marched
            // only as far as a lead asks (as the general march goes), and kept for the direction
            let mut seen = |i: usize| {
                let last = i + wide + 1;
                while seen_before.len() <= last {
                    let r = (seen_before.len() - 1) as f64 * step_m;
                    let inside = field
                        .region
                        .contains([position[0] + back[0] * r, position[1] + back[1] * r]);
                    seen_before.push(seen_before[seen_before.len() - 1] + u32::from(inside));
                }
                seen_before[last] > seen_before[i]
            };
            let dt = step_m / cg;
            let mut i = 0;
            while !seen(i) {
                i += 1;
                if i as f64 * step_m > reach {
                    return [0.0, 0.0];
                }
            }
            let start = i;
            while i as f64 * step_m <= reach && seen(i + 1) {
                i += 1;
            }
            [start as f64 * dt, i as f64 * dt]
        })
        .collect()
}

/// For each component of a field, the lead times (s, from the field's time) over which the waves it
/// brings to a vessel at `position_m` moving at `velocity_m_s` (earth frame) had been observed:
/// inside the observed disc or coverage at the field's time (a coverage: or at an earlier scan of its
/// window), or past the probe within its fitted
/// window (a probe whose window is not said: from 0). Known everywhere: [0, infinity).
pub fn known_leads(field: &WaveField, position_m: [f64; 2], velocity_m_s: [f64; 2]) -> Vec<[f64; 2]> {
    if matches!(field.region, Region::Coverage { .. }) && velocity_m_s == [0.0, 0.0] {
        return coverage_spans_at_rest(field, position_m);
    }
    field
        .components
        .iter()
        .map(|c| {
            let cg = group_velocity(c.omega_rad_s, field.g_m_s2, field.depth_m);
            let d = [c.direction_rad.cos(), c.direction_rad.sin()];
            let rel = [velocity_m_s[0] - cg * d[0], velocity_m_s[1] - cg * d[1]];
            match field.region {
                Region::Everywhere => [0.0, f64::INFINITY],
                Region::Disc { centre_m, radius_m } => disc_span(
                    [position_m[0] - centre_m[0], position_m[1] - centre_m[1]],
                    radius_m,
                    rel,
                ),
                Region::Coverage { .. } => coverage_span(&field.region, position_m, rel, [-cg * d[0], -cg * d[1]]),
                Region::Point { at_m, window_s } => {
                    let along = d[0] * (position_m[0] - at_m[0]) + d[1] * (position_m[1] - at_m[1]);
                    let closing = cg - (velocity_m_s[0] * d[0] + velocity_m_s[1] * d[1]);
                    if along > 0.0 && closing > 0.0 {
                        let arrive = along / closing;
                        let start = if window_s > 0.0 {
                            (arrive - window_s).max(0.0)
                        } else {
                            0.0
                        };
                        [start, arrive]
                    } else {
                        [0.0, 0.0]
                    }
                }
            }
        })
        .collect()
}

/// A sea state for planning: JONSWAP (gamma = 1: Pierson-Moskowitz).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanningSea {
    pub hs_m: f64,
    pub tp_s: f64,
    pub gamma: f64,
    pub spreading: Spreading,
    /// Mean direction the waves travel to, relative to the vessel's +x, rad (pi: head seas).
    pub heading_rad: f64,
}

/// The horizon of a radar disc of `radius_m` centred on a vessel moving at `speed_m_s` along its +x,
/// for a sea state (spectrum discretized finely in frequency and direction).
pub fn of_sea(
    sea: &PlanningSea,
    radius_m: f64,
    speed_m_s: f64,
    g_m_s2: f64,
    depth_m: Option<f64>,
    noncausal_s: f64,
) -> Horizon {
    let wp = 2.0 * PI / sea.tp_s;
    let nw = 2000;
    let (w0, w1) = (0.2 * wp, 6.0 * wp);
    let dw = (w1 - w0) / nw as f64;
    let dirs: Vec<(f64, f64)> = match sea.spreading {
        Spreading::LongCrested => vec![(0.0, 1.0)],
        s => {
            let nd = 360;
            (0..nd)
                .map(|j| {
                    let d = -PI + (j as f64 + 0.5) * 2.0 * PI / nd as f64;
                    (d, s.weight(d))
                })
                .filter(|(_, w)| *w > 0.0)
                .collect()
        }
    };
    let mut parts = Vec::with_capacity(nw * dirs.len());
    for i in 0..nw {
        let w = w0 + (i as f64 + 0.5) * dw;
        let s = jonswap(sea.hs_m, sea.tp_s, sea.gamma, w) * dw;
        let cg = group_velocity(w, g_m_s2, depth_m);
        for (d, wd) in &dirs {
            let dir = sea.heading_rad + d;
            let rel = [speed_m_s - cg * dir.cos(), -cg * dir.sin()];
            parts.push((s * wd, disc_span([0.0, 0.0], radius_m, rel)[1], w, dir, cg));
        }
    }
    quantile(parts, noncausal_s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn disc_exit_is_the_end_of_the_disc_span() {
        // from the centre, moving at 5 m/s: R / 5
        assert!((disc_span([0.0, 0.0], 1000.0, [5.0, 0.0])[1] - 200.0).abs() < 1e-9);
        // starting 600 m upstream (groups coming towards it from beyond the far edge)
        assert!((disc_span([600.0, 0.0], 1000.0, [5.0, 0.0])[1] - 80.0).abs() < 1e-9);
        // outside and moving away: never inside
        assert_eq!(disc_span([2000.0, 0.0], 1000.0, [5.0, 0.0])[1], 0.0);
    }

    /// A field of one component of 0.6 rad/s travelling west (towards -x) observed over `region`, and
    /// its group speed, m/s.
    /// With a window, the share of spans the ray and the march may disagree on by more than two steps
    /// (a gap crossed as wide as the window, to a step).
    const RAY_APART_SHARE: f64 = 0.01;

    fn westward(region: Region) -> (WaveField, f64) {
        use crate::waves::field::FieldComponent;
        let w = 0.6;
        let comp = FieldComponent {
            omega_rad_s: w,
            direction_rad: PI,
            amplitude_m: num_complex::Complex64::new(1.0, 0.0),
        };
        let field = WaveField {
            components: vec![comp],
            reference_m: [0.0, 0.0],
            time_s: 0.0,
            g_m_s2: 9.81,
            depth_m: None,
            region,
        };
        (field, group_velocity(w, 9.81, None))
    }

    #[test]
    fn known_leads_of_a_disc() {
        let field = |region| westward(region).0;
        let cg = westward(Region::Everywhere).1;
        // a disc of 1000 m around a stationary vessel at its centre: known from 0 to R / c_g
        let k = known_leads(
            &field(Region::Disc {
                centre_m: [0.0, 0.0],
                radius_m: 1000.0,
            }),
            [0.0, 0.0],
            [0.0, 0.0],
        );
        assert!((k[0][0]).abs() < 1e-12 && (k[0][1] - 1000.0 / cg).abs() < 1e-9, "{k:?}");
        // a vessel 1500 m down-wave of the disc's centre: from (1500 - 1000) / c_g to (1500 + 1000) / c_g
        let k = known_leads(
            &field(Region::Disc {
                centre_m: [1500.0, 0.0],
                radius_m: 1000.0,
            }),
            [0.0, 0.0],
            [0.0, 0.0],
        );
        assert!(
            (k[0][0] - 500.0 / cg).abs() < 1e-9 && (k[0][1] - 2500.0 / cg).abs() < 1e-9,
            "{k:?}"
        );
    }

    #[test]
    fn known_leads_of_a_probe() {
        let field = |region| westward(region).0;
        let cg = westward(Region::Everywhere).1;
        // a probe 600 m up-wave that fitted 30 s: the groups passing it arrive 600 / c_g later
        let probe = |window_s| {
            field(Region::Point {
                at_m: [600.0, 0.0],
                window_s,
            })
        };
        let k = known_leads(&probe(30.0), [0.0, 0.0], [0.0, 0.0]);
        assert!(
            (k[0][1] - 600.0 / cg).abs() < 1e-9 && (k[0][0] - (600.0 / cg - 30.0)).abs() < 1e-9,
            "{k:?}"
        );
        // a window longer than the travel: known from now
        assert_eq!(known_leads(&probe(120.0), [0.0, 0.0], [0.0, 0.0])[0][0], 0.0);
        let k = known_leads(&probe(0.0), [0.0, 0.0], [0.0, 0.0]);
        assert_eq!(k[0][0], 0.0);
        // down-wave of the vessel, a probe tells nothing
        let k = known_leads(
            &field(Region::Point {
                at_m: [-600.0, 0.0],
                window_s: 120.0,
            }),
            [0.0, 0.0],
            [0.0, 0.0],
        );
        assert_eq!(k[0], [0.0, 0.0]);
    }

    #[test]
    fn known_leads_of_a_coverage() {
        use crate::waves::field::COVERAGE_SECTORS;
        let field = |region| westward(region).0;
        let cg = westward(Region::Everywhere).1;
        // a coverage of 1000 m in every sector: as the disc, to a step
        let cov = Region::Coverage {
            centre_m: [0.0, 0.0],
            inner_m: 0.0,
            ranges_m: [1000.0; COVERAGE_SECTORS],
            window_s: 0.0,
        };
        let k = known_leads(&field(cov), [0.0, 0.0], [0.0, 0.0]);
        assert!(
            k[0][0] == 0.0 && (k[0][1] - 1000.0 / cg).abs() < 10.0 / cg + 1e-9,
            "{k:?}"
        );
        let cov = Region::Coverage {
            centre_m: [1500.0, 0.0],
            inner_m: 0.0,
            ranges_m: [1000.0; COVERAGE_SECTORS],
            window_s: 0.0,
        };
        let k = known_leads(&field(cov), [0.0, 0.0], [0.0, 0.0]);
        assert!(
            (k[0][0] - 500.0 / cg).abs() < 11.0 / cg && (k[0][1] - 2500.0 / cg).abs() < 11.0 / cg,
            "{k:?}"
        );
        // a radar's blind zone (200 m) around the vessel: the next 200 m of water is not known, and
        // the horizon is the far edge's
        let cov = Region::Coverage {
            centre_m: [0.0, 0.0],
            inner_m: 200.0,
            ranges_m: [1000.0; COVERAGE_SECTORS],
            window_s: 0.0,
        };
        let f = field(cov);
        let k = known_leads(&f, [0.0, 0.0], [0.0, 0.0]);
        assert!(
            (k[0][0] - 200.0 / cg).abs() < 11.0 / cg && (k[0][1] - 1000.0 / cg).abs() < 11.0 / cg,
            "{k:?}"
        );
        let h = of_field(&f, [0.0, 0.0], [0.0, 0.0], 0.0);
        assert!((h.wave_horizon_s - 1000.0 / cg).abs() < 11.0 / cg, "{h:?}");
    }

    #[test]
    fn a_window_of_scans_fills_the_blind_zone_with_what_earlier_scans_saw() {
        use crate::waves::field::COVERAGE_SECTORS;
        let field = |region| westward(region).0;
        let cg = westward(Region::Everywhere).1;
        let blind = |window_s: f64, ranges_m| Region::Coverage {
            centre_m: [0.0, 0.0],
            inner_m: 200.0,
            ranges_m,
            window_s,
        };
        let all_round = [1000.0; COVERAGE_SECTORS];
        // the water inside the blind zone now crossed its edge 200 m / c_g ago: a window that long
        // saw all of it, and the far edge is where it was
        let k = known_leads(&field(blind(200.0 / cg + 2.0, all_round)), [0.0, 0.0], [0.0, 0.0]);
        assert!(k[0][0] == 0.0 && (k[0][1] - 1000.0 / cg).abs() < 11.0 / cg, "{k:?}");
        // a shorter window: the first leads' water was still in the blind zone at the oldest scan
        let k = known_leads(&field(blind(10.0, all_round)), [0.0, 0.0], [0.0, 0.0]);
        assert!((k[0][0] - (200.0 / cg - 10.0)).abs() < 11.0 / cg, "{k:?}");
        // the waves come from the east (travelling west): a sector masked to the east was never seen,
        // however long the window
        let masked = std::array::from_fn(|j| {
            if !(4..COVERAGE_SECTORS - 4).contains(&j) {
                0.0
            } else {
                1000.0
            }
        });
        let k = known_leads(&field(blind(600.0, masked)), [0.0, 0.0], [0.0, 0.0]);
        assert_eq!(k[0], [0.0, 0.0]);
    }

    /// A vessel at rest reads its leads off one ray per direction ([`coverage_spans_at_rest`]): the
    /// same spans as the general march's on ragged coverages, the vessel off the centre, many
    /// frequencies sharing each direction. Without a window, to the march's step; with one, to two
    /// (the ray takes the window's scans to its last whole step, never past it; the march to its
    /// end), and where the ray crosses a masked sector's gap about as wide as the window one of them
    /// bridges it: a few spans may differ more.
    #[test]
    fn a_vessel_at_rest_reads_the_general_march_s_spans_off_its_rays() {
        use crate::waves::field::FieldComponent;
        let mut seed = 11u64;
        let mut rnd = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut worst_steps, mut apart, mut spans): (f64, usize, usize) = (0.0, 0, 0);
        for case in 0..9 {
            let window_s = [0.0, 60.0, 17.3][case % 3];
            let ranges_m = std::array::from_fn(|_| if rnd() < 0.15 { 0.0 } else { 500.0 + 1500.0 * rnd() });
            let region = Region::Coverage {
                centre_m: [0.0, 0.0],
                inner_m: 150.0 + 100.0 * rnd(),
                ranges_m,
                window_s,
            };
            let components = (0..400)
                .map(|j| FieldComponent {
                    omega_rad_s: 0.3 + 1.2 * rnd(),
                    direction_rad: (j % 23) as f64 * 2.0 * PI / 23.0,
                    amplitude_m: num_complex::Complex64::new(0.1, 0.0),
                })
                .collect();
            let field = WaveField {
                components,
                reference_m: [0.0, 0.0],
                time_s: 0.0,
                g_m_s2: 9.81,
                depth_m: None,
                region,
            };
            let position = [60.0 * rnd() - 30.0, 60.0 * rnd() - 30.0];
            let at_rest = coverage_spans_at_rest(&field, position);
            assert_eq!(at_rest.len(), field.components.len());
            for (c, got) in field.components.iter().zip(&at_rest) {
                let cg = group_velocity(c.omega_rad_s, 9.81, None);
                let back = [-cg * c.direction_rad.cos(), -cg * c.direction_rad.sin()];
                let marched = coverage_span(&field.region, position, back, back);
                let off_steps = (0..2)
                    .map(|e| (got[e] - marched[e]).abs() * cg / COVERAGE_STEP_M)
                    .fold(0.0, f64::max);
                spans += 1;
                if window_s == 0.0 {
                    worst_steps = worst_steps.max(off_steps);
                } else if off_steps > 2.0 + 1e-9 {
                    apart += 1;
                }
            }
        }
        assert!(worst_steps <= 1.0 + 1e-9, "without a window: {worst_steps} steps off");
        assert!(
            (apart as f64) <= RAY_APART_SHARE * spans as f64,
            "{apart} of {spans} spans more than two steps off"
        );
    }

    #[test]
    fn head_speed_shortens_the_horizon() {
        let sea = PlanningSea {
            hs_m: 2.0,
            tp_s: 10.0,
            gamma: 3.3,
            spreading: Spreading::LongCrested,
            heading_rad: PI,
        };
        let still = of_sea(&sea, 2000.0, 0.0, 9.81, None, 0.0);
        let head = of_sea(&sea, 2000.0, 5.0, 9.81, None, 0.0);
        let short_crested = of_sea(
            &PlanningSea {
                spreading: Spreading::Cos2s(4.0),
                ..sea
            },
            2000.0,
            0.0,
            9.81,
            None,
            0.0,
        );
        assert!(head.horizon_s < still.horizon_s);
        // a disc is the same in every direction: spreading does not change a stationary vessel's horizon
        assert!((short_crested.horizon_s - still.horizon_s).abs() < 0.01 * still.horizon_s);
        let nc = of_sea(&sea, 2000.0, 0.0, 9.81, None, 12.0);
        assert!((nc.horizon_s - (still.horizon_s - 12.0)).abs() < 1e-9);
    }
}
