//! `shipcast rao`: motion RAOs as CSV, from the frequency domain, the time domain or the time-domain
//! model's implied frequency domain.

use super::Radiation;
use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};
use shipcast::hydro::VesselSystem;
use shipcast::rao::FrequencySolver;
use shipcast::rom::regular::{RegularOptions, time_domain_rao};
use shipcast::rom::{RomOptions, TimeModel, floor};
use shipcast::shell::files;
use std::io::Write;
use std::path::PathBuf;

#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// Solve the linear frequency-domain equations of motion.
    Frequency,
    /// Run the time-domain ROM in regular waves and fit the steady state.
    Time,
    /// Solve the frequency domain of the time-domain model itself (A and B implied by its radiation
    /// memory): the floor the time domain converges to.
    Implied,
}

#[derive(Args, Debug)]
pub struct RaoArgs {
    /// The system file (system.toml).
    pub system: PathBuf,
    #[arg(long, value_enum, default_value = "frequency")]
    pub method: Method,
    /// Wave headings in degrees (direction the waves travel to, counterclockwise from +x; 180 = head
    /// seas), comma-separated. Default: every heading in the database.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    pub heading: Option<Vec<f64>>,
    /// Wave frequencies in rad/s: START:STOP:STEP or a comma-separated list. Default: the database's.
    #[arg(long)]
    pub omega: Option<String>,
    /// Forward speed, m/s.
    #[arg(long, allow_negative_numbers = true, default_value_t = 0.0)]
    pub speed: f64,
    /// Radiation memory of the time-domain model.
    #[arg(long, value_enum, default_value = "convolution")]
    pub radiation: Radiation,
    /// Time step of the time-domain model, s. Default: the daemon's, 100 steps in the system's
    /// shortest natural period (in whole 0.005 s, at most 0.1 s; `db check` prints it).
    #[arg(long, allow_negative_numbers = true)]
    pub dt: Option<f64>,
}

/// Validated frequencies.
#[derive(Debug, PartialEq)]
struct Omegas(Vec<f64>);

impl Omegas {
    fn parse(s: &str) -> Result<Omegas> {
        let bad =
            |why: &str| anyhow::anyhow!("--omega `{s}`: {why} (expected START:STOP:STEP or a list a,b,c in rad/s)");
        let nums = |parts: Vec<&str>| -> Result<Vec<f64>> {
            parts
                .iter()
                .map(|p| {
                    p.trim()
                        .parse::<f64>()
                        .map_err(|_| bad(&format!("`{p}` is not a number")))
                })
                .collect()
        };
        let v = if s.contains(':') {
            let p = nums(s.split(':').collect())?;
            let [a, b, step] = p[..] else {
                return Err(bad("a range needs three fields"));
            };
            if !(step > 0.0 && b >= a) {
                return Err(bad("the step must be positive and STOP >= START"));
            }
            let n = ((b - a) / step + 1e-9).floor() as usize;
            if n > 100_000 {
                return Err(bad("more than 100000 frequencies"));
            }
            (0..=n).map(|k| a + k as f64 * step).collect()
        } else {
            nums(s.split(',').collect())?
        };
        if v.iter().any(|w| !(w.is_finite() && *w > 0.0)) {
            return Err(bad("frequencies must be positive"));
        }
        Ok(Omegas(v))
    }
}

/// `rao`'s model options, checked as they are read ([`RomOptions::validate`]); the error names the flag.
fn flag_checked(opts: RomOptions) -> Result<RomOptions> {
    opts.validate().map_err(|e| {
        let flag = match e.field {
            "dt_s" => "--dt",
            "speed_m_s" => "--speed",
            other => other,
        };
        anyhow::anyhow!("{flag}: {}", e.msg)
    })?;
    Ok(opts)
}

pub fn run(args: &RaoArgs) -> Result<()> {
    if args.method != Method::Time && args.speed != 0.0 {
        bail!(
            "--speed {}: the frequency-domain solver is for zero speed; use --method time",
            args.speed
        );
    }
    let loaded = files::load_system(&args.system)?;
    let sys = &loaded.system;
    let omegas = omegas_of(args, sys)?;
    let headings_deg = headings_deg_of(args, sys)?;
    let headings_rad: Vec<f64> = headings_deg.iter().map(|h| h.to_radians()).collect();
    let context = || args.system.display().to_string();
    let dt_s = args.dt.unwrap_or_else(|| shipcast::rom::step::default_step(sys).dt_s);
    // [heading][omega][mode]
    let table: floor::RaoTable = match args.method {
        Method::Frequency => FrequencySolver::new(sys)
            .table(&omegas, &headings_rad)
            .with_context(context)?,
        Method::Implied => {
            let opts = RomOptions {
                dt_s,
                radiation: args.radiation.into(),
                ..RomOptions::default()
            };
            let model = TimeModel::new(sys, flag_checked(opts)?).with_context(context)?;
            floor::implied_table(&model, &omegas, &headings_rad).with_context(context)?
        }
        Method::Time => time_table(args, sys, dt_s, &omegas, &headings_deg)?,
    };
    write_csv(&omegas, &headings_deg, &table)
}

