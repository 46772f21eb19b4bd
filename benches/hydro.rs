//! Database-side costs: one frequency-domain solve of the two-ship demo (12 DOF, full coupling) and the
//! impulse response functions of its database. Setup (loading files) is outside the timing.

use criterion::{Criterion, criterion_group, criterion_main};
use shipcast::radiation::memory::system_irf;
use shipcast::rao::FrequencySolver;
use shipcast::shell::files::load_system;
use std::hint::black_box;
use std::path::Path;

fn benches(c: &mut Criterion) {
    let pair = load_system(Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/config/vessels/pair/system.toml"
    )))
    .expect("demo pair database")
    .system;
    let solver = FrequencySolver::new(&pair);
    c.bench_function("frequency_domain_rao_pair_12dof", |b| {
        b.iter(|| solver.rao(black_box(0.7321), black_box(2.5)).unwrap())
    });
    let mut g = c.benchmark_group("irf");
    g.sample_size(10);
    g.bench_function("impulse_response_pair_600s_dt0.05", |b| {
        b.iter(|| system_irf(black_box(&pair)))
    });
    g.finish();
}

criterion_group!(hydro, benches);
criterion_main!(hydro);
