//! `shipcast replay LOG`: a recorded log through the daemon's engine, with a skill report.

use super::load_config;
use super::plot;
use anyhow::{Context, Result, bail};
use clap::Args;
use shipcast::hydro::VesselSystem;
use shipcast::operation::{Channel, SpanForecast, WindowScore, score_forecast_windows};
use shipcast::shell::config::ShipcastConfig;
use shipcast::shell::ipc::{Names, Output, SensorPublisher, spawn_output};
use shipcast::shell::record::{self, ForecastRecord, Record};
use shipcast::shell::replay;
use shipcast::skill::{self, SeriesForecast};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

#[derive(Args, Debug)]
pub struct ReplayArgs {
    /// The log (MCAP), e.g. from `shipcast simulate --record`; several files (a rotated recording)
    /// are replayed as one.
    #[arg(required = true)]
    log: Vec<PathBuf>,
    #[command(flatten)]
    config: super::ConfigArg,
    /// Log seconds per wall second (default: as fast as possible).
    #[arg(long, allow_negative_numbers = true, conflicts_with = "max")]
    speed: Option<f64>,
    /// As fast as possible (the default).
    #[arg(long)]
    max: bool,
    /// Write skill.json, skill.csv, skill.svg and skill.png here (and windows.json, forecast-<t>.svg/.png).
    #[arg(long)]
    report: Option<PathBuf>,
    /// Write the replayed forecasts to this log.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Compare every forecast recorded in the log with its replay, bit for bit (a daemon's log);
    /// fails if one differs or is missing.
    #[arg(long)]
    verify: bool,
    /// Publish the replay over iceoryx2 (motion, forecasts, status) under this service prefix, for
    /// a console (`shipcast console --prefix P`); default prefix `<ipc.service_prefix>-replay`. Use
    /// with --speed.
    #[arg(long, num_args = 0..=1, require_equals = true, default_missing_value = "", value_name = "PREFIX")]
    publish: Option<String>,
    /// With --report: also plot the forecast issued nearest this time, in seconds from the log's first
    /// motion sample (the sensors' clock), against what followed (`forecast-<t>.svg` and `.png`, t in
    /// the same seconds); repeatable. Default: the middle forecast of the log.
    #[arg(long, allow_negative_numbers = true)]
    at: Vec<f64>,
}

/// MCAP's magic number, the first and last 8 bytes of every MCAP file.
const MCAP_MAGIC: &[u8; 8] = b"\x89MCAP0\r\n";

/// Refuses, with the path, a file that does not start as an MCAP file (before reading any of it).
fn is_mcap(path: &std::path::Path) -> Result<()> {
    use std::io::Read;
    let mut head = [0u8; 8];
    let mut f = std::fs::File::open(path).with_context(|| path.display().to_string())?;
    let n = f.read(&mut head).with_context(|| path.display().to_string())?;
    if n < 8 || &head != MCAP_MAGIC {
        bail!(
            "{}: not an MCAP log (it does not start with MCAP's magic bytes); logs come from `shipcast simulate --record`, `shipcast import` or the daemon's [record] dir",
            path.display()
        );
    }
    Ok(())
}

