//! Wave fields (issue 5): realizations against their spectrum, radar grids and probe records turned
//! into fields and propagated, the predictable horizon against a synthetic radar's skill.

use num_complex::Complex64;
use rustfft::FftPlanner;
use shipcast::waves::field::{Region, WaveField, group_velocity};
use shipcast::waves::horizon::{self, PlanningSea, Spreading};
use shipcast::waves::observe::{Grid, GridOptions, from_grids, from_probe};
use shipcast::waves::sea::{SeaState, jonswap, realize};
use std::f64::consts::PI;

const G: f64 = 9.81;

/// Hs from a long record: sampling error of m0 over ~300 wave periods and a finite band, about 3 %.
const HS_TOL: f64 = 0.05;
/// Tp from the smoothed periodogram's peak: the smoothing bandwidth (0.02 rad/s at 0.63 rad/s).
const TP_TOL: f64 = 0.05;
/// Swell variance found travelling the right way: a non-periodic 1.9 km grid leaks the long swell's few
/// wavenumber bins (grid spacing 0.0033 rad/m against k = 0.012..0.031 rad/m) off the dispersion shell.
const SEPARATION_TOL: f64 = 0.3;
/// The bar for the horizon against R / c_g,max.
const HORIZON_TOL: f64 = 0.05;
/// Component variance against the band's m0: a jittered-midpoint sum over 3000 bins, 2 % a margin on its error.
const VARIANCE_TOL: f64 = 0.02;
/// Within the horizon the prediction's RMS error is at most a quarter of the sea's RMS (a margin, no figure kept).
const INSIDE_HORIZON_NRMSE: f64 = 0.25;
/// Past the horizon the error at least doubles: waves arrive there that were never observed.
const BEYOND_HORIZON_GROWTH: f64 = 2.0;
/// Two opposing seas, error at the centre over 20 s: looser than `INSIDE_HORIZON_NRMSE` for the swell's leakage.
const TWO_SEAS_CENTRE_NRMSE: f64 = 0.3;
/// Round-off on cos(direction) of a component at +-90 deg: with an east hint, none may travel west.
const DIRECTION_COS_ROUNDOFF: f64 = 1e-9;
/// The probe's FFT fit gives its own record back to this RMS fraction: loose, it loses only leakage off band.
const PROBE_FIT_NRMSE: f64 = 0.05;
/// Mean error over 0-0.8 horizons in four realizations, at most: the radar's noise and the disc's edge (a margin).
const BEFORE_HORIZON_NRMSE: f64 = 0.35;
/// ... and over 1.3-2.5 horizons at least: most of that sea was never seen (a forecast of calm scores 1).
const AFTER_HORIZON_NRMSE: f64 = 0.7;
/// `horizon --radius 2000 --tp 10`: R / c_g,max of the long-crested JONSWAP sea, s, as recorded.
const CLI_HORIZON_S: f64 = 201.8;
/// A margin around that figure, s: five times the 0.1 s the CLI prints it to.
const CLI_HORIZON_TOL_S: f64 = 0.5;
/// The `--noncausal 10` reach, s, taken off the horizon whole: head seas at 5 m/s must shorten it further.
const NONCAUSAL_REACH_S: f64 = 10.0;

fn sea(seed: u64, components: usize) -> SeaState {
    SeaState {
        hs_m: 2.0,
        tp_s: 10.0,
        gamma: 3.3,
        heading_rad: 0.0,
        spreading: shipcast::waves::sea::Spreading::LongCrested,
        components,
        omega_min_rad_s: 0.3,
        omega_max_rad_s: 1.4,
        seed,
    }
}

/// A realization as an earth-frame field (direction = heading: the vessel frame is east-aligned).
fn field_of(sea: &SeaState) -> WaveField {
    WaveField::from_components(&realize(sea), G, None, Region::Everywhere)
}

/// The radar processor's options: deep water, the realizations' band, no hint.
fn grid_options(region: Option<Region>) -> GridOptions {
    GridOptions {
        g_m_s2: G,
        depth_m: None,
        omega_min_rad_s: 0.25,
        omega_max_rad_s: 1.45,
        mean_direction_rad: None,
        region,
    }
}

