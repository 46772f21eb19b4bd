//! One whole engine tick of the shipped two-ship demo (`config/shipcast.toml`: the moored pair, the
//! default step and memory, the band, the in-situ tuning on), as the daemon runs it: `Engine::tick`
//! (flags, start states from the estimators, pose, the wave field's known leads, the job),
//! `Computer::run` (the forecast and its band) and `Engine::done` (checks, learning, the header).
//! Setup, outside the timing: 150 s of the demo simulated (`shipcast simulate --record`) and replayed
//! through the engine but its last second; then the engine is restored from the state that left and
//! given the newest wave field and that second's inputs, and every iteration ticks at the log's end.

use criterion::{Criterion, criterion_group, criterion_main};
use shipcast::engine::{Computer, Engine, rom_options};
use shipcast::shell::ipc::Input;
use shipcast::shell::replay::{self, Record};
use std::path::Path;

/// Simulated seconds before the tick: the model error checked, the tuning's first cases kept.
const HISTORY_S: f64 = 150.0;

fn benches(c: &mut Criterion) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let config = root.join("config/shipcast.toml");
    let cfg = shipcast::shell::config::load(&config).expect("the demo's config");
    let sys = shipcast::shell::files::load_system(&cfg.dir.join(&cfg.system.file))
        .expect("the demo's system")
        .system;
    let dir = std::env::temp_dir().join(format!("shipcast-bench-tick-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let log = dir.join("demo.mcap");
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_shipcast"))
        .args([
            "simulate",
            "--config",
            config.to_str().unwrap(),
            "--record",
            log.to_str().unwrap(),
        ])
        .args(["--duration", &HISTORY_S.to_string()])
        .status()
        .expect("shipcast simulate");
    assert!(status.success());
    let records = replay::read(&log).expect("the log").records;
    let end_s = records.last().unwrap().0;
    // the state a second before the end, then that second's inputs as they came
    let (before, last): (Vec<_>, Vec<_>) = records.into_iter().partition(|(t, _)| *t <= end_s - 1.0);
    let (_, state) = replay::drive_from(&cfg, &sys, &before, None, |_| {}, |_| {}).expect("replay");
    let model = shipcast::rom::TimeModel::new(&sys, rom_options(&cfg, &sys)).expect("model");
    let mut engine = Engine::new(&cfg, &sys, &model);
    let mut computer = Computer::new(model, &sys, &cfg);
    engine.restore(state, end_s - 1.0).expect("the state");
    computer.resume_tuning(engine.roll_tuning());
    let newest_field = before.iter().rev().find_map(|(t, r)| match r {
        Record::Waves(w) => Some((*t, w.field().expect("a field"))),
        _ => None,
    });
    let (wave_s, field) = newest_field.expect("a wave field");
    engine.input(Input::Waves(field), wave_s);
    for (t, r) in &last {
        match r {
            Record::Motion(m) => engine.input(Input::Motion(m.to_wire()), *t),
            Record::Navigation(n) => engine.input(Input::Navigation(n.to_wire()), *t),
            Record::Waves(w) => engine.input(Input::Waves(w.field().expect("a field")), *t),
            _ => {}
        }
    }
    let mut g = c.benchmark_group("engine_tick");
    g.sample_size(20);
    g.bench_function("two_ship_demo", |b| {
        b.iter(|| {
            let job = engine.tick(end_s).expect("a job");
            let done = computer.run(job, || 0.0);
            engine.done(done, end_s).is_some()
        })
    });
    g.finish();
    let _ = std::fs::remove_dir_all(&dir);
}

criterion_group! {
    name = tick;
    // the summary is the figure (criterion's plots of so few samples fail to draw)
    config = Criterion::default().without_plots();
    targets = benches
}
criterion_main!(tick);
