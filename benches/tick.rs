//! One whole engine tick of the shipped two-ship demo (`config/shipcast.toml`: the moored pair, the
//! default step and memory, the band, the in-situ tuning on), as the daemon runs it once its motion
//! memory is full: `Engine::tick` (flags, start states from the estimators, pose, the wave field's known
//! leads, the model error's checks, the job), `Computer::run` (the forecast and its band) and
//! `Engine::done` (checks, learning, the header).
//! Setup, outside the timing: [`HISTORY_S`] of the demo simulated (`shipcast simulate --record`) and
//! replayed through the engine, which is restored from the state that left. Each iteration then gives
//! the engine the log's next second of inputs, as they came (untimed: the daemon's `received` stage),
//! times the tick at that second's end, and lets the computer take its tuning round (untimed: the
//! daemon does it after handing the forecast over).

use criterion::{Criterion, SamplingMode, criterion_group, criterion_main};
use shipcast::engine::{Computer, Engine, rom_options};
use shipcast::shell::ipc::Input;
use shipcast::shell::replay::{self, Record};
use std::path::Path;
use std::time::{Duration, Instant};

/// Simulated seconds before the first timed tick: the demo's 600 s motion memory full, the model
/// error checked, the tuning's cases kept.
const HISTORY_S: f64 = 620.0;
/// Simulated seconds after it, a tick each: more than the iterations criterion runs below.
const TICKED_S: f64 = 300.0;

fn feed(engine: &mut Engine, t: f64, r: &Record) {
    match r {
        Record::Motion(m) => engine.input(Input::Motion(m.to_wire()), t),
        Record::Navigation(n) => engine.input(Input::Navigation(n.to_wire()), t),
        Record::Waves(w) => engine.input(Input::Waves(w.field().expect("a field")), t),
        _ => {}
    }
}

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
        .args(["--duration", &(HISTORY_S + TICKED_S).to_string()])
        .status()
        .expect("shipcast simulate");
    assert!(status.success());
    let records = replay::read(&log).expect("the log").records;
    let split_s = records.first().expect("a record").0 + HISTORY_S;
    let (before, after): (Vec<_>, Vec<_>) = records.into_iter().partition(|(t, _)| *t <= split_s);
    let (_, state) = replay::drive_from(&cfg, &sys, &before, None, |_| {}, |_| {}).expect("replay");
    let model = shipcast::rom::TimeModel::new(&sys, rom_options(&cfg, &sys)).expect("model");
    let mut engine = Engine::new(&cfg, &sys, &model);
    let mut computer = Computer::new(model, &sys, &cfg);
    engine.restore(state, split_s).expect("the state");
    computer.resume_tuning(engine.roll_tuning());
    // the field the engine had: the newest before the restore point
    let newest_field = before.iter().rev().find(|(_, r)| matches!(r, Record::Waves(_)));
    let (wave_s, field) = newest_field.expect("a wave field");
    feed(&mut engine, *wave_s, field);
    let mut rest = after.into_iter().peekable();
    let mut now_s = split_s;
    let mut g = c.benchmark_group("engine_tick");
    g.sample_size(10)
        .sampling_mode(SamplingMode::Flat)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(5));
    g.bench_function("two_ship_demo", |b| {
        b.iter_custom(|iters| {
            let mut spent = Duration::ZERO;
            for _ in 0..iters {
                now_s += 1.0;
                assert!(rest.peek().is_some(), "the log ran out: lengthen TICKED_S");
                while let Some((t, r)) = rest.next_if(|(t, _)| *t <= now_s) {
                    feed(&mut engine, t, &r);
                }
                let start = Instant::now();
                let job = engine.tick(now_s).expect("a job");
                let done = computer.run(job, || 0.0);
                std::hint::black_box(engine.done(done, now_s));
                spent += start.elapsed();
                computer.tune();
            }
            spent
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
