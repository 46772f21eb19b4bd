//! `shipcast run`, `simulate`, `watch` and `demo`: the daemon and its companions (wiring only).

use super::{load_config, load_system};
use anyhow::{Context, Result, bail};
use clap::Args;
use shipcast::engine::vessel_positions;
use shipcast::hydro::{Dof, VesselSystem};
use shipcast::shell::config::ShipcastConfig;
use shipcast::shell::daemon::{self, to_wire};
use shipcast::shell::files;
use shipcast::shell::ipc::wire::{Status, flags};
use shipcast::shell::ipc::{ForecastSubscriber, Names, Received, SensorPublisher};
use shipcast::sim::{ImuSpec, RadarSpec, SimSpec, Simulation};
use shipcast::waves::field::heading_from_compass_deg;
use shipcast::waves::sea::{SeaState, Spreading};
use std::io::Write;
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

#[derive(Args, Debug)]
pub struct RunArgs {
    #[command(flatten)]
    pub config: super::ConfigArg,
}

#[derive(Args, Debug)]
pub struct SimulateArgs {
    #[command(flatten)]
    config: super::ConfigArg,
    /// Publish the sensor streams live over iceoryx2 (paced by the data clock / simulate.speed).
    #[arg(long)]
    publish: bool,
    /// Write the true motion (t_s and every body DOF, at the IMU rate) to this CSV.
    #[arg(long)]
    truth: Option<PathBuf>,
    /// Write the sensor streams and the truth to this log (MCAP), as fast as possible.
    #[arg(long, conflicts_with = "publish")]
    record: Option<PathBuf>,
    /// Simulated duration, s (default: simulate.duration_s).
    #[arg(long, allow_negative_numbers = true)]
    duration: Option<f64>,
    /// With --publish: publish this vessel's motion and navigation under another iceoryx2 prefix,
    /// VESSEL=PREFIX (the other ship's host, to try `shipcast link` on one machine); repeatable.
    #[arg(long = "vessel-prefix", value_name = "VESSEL=PREFIX", requires = "publish")]
    vessel_prefix: Vec<String>,
}

#[derive(Args, Debug)]
pub struct WatchArgs {
    #[command(flatten)]
    config: super::ConfigArg,
    /// Stop after N forecasts.
    #[arg(long, allow_negative_numbers = true)]
    count: Option<usize>,
    /// One JSON object a line.
    #[arg(long)]
    json: bool,
    /// Give up after this many seconds without a forecast (default: wait for ever).
    #[arg(long, allow_negative_numbers = true)]
    timeout: Option<f64>,
}

pub fn run(cfg: ShipcastConfig) -> Result<()> {
    let sys = load_system(&cfg)?;
    // the consoles and reports read `[operation]` from the same file: a channel the system does not
    // have is the file's error, said at start and not at the first console
    let vessels: Vec<String> = sys.spec.bodies.iter().map(|b| b.name.clone()).collect();
    cfg.operation_channels(&vessels, &sys.spec.external, &cfg.path)?;
    let rt = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(1)
        .enable_all()
        .build()?;
    let stop = Arc::new(AtomicBool::new(false));
    rt.block_on(async {
        let shutdown = daemon::shutdown_signals()?;
        daemon::run(cfg, sys, stop, shutdown).await
    })
    .map_err(|e| anyhow::anyhow!("{e}"))
}

fn sim_spec(cfg: &ShipcastConfig, duration_s: f64) -> SimSpec {
    let s = &cfg.simulate;
    SimSpec {
        seas: vec![SeaState {
            hs_m: s.sea.hs_m,
            tp_s: s.sea.tp_s,
            gamma: s.sea.gamma,
            heading_rad: heading_from_compass_deg(s.sea.towards_deg),
            spreading: match s.sea.spreading_s {
                Some(e) => Spreading::Cos2s(e),
                None => Spreading::LongCrested,
            },
            components: s.sea.components,
            omega_min_rad_s: s.sea.omega_min_rad_s,
            omega_max_rad_s: s.sea.omega_max_rad_s,
            seed: s.seed,
        }],
        radar: RadarSpec {
            radius_m: s.radar.radius_m,
            cells: s.radar.cells,
            period_s: s.radar.period_s,
            noise_m: s.radar.noise_m,
            snapshots: s.radar.snapshots,
            omega_min_rad_s: 0.8 * s.sea.omega_min_rad_s,
            omega_max_rad_s: 1.1 * s.sea.omega_max_rad_s,
            blind_radius_m: s.radar.blind_radius_m,
            masked_sector_deg: s.radar.masked_sector_deg.map(|m| (m[0], m[1])),
            antenna_height_m: s.radar.antenna_height_m,
        },
        imu: ImuSpec {
            rate_hz: s.imu.rate_hz,
            noise_m: s.imu.noise_m,
            noise_rad: s.imu.noise_rad,
            bias_m: s.imu.bias_m,
            bias_rad: s.imu.bias_rad,
            drift_m: s.imu.drift_m,
            drift_rad: s.imu.drift_rad,
            drift_time_s: s.imu.drift_time_s,
        },
        duration_s,
        ramp_s: s.ramp_s,
        heading_rad: heading_from_compass_deg(s.track.heading_deg.unwrap_or(cfg.site.heading_deg)),
        origin_m: [cfg.site.origin_east_m, cfg.site.origin_north_m],
        // compass rate of turn (to starboard) is clockwise: the track's is counterclockwise
        track: shipcast::rom::Track {
            speed_m_s: s.track.speed_m_s,
            turn_rate_rad_s: -s.track.turn_deg_s.to_radians(),
            turn_start_s: s.track.turn_start_s,
            piece_rad: shipcast::sim::TRUTH_PIECE_RAD,
        },
        navigation: shipcast::sim::NavSpec {
            rate_hz: s.navigation.rate_hz,
            heading_noise_rad: s.navigation.heading_noise_deg.to_radians(),
            position_noise_m: s.navigation.position_noise_m,
        },
        damping_factor: s.damping_factor,
        bound_waves: s.sea.bound_waves,
        seed: s.seed,
    }
}

