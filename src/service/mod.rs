//! The forecasting daemon (shell): configuration, motion history, cadence, health, shutdown.
//!
//! Threads: the tokio runtime owns the state (histories, the newest wave field, counters) and the
//! cadence; the iceoryx2 input and output threads ([`crate::ipc`]) bridge to it with channels; the
//! forecast itself runs on a compute thread of its own so a slow forecast never blocks the ports. A
//! forecast that is still running when the next tick comes is counted as an overrun and that tick is
//! skipped (no pile-up). Every tick publishes a status; a forecast is published only when the inputs
//! allow one (see [`crate::ipc::wire::flags`]).

pub mod config;
pub mod history;

use crate::hydro::VesselSystem;
use crate::ipc::wire::{self, ForecastHeader, MAX_VESSELS, MotionSample, SCHEMA_VERSION, Status, flags};
use crate::ipc::{self, Input, Names, Output};
use crate::rom::{ForecastRequest, Forecaster, Memory, RadiationMethod, RomOptions, TimeModel};
use crate::waves::field::{WaveField, heading_from_compass_deg};
use crate::waves::horizon;
use config::ShipcastConfig;
use history::{Drop, History, Sample};
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

/// The model options a configuration asks for.
pub fn rom_options(cfg: &ShipcastConfig) -> RomOptions {
    RomOptions {
        dt_s: cfg.forecast.dt_s,
        radiation: if cfg.forecast.radiation == "state-space" {
            RadiationMethod::StateSpace
        } else {
            RadiationMethod::Convolution
        },
        memory_s: cfg.forecast.memory_s,
        ..RomOptions::default()
    }
}

/// Earth position (east, north) of each body's reference point and the system's heading (rad,
/// counterclockwise from east).
pub fn vessel_positions(cfg: &ShipcastConfig, sys: &VesselSystem) -> (Vec<[f64; 2]>, f64) {
    let h = heading_from_compass_deg(cfg.site.heading_deg);
    let (s, c) = h.sin_cos();
    let o = [cfg.site.origin_east_m, cfg.site.origin_north_m];
    let pos = sys
        .spec
        .bodies
        .iter()
        .map(|b| {
            let (x, y) = (b.position_m.x, b.position_m.y);
            [o[0] + c * x - s * y, o[1] + s * x + c * y]
        })
        .collect();
    (pos, h)
}

/// One forecast job for the compute thread.
struct Job {
    t0_s: f64,
    x0: Vec<f64>,
    v0: Vec<f64>,
    velocities: Vec<Vec<f64>>,
    waves: Vec<crate::waves::WaveComponent>,
    header: ForecastHeader,
}

struct Done {
    header: ForecastHeader,
    values: Option<Vec<f64>>,
    compute_ms: f64,
    error: Option<String>,
}

fn compute_thread(
    model: TimeModel,
    n_bodies: usize,
    horizon_s: f64,
    jobs: std::sync::mpsc::Receiver<Job>,
    done: tokio::sync::mpsc::Sender<Done>,
) -> std::thread::JoinHandle<()> {
    std::thread::Builder::new()
        .name("shipcast-compute".into())
        .spawn(move || {
            let mut fc = Forecaster::new();
            while let Ok(job) = jobs.recv() {
                let t = Instant::now();
                let result = Memory::from_history(&model, &job.velocities).and_then(|memory| {
                    let req = ForecastRequest {
                        x0: &job.x0,
                        v0: &job.v0,
                        memory: &memory,
                        waves: &job.waves,
                        horizon_s,
                        ramp_s: 0.0,
                    };
                    fc.forecast(&model, &req).map(|f| {
                        let mut values = Vec::with_capacity(6 * n_bodies * (f.steps + 1));
                        for i in 0..6 * n_bodies {
                            values.extend((0..=f.steps).map(|k| f.at(k, i)));
                        }
                        (values, f.steps)
                    })
                });
                let compute_ms = t.elapsed().as_secs_f64() * 1e3;
                let mut header = job.header;
                header.compute_ms = compute_ms;
                header.issue_time_s = job.t0_s;
                let msg = match result {
                    Ok((values, steps)) => {
                        header.steps = steps as u32;
                        Done {
                            header,
                            values: Some(values),
                            compute_ms,
                            error: None,
                        }
                    }
                    Err(e) => Done {
                        header,
                        values: None,
                        compute_ms,
                        error: Some(e.to_string()),
                    },
                };
                if done.blocking_send(msg).is_err() {
                    break;
                }
            }
        })
        .expect("spawning the compute thread")
}

