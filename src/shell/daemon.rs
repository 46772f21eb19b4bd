//! The forecasting daemon (shell): the tokio loop, the compute thread, systemd, recording.
//!
//! The decisions are the engine's ([`crate::engine::Engine`]: what to drop, when a forecast is
//! possible, its flags and horizon, the status, against a clock it is given; [`Computer`] runs a
//! forecast job). [`run`] feeds them from iceoryx2 and a wall-clock cadence; replay feeds the same two
//! from a log's clock: one code path.
//!
//! Threads: the tokio runtime owns the engine and the cadence; the iceoryx2 input and output threads
//! ([`crate::shell::ipc`]) bridge to it with channels; the forecast itself runs on a compute thread of its own
//! so a slow forecast never blocks the ports. A forecast that is still running when the next tick
//! comes is counted as an overrun and that tick is skipped (no pile-up). Every tick publishes a status;
//! a forecast is published only when the inputs allow one (see [`crate::engine::message::flags`]).

use crate::engine::{Computer, Done, Engine, Job, MotionSet, describe_step, fits_the_wire, rom_options, watchdog_fits};
use crate::hydro::VesselSystem;
use crate::rom::TimeModel;
use crate::shell::config::ShipcastConfig;
use crate::shell::ipc::wire::{MotionSample, SCHEMA_VERSION};
use crate::shell::ipc::{self, Input, Names, Output};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

pub type Error = Box<dyn std::error::Error + Send + Sync>;

/// Wall clock, UNIX seconds.
pub fn wall_s() -> f64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map(|d| d.as_secs_f64())
        .unwrap_or(0.0)
}

pub use crate::shell::config::FAULT_ENV;

fn compute_thread(
    mut computer: Computer,
    jobs: std::sync::mpsc::Receiver<(Job, Instant)>,
    done: tokio::sync::mpsc::Sender<Done>,
    fault: Option<String>,
) -> std::thread::JoinHandle<()> {
    std::thread::Builder::new()
        .name("shipcast-compute".into())
        .spawn(move || {
            while let Ok((job, sent)) = jobs.recv() {
                match fault.as_deref() {
                    Some("compute-panic") => {
                        panic!("{FAULT_ENV}=compute-panic: the compute thread panics on its first job")
                    }
                    Some("compute-hang") => loop {
                        // a computation that never ends
                        std::thread::park();
                    },
                    _ => {}
                }
                let t = Instant::now();
                let mut msg = computer.run(job, || t.elapsed().as_secs_f64() * 1e3);
                msg.times.queued_ms = t.duration_since(sent).as_secs_f64() * 1e3;
                if done.blocking_send(msg).is_err() {
                    break;
                }
                // the in-situ tuning's work, once the forecast is on its way
                computer.tune();
            }
        })
        .expect("spawning the compute thread")
}

/// The model and the engine of a configuration, built and logged.
fn build(cfg: &ShipcastConfig, sys: &VesselSystem) -> Result<(TimeModel, Engine), Error> {
    let t_build = Instant::now();
    let model = TimeModel::new(sys, rom_options(cfg, sys))?;
    let engine = Engine::new(cfg, sys, &model);
    tracing::info!(
        vessels = sys.spec.bodies.len(),
        active_dofs = model.n(),
        memory_s = engine.memory_s(),
        step = %describe_step(cfg, sys),
        build_s = t_build.elapsed().as_secs_f64(),
        "model ready"
    );
    Ok((model, engine))
}

/// The daemon's recorder (`[record]`), or None when it records nothing or cannot (logged).
fn open_recorder(cfg: &ShipcastConfig, sys: &VesselSystem) -> Option<crate::shell::record::RotatingRecorder> {
    if cfg.record.dir.is_empty() {
        return None;
    }
    let dir = cfg.dir.join(&cfg.record.dir);
    match crate::shell::record::RotatingRecorder::new(
        &dir,
        cfg.record.rotate_mb,
        cfg.record.rotate_s,
        crate::shell::record::LogInfo::of(cfg, &cfg.system.file, sys, "daemon"),
    ) {
        Ok(r) => Some(r),
        Err(e) => {
            tracing::error!("recording disabled: {e}");
            None
        }
    }
}