pub fn simulate(a: &SimulateArgs) -> Result<()> {
    let cfg = load_config(&a.config)?;
    let sys = load_system(&cfg)?;
    let duration = a.duration.unwrap_or(cfg.simulate.duration_s);
    if !(duration.is_finite() && duration > 0.0) {
        bail!("--duration {duration}: must be positive");
    }
    let t = Instant::now();
    let truth = truth_system(&cfg)?;
    let mut sim = Simulation::new(
        &sys,
        truth.as_ref(),
        shipcast::engine::rom_options(&cfg, &sys),
        sim_spec(&cfg, duration),
    )
    .context("computing the true motion")?;
    tracing::info!(seconds = t.elapsed().as_secs_f64(), "true motion computed");
    let mut out = SimOutputs::open(a, &cfg, &sys, sim.n_bodies)?;
    // the data clock: UNIX seconds at the start (simulate.start_unix_s, default the wall clock), then
    // simulation time; published and recorded stamps and log times are on it
    let epoch = cfg.simulate.start_unix_s.unwrap_or_else(daemon::wall_s);
    let imu_dt = 1.0 / cfg.simulate.imu.rate_hz;
    let radar_dt = cfg.simulate.radar.period_s;
    let (mut next_imu, mut next_radar) = (0.0f64, 0.0f64);
    let nav_rate = cfg.simulate.navigation.rate_hz;
    let nav_dt = if nav_rate > 0.0 { 1.0 / nav_rate } else { f64::INFINITY };
    let mut next_nav = 0.0f64;
    let grid_every = cfg.simulate.radar.record_grid_every;
    let grid_output = cfg.simulate.radar.output == "grid";
    let mut scans = 0u64;
    let start = Instant::now();
    let speed = cfg.simulate.speed;
    let mut stop_seen = false;
    let stop = Arc::new(AtomicBool::new(false));
    {
        let stop = stop.clone();
        let _ = ctrlc_flag(stop);
    }
    let wait_until = |t: f64| {
        let due = Duration::from_secs_f64(t / speed);
        if let Some(wait) = due.checked_sub(start.elapsed()) {
            std::thread::sleep(wait);
        }
    };
    while next_imu <= duration && !stop_seen {
        let t = next_imu.min(next_radar).min(next_nav);
        if next_nav <= next_imu && next_nav <= next_radar {
            out.navigation(&mut sim, t, epoch, &wait_until)?;
            next_nav += nav_dt;
            continue;
        }
        if let Some(p) = &out.publisher {
            wait_until(t);
            if next_radar <= next_imu {
                publish_radar(p, &mut sim, t, epoch, grid_output)?;
                next_radar += radar_dt;
                continue;
            }
            publish_imu(&out, p, &mut sim, t, epoch)?;
        } else if let Some(rec) = out.recorder.as_mut() {
            let radar = next_radar <= next_imu;
            let at = a.record.as_ref().map(|p| p.display().to_string()).unwrap_or_default();
            record_step(rec, &mut sim, t, epoch, radar, (grid_every, &mut scans), grid_output)
                .map_err(|e| anyhow::anyhow!("{at}: {e}"))?;
            if radar {
                next_radar += radar_dt;
                continue;
            }
        } else if next_radar <= next_imu {
            next_radar += radar_dt;
            continue;
        }
        out.truth(&sim, t, epoch)?;
        next_imu += imu_dt;
        stop_seen = stop.load(std::sync::atomic::Ordering::Relaxed);
    }
    out.finish(duration, t)
}

/// The system the true motion is computed with when it is not the forecaster's
/// (`[simulate] truth_system`); an error names the config file and the key.
fn truth_system(cfg: &ShipcastConfig) -> Result<Option<VesselSystem>> {
    Ok(match &cfg.simulate.truth_system {
        Some(file) => Some(
            files::load_system(&cfg.dir.join(file))
                .map(|l| l.system)
                .with_context(|| format!("{}: [simulate] truth_system = {file:?}", cfg.path.display()))?,
        ),
        None => None,
    })
}

