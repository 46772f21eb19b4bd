//! `shipcast replay LOG`: a recorded log through the daemon's engine, with a skill report.

use super::daemon::{DEFAULT_CONFIG, load_config};
use anyhow::{Context, Result, bail};
use clap::Args;
use shipcast::replay::{self, ForecastRecord, Record};
use shipcast::skill::{self, SeriesForecast};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

#[derive(Args, Debug)]
pub struct ReplayArgs {
    /// The log (MCAP), e.g. from `shipcast simulate --record`.
    log: PathBuf,
    #[arg(long, default_value = DEFAULT_CONFIG)]
    config: PathBuf,
    /// Log seconds per wall second (default: as fast as possible).
    #[arg(long, conflicts_with = "max")]
    speed: Option<f64>,
    /// As fast as possible (the default).
    #[arg(long)]
    max: bool,
    /// Write skill.json, skill.csv and skill.svg here.
    #[arg(long)]
    report: Option<PathBuf>,
    /// Write the replayed forecasts to this log.
    #[arg(long)]
    out: Option<PathBuf>,
}

const DOFS: [&str; 6] = ["surge", "sway", "heave", "roll", "pitch", "yaw"];

pub fn run(a: &ReplayArgs) -> Result<()> {
    let cfg = load_config(&a.config)?;
    let sys = shipcast::files::load_system(&cfg.dir.join(&cfg.system.file))?.system;
    if let Some(s) = a.speed
        && !(s.is_finite() && s > 0.0)
    {
        bail!("--speed {s}: must be positive");
    }
    let log = replay::read(&a.log).map_err(|e| anyhow::anyhow!("{e}"))?;
    for w in &log.warnings {
        eprintln!("shipcast replay: warning: {w}");
    }
    let (Some(first), Some(last)) = (log.records.first(), log.records.last()) else {
        bail!("{}: no messages", a.log.display());
    };
    let (t_first, t_last) = (first.0, last.0);
    let wall = Instant::now();
    let mut forecasts: Vec<ForecastRecord> = vec![];
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
        },
        |h, v| forecasts.push(ForecastRecord::of(h, v)),
    )
    .map_err(|e| anyhow::anyhow!("{e}"))?;
    let secs = wall.elapsed().as_secs_f64();
    let span_h = (t_last - t_first) / 3600.0;
    eprintln!(
        "shipcast replay: {} messages over {:.1} s of log, {} forecasts ({} samples, {} dropped) in {:.1} s: {:.2} log hours per wall minute",
        log.records.len(),
        t_last - t_first,
        forecasts.len(),
        counters.samples,
        counters.nonfinite + counters.late + counters.duplicate,
        secs,
        span_h / (secs / 60.0)
    );
    if let Some(p) = &a.out {
        let mut rec = replay::Recorder::create(p).map_err(|e| anyhow::anyhow!("{e}"))?;
        for f in &forecasts {
            rec.write("/forecast", f.issue_time_s, f)
                .map_err(|e| anyhow::anyhow!("{e}"))?;
        }
        rec.finish().map_err(|e| anyhow::anyhow!("{e}"))?;
    }
    if let Some(dir) = &a.report {
        report(dir, &sys, &log.records, &forecasts, cfg.forecast.horizon_s)?;
    }
    Ok(())
}

