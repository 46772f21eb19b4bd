//! The inversion of one radar scan: the field from the newest three snapshots of a 128 x 128 grid over a
//! 2 km square (the simulator's default radar: 15.6 m cells, one scan every 2 s), a short-crested
//! JONSWAP sea (Hs 2 m, Tp 9 s, 200 components) with 5 cm noise. A radar processor inverts once a scan:
//! the bench's median must stay well under the 2 s scan on one core. Setup outside the timing.

use criterion::{Criterion, criterion_group, criterion_main};
use rand::{Rng, SeedableRng};
use shipcast::waves::field::{Region, WaveField};
use shipcast::waves::observe::{Grid, GridOptions, from_grids};
use shipcast::waves::sea::{SeaState, Spreading, realize_all};
use std::hint::black_box;

fn scans() -> Vec<Grid> {
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
    (0..3)
        .map(|s| {
            let t = 2.0 * s as f64;
            let mut values = vec![0.0; pts.len()];
            field.elevation(&pts, t, &mut values);
            for v in values.iter_mut() {
                // uniform noise of 5 cm standard deviation
                *v += 0.05 * 3f64.sqrt() * (2.0 * rng.random::<f64>() - 1.0);
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
    let grids = scans();
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
    g.finish();
}

criterion_group!(radar, benches);
criterion_main!(radar);