/// Publishes the radar scan at `t` (data clock `t + epoch`): its elevation grid with `grid_output`,
/// else its wave field.
fn publish_radar(p: &SensorPublisher, sim: &mut Simulation, t: f64, epoch: f64, grid_output: bool) -> Result<()> {
    let field = sim.radar(t);
    if grid_output {
        if let Some(scan) = scan_of(sim, epoch) {
            p.elevation(&scan)
                .map_err(|e| anyhow::anyhow!("publishing elevation: {e}"))?;
        }
    } else if let Some(mut f) = field {
        f.time_s += epoch;
        p.waves(&f).map_err(|e| anyhow::anyhow!("publishing waves: {e}"))?;
    }
    Ok(())
}

/// Publishes the IMU samples at `t` (data clock `t + epoch`), each through its vessel's publisher,
/// else `p`.
fn publish_imu(out: &SimOutputs, p: &SensorPublisher, sim: &mut Simulation, t: f64, epoch: f64) -> Result<()> {
    for mut s in sim.imu(t) {
        s.time_s += epoch;
        let m = to_wire(&s);
        out.publisher_of(m.vessel)
            .unwrap_or(p)
            .motion(&m)
            .map_err(|e| anyhow::anyhow!("publishing motion: {e}"))?;
    }
    Ok(())
}

/// Where `simulate` sends what it makes: iceoryx2 publishers (one per `--vessel-prefix`, the default
/// one), a log, the true motion's CSV.
struct SimOutputs {
    publisher: Option<SensorPublisher>,
    elsewhere: Vec<(u32, SensorPublisher)>,
    recorder: Option<shipcast::shell::record::Recorder<std::io::BufWriter<std::fs::File>>>,
    truth_out: Option<std::io::BufWriter<std::fs::File>>,
    n_bodies: usize,
}

impl SimOutputs {
    fn open(a: &SimulateArgs, cfg: &ShipcastConfig, sys: &VesselSystem, n_bodies: usize) -> Result<SimOutputs> {
        let publisher = if a.publish {
            Some(
                SensorPublisher::new(&Names {
                    prefix: cfg.ipc.service_prefix.clone(),
                })
                .map_err(|e| anyhow::anyhow!("iceoryx2: {e}"))?,
            )
        } else {
            None
        };
        let mut elsewhere: Vec<(u32, SensorPublisher)> = vec![];
        for vp in &a.vessel_prefix {
            let (v, prefix) = vp
                .split_once('=')
                .and_then(|(v, p)| Some((v.trim().parse::<u32>().ok()?, p.trim())))
                .filter(|(v, p)| (*v as usize) < n_bodies && !p.is_empty())
                .ok_or_else(|| anyhow::anyhow!("--vessel-prefix {vp:?}: VESSEL=PREFIX, a vessel 0..{n_bodies}"))?;
            let p = SensorPublisher::new(&Names { prefix: prefix.into() })
                .map_err(|e| anyhow::anyhow!("iceoryx2 (--vessel-prefix {vp}): {e}"))?;
            elsewhere.push((v, p));
        }
        let names: Vec<String> = sys
            .spec
            .bodies
            .iter()
            .flat_map(|b| Dof::ALL.map(|d| format!("{}.{}", b.name, d.output_name())))
            .collect();
        let truth_out = match &a.truth {
            Some(p) => {
                let mut f = std::io::BufWriter::new(
                    std::fs::File::create(p).with_context(|| format!("creating {}", p.display()))?,
                );
                writeln!(f, "t_s,{}", names.join(","))?;
                Some(f)
            }
            None => None,
        };
        let recorder = match &a.record {
            Some(p) => Some(
                shipcast::shell::record::Recorder::create(
                    p,
                    &shipcast::shell::record::LogInfo::of(cfg, &cfg.system.file, sys, "simulate"),
                )
                .map_err(|e| anyhow::anyhow!("{e}"))?,
            ),
            None => None,
        };
        Ok(SimOutputs {
            publisher,
            elsewhere,
            recorder,
            truth_out,
            n_bodies,
        })
    }

    /// The publisher of a vessel's sensors: its `--vessel-prefix`'s, else the default one.
    fn publisher_of(&self, vessel: u32) -> Option<&SensorPublisher> {
        self.elsewhere
            .iter()
            .find(|(v, _)| *v == vessel)
            .map(|(_, p)| p)
            .or(self.publisher.as_ref())
    }

