//! The inversion of one radar scan on a 128 x 128 grid over a 2 km square (the simulator's default
//! radar: 15.6 m cells, one scan every 2 s), a short-crested JONSWAP sea (Hs 2 m, Tp 9 s, 200
//! components) with 5 cm noise: from the newest three snapshots, and one scan's update at the default
//! window (a 200 m blind zone, NaN, as the default radar's; as many scans as
//! `waves::window::window_scans` asks of the field, at most `forecast.radar_snapshots`' default 48),
//! started from the window before's fit as the daemon's are, and cold (the first window).
//! A radar processor inverts once a scan: the bench's median must stay within a fifth of the 2 s scan on
//! one core. Setup outside the timing.

use criterion::{Criterion, criterion_group, criterion_main};
use rand::{Rng, SeedableRng};
use shipcast::waves::field::{Region, WaveField};
use shipcast::waves::observe::{Grid, GridFrame, GridOptions, from_grids, from_scans, from_scans_after};
use shipcast::waves::sea::{SeaState, Spreading, realize_all};
use shipcast::waves::window::window_scans;
use std::hint::black_box;

fn scans(count: usize, blind_m: f64) -> Vec<Grid> {
    let sea = SeaState {
        hs_m: 2.0,
        tp_s: 9.0,
        gamma: 3.3,
        heading_rad: 0.3,
        spreading: Spreading::Cos2s(8.0),
        components: 200,
        omega_min_rad_s: 0.3,
        omega_max_rad_s: 1.4,
        seed: 7,
    };
    let field = WaveField::from_components(&realize_all(&[sea]), 9.81, None, Region::Everywhere);
    let (n, radius) = (128, 1000.0);
    let d = 2.0 * radius / n as f64;
    let xs: Vec<f64> = (0..n).map(|i| -radius + (i as f64 + 0.5) * d).collect();
    let pts: Vec<[f64; 2]> = xs.iter().flat_map(|y| xs.iter().map(move |x| [*x, *y])).collect();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
    (0..count)
        .map(|s| {
            let t = 2.0 * s as f64;
            let mut values = vec![0.0; pts.len()];
            field.elevation(&pts, t, &mut values);
            for (v, p) in values.iter_mut().zip(&pts) {
                // uniform noise of 5 cm standard deviation; nothing seen in the blind zone
                *v += 0.05 * 3f64.sqrt() * (2.0 * rng.random::<f64>() - 1.0);
                if p[0].hypot(p[1]) < blind_m {
                    *v = f64::NAN;
                }
            }
            Grid {
                x_m: xs.clone(),
                y_m: xs.clone(),
                time_s: t,
                values,
            }
        })
        .collect()
}

fn benches(c: &mut Criterion) {
    let grids = scans(3, 0.0);
    let opts = GridOptions {
        g_m_s2: 9.81,
        depth_m: None,
        omega_min_rad_s: 0.24,
        omega_max_rad_s: 1.54,
        mean_direction_rad: None,
        region: None,
    };
    let mut g = c.benchmark_group("radar");
    g.sample_size(10);
    g.bench_function("inversion_128x128_3_snapshots", |b| {
        b.iter(|| {
            from_grids(black_box(&grids), &opts)
                .map(|f| f.components.len())
                .unwrap()
        })
    });
    // the default window: what the field of the whole stack asks for
    let stack = scans(48, 200.0);
    let frame = GridFrame {
        origin_m: [0.0, 0.0],
        orientation_rad: 0.0,
    };
    let first = from_scans(&stack, frame, &opts).unwrap().pruned(0.995);
    let n = window_scans(&first, 2.0, stack.len());
    let window = &stack[stack.len() - n..];
    eprintln!("radar: the default window holds {n} scans");
    // the daemon's steady state: the window before's fit is at hand
    let (_, prior) = from_scans_after(&stack[stack.len() - n - 1..stack.len() - 1], frame, &opts, None).unwrap();
    g.bench_function("scan_update_default_window", |b| {
        b.iter(|| {
            from_scans_after(black_box(window), frame, &opts, Some(&prior))
                .map(|(f, _)| f.components.len())
                .unwrap()
        })
    });
    // the first window, or one after the grid changed: the fill's passes from cold
    g.bench_function("scan_update_default_window_cold", |b| {
        b.iter(|| {
            from_scans(black_box(window), frame, &opts)
                .map(|f| f.components.len())
                .unwrap()
        })
    });
    g.finish();
}

criterion_group!(radar, benches);
criterion_main!(radar);