#[test]
fn long_realization_recovers_hs_and_tp() {
    let s = sea(11, 3000);
    let f = field_of(&s);
    let dt = 0.5;
    let n = 1 << 13; // 4096 s: about 400 peak periods
    let eta: Vec<f64> = (0..n).map(|j| f.elevation_at([0.0, 0.0], j as f64 * dt)).collect();
    let mut c: Vec<Complex64> = eta.iter().map(|v| Complex64::new(*v, 0.0)).collect();
    FftPlanner::new().plan_fft_forward(n).process(&mut c);
    let dw = 2.0 * PI / (n as f64 * dt);
    // one-sided spectrum S(w) = 2 |C|^2 dt / (2 pi n)
    let spec: Vec<f64> = (0..n / 2)
        .map(|m| 2.0 * c[m].norm_sqr() * dt / (2.0 * PI * n as f64))
        .collect();
    let m0: f64 = spec.iter().skip(1).sum::<f64>() * dw;
    let hs = 4.0 * m0.sqrt();
    // smooth over +-0.01 rad/s before taking the peak
    let half = (0.01 / dw) as usize;
    let smooth: Vec<f64> = (half..spec.len() - half)
        .map(|m| spec[m - half..=m + half].iter().sum::<f64>())
        .collect();
    let (mp, _) = smooth
        .iter()
        .enumerate()
        .fold((0, 0.0), |b, (m, v)| if *v > b.1 { (m, *v) } else { b });
    let tp = 2.0 * PI / ((mp + half) as f64 * dw);
    // the variance of the components themselves against the spectrum's m0 over the band
    let band_m0: f64 = (0..20000)
        .map(|k| {
            let w = 0.3 + (k as f64 + 0.5) * 1.1 / 20000.0;
            jonswap(2.0, 10.0, 3.3, w) * 1.1 / 20000.0
        })
        .sum();
    eprintln!(
        "Hs {hs:.3} m (2.0; band m0 gives {:.3}), Tp {tp:.2} s (10.0), component variance {:.4} vs band m0 {band_m0:.4}",
        4.0 * band_m0.sqrt(),
        f.variance_m2()
    );
    assert!((f.variance_m2() - band_m0).abs() < VARIANCE_TOL * band_m0);
    assert!((hs - 4.0 * band_m0.sqrt()).abs() < HS_TOL * hs);
    assert!((tp - 10.0).abs() < TP_TOL * 10.0);
}

/// Radar snapshots of a field on an n x n grid of spacing d centred on the origin, with noise, cells
/// beyond `radius` (the radar's view) zero.
fn radar(truth: &WaveField, n: usize, d: f64, times: &[f64], noise_m: f64, radius: f64, seed: u64) -> Vec<Grid> {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let x: Vec<f64> = (0..n).map(|i| (i as f64 - 0.5 * n as f64) * d).collect();
    let mut pts = vec![];
    for yy in &x {
        for xx in &x {
            pts.push([*xx, *yy]);
        }
    }
    times
        .iter()
        .map(|&t| {
            let mut v = vec![0.0; pts.len()];
            truth.elevation(&pts, t, &mut v);
            for (p, e) in pts.iter().zip(v.iter_mut()) {
                if p[0].hypot(p[1]) > radius {
                    *e = 0.0;
                } else {
                    // uniform noise of the given standard deviation
                    *e += noise_m * 3f64.sqrt() * (2.0 * rng.random::<f64>() - 1.0);
                }
            }
            Grid {
                x_m: x.clone(),
                y_m: x.clone(),
                time_s: t,
                values: v,
            }
        })
        .collect()
}

/// Normalized RMS error of the prediction at `p` over lead times [a, b) s (1 s steps).
fn nrmse(pred: &WaveField, truth: &WaveField, p: [f64; 2], a: f64, b: f64) -> f64 {
    let (mut e2, mut t2) = (0.0, 0.0);
    let mut t = a;
    while t < b {
        let (x, y) = (pred.elevation_at(p, t), truth.elevation_at(p, t));
        e2 += (x - y) * (x - y);
        t2 += y * y;
        t += 1.0;
    }
    (e2 / t2).sqrt()
}