/// One record into the recording; a write error ends the recording (logged), never the daemon.
fn record(recorder: &mut Option<crate::shell::record::RotatingRecorder>, t: f64, r: crate::shell::record::Record) {
    if let Some(rec) = recorder.as_mut()
        && let Err(e) = rec.record(t, &r)
    {
        tracing::error!("recording stopped: {e}");
        *recorder = None;
    }
}

/// An input as it arrived, into the recording.
fn record_input(recorder: &mut Option<crate::shell::record::RotatingRecorder>, t: f64, msg: &Input) {
    use crate::shell::record::{MotionRecord, Record, WavesRecord};
    if recorder.is_none() {
        return;
    }
    match msg {
        Input::Motion(m) => record(
            recorder,
            t,
            Record::Motion(MotionRecord {
                vessel: m.vessel,
                time_s: m.time_s,
                x: m.x,
                v: m.v,
            }),
        ),
        Input::Waves(f) => record(recorder, t, Record::Waves(WavesRecord::of(f))),
        Input::Navigation(n) => record(
            recorder,
            t,
            Record::Navigation(crate::shell::record::NavigationRecord::of(n)),
        ),
        Input::Elevation(scan) => record(
            recorder,
            t,
            Record::Elevation(Box::new(crate::shell::record::GridRecord::of_scan(scan))),
        ),
        // the link's health changes no forecast
        Input::Rejected(_) | Input::Link(_) => {}
    }
}

/// The daemon's iceoryx2 threads and its compute thread, started and ready, and the channels to them.
struct Threads {
    in_rx: tokio::sync::mpsc::Receiver<ipc::Arrived>,
    out_tx: std::sync::mpsc::Sender<Output>,
    job_tx: std::sync::mpsc::Sender<(Job, Instant)>,
    done_rx: tokio::sync::mpsc::Receiver<Done>,
    input: std::thread::JoinHandle<()>,
    output: std::thread::JoinHandle<()>,
    compute: std::thread::JoinHandle<()>,
}

impl Threads {
    /// Starts the input and output threads (waiting until both are ready) and the compute thread.
    fn start(
        names: &Names,
        computer: Computer,
        stop: &Arc<AtomicBool>,
        clock: impl Fn() -> f64 + Send + 'static,
    ) -> Result<Threads, Error> {
        let (in_tx, in_rx) = tokio::sync::mpsc::channel::<ipc::Arrived>(8192);
        let (out_tx, out_rx) = std::sync::mpsc::channel::<Output>();
        let (ready_tx, ready_rx) = std::sync::mpsc::channel();
        let input = ipc::spawn_input(names.clone(), in_tx, clock, stop.clone(), ready_tx.clone());
        let output = ipc::spawn_output(names.clone(), out_rx, ready_tx);
        for _ in 0..2 {
            ready_rx
                .recv()
                .map_err(|_| "an iceoryx2 thread ended before it was ready")??;
        }
        let (job_tx, job_rx) = std::sync::mpsc::channel::<(Job, Instant)>();
        let (done_tx, done_rx) = tokio::sync::mpsc::channel::<Done>(4);
        let compute = compute_thread(computer, job_rx, done_tx, std::env::var(FAULT_ENV).ok());
        Ok(Threads {
            in_rx,
            out_tx,
            job_tx,
            done_rx,
            input,
            output,
            compute,
        })
    }
}

/// Resolves on SIGINT, SIGTERM or SIGHUP (each a clean stop), logging which: the shutdown `run` is
/// given by the binary. SIGHUP (a closed terminal or SSH session) stops as SIGTERM does; the
/// configuration is read at start only, so a restart is how it is reloaded.
pub fn shutdown_signals() -> Result<impl std::future::Future<Output = ()>, Error> {
    use tokio::signal::unix::{SignalKind, signal};
    let mut sigterm = signal(SignalKind::terminate())?;
    let mut sighup = signal(SignalKind::hangup())?;
    Ok(async move {
        tokio::select! {
            _ = tokio::signal::ctrl_c() => tracing::info!("SIGINT: stopping"),
            _ = sigterm.recv() => tracing::info!("SIGTERM: stopping"),
            _ = sighup.recv() => tracing::info!("SIGHUP: stopping (restart shipcast to reload its configuration)"),
        }
    })
}