pub fn run(a: &ReplayArgs) -> Result<()> {
    let cfg = load_config(&a.config)?;
    let sys = super::load_system(&cfg)?;
    if let Some(s) = a.speed
        && !(s.is_finite() && s > 0.0)
    {
        bail!("--speed {s}: must be positive");
    }
    let log = read_logs(&a.log)?;
    for w in &log.warnings {
        eprintln!("shipcast replay: warning: {w}");
    }
    let (Some(first), Some(last)) = (log.records.first(), log.records.last()) else {
        bail!("{}: no messages", a.log[0].display());
    };
    let (t_first, t_last) = (first.0, last.0);
    let publisher = match &a.publish {
        Some(p) => Some(Publisher::new(if p.is_empty() {
            format!("{}-replay", cfg.ipc.service_prefix)
        } else {
            p.clone()
        })?),
        None => None,
    };
    let wall = Instant::now();
    let mut forecasts: Vec<ForecastRecord> = vec![];
    let mut published = 0usize;
    let counters = replay::drive(
        &cfg,
        &sys,
        &log.records,
        |t| {
            if let Some(s) = a.speed {
                let due = Duration::from_secs_f64((t - t_first).max(0.0) / s);
                if let Some(w) = due.checked_sub(wall.elapsed()) {
                    std::thread::sleep(w);
                }
            }
            if let Some(p) = &publisher {
                published = p.motion_until(&log.records, published, t);
            }
        },
        |o| match o {
            Output::Forecast(h, v) => {
                forecasts.push(ForecastRecord::of(&h, &v));
                if let Some(p) = &publisher {
                    let _ = p.out.send(Output::Forecast(h, v));
                }
            }
            status => {
                if let Some(p) = &publisher {
                    let _ = p.out.send(status);
                }
            }
        },
    )
    .map_err(|e| anyhow::anyhow!("{e}"))?;
    if let Some(p) = publisher {
        p.finish();
    }
    let secs = wall.elapsed().as_secs_f64();
    // the sensors' clock: what was simulated or measured (a daemon's log time is its own clock, which
    // runs slower than the data when the simulator ran faster than real time)
    let data_times = log.records.iter().filter_map(|(_, r)| match r {
        Record::Motion(m) => Some(m.time_s),
        _ => None,
    });
    let (d0, d1) = data_times.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), t| (a.min(t), b.max(t)));
    let data_s = if d1 > d0 { d1 - d0 } else { t_last - t_first };
    eprintln!(
        "shipcast replay: {} messages over {:.1} s of log ({:.1} s of sensor data), {} forecasts ({} samples, {} dropped) in {:.1} s: {:.2} data hours per wall minute",
        log.records.len(),
        t_last - t_first,
        data_s,
        forecasts.len(),
        counters.samples,
        counters.nonfinite + counters.late + counters.duplicate,
        secs,
        data_s / 3600.0 / (secs / 60.0)
    );
    if let Some(p) = &a.out {
        let mut rec = record::Recorder::create(p, &record::LogInfo::of(&cfg, &cfg.system.file, &sys, "replay"))
            .map_err(|e| anyhow::anyhow!("{e}"))?;
        for f in &forecasts {
            rec.write("/forecast", f.issue_time_s, f)
                .map_err(|e| anyhow::anyhow!("{e}"))?;
        }
        rec.finish().map_err(|e| anyhow::anyhow!("{e}"))?;
    }
    if let Some(dir) = &a.report {
        // issue times are on the sensors' clock (UNIX seconds), --at from its start
        let t0 = if d0.is_finite() { d0 } else { t_first };
        reports(dir, a, &cfg, &sys, &log.records, &forecasts, t0)?;
    }
    if a.verify {
        verify(&log.records, &forecasts)?;
    }
    Ok(())
}

/// The logs read and joined as one: several files are a recording rotated by the daemon, replayed in
/// the order of their first message (each file's own order is kept: it is the order the daemon saw).
fn read_logs(paths: &[PathBuf]) -> Result<record::Read> {
    let mut parts = vec![];
    for p in paths {
        is_mcap(p)?;
        parts.push(record::read(p).map_err(|e| anyhow::anyhow!("{e}"))?);
    }
    parts.sort_by(|x, y| {
        let first = |r: &record::Read| r.records.first().map_or(f64::INFINITY, |m| m.0);
        first(x).total_cmp(&first(y))
    });
    let mut log = record::Read {
        records: vec![],
        warnings: vec![],
    };
    for part in parts {
        log.records.extend(part.records);
        log.warnings.extend(part.warnings);
    }
    Ok(log)
}