#[test]
fn radar_grid_predicts_a_point_1_km_away_within_the_horizon() {
    let s = sea(5, 400);
    let truth = field_of(&s);
    // 128 x 128 cells of 15 m, three snapshots 1.5 s apart, 5 cm noise
    let grids = radar(&truth, 128, 15.0, &[-3.0, -1.5, 0.0], 0.05, f64::INFINITY, 1);
    let opts = grid_options(None);
    let f = from_grids(&grids, &opts).unwrap();
    let p = [1000.0, 0.0];
    let h = horizon::of_field(&f, p, [0.0, 0.0], 0.0);
    // the waves reaching p came from inside the grid after (1000 - 960) / c_g,max
    let entry = 40.0 / group_velocity(0.3, G, None);
    let inside = nrmse(&f, &truth, p, entry, h.horizon_s);
    let beyond = nrmse(&f, &truth, p, h.horizon_s + 60.0, h.horizon_s + 260.0);
    let at_centre = nrmse(&f, &truth, [0.0, 0.0], 0.0, 20.0);
    eprintln!(
        "{} components; horizon at 1 km: {:.1} s (limited by {:.3} rad/s, c_g {:.2} m/s); normalized RMS error {:.3} within it, {:.3} beyond; at the centre over 20 s {:.3}",
        f.components.len(),
        h.horizon_s,
        h.limiting_omega_rad_s,
        h.limiting_group_velocity_m_s,
        inside,
        beyond,
        at_centre
    );
    assert!(inside < INSIDE_HORIZON_NRMSE, "{inside}");
    assert!(beyond > BEYOND_HORIZON_GROWTH * inside, "{beyond}");
}

#[test]
fn opposite_swell_and_wind_sea_are_separated_by_a_sequence() {
    // wind sea travelling east, swell travelling west at a different frequency band
    let mut truth = field_of(&sea(3, 200));
    let swell = SeaState {
        hs_m: 1.0,
        tp_s: 14.0,
        heading_rad: PI,
        omega_min_rad_s: 0.35,
        omega_max_rad_s: 0.55,
        components: 60,
        ..sea(4, 60)
    };
    truth.components.extend(field_of(&swell).components);
    let grids = radar(&truth, 128, 15.0, &[-3.0, -1.5, 0.0], 0.02, f64::INFINITY, 2);
    let opts = grid_options(None);
    let f = from_grids(&grids, &opts).unwrap();
    let energy = |west: bool| -> f64 {
        f.components
            .iter()
            .filter(|c| (c.direction_rad.cos() < 0.0) == west)
            .map(|c| 0.5 * c.amplitude_m.norm_sqr())
            .sum()
    };
    let (east, west) = (energy(false), energy(true));
    let want_west = field_of(&swell).variance_m2();
    eprintln!(
        "variance travelling east {east:.4} m^2 (truth {:.4}), west {west:.4} (truth {want_west:.4})",
        field_of(&sea(3, 200)).variance_m2()
    );
    let at_centre = nrmse(&f, &truth, [0.0, 0.0], 0.0, 20.0);
    eprintln!("two-directional sea, normalized RMS error at the centre over 20 s: {at_centre:.3}");
    assert!((west - want_west).abs() < SEPARATION_TOL * want_west);
    assert!(at_centre < TWO_SEAS_CENTRE_NRMSE);
    // one snapshot with a wrong hint puts everything one way: the sequence is what separates them
    let one = from_grids(
        &grids[2..],
        &GridOptions {
            mean_direction_rad: Some(0.0),
            ..opts
        },
    )
    .unwrap();
    assert!(
        one.components
            .iter()
            .all(|c| c.direction_rad.cos() >= -DIRECTION_COS_ROUNDOFF)
    );
}

#[test]
fn probe_record_predicts_downstream_within_the_horizon() {
    // the seed paper's method: FFT of a 20-minute probe record 1 km upstream, long-crested
    let truth = field_of(&sea(9, 400));
    let dt = 0.5;
    let n = 2400;
    let probe = [-1000.0, 0.0];
    let eta: Vec<f64> = (0..n)
        .map(|j| truth.elevation_at(probe, -((n - 1 - j) as f64) * dt))
        .collect();
    let f = from_probe(&eta, dt, 0.0, probe, 0.0, (0.25, 1.45), G, None).unwrap();
    // at the probe, over the record
    let mut e2 = 0.0;
    for (j, v) in eta.iter().enumerate() {
        let t = -((n - 1 - j) as f64) * dt;
        e2 += (f.elevation_at(probe, t) - v).powi(2);
    }
    let at_probe = (e2 / eta.iter().map(|v| v * v).sum::<f64>()).sqrt();
    let vessel = [0.0, 0.0];
    let h = horizon::of_field(&f, vessel, [0.0, 0.0], 0.0);
    let inside = nrmse(&f, &truth, vessel, 0.0, h.horizon_s);
    let beyond = nrmse(&f, &truth, vessel, h.horizon_s + 100.0, h.horizon_s + 400.0);
    eprintln!(
        "probe: record reproduced to {at_probe:.2e}; horizon 1 km downstream {:.1} s; error {inside:.3} within, {beyond:.3} beyond",
        h.horizon_s
    );
    assert!(at_probe < PROBE_FIT_NRMSE);
    assert!(inside < INSIDE_HORIZON_NRMSE && beyond > BEYOND_HORIZON_GROWTH * inside);
}