    /// The navigation fixes at `t`: published (at their time, `wait_until`) or recorded.
    fn navigation(&mut self, sim: &mut Simulation, t: f64, epoch: f64, wait_until: &impl Fn(f64)) -> Result<()> {
        for fix in sim.navigation(t) {
            let n = shipcast::engine::navigation::to_wire(fix.vessel as u32, t + epoch, &fix);
            if let Some(p) = self.publisher_of(n.vessel) {
                wait_until(t);
                p.navigation(&n)
                    .map_err(|e| anyhow::anyhow!("publishing navigation: {e}"))?;
            } else if let Some(rec) = self.recorder.as_mut() {
                rec.write(
                    "/navigation",
                    t + epoch,
                    &shipcast::shell::record::NavigationRecord::of(&n),
                )
                .map_err(|e| anyhow::anyhow!("{e}"))?;
            }
        }
        Ok(())
    }

    /// The true motion at `t` into the CSV, if asked for.
    fn truth(&mut self, sim: &Simulation, t: f64, epoch: f64) -> Result<()> {
        if let Some(f) = self.truth_out.as_mut() {
            write!(f, "{:.3}", t + epoch)?;
            for i in 0..6 * self.n_bodies {
                write!(f, ",{:.6e}", Dof::of_index(i).to_output(sim.true_x(t, i)))?;
            }
            writeln!(f)?;
        }
        Ok(())
    }

    fn finish(self, duration: f64, t: Instant) -> Result<()> {
        if let Some(mut f) = self.truth_out {
            f.flush()?;
        }
        if let Some(rec) = self.recorder {
            rec.finish().map_err(|e| anyhow::anyhow!("{e}"))?;
            eprintln!(
                "shipcast simulate: {duration} s recorded in {:.1} s",
                t.elapsed().as_secs_f64()
            );
        }
        Ok(())
    }
}

/// Records the simulator's output at `t` (log time `t + epoch`): with `radar`, a scan's field and, every
/// `grid_every` scans (counted in `scans`), its elevation grid; else the IMU samples and the true motion.
fn record_step(
    rec: &mut shipcast::shell::record::Recorder<std::io::BufWriter<std::fs::File>>,
    sim: &mut Simulation,
    t: f64,
    epoch: f64,
    radar: bool,
    (grid_every, scans): (u32, &mut u64),
    grid_output: bool,
) -> std::result::Result<(), shipcast::shell::record::Error> {
    use shipcast::shell::record::{GridRecord, MotionRecord, WavesRecord};
    if radar {
        let field = sim.radar(t);
        if grid_every > 0
            && scans.is_multiple_of(u64::from(grid_every))
            && let Some(g) = sim.last_grid()
        {
            let grid = GridRecord::elevation(&g.x_m, &g.y_m, &g.values, t + epoch);
            rec.write("/radar", t + epoch, &grid)?;
        }
        *scans += 1;
        if grid_output {
            if let Some(scan) = scan_of(sim, epoch) {
                rec.write("/elevation", t + epoch, &GridRecord::of_scan(&scan))?;
            }
        } else if let Some(mut f) = field {
            f.time_s += epoch;
            rec.write("/waves", t + epoch, &WavesRecord::of(&f))?;
        }
        return Ok(());
    }
    let stamp = t + epoch;
    for s in sim.imu(t) {
        rec.write(
            "/motion",
            stamp,
            &MotionRecord {
                vessel: s.vessel as u32,
                time_s: stamp,
                x: s.x,
                v: s.v,
            },
        )?;
        let mut x = [0.0; 6];
        for (d, xd) in x.iter_mut().enumerate() {
            *xd = sim.true_x(t, 6 * s.vessel + d);
        }
        rec.write(
            "/truth",
            stamp,
            &MotionRecord {
                vessel: s.vessel as u32,
                time_s: stamp,
                x,
                v: [0.0; 6],
            },
        )?;
    }
    Ok(())
}

/// The simulator's newest radar scan on the data clock (`simulate.radar.output = "grid"`).
fn scan_of(sim: &Simulation, epoch: f64) -> Option<shipcast::shell::ipc::Scan> {
    let (mut grid, frame) = sim.last_scan()?;
    grid.time_s += epoch;
    Some(shipcast::shell::ipc::Scan { grid, frame })
}

/// Sets `flag` on SIGINT/SIGTERM (the simulator is not async).
pub(crate) fn ctrlc_flag(flag: Arc<AtomicBool>) -> std::io::Result<()> {
    std::thread::Builder::new().name("signals".into()).spawn(move || {
        let Ok(rt) = tokio::runtime::Builder::new_current_thread().enable_all().build() else {
            return;
        };
        rt.block_on(async {
            let Ok(mut term) = tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate()) else {
                return;
            };
            tokio::select! {
                _ = tokio::signal::ctrl_c() => {}
                _ = term.recv() => {}
            }
        });
        flag.store(true, std::sync::atomic::Ordering::Relaxed);
    })?;
    Ok(())
}

/// A finite number, or JSON null: no `inf` or `NaN` reaches a JSON line.
fn finite(v: f64) -> serde_json::Value {
    if v.is_finite() {
        serde_json::json!(v)
    } else {
        serde_json::Value::Null
    }
}

/// A trusted span (from, to) as `[from, to]`.
fn span_json(span: &(f64, f64)) -> serde_json::Value {
    serde_json::json!([finite(span.0), finite(span.1)])
}