#[derive(Default)]
struct Counters {
    forecasts: u64,
    overruns: u64,
    samples: u64,
    wave_fields: u64,
    nonfinite: u64,
    late: u64,
    duplicate: u64,
    rejected: u64,
}

/// Runs the daemon until SIGINT/SIGTERM or `stop` is set. `on_ready` is called once the ports are up.
pub async fn run(cfg: ShipcastConfig, sys: VesselSystem, stop: Arc<AtomicBool>) -> Result<(), Error> {
    let n_bodies = sys.spec.bodies.len();
    if n_bodies > MAX_VESSELS {
        return Err(format!("{n_bodies} vessels: the wire format carries at most {MAX_VESSELS}").into());
    }
    let t_build = Instant::now();
    let model = TimeModel::new(&sys, rom_options(&cfg))?;
    let taps = match &model.kernel {
        crate::rom::model::Kernel::Convolution { taps, .. } => *taps,
        crate::rom::model::Kernel::StateSpace { .. } => {
            (cfg.forecast.memory_s.unwrap_or(120.0) / cfg.forecast.dt_s).round() as usize
        }
    };
    let memory_s = taps as f64 * cfg.forecast.dt_s;
    tracing::info!(
        vessels = n_bodies,
        active_dofs = model.n(),
        memory_s,
        build_s = t_build.elapsed().as_secs_f64(),
        "model ready"
    );
    let (positions, heading) = vessel_positions(&cfg, &sys);
    let names = Names {
        prefix: cfg.ipc.service_prefix.clone(),
    };
    let (in_tx, mut in_rx) = tokio::sync::mpsc::channel::<Input>(8192);
    let (out_tx, out_rx) = std::sync::mpsc::channel::<Output>();
    let (ready_tx, ready_rx) = std::sync::mpsc::channel();
    let input = ipc::spawn_input(names.clone(), in_tx, stop.clone(), ready_tx.clone());
    let output = ipc::spawn_output(names.clone(), out_rx, ready_tx);
    for _ in 0..2 {
        ready_rx
            .recv()
            .map_err(|_| "an iceoryx2 thread ended before it was ready")??;
    }
    let (job_tx, job_rx) = std::sync::mpsc::channel::<Job>();
    let (done_tx, mut done_rx) = tokio::sync::mpsc::channel::<Done>(4);
    let active = model.active.clone();
    let n_active = model.n();
    let compute = compute_thread(model, n_bodies, cfg.forecast.horizon_s, job_rx, done_tx);
    let keep_s = memory_s + cfg.forecast.history_margin_s;
    let mut hist: Vec<History> = (0..n_bodies).map(|_| History::new(keep_s)).collect();
    let mut arrival: Vec<Option<Instant>> = vec![None; n_bodies];
    let mut field: Option<WaveField> = None;
    let mut c = Counters::default();
    let mut busy = false;
    let mut last_forecast_time = -1.0;
    let mut last_compute_ms = 0.0;
    let mut last_horizon = [0.0; MAX_VESSELS];
    let mut state_flags = 0u32;
    let _ = sd_notify::notify(false, &[sd_notify::NotifyState::Ready]);
    let mut watchdog_usec = 0u64;
    let watchdog = sd_notify::watchdog_enabled(false, &mut watchdog_usec);
    tracing::info!(prefix = %names.prefix, period_s = cfg.forecast.period_s, "shipcast running");
    let mut tick = tokio::time::interval(Duration::from_secs_f64(cfg.forecast.period_s));
    tick.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Skip);
    let mut sigterm = tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate())?;
    let dt = cfg.forecast.dt_s;
    let status = |flags_now: u32,
                  hist: &[History],
                  arrival: &[Option<Instant>],
                  field: &Option<WaveField>,
                  c: &Counters,
                  last_forecast_time: f64,
                  last_compute_ms: f64,
                  last_horizon: [f64; MAX_VESSELS],
                  running: bool|
     -> Status {
        let now_data = hist
            .iter()
            .filter_map(|h| h.newest_time_s())
            .fold(f64::NEG_INFINITY, f64::max);
        let mut s = Status {
            schema_version: SCHEMA_VERSION,
            flags: flags_now,
            time_s: if now_data.is_finite() { now_data } else { -1.0 },
            wall_time_s: wall_s(),
            wave_age_s: match field {
                Some(f) if now_data.is_finite() => now_data - f.time_s,
                _ => -1.0,
            },
            last_forecast_time_s: last_forecast_time,
            last_compute_ms,
            horizon_s: last_horizon,
            forecasts: c.forecasts,
            overruns: c.overruns,
            samples: c.samples,
            wave_fields: c.wave_fields,
            dropped_nonfinite: c.nonfinite,
            dropped_late: c.late,
            dropped_duplicate: c.duplicate,
            running: running as u32,
            ..Status::default()
        };
        for (b, h) in hist.iter().enumerate() {
            s.motion_age_s[b] = arrival[b].map(|a| a.elapsed().as_secs_f64()).unwrap_or(-1.0);
            s.motion_rate_hz[b] = h.rate_hz();
        }
        s
    };
    loop {
        tokio::select! {
            _ = tokio::signal::ctrl_c() => { tracing::info!("SIGINT: stopping"); break; }
            _ = sigterm.recv() => { tracing::info!("SIGTERM: stopping"); break; }
            msg = in_rx.recv() => {
                let Some(msg) = msg else { break };
                match msg {
                    Input::Motion(m) => {
                        c.samples += 1;
                        let b = m.vessel as usize;
                        if m.schema_version != SCHEMA_VERSION || b >= n_bodies {
                            c.rejected += 1;
                            continue;
                        }
                        match hist[b].push(Sample { time_s: m.time_s, x: m.x, v: m.v }) {
                            Ok(()) => arrival[b] = Some(Instant::now()),
                            Err(Drop::NonFinite) => c.nonfinite += 1,
                            Err(Drop::Late) => c.late += 1,
                            Err(Drop::Duplicate) => c.duplicate += 1,
                        }
                    }
                    Input::Waves(f) => {
                        c.wave_fields += 1;
                        let f = f.pruned(cfg.forecast.wave_variance_kept);
                        if field.as_ref().is_none_or(|old| f.time_s > old.time_s) {
                            field = Some(f);
                        }
                    }
                    Input::Rejected(why) => {
                        c.rejected += 1;
                        tracing::warn!("input rejected: {why}");
                    }
                }
            }
            done = done_rx.recv() => {
                let Some(d) = done else { break };
                busy = false;
                last_compute_ms = d.compute_ms;
                match (d.values, d.error) {
                    (Some(values), _) => {
                        c.forecasts += 1;
                        last_forecast_time = d.header.issue_time_s;
                        last_horizon = d.header.horizon_s;
                        let _ = out_tx.send(Output::Forecast(d.header, values));
                    }
                    (None, e) => {
                        state_flags |= flags::NUMERICAL;
                        tracing::warn!("forecast abandoned: {}", e.unwrap_or_default());
                    }
                }
            }
            _ = tick.tick() => {
                if watchdog {
                    let _ = sd_notify::notify(false, &[sd_notify::NotifyState::Watchdog]);
                }
                let mut fl = 0u32;
                // inputs
                let motion_ok: Vec<bool> = (0..n_bodies)
                    .map(|b| arrival[b].is_some_and(|a| a.elapsed().as_secs_f64() <= cfg.forecast.max_motion_age_s))
                    .collect();
                if arrival.iter().any(|a| a.is_none()) {
                    fl |= flags::NO_MOTION;
                }
                if motion_ok.iter().any(|ok| !ok) {
                    fl |= flags::STALE_MOTION;
                }
                let t0 = hist.iter().filter_map(|h| h.newest_time_s()).fold(f64::INFINITY, f64::min);
                let wave_age = field.as_ref().map(|f| t0 - f.time_s);
                match wave_age {
                    None => fl |= flags::NO_WAVES,
                    Some(a) if a.is_nan() || a > cfg.forecast.suppress_wave_age_s => fl |= flags::NO_WAVES | flags::STALE_WAVES,
                    Some(a) if a > cfg.forecast.max_wave_age_s => fl |= flags::STALE_WAVES,
                    _ => {}
                }
                let can = fl & (flags::NO_WAVES | flags::NO_MOTION | flags::STALE_MOTION) == 0 && t0.is_finite();
                if can && busy {
                    c.overruns += 1;
                } else if can {
                    // build the job from the histories at t0
                    let mut x0 = vec![0.0; n_active];
                    let mut v0 = vec![0.0; n_active];
                    let mut velocities = vec![vec![0.0; n_active]; taps.saturating_sub(1)];
                    let mut ok = true;
                    for b in 0..n_bodies {
                        let Some(r) = hist[b].resample(t0, dt, taps.saturating_sub(1), cfg.forecast.max_gap_s) else {
                            ok = false;
                            break;
                        };
                        if r.short { fl |= flags::HISTORY_SHORT; }
                        if r.gap { fl |= flags::HISTORY_GAP; }
                        for (row, &i) in active.iter().enumerate() {
                            if i / 6 == b && i < 6 * n_bodies {
                                x0[row] = r.x0[i % 6];
                                v0[row] = r.v0[i % 6];
                                for (m, v) in r.velocities.iter().enumerate() {
                                    velocities[m][row] = v[i % 6];
                                }
                            }
                        }
                    }
                    if let (true, Some(f)) = (ok, &field) {
                        let mut header = ForecastHeader {
                            schema_version: SCHEMA_VERSION,
                            n_vessels: n_bodies as u32,
                            dt_s: dt,
                            n_series: (6 * n_bodies) as u32,
                            flags: fl,
                            wave_time_s: f.time_s,
                            motion_time_s: t0,
                            ..ForecastHeader::default()
                        };
                        for (b, p) in positions.iter().enumerate() {
                            let h = horizon::of_field(f, *p, [0.0, 0.0], 0.0);
                            header.horizon_s[b] = (h.horizon_s - (t0 - f.time_s)).max(0.0);
                        }
                        let waves = f.for_vessel(positions_origin(&cfg), heading, t0);
                        if job_tx.send(Job { t0_s: t0, x0, v0, velocities, waves, header }).is_ok() {
                            busy = true;
                        }
                    }
                }
                state_flags = fl | (state_flags & flags::NUMERICAL);
                let _ = out_tx.send(Output::Status(status(
                    state_flags, &hist, &arrival, &field, &c, last_forecast_time, last_compute_ms, last_horizon, true,
                )));
                state_flags &= !flags::NUMERICAL;
            }
        }
    }
    // clean shutdown: the last status says so, then the ports go
    stop.store(true, Ordering::Relaxed);
    let _ = out_tx.send(Output::Status(status(
        state_flags,
        &hist,
        &arrival,
        &field,
        &c,
        last_forecast_time,
        last_compute_ms,
        last_horizon,
        false,
    )));
    drop(out_tx);
    drop(job_tx);
    drop(in_rx);
    let _ = sd_notify::notify(false, &[sd_notify::NotifyState::Stopping]);
    let _ = output.join();
    let _ = input.join();
    let _ = compute.join();
    tracing::info!(
        forecasts = c.forecasts,
        overruns = c.overruns,
        samples = c.samples,
        "shipcast stopped"
    );
    let _ = wire::SCHEMA_VERSION;
    Ok(())
}

/// The system's origin in the earth frame.
fn positions_origin(cfg: &ShipcastConfig) -> [f64; 2] {
    [cfg.site.origin_east_m, cfg.site.origin_north_m]
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