#[test]
fn long_crested_horizon_is_radius_over_the_fastest_group() {
    let sea = PlanningSea {
        hs_m: 2.0,
        tp_s: 10.0,
        gamma: 3.3,
        spreading: Spreading::LongCrested,
        heading_rad: PI,
    };
    let r = 2000.0;
    let h = horizon::of_sea(&sea, r, 0.0, G, None, 0.0);
    // independently: the frequency below which 2.5 % of the energy lies, deep-water c_g = g / (2 w)
    let dw = 1e-4;
    let total: f64 = (1..40000).map(|k| jonswap(2.0, 10.0, 3.3, k as f64 * dw)).sum();
    let mut acc = 0.0;
    let mut wq = 0.0;
    for k in 1..40000 {
        acc += jonswap(2.0, 10.0, 3.3, k as f64 * dw);
        if acc > horizon::UNKNOWN_FRACTION * total {
            wq = k as f64 * dw;
            break;
        }
    }
    let expected = r / (G / (2.0 * wq));
    eprintln!("horizon {:.1} s, R / c_g,max {expected:.1} s", h.horizon_s);
    assert!((h.horizon_s - expected).abs() < HORIZON_TOL * expected);
}

#[test]
fn skill_of_a_synthetic_radar_falls_past_the_horizon_and_not_before() {
    // a radar disc of 900 m around a stationary vessel, long-crested sea, several realizations
    let r = 900.0;
    let planning = horizon::of_sea(
        &PlanningSea {
            hs_m: 2.0,
            tp_s: 10.0,
            gamma: 3.3,
            spreading: Spreading::LongCrested,
            heading_rad: 0.0,
        },
        r,
        0.0,
        G,
        None,
        0.0,
    );
    let hz = planning.horizon_s;
    let (mut before, mut after) = (vec![], vec![]);
    for seed in 0..4 {
        let truth = field_of(&sea(20 + seed, 400));
        let grids = radar(&truth, 128, 15.0, &[-3.0, -1.5, 0.0], 0.05, r, seed);
        let f = from_grids(
            &grids,
            &grid_options(Some(Region::Disc {
                centre_m: [0.0, 0.0],
                radius_m: r,
            })),
        )
        .unwrap();
        before.push(nrmse(&f, &truth, [0.0, 0.0], 0.0, 0.8 * hz));
        after.push(nrmse(&f, &truth, [0.0, 0.0], 1.3 * hz, 2.5 * hz));
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    eprintln!(
        "horizon {hz:.1} s (R / c_g at {:.3} rad/s); normalized RMS error of the elevation at the vessel: {:.3} over 0-0.8 H, {:.3} over 1.3-2.5 H (per realization {before:.3?} / {after:.3?})",
        planning.limiting_omega_rad_s,
        mean(&before),
        mean(&after)
    );
    assert!(mean(&before) < BEFORE_HORIZON_NRMSE);
    assert!(mean(&after) > AFTER_HORIZON_NRMSE);
}

#[test]
fn horizon_cli_explains_and_ends_with_the_figure() {
    let (ok, out, err) = crate::util::shipcast(&["horizon", "--radius", "2000", "--tp", "10"]);
    assert!(ok, "{err}");
    let last = out.lines().last().unwrap();
    let h: f64 = last
        .strip_prefix("horizon_s=")
        .expect("last line horizon_s=")
        .parse()
        .unwrap();
    assert!((h - CLI_HORIZON_S).abs() < CLI_HORIZON_TOL_S, "{h}");
    assert!(out.contains("R / c_g,max"));
    // head seas at 5 m/s and a non-causal reach shorten it
    let (ok, out, _) = crate::util::shipcast(&[
        "horizon",
        "--radius",
        "2000",
        "--tp",
        "10",
        "--speed",
        "5",
        "--noncausal",
        "10",
    ]);
    assert!(ok);
    let h2: f64 = out.lines().last().unwrap()["horizon_s=".len()..].parse().unwrap();
    assert!(h2 < h - NONCAUSAL_REACH_S, "{h2}");
    let (ok, _, err) = crate::util::shipcast(&["horizon", "--radius=-1", "--tp", "10"]);
    assert!(!ok && err.contains("--radius -1: must be a positive number"), "{err}");
}