/// Runs the daemon until `shutdown` resolves (a clean stop: a last status with `running = 0`, exit 0;
/// the binary passes [`shutdown_signals`], a test any future). Ends with an error (a non-zero exit:
/// systemd restarts it) if the compute thread dies. `stop` is set when it stops, for the input thread.
pub async fn run(
    cfg: ShipcastConfig,
    sys: VesselSystem,
    stop: Arc<AtomicBool>,
    shutdown: impl std::future::Future<Output = ()>,
) -> Result<(), Error> {
    let mut watchdog_usec = 0u64;
    let watchdog = sd_notify::watchdog_enabled(false, &mut watchdog_usec);
    watchdog_fits(cfg.forecast.period_s, watchdog.then_some(watchdog_usec as f64 / 1e6))?;
    fits_the_wire(&sys)?;
    let t_ready = Instant::now();
    let (model, mut engine) = build(&cfg, &sys)?;
    let names = Names {
        prefix: cfg.ipc.service_prefix.clone(),
    };
    let start = Instant::now();
    // the engine's clock: monotonic, in UNIX seconds from the wall clock at the start (a recording's
    // log times are this clock, so they line up with the ship's other logs)
    let clock_anchor_s = wall_s();
    let clock = move || clock_anchor_s + start.elapsed().as_secs_f64();
    let mut computer = Computer::new(model, &sys, &cfg);
    let state_path = crate::shell::state::path(&cfg);
    if let Some(p) = &state_path
        && warm_start(&mut engine, p, clock())
    {
        computer.resume_tuning(engine.roll_tuning());
    }
    let mut th = Threads::start(&names, computer, &stop, clock)?;
    let _ = sd_notify::notify(false, &[sd_notify::NotifyState::Ready]);
    tracing::info!(
        prefix = %names.prefix,
        period_s = cfg.forecast.period_s,
        ready_s = t_ready.elapsed().as_secs_f64(),
        "shipcast running"
    );
    let period_s = cfg.forecast.period_s;
    // the cadence follows the motion (`Cadence::due`); this timer only looks whether a tick is due
    // without it (no motion, or the vessels' samples never together)
    let mut look = tokio::time::interval(Duration::from_secs_f64((period_s / 4.0).min(LATE_TICK_S)));
    look.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Skip);
    let mut c = Cadence {
        period_s,
        watchdog,
        // the watchdog is fed while the compute thread keeps up: a job outstanding for longer than
        // this is a hung computation, and systemd restarts the service
        hung_after_s: hung_after_s(period_s, watchdog.then_some(watchdog_usec as f64 / 1e6)),
        outstanding: None,
        hung: false,
        failure: None,
        // recording: inputs, ticks and forecasts, log time = the engine's clock (replay retakes every
        // decision); a write error is logged and ends the recording, never the daemon
        recorder: open_recorder(&cfg, &sys),
        state: state_path.clone().map(|p| (p, cfg.state.every_s, clock())),
        last_tick_s: f64::NEG_INFINITY,
        last_set: None,
        build_ms: 0.0,
    };
    tokio::pin!(shutdown);
    loop {
        tokio::select! {
            _ = &mut shutdown => break,
            msg = th.in_rx.recv() => {
                // the input's arrival (the input thread's clock), not when the loop came to it
                let Some((msg, t)) = msg else { break };
                record_input(&mut c.recorder, t, &msg);
                let motion = matches!(msg, Input::Motion(_));
                {
                    let _span = tracing::debug_span!("input", motion).entered();
                    engine.input(msg, t);
                }
                let now = clock();
                if motion && c.due(&engine, now) && !c.tick(&mut engine, &th, now) {
                    break;
                }
            }
            done = th.done_rx.recv() => {
                let Some(d) = done else {
                    c.compute_ended();
                    break;
                };
                c.done(&mut engine, &th, d, clock());
            }
            _ = look.tick() => {
                let t = clock();
                if c.due(&engine, t) && !c.tick(&mut engine, &th, t) {
                    break;
                }
            }
        }
    }
    stop.store(true, Ordering::Relaxed);
    let _ = th.out_tx.send(Output::Status(engine.status(clock(), wall_s(), false)));
    if let Some(p) = &state_path
        && c.failure.is_none()
    {
        keep_state(p, &engine.state(clock()));
    }
    finish(th, c.recorder, &engine, c.hung);
    match c.failure {
        Some(why) => Err(why.to_string().into()),
        None => Ok(()),
    }
}