/// `--report DIR`: skill against lead time, the operation's windows, and forecasts against what
/// followed (`--at`, seconds after `t0`, the sensors' first stamp).
fn reports(
    dir: &Path,
    a: &ReplayArgs,
    cfg: &ShipcastConfig,
    sys: &VesselSystem,
    records: &[(f64, Record)],
    forecasts: &[ForecastRecord],
    t0: f64,
) -> Result<()> {
    let vessels: Vec<String> = sys.spec.bodies.iter().map(|b| b.name.clone()).collect();
    // forecasts are scored against the true motion when the log has it (a simulation), else the
    // measured: the sensor's noise and bias are not the vessel's motion, and IMU noise near a limit
    // breaks windows that the motion itself kept
    let truth = measured_series(records, vessels.len(), true);
    let (measured, reference) = if truth.iter().any(|s| !s.is_empty()) {
        (truth, "truth")
    } else {
        (measured_series(records, vessels.len(), false), "measured")
    };
    report(dir, sys, &measured, reference, forecasts, cfg.forecast.horizon_s)?;
    let channels = cfg.operation_channels(&vessels, &sys.spec.external, &cfg.path)?;
    windows_report(
        dir,
        sys,
        &channels,
        (cfg.operation.duration_s, cfg.operation.confidence),
        forecasts,
        &measured,
        reference,
    )?;
    // default: the middle forecast
    let ats = if a.at.is_empty() {
        forecasts
            .get(forecasts.len() / 2)
            .map(|f| f.issue_time_s)
            .into_iter()
            .collect()
    } else {
        a.at.iter().map(|t| t0 + t).collect::<Vec<f64>>()
    };
    for at in ats {
        if let Some(f) = forecasts
            .iter()
            .min_by(|x, y| (x.issue_time_s - at).abs().total_cmp(&(y.issue_time_s - at).abs()))
        {
            let p = dir.join(format!("forecast-{:.0}.svg", f.issue_time_s - t0));
            forecast_plot(&p, f, t0, sys, &channels, &measured, reference)?;
            println!("forecast against actual: {} (and .png)", p.display());
        }
    }
    Ok(())
}

/// The replay's iceoryx2 side: motion from the log as a sensor would send it, forecasts and status
/// through the daemon's own output thread.
struct Publisher {
    sensor: SensorPublisher,
    out: std::sync::mpsc::Sender<Output>,
    thread: std::thread::JoinHandle<()>,
}

impl Publisher {
    fn new(prefix: String) -> Result<Publisher> {
        let names = Names { prefix: prefix.clone() };
        let sensor = SensorPublisher::new(&names).map_err(|e| anyhow::anyhow!("iceoryx2: {e}"))?;
        let (out, rx) = std::sync::mpsc::channel();
        let (ready_tx, ready) = std::sync::mpsc::channel();
        let thread = spawn_output(names, rx, ready_tx);
        ready
            .recv()
            .context("the output thread ended")?
            .map_err(|e| anyhow::anyhow!("iceoryx2: {e}"))?;
        eprintln!("shipcast replay: publishing under \"{prefix}\" (watch: shipcast console --prefix {prefix})");
        Ok(Publisher { sensor, out, thread })
    }

    /// Publishes the motion records from index `from` up to log time `t`; returns the next index.
    fn motion_until(&self, records: &[(f64, Record)], from: usize, t: f64) -> usize {
        let mut i = from;
        while i < records.len() && records[i].0 <= t {
            if let Record::Motion(m) = &records[i].1 {
                let _ = self.sensor.motion(&m.to_wire());
            }
            i += 1;
        }
        i
    }

    fn finish(self) {
        drop(self.out);
        let _ = self.thread.join();
    }
}

/// Every forecast recorded in the log against its replay (same issue time), bit for bit.
fn verify(records: &[(f64, Record)], replayed: &[ForecastRecord]) -> Result<()> {
    let recorded: Vec<&ForecastRecord> = records
        .iter()
        .filter_map(|(_, r)| match r {
            Record::Forecast(f) => Some(f),
            _ => None,
        })
        .collect();
    if recorded.is_empty() {
        bail!("--verify: the log holds no forecasts (record one with the daemon's [record] dir)");
    }
    let (mut same, mut differ, mut missing) = (0, 0, 0);
    for r in &recorded {
        match replayed
            .iter()
            .find(|b| b.issue_time_s.to_bits() == r.issue_time_s.to_bits())
        {
            None => missing += 1,
            Some(b)
                if b.flags == r.flags
                    && b.values.len() == r.values.len()
                    && b.values.iter().zip(&r.values).all(|(x, y)| x.to_bits() == y.to_bits()) =>
            {
                same += 1
            }
            Some(_) => differ += 1,
        }
    }
    println!(
        "verify: {} recorded forecasts: {same} identical bit for bit, {differ} different, {missing} not replayed ({} replayed in all)",
        recorded.len(),
        replayed.len()
    );
    if differ + missing > 0 {
        bail!("--verify: {differ} forecasts differ and {missing} were not replayed");
    }
    Ok(())
}