/// The operator channel of point `point`'s `axis` (0 x, 1 y, 2 z), for its trusted span.
fn point_channel(point: usize, axis: usize) -> shipcast::operation::Channel {
    shipcast::operation::Channel {
        name: String::new(),
        source: shipcast::operation::Source::Point { point, axis },
        limit: f64::INFINITY,
    }
}

/// A forecast as one JSON line (the format `watch --json` documents): per vessel its DOFs in output
/// units (`heave_m`, `roll_deg`, ...) and the displacement of its points of interest (`x_m`, `y_m`,
/// `z_m`, global axes); non-finite numbers as null.
pub fn forecast_json(
    h: &shipcast::shell::ipc::wire::ForecastHeader,
    values: &[f64],
    sys: &shipcast::hydro::VesselSystem,
) -> String {
    use serde_json::{Map, Value, json};
    let n = h.steps as usize + 1;
    let series = |s: usize| -> &[f64] { values.get(s * n..(s + 1) * n).unwrap_or(&[]) };
    let ext = &sys.spec.external;
    let n_vessels = (h.n_vessels as usize).min(h.horizon_s.len());
    let vessels: Vec<Value> = (0..n_vessels)
        .map(|b| {
            let name = sys.spec.bodies.get(b).map(|x| x.name.as_str()).unwrap_or("?");
            let dofs: Map<String, Value> = Dof::ALL
                .iter()
                .map(|d| {
                    let v: Vec<Value> = series(6 * b + d.index())
                        .iter()
                        .map(|x| finite(d.to_output(*x)))
                        .collect();
                    (d.output_name().to_string(), Value::Array(v))
                })
                .collect();
            let points: Map<String, Value> = ext
                .points
                .iter()
                .enumerate()
                .filter(|(_, p)| p.body == b)
                .map(|(idx, p)| {
                    let mut comps = [vec![], vec![], vec![]];
                    let mut x = vec![0.0; 6 * n_vessels];
                    for k in 0..n {
                        for (i, xi) in x.iter_mut().enumerate() {
                            *xi = series(i).get(k).copied().unwrap_or(0.0);
                        }
                        let m = ext.point_motion(p, &x);
                        for c in 0..3 {
                            comps[c].push(finite(m[c]));
                        }
                    }
                    let [x_m, y_m, z_m] = comps;
                    let spans: Vec<Value> = (0..3)
                        .map(|axis| {
                            span_json(&point_channel(idx, axis).span_s(ext, 6 * n_vessels, |i| h.series_span(i)))
                        })
                        .collect();
                    (
                        p.name.clone(),
                        json!({"x_m": x_m, "y_m": y_m, "z_m": z_m, "spans_s": spans}),
                    )
                })
                .collect();
            // each DOF's own trusted span [from, to], s of lead
            let spans: Map<String, Value> = Dof::ALL
                .iter()
                .map(|d| {
                    (
                        d.output_name().to_string(),
                        span_json(&h.series_span(6 * b + d.index())),
                    )
                })
                .collect();
            // the band: each DOF's standard deviation, after the displacements on the wire
            let sigma0 = 6 * n_vessels * n;
            let sigma: Map<String, Value> = Dof::ALL
                .iter()
                .map(|d| {
                    let s = 6 * b + d.index();
                    let v: Vec<Value> = values
                        .get(sigma0 + s * n..sigma0 + (s + 1) * n)
                        .unwrap_or(&[])
                        .iter()
                        .map(|x| finite(d.to_output(*x)))
                        .collect();
                    (d.output_name().to_string(), Value::Array(v))
                })
                .collect();
            json!({
                "name": name,
                "trusted_from_s": finite(h.trusted_from_s[b]),
                "horizon_s": finite(h.horizon_s[b]),
                "spans_s": spans,
                "dofs": dofs,
                "sigma": sigma,
                "points": points
            })
        })
        .collect();
    json!({
        "kind": "forecast",
        "issue_time_s": finite(h.issue_time_s),
        "dt_s": finite(h.dt_s),
        "wave_time_s": finite(h.wave_time_s),
        "compute_ms": finite(h.compute_ms),
        "received_wall_s": finite(daemon::wall_s()),
        "vessels": vessels,
        "flags": flags::names(h.flags),
    })
    .to_string()
}