/// A tick waits at most this long past its period for every vessel's newest sample, s.
const LATE_TICK_S: f64 = 0.05;

/// How much earlier than the last a sample may arrive after its stamp and still start its tick, s (the
/// received stage's p99 is about 1 ms: `tools/latency/measure.py`).
const ARRIVAL_JITTER_S: f64 = 0.01;

/// The daemon loop's cadence and what it keeps beside the engine: the watchdog, the job outstanding,
/// the recorder, the learnt state's file.
struct Cadence {
    period_s: f64,
    watchdog: bool,
    hung_after_s: f64,
    outstanding: Option<Instant>,
    hung: bool,
    failure: Option<&'static str>,
    recorder: Option<crate::shell::record::RotatingRecorder>,
    /// Where the learnt state is kept, how often, and when it was last written (engine clock).
    state: Option<(std::path::PathBuf, f64, f64)>,
    last_tick_s: f64,
    /// Every vessel's newest motion at the last tick, when all were in.
    last_set: Option<MotionSet>,
    /// How long the outstanding job took to make on the loop, ms.
    build_ms: f64,
}

impl Cadence {
    /// Whether a tick is due at `t` ([`tick_due`]).
    fn due(&self, engine: &Engine, t: f64) -> bool {
        tick_due(
            t - self.last_tick_s,
            self.period_s,
            engine.motion_complete(),
            self.last_set,
        )
    }

    /// One tick at `t`: the watchdog, the job, the status, the learnt state; false when the compute
    /// thread has ended.
    fn tick(&mut self, engine: &mut Engine, th: &Threads, t: f64) -> bool {
        self.last_tick_s = t;
        self.last_set = engine.motion_complete();
        if th.compute.is_finished() {
            self.compute_ended();
            return false;
        }
        let busy_s = self.outstanding.map_or(0.0, |o| o.elapsed().as_secs_f64());
        if busy_s > self.hung_after_s && !self.hung {
            self.hung = true;
            tracing::error!(
                busy_s,
                "the compute thread has been on one forecast for more than {} s (hung): {}",
                self.hung_after_s,
                if self.watchdog {
                    "the watchdog is no longer fed, so that systemd restarts shipcast"
                } else {
                    "no watchdog is set (systemd's WatchdogSec) to restart shipcast"
                }
            );
        }
        if self.watchdog && !self.hung {
            let _ = sd_notify::notify(false, &[sd_notify::NotifyState::Watchdog]);
        }
        let rec = crate::shell::record::Record::Tick(crate::shell::record::TickRecord { clock_s: t });
        record(&mut self.recorder, t, rec);
        let _span = tracing::debug_span!("tick", clock_s = t).entered();
        let building = Instant::now();
        if let Some(job) = engine.tick(t) {
            self.build_ms = building.elapsed().as_secs_f64() * 1e3;
            let _ = th.job_tx.send((job, Instant::now()));
            self.outstanding = Some(Instant::now());
        }
        let _ = th.out_tx.send(Output::Status(engine.status(t, wall_s(), true)));
        if let Some((p, every_s, saved_s)) = &mut self.state
            && t - *saved_s >= *every_s
        {
            *saved_s = t;
            let _span = tracing::debug_span!("snapshot").entered();
            let (p, state) = (p.clone(), engine.state(t));
            // written off the loop: a few megabytes
            tokio::task::spawn_blocking(move || keep_state(&p, &state));
        }
        true
    }