/// Measured (or, with `truth`, true) (time, value) of every series (6 per vessel, m or rad), sorted
/// by time.
fn measured_series(records: &[(f64, Record)], n_vessels: usize, truth: bool) -> Vec<Vec<(f64, f64)>> {
    let mut out = vec![vec![]; 6 * n_vessels];
    for (_, r) in records {
        let m = match (r, truth) {
            (Record::Motion(m), false) | (Record::Truth(m), true) => m,
            _ => continue,
        };
        if (m.vessel as usize) < n_vessels {
            for d in 0..6 {
                out[6 * m.vessel as usize + d].push((m.time_s, m.x[d]));
            }
        }
    }
    for s in &mut out {
        s.sort_by(|a, b| a.0.total_cmp(&b.0));
        s.dedup_by(|a, b| a.0 == b.0);
    }
    out
}

/// Operator windows forecast against those that happened (`[operation]` of the config), written into
/// `windows.json` and summed up on stdout.
fn windows_report(
    dir: &Path,
    sys: &shipcast::hydro::VesselSystem,
    channels: &[Channel],
    (duration_s, confidence): (f64, f64),
    forecasts: &[ForecastRecord],
    measured: &[Vec<(f64, f64)>],
    reference: &str,
) -> Result<()> {
    let ext = &sys.spec.external;
    let mut total = WindowScore::default();
    let mut scored = 0usize;
    for f in forecasts {
        let n = f.steps as usize + 1;
        let series: Vec<&[f64]> = f.values.chunks_exact(n).collect();
        let sigma: Vec<&[f64]> = f.sigma.chunks_exact(n).collect();
        let (trusted_from_s, trusted_s) =
            shipcast::operation::trusted_span_s(channels, ext, series.len(), |i| f.series_span(i));
        let span = SpanForecast {
            t0_s: f.issue_time_s,
            dt_s: f.dt_s,
            values: &series,
            sigma: &sigma,
            trusted_from_s,
            trusted_s,
        };
        let s = score_forecast_windows(channels, ext, &span, measured, duration_s, confidence);
        if let Some(s) = s {
            total.add(&s);
            scored += 1;
        }
    }
    let te = &total.timing_errors_s;
    let mean = (!te.is_empty()).then(|| te.iter().sum::<f64>() / te.len() as f64);
    let mean_abs = (!te.is_empty()).then(|| te.iter().map(|x| x.abs()).sum::<f64>() / te.len() as f64);
    let json = serde_json::json!({
        "duration_s": duration_s,
        "reference": reference,
        "channels": channels.iter().map(|c| serde_json::json!({"name": c.name, "limit": c.limit, "unit": c.unit()})).collect::<Vec<_>>(),
        "forecasts_scored": scored,
        "windows_that_happened": total.hits + total.misses,
        "hits": total.hits,
        "misses": total.misses,
        "forecast_windows": total.good_calls + total.false_alarms,
        "false_alarms": total.false_alarms,
        "detection_rate": total.detection_rate(),
        "false_alarm_ratio": total.false_alarm_ratio(),
        "timing_error_mean_s": mean,
        "timing_error_mean_abs_s": mean_abs,
        "confidence": confidence,
        "definitions": "per forecast, over its trusted span: a forecast window is every channel inside its limit with the confidence by the forecast's band (as the console judges it), a window that happened every channel inside its limit, each for at least duration_s; a window that happened is detected when a forecast window overlaps it (timing error = forecast start - actual start); a forecast window is a false alarm when the motion left a limit within duration_s of its start",
    });
    std::fs::write(dir.join("windows.json"), serde_json::to_string_pretty(&json)? + "\n")?;
    let pct = |x: Option<f64>| x.map_or("n/a".to_string(), |v| format!("{:.0} %", 100.0 * v));
    println!(
        "operator windows ({duration_s:.0} s, {} channels, {scored} forecasts, against the {reference} motion): detection {}, false alarms {}, timing error {} (mean abs): {}/windows.json",
        channels.len(),
        pct(total.detection_rate()),
        pct(total.false_alarm_ratio()),
        mean_abs.map_or("n/a".into(), |v| format!("{v:.1} s")),
        dir.display()
    );
    Ok(())
}