/// A status as one JSON line (`watch --json`); non-finite numbers as null.
pub fn status_json(s: &Status, n_vessels: usize) -> String {
    let list = |a: &[f64]| a.iter().take(n_vessels).map(|v| finite(*v)).collect::<Vec<_>>();
    serde_json::json!({
        "kind": "status",
        "running": s.running == 1,
        "time_s": finite(s.time_s),
        "wall_time_s": finite(s.wall_time_s),
        "wave_age_s": finite(s.wave_age_s),
        "motion_age_s": list(&s.motion_age_s),
        "motion_rate_hz": list(&s.motion_rate_hz),
        "last_forecast_time_s": finite(s.last_forecast_time_s),
        "last_compute_ms": finite(s.last_compute_ms),
        // where the last forecast's time went, and the quantiles of the total over the newest
        // forecasts (src/engine/latency.rs)
        "latency": serde_json::json!({
            "stages_ms": shipcast::engine::latency::STAGE_NAMES
                .iter()
                .zip(s.latency_ms)
                .map(|(n, v)| (n.to_string(), finite(v)))
                .collect::<serde_json::Map<_, _>>(),
            "p50_ms": finite(s.latency_p50_ms).as_f64().filter(|v| *v >= 0.0),
            "p99_ms": finite(s.latency_p99_ms).as_f64().filter(|v| *v >= 0.0),
        }),
        "horizon_s": list(&s.horizon_s),
        "forecasts": s.forecasts,
        "overruns": s.overruns,
        "samples": s.samples,
        "wave_fields": s.wave_fields,
        "dropped_nonfinite": s.dropped_nonfinite,
        "dropped_late": s.dropped_late,
        "dropped_duplicate": s.dropped_duplicate,
        "dropped_future": s.dropped_future,
        "dropped_past": s.dropped_past,
        "dropped_rejected": s.dropped_rejected,
        "clock_steps": s.clock_steps,
        "dropped_wave_share": finite(s.dropped_wave_share),
        "dropped_implausible": s.dropped_implausible,
        "motion_restarts": s.motion_restarts,
        // heave m, roll and pitch deg, as the forecasts are shown
        "motion_bias": s.motion_bias.iter().take(n_vessels).map(|b| serde_json::json!({
            "heave_m": finite(b[0]),
            "roll_deg": finite(b[1].to_degrees()),
            "pitch_deg": finite(b[2].to_degrees()),
        })).collect::<Vec<_>>(),
        // the in-situ roll tuning in force (fractions; src/tuning/)
        "roll_tuning": s.roll_tuning.iter().take(n_vessels).map(|t| serde_json::json!({
            "damping_fraction": finite(t[0]),
            "quadratic_fraction": finite(t[1]),
            "frequency_correction": finite(t[2]),
        })).collect::<Vec<_>>(),
        "roll_tuning_converged": s.roll_tuning_converged == 1,
        // the ship-to-ship link: null when none runs
        "link": (s.link_state != shipcast::shell::ipc::wire::link_state::NONE).then(|| serde_json::json!({
            "up": s.link_state == shipcast::shell::ipc::wire::link_state::UP,
            "latency_ms": finite(s.link_latency_ms).as_f64().filter(|v| *v >= 0.0),
            "loss": finite(s.link_loss).as_f64().filter(|v| *v >= 0.0),
            "last_message_age_s": finite(s.link_age_s).as_f64().filter(|v| *v >= 0.0),
        })),
        "flags": flags::names(s.flags),
    })
    .to_string()
}

pub fn watch(a: &WatchArgs) -> Result<()> {
    let cfg = load_config(&a.config)?;
    let sys = load_system(&cfg)?;
    let sub = ForecastSubscriber::new(&Names {
        prefix: cfg.ipc.service_prefix.clone(),
    })
    .map_err(|e| anyhow::anyhow!("iceoryx2: {e}"))?;
    let (_, _) = vessel_positions(&cfg, &sys);
    let mut seen = 0usize;
    let mut last_forecast = Instant::now();
    let stop = Arc::new(AtomicBool::new(false));
    ctrlc_flag(stop.clone())?;
    let mut out = std::io::stdout().lock();
    let mut got = vec![];
    let n_vessels = sys.spec.bodies.len().min(shipcast::shell::ipc::wire::MAX_VESSELS);
    while !stop.load(std::sync::atomic::Ordering::Relaxed) {
        got.clear();
        sub.wait(Duration::from_millis(500), &mut got)
            .map_err(|e| anyhow::anyhow!("iceoryx2: {e}"))?;
        for r in &got {
            match r {
                Received::Forecast(h, v) => {
                    if h.schema_version != shipcast::shell::ipc::wire::FORECAST_SCHEMA_VERSION {
                        eprintln!("skipping a forecast of schema version {}", h.schema_version);
                        continue;
                    }
                    seen += 1;
                    last_forecast = Instant::now();
                    if a.json {
                        writeln!(out, "{}", forecast_json(h, v, &sys))?;
                    } else {
                        let n = h.steps as usize + 1;
                        let mut line = format!(
                            "forecast issued {}, {:.0} s ahead, computed in {:.1} ms",
                            super::utc(h.issue_time_s),
                            h.steps as f64 * h.dt_s,
                            h.compute_ms
                        );
                        for b in 0..h.n_vessels as usize {
                            let heave = &v[(6 * b + 2) * n..(6 * b + 3) * n];
                            let peak = heave.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                            let name = sys.spec.bodies.get(b).map(|x| x.name.as_str()).unwrap_or("?");
                            line.push_str(&format!(
                                "; {name}: heave peak {peak:.2} m, horizon {:.0} s",
                                h.horizon_s[b]
                            ));
                        }
                        if h.flags != 0 {
                            line.push_str(&format!(" [{}]", flags::names(h.flags).join(", ")));
                        }
                        writeln!(out, "{line}")?;
                    }
                    out.flush()?;
                }
                Received::Status(s) => {
                    if a.json {
                        writeln!(out, "{}", status_json(s, n_vessels))?;
                    } else if s.running == 0 {
                        writeln!(out, "shipcast stopped (last status)")?;
                    }
                    out.flush()?;
                }
            }
        }
        if a.count.is_some_and(|c| seen >= c) {
            break;
        }
        if let Some(t) = a.timeout
            && last_forecast.elapsed().as_secs_f64() > t
        {
            bail!("no forecast for {t} s");
        }
    }
    Ok(())
}