/// The frequencies of `--omega`, else the database's within its range, rad/s.
fn omegas_of(args: &RaoArgs, sys: &VesselSystem) -> Result<Vec<f64>> {
    Ok(match &args.omega {
        Some(s) => Omegas::parse(s)?.0,
        None => {
            let (lo, hi) = sys.db.omega_range();
            sys.db
                .omega_rad_s
                .iter()
                .copied()
                .filter(|w| *w >= lo && *w <= hi)
                .collect()
        }
    })
}

/// The headings of `--heading` (refused unless finite), else the database's, deg.
fn headings_deg_of(args: &RaoArgs, sys: &VesselSystem) -> Result<Vec<f64>> {
    Ok(match &args.heading {
        Some(h) => {
            if let Some(bad) = h.iter().find(|v| !v.is_finite()) {
                bail!("--heading {bad}: not a finite angle in degrees");
            }
            h.clone()
        }
        None => sys.db.heading_rad.iter().map(|h| h.to_degrees()).collect(),
    })
}

/// The time-domain RAO table ([heading][omega][mode]): the model at `--speed` run in regular waves at
/// every heading, the headings spread over the cores; a summary on stderr.
fn time_table(
    args: &RaoArgs,
    sys: &VesselSystem,
    dt_s: f64,
    omegas: &[f64],
    headings_deg: &[f64],
) -> Result<floor::RaoTable> {
    let t0 = std::time::Instant::now();
    let context = || args.system.display().to_string();
    let opts = RomOptions {
        dt_s,
        radiation: args.radiation.into(),
        speed_m_s: args.speed,
        ..RomOptions::default()
    };
    // a system with databases at several speeds: the one at this speed
    let at = sys.at_speed(args.speed).with_context(context)?;
    let model = TimeModel::new(&at, flag_checked(opts)?).with_context(context)?;
    // the headings are independent runs: one thread per core, each taking every n-th heading
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .clamp(1, headings_deg.len().max(1));
    let table = headings_in_threads(args, &model, omegas, headings_deg, threads)?;
    eprintln!(
        "shipcast rao: time domain, {:?} radiation (memory {}), dt {} s: {} headings x {} frequencies in {:.2} s ({threads} threads)",
        opts.radiation,
        model.memory_size(),
        opts.dt_s,
        headings_deg.len(),
        omegas.len(),
        t0.elapsed().as_secs_f64()
    );
    Ok(table)
}

/// Runs `model` in regular waves at every heading on `threads` threads (thread t takes every
/// `threads`-th heading from the t-th) and gathers the RAOs by heading; the first failed heading in
/// heading order is the error.
fn headings_in_threads(
    args: &RaoArgs,
    model: &TimeModel,
    omegas: &[f64],
    headings_deg: &[f64],
    threads: usize,
) -> Result<floor::RaoTable> {
    let runs: Vec<Vec<(usize, _)>> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..threads)
            .map(|t| {
                scope.spawn(move || {
                    (t..headings_deg.len())
                        .step_by(threads)
                        .map(|ih| {
                            let h: f64 = headings_deg[ih];
                            (
                                ih,
                                time_domain_rao(model, h.to_radians(), omegas, RegularOptions::default()),
                            )
                        })
                        .collect()
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|j| j.join().unwrap_or_else(|p| std::panic::resume_unwind(p)))
            .collect()
    });
    let mut table = vec![vec![]; headings_deg.len()];
    for (ih, r) in runs.into_iter().flatten() {
        let h = headings_deg[ih];
        let r = r.with_context(|| format!("{}: heading {h} deg", args.system.display()))?;
        tracing::info!(heading_deg = h, settled_s = r.settled_s, "steady state reached");
        table[ih] = r.rao;
    }
    Ok(table)
}

/// Writes the table as CSV on stdout: a row per frequency, heading and mode (1-based), amplitude and
/// phase in degrees.
fn write_csv(omegas: &[f64], headings_deg: &[f64], table: &floor::RaoTable) -> Result<()> {
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    writeln!(out, "omega,heading_deg,mode,amplitude,phase_deg")?;
    for (iw, &w) in omegas.iter().enumerate() {
        for (ih, &h) in headings_deg.iter().enumerate() {
            for (i, x) in table[ih][iw].iter().enumerate() {
                writeln!(out, "{w},{h},{},{:.9e},{:.6}", i + 1, x.norm(), x.arg().to_degrees())?;
            }
        }
    }
    out.flush()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn omegas_parse_ranges_and_lists() {
        assert_eq!(Omegas::parse("0.5,1.0").unwrap(), Omegas(vec![0.5, 1.0]));
        let r = Omegas::parse("0.2:0.5:0.1").unwrap().0;
        assert_eq!(r.len(), 4);
        assert!((r[3] - 0.5).abs() < 1e-12);
        for bad in ["0.2:0.1:0.1", "a,b", "0.1:0.2", "-1", "0.2:0.5:0"] {
            assert!(Omegas::parse(bad).is_err(), "{bad}");
        }
    }
}