/// One forecast against what followed, a panel per operation channel (display units), plotted by
/// [`plot::forecast`] into `svg` and the PNG beside it.
fn forecast_plot(
    svg: &Path,
    f: &ForecastRecord,
    log_start_s: f64,
    sys: &shipcast::hydro::VesselSystem,
    channels: &[Channel],
    measured: &[Vec<(f64, f64)>],
    reference: &str,
) -> Result<()> {
    let ext = &sys.spec.external;
    let n = f.steps as usize + 1;
    let series: Vec<&[f64]> = f.values.chunks_exact(n).collect();
    let span = (n - 1) as f64 * f.dt_s;
    let mut xs = vec![0.0; series.len()];
    let panels: Vec<plot::ForecastPanel> = channels
        .iter()
        .map(|ch| {
            let actual = (0..n)
                .map(|k| {
                    let t = f.issue_time_s + k as f64 * f.dt_s;
                    // NaN (a gap in the line) where a series has no sample around t
                    let v = xs
                        .iter_mut()
                        .zip(measured)
                        .try_for_each(|(xi, sr)| {
                            *xi = skill::interpolate(sr, t)?;
                            Some(())
                        })
                        .map_or(f64::NAN, |()| ch.value(ext, &xs));
                    (k as f64 * f.dt_s, v)
                })
                .collect();
            let along = ch.along(ext, &series);
            let sigma_series: Vec<&[f64]> = f.sigma.chunks_exact(n).collect();
            let band = ch
                .sigma_along(ext, &sigma_series)
                .into_iter()
                .zip(&along)
                .enumerate()
                .map(|(k, (s, v))| (k as f64 * f.dt_s, v - skill::Z_90 * s, v + skill::Z_90 * s))
                .collect();
            let forecast = along
                .into_iter()
                .enumerate()
                .map(|(k, v)| (k as f64 * f.dt_s, v))
                .collect();
            let (trusted_from_s, trusted_s) = ch.span_s(ext, series.len(), |i| f.series_span(i));
            plot::ForecastPanel {
                name: ch.name.clone(),
                unit: ch.unit().into(),
                limit: ch.limit,
                trusted_s: trusted_s.min(span),
                trusted_from_s,
                band,
                forecast,
                actual,
            }
        })
        .collect();
    plot::forecast(svg, f.issue_time_s - log_start_s, reference, span, &panels)
}

/// Skill of every vessel DOF against lead time, against `measured_all` (every series, 6 per vessel:
/// the true motion of a simulation, or the measured), named by `reference`.
fn report(
    dir: &Path,
    sys: &shipcast::hydro::VesselSystem,
    measured_all: &[Vec<(f64, f64)>],
    reference: &str,
    forecasts: &[ForecastRecord],
    length_s: f64,
) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let nb = sys.spec.bodies.len();
    let step = 5.0;
    let mut json_vessels = vec![];
    let mut csv = String::from(
        "vessel,dof,lead_s,correlation,nrmse,ssp,bias,coverage_90,spread_skill,count,correlation_trusted,coverage_90_trusted,count_trusted\n",
    );
    let mut curves: Vec<plot::SkillCurve> = vec![];
    let mut lead = vec![];
    for b in 0..nb {
        let name = &sys.spec.bodies[b].name;
        let mut dofs = vec![];
        for (d, dof) in shipcast::hydro::Dof::NAMES.iter().enumerate() {
            let measured = &measured_all[6 * b + d];
            let fs = series_forecasts(forecasts, 6 * b + d);
            let sk = skill::score(&fs, measured, step, length_s);
            // the same, scored only inside each forecast's trusted span of this DOF
            let inside = trusted_values(forecasts, 6 * b + d);
            let fs_trusted: Vec<SeriesForecast> = fs
                .iter()
                .zip(&inside)
                .map(|(f, v)| SeriesForecast { values: v, ..*f })
                .collect();
            let trusted = skill::score(&fs_trusted, measured, step, length_s);
            lead = sk.lead_s.clone();
            dofs.push(dof_skill_json(dof, &sk, &trusted));
            push_skill_csv(&mut csv, name, dof, &sk, &trusted);
            if ["heave", "roll", "pitch"].contains(dof) {
                curves.push(plot::SkillCurve {
                    label: format!("{name} {dof}"),
                    correlation: sk.correlation.clone(),
                    nrmse: sk.nrmse.clone(),
                });
            }
        }
        json_vessels.push(format!("\"{name}\":{{{}}}", dofs.join(",")));
    }
    write_skill_json(dir, sys, reference, forecasts, &lead, &json_vessels)?;
    std::fs::write(dir.join("skill.csv"), csv)?;
    plot::skill(&dir.join("skill.svg"), forecasts.len(), reference, &lead, &curves)?;
    let mut out = std::io::stdout().lock();
    writeln!(
        out,
        "report (against the {reference} motion): {}/skill.json, skill.csv, skill.svg, skill.png",
        dir.display()
    )?;
    Ok(())
}