    /// A finished job: published (and recorded), the watchdog fed again.
    fn done(&mut self, engine: &mut Engine, th: &Threads, mut d: Done, t: f64) {
        self.outstanding = None;
        d.times.build_ms = self.build_ms;
        if self.hung {
            tracing::warn!("the compute thread finished its forecast at last: the watchdog is fed again");
            self.hung = false;
        }
        let _span = tracing::debug_span!("publish", t0_s = d.header.issue_time_s).entered();
        if let Some(out) = engine.done(d, t) {
            if let Output::Forecast(h, v) = &out {
                let rec = crate::shell::record::Record::Forecast(crate::shell::record::ForecastRecord::of(h, v));
                record(&mut self.recorder, t, rec);
            }
            let _ = th.out_tx.send(out);
        }
    }

    fn compute_ended(&mut self) {
        tracing::error!(
            "the compute thread has ended (a panic): stopping, with an error, so that systemd restarts shipcast"
        );
        self.failure = Some("the compute thread ended unexpectedly");
    }
}

/// Whether a tick is due, `since_s` after the last on the loop's clock: every vessel's newest sample
/// in (`now`), stamped a period (less the stamps' jitter allowance) after those of the last tick
/// (`last`), and arrived a period (less [`ARRIVAL_JITTER_S`]) after them; or, whatever came,
/// [`LATE_TICK_S`] past a period on the loop's clock. A tick thus comes with the sample that completes
/// it and keeps the sensors' phase (a rule on the loop's clock drifts behind them by the loop's delays
/// and then waits for its look timer), and data faster than real time, or a backlog delivered at once,
/// starts one forecast a period, not several.
fn tick_due(since_s: f64, period_s: f64, now: Option<MotionSet>, last: Option<MotionSet>) -> bool {
    if since_s >= period_s + LATE_TICK_S {
        return true;
    }
    match (now, last) {
        (Some(n), Some(l)) => {
            n.stamp_s - l.stamp_s >= period_s - n.jitter_s && n.arrival_s - l.arrival_s >= period_s - ARRIVAL_JITTER_S
        }
        (Some(_), None) => since_s >= period_s,
        (None, _) => false,
    }
}

/// Takes the learnt state kept at `path` into the engine, or says why not (the daemon then starts
/// cold); whether it was taken.
fn warm_start(engine: &mut Engine, path: &std::path::Path, clock_s: f64) -> bool {
    match crate::shell::state::read(path) {
        Ok(None) => tracing::info!(path = %path.display(), "no state kept: a cold start"),
        Ok(Some(s)) => {
            let age_s = clock_s - s.clock_s;
            match engine.restore(s, clock_s) {
                Ok(()) => {
                    tracing::info!(path = %path.display(), age_s, "warm start: the learnt state kept {age_s:.1} s ago taken back");
                    return true;
                }
                Err(why) => tracing::warn!(path = %path.display(), "{why}: refused, a cold start"),
            }
        }
        Err(e) => tracing::warn!("{e}: refused, a cold start"),
    }
    false
}

/// Writes the learnt state, logging a failure (the daemon goes on).
fn keep_state(path: &std::path::Path, state: &crate::engine::state::EngineState) {
    if let Err(e) = crate::shell::state::write(path, state) {
        tracing::warn!("the learnt state was not kept: {e}");
    }
}

/// The compute thread is hung when a job has been outstanding this long, s: with a watchdog, its
/// interval less two periods (the last ping before it then lands inside the interval, and systemd acts
/// one interval later), at least half of it; without, 30 s (said, nothing else acts on it).
fn hung_after_s(period_s: f64, watchdog_s: Option<f64>) -> f64 {
    match watchdog_s {
        Some(w) => (w - 2.0 * period_s).max(w / 2.0),
        None => 30.0,
    }
}

/// A clean shutdown after the last status: the recording closed, systemd told, the threads joined (a
/// hung compute thread is left to the process's end).
fn finish(th: Threads, recorder: Option<crate::shell::record::RotatingRecorder>, engine: &Engine, hung: bool) {
    drop(th.out_tx);
    drop(th.job_tx);
    drop(th.in_rx);
    if let Some(r) = recorder
        && let Err(e) = r.finish()
    {
        tracing::error!("closing the recording: {e}");
    }
    let _ = sd_notify::notify(false, &[sd_notify::NotifyState::Stopping]);
    let _ = th.output.join();
    let _ = th.input.join();
    if !hung {
        let _ = th.compute.join();
    }
    let c = &engine.counters;
    tracing::info!(
        forecasts = c.forecasts,
        overruns = c.overruns,
        samples = c.samples,
        "shipcast stopped"
    );
}