#[derive(Args, Debug)]
pub struct DemoArgs {
    #[command(flatten)]
    config: super::ConfigArg,
    /// Stop after this many seconds (default: until Ctrl-C).
    #[arg(long, allow_negative_numbers = true)]
    seconds: Option<f64>,
    /// Plain text lines even in a terminal (the default when the output is not a terminal).
    #[arg(long)]
    plain: bool,
}

/// `shipcast demo`: the synthetic sea publishing radar and IMU data, the daemon on the bundled demo,
/// and, in a terminal, the operator console on it (else, or with --plain, a line per forecast with its
/// skill so far: the forecasts of 30 s ago against the motion measured now). Ctrl-C (or q in the
/// console) stops all three.
pub fn demo(a: &DemoArgs) -> Result<()> {
    use shipcast::shell::process::Interrupting;
    let cfg = load_config(&a.config)?;
    let sys = load_system(&cfg)?;
    let exe = std::env::current_exe()?;
    let config = cfg.path.to_str().context("config path is not UTF-8")?.to_string();
    use std::io::IsTerminal;
    let console = !a.plain && std::io::stdout().is_terminal();
    // under the console the children's logs would tear the screen: they go to a file
    let log_path = std::env::temp_dir().join(format!("shipcast-demo-{}.log", std::process::id()));
    let log = if console {
        Some(std::fs::File::create(&log_path).with_context(|| log_path.display().to_string())?)
    } else {
        None
    };
    let spawn = |args: &[&str]| -> Result<Interrupting> {
        let mut cmd = std::process::Command::new(&exe);
        cmd.args(args).stdout(std::process::Stdio::null());
        if let Some(f) = &log {
            cmd.stderr(f.try_clone()?);
        }
        Ok(Interrupting(
            cmd.spawn().with_context(|| format!("starting shipcast {}", args[0]))?,
        ))
    };
    let stop = Arc::new(AtomicBool::new(false));
    ctrlc_flag(stop.clone())?;
    println!(
        "shipcast demo: {} vessels ({}), sea Hs {} m Tp {} s, radar {} m; starting the daemon and the synthetic sea (Ctrl-C stops all)",
        sys.spec.bodies.len(),
        sys.spec
            .bodies
            .iter()
            .map(|b| b.name.as_str())
            .collect::<Vec<_>>()
            .join(", "),
        cfg.simulate.sea.hs_m,
        cfg.simulate.sea.tp_s,
        cfg.simulate.radar.radius_m
    );
    let _daemon = spawn(&["run", "--config", &config])?;
    std::thread::sleep(Duration::from_millis(1500));
    let _sim = spawn(&["simulate", "--publish", "--config", &config])?;
    if console {
        let r = super::console::view(&cfg, &sys, None, a.seconds);
        println!(
            "shipcast demo: stopping (the daemon's and the simulator's logs: {})",
            log_path.display()
        );
        return r;
    }
    plain_demo(&cfg, &sys, a.seconds, &stop)
}

/// `demo` without the console: a line per forecast with its skill so far (the forecasts of 30 s ago
/// against the motion measured now), until `stop` or `seconds`.
fn plain_demo(
    cfg: &ShipcastConfig,
    sys: &shipcast::hydro::VesselSystem,
    seconds: Option<f64>,
    stop: &AtomicBool,
) -> Result<()> {
    use shipcast::shell::ipc::MotionSubscriber;
    let mut demo = DemoSkill {
        wanted_s: shipcast::engine::history_wanted_s(cfg, sys),
        first_motion_s: None,
        pending: vec![],
        measured: Default::default(),
        pairs_f: vec![],
        pairs_m: vec![],
    };
    let names = Names {
        prefix: cfg.ipc.service_prefix.clone(),
    };
    let sub = ForecastSubscriber::new(&names).map_err(|e| anyhow::anyhow!("iceoryx2: {e}"))?;
    let motion = MotionSubscriber::new(&names).map_err(|e| anyhow::anyhow!("iceoryx2: {e}"))?;
    let mut got = vec![];
    let mut samples = vec![];
    let start = Instant::now();
    let name0 = sys.spec.bodies[0].name.clone();
    while !stop.load(std::sync::atomic::Ordering::Relaxed) {
        if seconds.is_some_and(|s| start.elapsed().as_secs_f64() > s) {
            break;
        }
        got.clear();
        sub.wait(Duration::from_millis(500), &mut got)
            .map_err(|e| anyhow::anyhow!("iceoryx2: {e}"))?;
        samples.clear();
        motion
            .drain(&mut samples)
            .map_err(|e| anyhow::anyhow!("iceoryx2: {e}"))?;
        for s in samples.iter().filter(|s| s.vessel == 0) {
            demo.measured.push_back((s.time_s, s.x[2]));
            demo.first_motion_s.get_or_insert(s.time_s);
        }
        while demo.measured.len() > 5000 {
            demo.measured.pop_front();
        }
        demo.score_pending();
        for r in &got {
            if let Received::Forecast(h, v) = r {
                demo.on_forecast(h, v, &name0);
            }
        }
    }
    println!("shipcast demo: stopping");
    Ok(())
}