/// Series `s` (6 per vessel) of every forecast, with its band, as [`skill::score`] takes them.
fn series_forecasts(forecasts: &[ForecastRecord], s: usize) -> Vec<SeriesForecast<'_>> {
    forecasts
        .iter()
        .map(|f| {
            let n = f.steps as usize + 1;
            SeriesForecast {
                t0_s: f.issue_time_s,
                dt_s: f.dt_s,
                values: f.values.get(s * n..(s + 1) * n).unwrap_or(&[]),
                sigma: f.sigma.get(s * n..(s + 1) * n).unwrap_or(&[]),
            }
        })
        .collect()
}

/// Series `s` of every forecast, NaN outside its own trusted span (nothing where it has none).
fn trusted_values(forecasts: &[ForecastRecord], s: usize) -> Vec<Vec<f64>> {
    forecasts
        .iter()
        .map(|f| {
            let n = f.steps as usize + 1;
            let (from, to) = f.series_span(s);
            let values = f.values.get(s * n..(s + 1) * n).unwrap_or(&[]);
            values
                .iter()
                .enumerate()
                .map(|(k, v)| {
                    let lead = k as f64 * f.dt_s;
                    if to > 0.0 && lead >= from - 1e-9 && lead <= to + 1e-9 {
                        *v
                    } else {
                        f64::NAN
                    }
                })
                .collect()
        })
        .collect()
}

/// Numbers as the inside of a JSON array, 5 decimals, null where not finite.
fn json_numbers(v: &[f64]) -> String {
    v.iter()
        .map(|x| {
            if x.is_finite() {
                format!("{x:.5}")
            } else {
                "null".into()
            }
        })
        .collect::<Vec<_>>()
        .join(",")
}

/// One DOF's skill as a JSON member, `"dof":{...}`: a value per lead of every score, and `trusted`:
/// correlation, coverage and count inside each forecast's trusted span of the DOF.
fn dof_skill_json(dof: &str, sk: &skill::Skill, trusted: &skill::Skill) -> String {
    format!(
        "\"{dof}\":{{\"correlation\":[{}],\"nrmse\":[{}],\"ssp\":[{}],\"bias\":[{}],\"coverage_90\":[{}],\"spread_skill\":[{}],\"count\":[{}],\"trusted\":{{\"correlation\":[{}],\"coverage_90\":[{}],\"count\":[{}]}}}}",
        json_numbers(&sk.correlation),
        json_numbers(&sk.nrmse),
        json_numbers(&sk.ssp),
        json_numbers(&sk.bias),
        json_numbers(&sk.coverage_90),
        json_numbers(&sk.spread_skill),
        sk.count.iter().map(|c| c.to_string()).collect::<Vec<_>>().join(","),
        json_numbers(&trusted.correlation),
        json_numbers(&trusted.coverage_90),
        trusted
            .count
            .iter()
            .map(|c| c.to_string())
            .collect::<Vec<_>>()
            .join(",")
    )
}