/// Skill of every vessel DOF against lead time, against the measured motion in the log.
fn report(
    dir: &Path,
    sys: &shipcast::hydro::VesselSystem,
    records: &[(f64, Record)],
    forecasts: &[ForecastRecord],
    horizon_s: f64,
) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let nb = sys.spec.bodies.len();
    let step = 5.0;
    let mut json_vessels = vec![];
    let mut csv = String::from("vessel,dof,lead_s,correlation,nrmse,ssp,bias,count\n");
    let mut curves: Vec<(String, Vec<f64>, Vec<f64>)> = vec![];
    let mut lead = vec![];
    for b in 0..nb {
        let name = &sys.spec.bodies[b].name;
        let mut dofs = vec![];
        for (d, dof) in DOFS.iter().enumerate() {
            let measured: Vec<(f64, f64)> = records
                .iter()
                .filter_map(|(_, r)| match r {
                    Record::Motion(m) if m.vessel as usize == b => Some((m.time_s, m.x[d])),
                    _ => None,
                })
                .collect();
            let fs: Vec<SeriesForecast> = forecasts
                .iter()
                .map(|f| {
                    let n = f.steps as usize + 1;
                    let s = 6 * b + d;
                    SeriesForecast {
                        t0_s: f.issue_time_s,
                        dt_s: f.dt_s,
                        values: f.values.get(s * n..(s + 1) * n).unwrap_or(&[]),
                    }
                })
                .collect();
            let sk = skill::score(&fs, &measured, step, horizon_s);
            lead = sk.lead_s.clone();
            let arr = |v: &[f64]| {
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
            };
            dofs.push(format!(
                "\"{dof}\":{{\"correlation\":[{}],\"nrmse\":[{}],\"ssp\":[{}],\"bias\":[{}],\"count\":[{}]}}",
                arr(&sk.correlation),
                arr(&sk.nrmse),
                arr(&sk.ssp),
                arr(&sk.bias),
                sk.count.iter().map(|c| c.to_string()).collect::<Vec<_>>().join(",")
            ));
            for l in 0..sk.lead_s.len() {
                csv.push_str(&format!(
                    "{name},{dof},{},{:.5},{:.5},{:.5},{:.5},{}\n",
                    sk.lead_s[l], sk.correlation[l], sk.nrmse[l], sk.ssp[l], sk.bias[l], sk.count[l]
                ));
            }
            if ["heave", "roll", "pitch"].contains(dof) {
                curves.push((format!("{name} {dof}"), sk.correlation.clone(), sk.nrmse.clone()));
            }
        }
        json_vessels.push(format!("\"{name}\":{{{}}}", dofs.join(",")));
    }
    let lead_json = lead.iter().map(|l| format!("{l}")).collect::<Vec<_>>().join(",");
    std::fs::write(
        dir.join("skill.json"),
        format!(
            "{{\"lead_s\":[{lead_json}],\"forecasts\":{},\"vessels\":{{{}}}}}\n",
            forecasts.len(),
            json_vessels.join(",")
        ),
    )?;
    std::fs::write(dir.join("skill.csv"), csv)?;
    std::fs::write(dir.join("skill.svg"), svg(&lead, &curves))?;
    let mut out = std::io::stdout().lock();
    writeln!(out, "report: {}/skill.json, skill.csv, skill.svg", dir.display())?;
    Ok(())
}

/// A plain SVG of correlation (solid) and normalized RMS error (dashed) against lead time. Hand-written:
/// polylines and a few labels need no plotting library (and no fonts at build time).
fn svg(lead: &[f64], curves: &[(String, Vec<f64>, Vec<f64>)]) -> String {
    let (w, h, m) = (900.0, 500.0, 60.0);
    let lmax = lead.last().copied().unwrap_or(1.0).max(1.0);
    let x = |l: f64| m + (w - 2.0 * m) * l / lmax;
    let y = |v: f64| h - m - (h - 2.0 * m) * v.clamp(0.0, 1.5) / 1.5;
    let colours = [
        "#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#17becf", "#e377c2",
    ];
    let mut s = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
    );
    s.push_str(&format!(
        "<line x1=\"{m}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" stroke=\"black\"/><line x1=\"{m}\" y1=\"{m}\" x2=\"{m}\" y2=\"{}\" stroke=\"black\"/>\n",
        h - m,
        w - m,
        h - m,
        h - m
    ));
    for v in [0.0, 0.5, 1.0, 1.5] {
        s.push_str(&format!(
            "<text x=\"{}\" y=\"{}\" text-anchor=\"end\">{v}</text><line x1=\"{m}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" stroke=\"#ddd\"/>\n",
            m - 5.0,
            y(v) + 4.0,
            y(v),
            w - m,
            y(v)
        ));
    }
    let mut l = 0.0;
    while l <= lmax + 1e-9 {
        s.push_str(&format!(
            "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">{l:.0}</text>\n",
            x(l),
            h - m + 18.0
        ));
        l += (lmax / 6.0).max(5.0).round();
    }
    s.push_str(&format!(
        "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">lead time, s (solid: correlation; dashed: RMS error / measured std)</text>\n",
        w / 2.0,
        h - 15.0
    ));
    for (i, (name, corr, nrmse)) in curves.iter().enumerate() {
        let c = colours[i % colours.len()];
        for (vals, dash) in [(corr, ""), (nrmse, " stroke-dasharray=\"6,4\"")] {
            let pts: Vec<String> = lead
                .iter()
                .zip(vals.iter())
                .filter(|(_, v)| v.is_finite())
                .map(|(l, v)| format!("{:.1},{:.1}", x(*l), y(*v)))
                .collect();
            s.push_str(&format!(
                "<polyline fill=\"none\" stroke=\"{c}\" stroke-width=\"2\"{dash} points=\"{}\"/>\n",
                pts.join(" ")
            ));
        }
        s.push_str(&format!(
            "<text x=\"{}\" y=\"{}\" fill=\"{c}\">{name}</text>\n",
            w - m - 150.0,
            m + 16.0 * i as f64
        ));
    }
    s.push_str("</svg>\n");
    s
}