/// A motion sample on the wire from the simulator's.
pub fn to_wire(s: &crate::sim::ImuSample) -> MotionSample {
    MotionSample {
        schema_version: SCHEMA_VERSION,
        vessel: s.vessel as u32,
        time_s: s.time_s,
        x: s.x,
        v: s.v,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn set(stamp_s: f64, arrival_s: f64) -> Option<MotionSet> {
        Some(MotionSet {
            stamp_s,
            jitter_s: 0.05,
            arrival_s,
        })
    }

    /// A 10 Hz stream whose samples arrive 0-3 ms after their stamps, a look timer every 50 ms, and a
    /// loop that comes to one sample 30 ms late (busy): each tick comes with a sample, and the ticks'
    /// stamps are a period apart all run long. A rule on the loop's clock alone drifts behind whenever
    /// a sample arrives a hair early, or the loop is late once, and then ticks on its look timer.
    #[test]
    fn the_cadence_ticks_with_the_sample_a_period_after_the_last() {
        let period_s = 1.0;
        let mut last_tick_s = f64::NEG_INFINITY;
        let (mut newest, mut last) = (None, None);
        let mut ticks = vec![];
        // events: (loop time, Some((stamp, arrival)) for a sample, None for the look timer)
        let mut events: Vec<(f64, Option<(f64, f64)>)> = (0..3000)
            .map(|k| {
                let stamp = k as f64 * 0.1;
                // a deterministic jitter of 0-3 ms
                let arrival = stamp + 0.003 * ((k * 7919 % 13) as f64 / 12.0);
                let busy = if k == 1200 { 0.030 } else { 0.0 };
                (arrival + busy, Some((stamp, arrival)))
            })
            .collect();
        events.extend((0..6000).map(|j| (j as f64 * 0.05 + 0.0271, None)));
        events.sort_by(|a, b| a.0.total_cmp(&b.0));
        for (t, sample) in events {
            if let Some((s, a)) = sample {
                newest = set(s, a);
            }
            if tick_due(t - last_tick_s, period_s, newest, last) {
                last_tick_s = t;
                last = newest;
                ticks.push((t, newest.map_or(f64::NAN, |n| n.stamp_s)));
            }
        }
        assert!(ticks.len() >= 295, "{} ticks", ticks.len());
        for w in ticks.windows(2).skip(1) {
            let (a, b) = (w[0], w[1]);
            assert!(
                (b.1 - a.1 - period_s).abs() < 1e-9,
                "ticks' stamps {} s apart",
                b.1 - a.1
            );
            // the tick comes with its sample (within the 3 ms jitter of its arrival; the busy one 30 ms)
            let late_s = if (b.1 - 120.0).abs() < 1e-9 { 0.0331 } else { 0.0031 };
            assert!(
                b.0 - b.1 <= late_s,
                "tick {} s after its sample's stamp {}",
                b.0 - b.1,
                b.1
            );
        }
    }

    #[test]
    fn without_a_complete_set_a_tick_comes_late_and_fast_data_ticks_a_period_apart() {
        // the other vessel's sample missing: late by LATE_TICK_S, not never
        assert!(!tick_due(1.0 + 0.5 * LATE_TICK_S, 1.0, None, set(0.0, 0.0)));
        assert!(tick_due(1.0 + LATE_TICK_S, 1.0, None, set(0.0, 0.0)));
        // data four times faster than real time (or a backlog): a period of arrivals, not of stamps
        assert!(!tick_due(0.5, 1.0, set(5.0, 10.5), set(3.0, 10.0)));
        assert!(!tick_due(0.98, 1.0, set(7.0, 10.98), set(3.0, 10.0)));
        assert!(tick_due(0.995, 1.0, set(7.0, 10.995), set(3.0, 10.0)));
        // the first tick: a period after the start
        assert!(tick_due(1.0, 1.0, set(3.0, 10.0), None));
    }
}