/// Appends a CSV row per lead of one DOF's skill to `csv`.
fn push_skill_csv(csv: &mut String, name: &str, dof: &str, sk: &skill::Skill, trusted: &skill::Skill) {
    for l in 0..sk.lead_s.len() {
        csv.push_str(&format!(
            "{name},{dof},{},{:.5},{:.5},{:.5},{:.5},{:.5},{:.5},{},{:.5},{:.5},{}\n",
            sk.lead_s[l],
            sk.correlation[l],
            sk.nrmse[l],
            sk.ssp[l],
            sk.bias[l],
            sk.coverage_90[l],
            sk.spread_skill[l],
            sk.count[l],
            trusted.correlation[l],
            trusted.coverage_90[l],
            trusted.count[l]
        ));
    }
}

/// The median over the log of each DOF's own trusted span, as JSON members
/// `"vessel":{"heave":[from, to],..}` (null when no forecast has it).
fn dof_span_medians(sys: &shipcast::hydro::VesselSystem, forecasts: &[ForecastRecord]) -> String {
    let median = |mut v: Vec<f64>| -> String {
        v.sort_by(f64::total_cmp);
        v.get(v.len() / 2).map_or("null".to_string(), |x| format!("{x:.3}"))
    };
    (0..sys.spec.bodies.len())
        .map(|b| {
            let dofs = shipcast::hydro::Dof::NAMES
                .iter()
                .enumerate()
                .map(|(d, dof)| {
                    let spans: Vec<(f64, f64)> = forecasts.iter().map(|f| f.series_span(6 * b + d)).collect();
                    let from = median(spans.iter().map(|s| s.0).collect());
                    let to = median(spans.iter().map(|s| s.1).collect());
                    format!("\"{dof}\":[{from},{to}]")
                })
                .collect::<Vec<_>>()
                .join(",");
            format!("\"{}\":{{{dofs}}}", sys.spec.bodies[b].name)
        })
        .collect::<Vec<_>>()
        .join(",")
}

/// The median over the log of a per-vessel value of the forecasts (`get`), as JSON members
/// `"vessel":value` (null when no forecast has it).
fn vessel_medians(
    sys: &shipcast::hydro::VesselSystem,
    forecasts: &[ForecastRecord],
    get: fn(&ForecastRecord) -> &Vec<f64>,
) -> String {
    (0..sys.spec.bodies.len())
        .map(|b| {
            let mut v: Vec<f64> = forecasts.iter().filter_map(|f| get(f).get(b).copied()).collect();
            v.sort_by(f64::total_cmp);
            let m = v.get(v.len() / 2).map_or("null".to_string(), |x| format!("{x:.3}"));
            format!("\"{}\":{m}", sys.spec.bodies[b].name)
        })
        .collect::<Vec<_>>()
        .join(",")
}

/// Writes `skill.json`: the leads, the number of forecasts, the median trusted span of each vessel,
/// and the vessels' skill (`json_vessels`, a JSON member each).
fn write_skill_json(
    dir: &Path,
    sys: &shipcast::hydro::VesselSystem,
    reference: &str,
    forecasts: &[ForecastRecord],
    lead_s: &[f64],
    json_vessels: &[String],
) -> Result<()> {
    let lead_json = lead_s.iter().map(|l| format!("{l}")).collect::<Vec<_>>().join(",");
    // the median published trusted span of each vessel over the log
    let horizons = vessel_medians(sys, forecasts, |f| &f.horizon_s);
    let froms = vessel_medians(sys, forecasts, |f| &f.trusted_from_s);
    let spans = dof_span_medians(sys, forecasts);
    std::fs::write(
        dir.join("skill.json"),
        format!(
            "{{\"reference\":\"{reference}\",\"lead_s\":[{lead_json}],\"forecasts\":{},\"trusted_horizon_s\":{{{horizons}}},\"trusted_from_s\":{{{froms}}},\"spans_s\":{{{spans}}},\"vessels\":{{{}}}}}\n",
            forecasts.len(),
            json_vessels.join(",")
        ),
    )?;
    Ok(())
}