/// The lead `plain_demo` scores the forecasts at, s.
const DEMO_LEAD_S: f64 = 30.0;

/// What `plain_demo` keeps: the first vessel's measured heave, the forecasts of it waiting for their
/// valid time, and the (forecast, measured) pairs scored so far.
struct DemoSkill {
    /// The motion memory the daemon wants, s.
    wanted_s: f64,
    /// The first measured time, s.
    first_motion_s: Option<f64>,
    /// (valid time, forecast heave of vessel 0)
    pending: Vec<(f64, f64)>,
    /// (time, measured heave of vessel 0), the newest 5000.
    measured: std::collections::VecDeque<(f64, f64)>,
    /// Forecast heave of the scored pairs, m.
    pairs_f: Vec<f64>,
    /// Measured heave of the scored pairs, m.
    pairs_m: Vec<f64>,
}

impl DemoSkill {
    /// Scores the pending forecasts whose valid time has been measured (the measured heave
    /// interpolated to it) and drops them.
    fn score_pending(&mut self) {
        let (measured, pairs_f, pairs_m) = (&self.measured, &mut self.pairs_f, &mut self.pairs_m);
        self.pending.retain(|(t, f)| {
            let Some(i) = measured.iter().position(|(tm, _)| *tm >= *t) else {
                return true;
            };
            if i > 0 {
                let (t0, x0) = measured[i - 1];
                let (t1, x1) = measured[i];
                let m = x0 + (x1 - x0) * (t - t0) / (t1 - t0);
                pairs_f.push(*f);
                pairs_m.push(m);
            }
            false
        });
    }

    /// Queues the forecast's heave at [`DEMO_LEAD_S`] for scoring and prints its line: heave now and
    /// at the lead, horizon, compute time, skill so far, flags.
    fn on_forecast(&mut self, h: &shipcast::shell::ipc::wire::ForecastHeader, v: &[f64], name0: &str) {
        let n = h.steps as usize + 1;
        let k = (DEMO_LEAD_S / h.dt_s).round() as usize;
        let heave = &v[2 * n..3 * n];
        if k < n {
            self.pending.push((h.issue_time_s + DEMO_LEAD_S, heave[k]));
        }
        let skill = self.skill_words();
        let fl = self.flag_words(h.flags);
        println!(
            "{name0} heave now {:+.2} m, in {DEMO_LEAD_S:.0} s {:+.2} m, horizon {:.0} s, computed in {:.0} ms; {skill}{fl}",
            heave[0],
            heave[k.min(n - 1)],
            h.horizon_s[0],
            h.compute_ms
        );
    }

    /// The correlation at the lead so far (from 10 pairs), or how many pairs are scored yet.
    fn skill_words(&self) -> String {
        if self.pairs_f.len() >= 10 {
            format!(
                "skill at {DEMO_LEAD_S:.0} s so far: correlation {:.3} over {} forecasts",
                shipcast::skill::correlation(&self.pairs_f, &self.pairs_m),
                self.pairs_f.len()
            )
        } else {
            format!(
                "skill at {DEMO_LEAD_S:.0} s: waiting for the measured motion ({} scored)",
                self.pairs_f.len()
            )
        }
    }

    /// The forecast's flags in brackets (empty without), and while the motion memory fills, how long
    /// until it is full.
    fn flag_words(&self, forecast_flags: u32) -> String {
        let wanted_s = self.wanted_s;
        let mut fl = if forecast_flags != 0 {
            format!(" [{}]", flags::names(forecast_flags).join(", "))
        } else {
            String::new()
        };
        if forecast_flags & flags::HISTORY_SHORT != 0
            && let (Some(first), Some((last, _))) = (self.first_motion_s, self.measured.back())
        {
            let left = wanted_s - (last - first);
            if left > 0.0 {
                fl.push_str(&format!(
                    " warming up: the {wanted_s:.0} s motion memory fills in {left:.0} s more (forecasts less sure until then)"
                ));
            }
        }
        fl
    }
}