#[derive(Args, Debug)]
pub struct ImportArgs {
    /// The log to write (MCAP).
    #[arg(long)]
    out: PathBuf,
    #[command(flatten)]
    config: super::ConfigArg,
    /// Motion CSV (layout: `src/replay/import.rs`); repeatable.
    #[arg(long)]
    motion: Vec<PathBuf>,
    /// Wave-probe CSV; repeatable (each becomes a stream of fields).
    #[arg(long)]
    probe: Vec<PathBuf>,
    /// Compass direction the waves travel to, for probe files without a towards_deg column.
    #[arg(long, allow_negative_numbers = true)]
    towards_deg: Option<f64>,
    /// A field every this many seconds of a probe record.
    #[arg(long, allow_negative_numbers = true, default_value_t = 2.0)]
    probe_period: f64,
    /// ... fitted to this many seconds of it (default: what the waves take from the probe to the
    /// farthest vessel at the band's slowest group velocity, and 30 s, at least 120 s).
    #[arg(long, allow_negative_numbers = true)]
    probe_window: Option<f64>,
    /// Frequencies kept from a probe record, rad/s.
    #[arg(long, default_value = "0.25:1.6")]
    band: String,
}

/// `shipcast import`: external CSV recordings written as a log that `shipcast replay` takes.
pub fn import(a: &ImportArgs) -> Result<()> {
    use shipcast::shell::replay::import::{ProbeOptions, default_probe_window_s, motion_csv, probe_csv, probe_fields};
    let cfg = load_config(&a.config)?;
    let sys = super::load_system(&cfg)?;
    let vessels: Vec<String> = sys.spec.bodies.iter().map(|b| b.name.clone()).collect();
    if a.motion.is_empty() && a.probe.is_empty() {
        bail!("nothing to import: give --motion and/or --probe files");
    }
    let band = a
        .band
        .split_once(':')
        .and_then(|(l, h)| Some((l.trim().parse::<f64>().ok()?, h.trim().parse::<f64>().ok()?)))
        .with_context(|| format!("--band {}: expected MIN:MAX in rad/s", a.band))?;
    for (name, v) in [
        ("--probe-period", Some(a.probe_period)),
        ("--probe-window", a.probe_window),
    ]
    .into_iter()
    .filter_map(|(n, v)| Some((n, v?)))
    {
        if !(v.is_finite() && v > 0.0) {
            bail!("{name} {v}: must be positive");
        }
    }
    let read = |p: &Path| std::fs::read_to_string(p).with_context(|| format!("reading {}", p.display()));
    let mut records: Vec<(f64, Record)> = vec![];
    for p in &a.motion {
        let m = motion_csv(&read(p)?, &p.display().to_string(), &vessels).map_err(|e| anyhow::anyhow!(e))?;
        eprintln!("{}: {} motion samples", p.display(), m.len());
        records.extend(m.into_iter().map(|r| (r.time_s, Record::Motion(r))));
    }
    let (vessels_m, _) = shipcast::engine::vessel_positions(&cfg, &sys);
    for p in &a.probe {
        let file = p.display().to_string();
        let rec = probe_csv(&read(p)?, &file).map_err(|e| anyhow::anyhow!(e))?;
        let window_s = a.probe_window.unwrap_or_else(|| {
            rec.towards_deg
                .or(a.towards_deg)
                .map_or(shipcast::shell::replay::import::MIN_PROBE_WINDOW_S, |towards| {
                    default_probe_window_s(
                        rec.position_m,
                        towards,
                        &vessels_m,
                        band,
                        sys.spec.g_m_s2,
                        sys.spec.water_depth_m,
                    )
                })
        });
        let opts = ProbeOptions {
            period_s: a.probe_period,
            window_s,
            band_rad_s: band,
            g_m_s2: sys.spec.g_m_s2,
            depth_m: sys.spec.water_depth_m,
            towards_deg: a.towards_deg,
        };
        let f = probe_fields(&rec, &opts, &file).map_err(|e| anyhow::anyhow!(e))?;
        eprintln!(
            "{file}: {} samples, {} wave fields, each fitted to {window_s:.0} s",
            rec.time_s.len(),
            f.len()
        );
        records.extend(f.into_iter().map(|w| (w.time_s, Record::Waves(w))));
    }
    records.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut rec = record::Recorder::create(&a.out, &record::LogInfo::of(&cfg, &cfg.system.file, &sys, "import"))
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    for (t, r) in &records {
        rec.record(*t, r).map_err(|e| anyhow::anyhow!("{e}"))?;
    }
    rec.finish().map_err(|e| anyhow::anyhow!("{e}"))?;
    println!("{}: {} messages", a.out.display(), records.len());
    Ok(())
}
