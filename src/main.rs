//! The `shipcast` binary: argument parsing and wiring only (the work is in the library).
//!
//! Command-line handling in two stages (ripgrep's habit): clap's raw flags, close to what was typed,
//! then validated values ([`Omegas`], headings in radians) that build the real objects.

use anyhow::{Context, Result, bail};
use clap::{Args, Parser, Subcommand, ValueEnum};
use shipcast::files;
use shipcast::hydro::check::{self, mode_label};
use shipcast::rao::FrequencySolver;
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser, Debug)]
#[command(
    name = "shipcast",
    version,
    about = "Real-time ship-motion forecasting for one or more vessels"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Vessel databases: load, validate and summarize.
    Db {
        #[command(subcommand)]
        command: DbCommand,
    },
    /// Motion RAOs of a system as CSV on stdout: omega,heading_deg,mode,amplitude,phase_deg.
    Rao(RaoArgs),
}

#[derive(Subcommand, Debug)]
enum DbCommand {
    /// Load and validate a system file and its WAMIT database; print a summary with the natural
    /// periods and the Kramers-Kronig consistency. Exits non-zero on any invalid input.
    Check {
        /// The system file (system.toml).
        system: PathBuf,
        /// Print the Kramers-Kronig error of every DOF pair, not only the worst ones.
        #[arg(long)]
        all_pairs: bool,
    },
}

#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
enum Method {
    /// Solve the linear frequency-domain equations of motion.
    Frequency,
    /// Run the time-domain ROM in regular waves and fit the steady state.
    Time,
}

#[derive(Args, Debug)]
struct RaoArgs {
    /// The system file (system.toml).
    system: PathBuf,
    #[arg(long, value_enum, default_value = "frequency")]
    method: Method,
    /// Wave headings in degrees (direction the waves travel to, counterclockwise from +x; 180 = head
    /// seas), comma-separated. Default: every heading in the database.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    heading: Option<Vec<f64>>,
    /// Wave frequencies in rad/s: START:STOP:STEP or a comma-separated list. Default: the database's.
    #[arg(long)]
    omega: Option<String>,
    /// Forward speed, m/s.
    #[arg(long, default_value_t = 0.0)]
    speed: f64,
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

fn main() -> ExitCode {
    tracing_subscriber::fmt()
        .with_env_filter(tracing_subscriber::EnvFilter::try_from_default_env().unwrap_or_else(|_| "warn".into()))
        .with_writer(std::io::stderr)
        .init();
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Db {
            command: DbCommand::Check { system, all_pairs },
        } => db_check(&system, all_pairs),
        Command::Rao(args) => rao(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) if is_broken_pipe(&e) => ExitCode::SUCCESS, // `shipcast rao ... | head`
        Err(e) => {
            eprintln!("shipcast: error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn is_broken_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        c.downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
    })
}

fn db_check(path: &std::path::Path, all_pairs: bool) -> Result<()> {
    let t0 = std::time::Instant::now();
    let loaded = files::load_system(path)?;
    let sys = &loaded.system;
    let db = &sys.db;
    let mut out = std::io::stdout().lock();
    writeln!(out, "system: {}", path.display())?;
    for f in &loaded.files[1..] {
        writeln!(out, "  read {}", f.display())?;
    }
    let depth = sys
        .spec
        .water_depth_m
        .map(|d| format!("{d} m"))
        .unwrap_or("infinite".into());
    writeln!(
        out,
        "rho = {} kg/m^3, g = {} m/s^2, ULEN = {} m, water depth {depth}, hydrodynamic coupling {}",
        sys.spec.rho_kg_m3,
        sys.spec.g_m_s2,
        sys.spec.ulen_m,
        if sys.spec.hydrodynamic_coupling {
            "on"
        } else {
            "off (own 6x6 blocks only)"
        }
    )?;
    writeln!(out, "bodies: {} ({} modes)", sys.spec.bodies.len(), sys.n_modes())?;
    for (k, b) in sys.spec.bodies.iter().enumerate() {
        let active: Vec<&str> = (0..6)
            .filter(|j| b.active[*j])
            .map(|j| shipcast::hydro::Dof::ALL[j].name())
            .collect();
        writeln!(
            out,
            "  {k}: {} at ({:.3}, {:.3}, {:.3}) m, mass {:.6e} kg, modes {}..{}, active: {}",
            b.name,
            b.position_m.x,
            b.position_m.y,
            b.position_m.z,
            b.mass[(0, 0)],
            6 * k + 1,
            6 * k + 6,
            active.join(" ")
        )?;
    }
    let w = &db.omega_rad_s;
    let min_dw = w.windows(2).map(|p| p[1] - p[0]).fold(f64::INFINITY, f64::min);
    let max_dw = w.windows(2).map(|p| p[1] - p[0]).fold(0.0, f64::max);
    writeln!(
        out,
        "radiation: {} frequencies {:.4}..{:.4} rad/s (spacing {:.4}..{:.4} rad/s), A(0) {}, A_inf {}",
        w.len(),
        w[0],
        w[w.len() - 1],
        min_dw,
        max_dw,
        if db.added_mass_zero.is_some() {
            "present"
        } else {
            "absent"
        },
        if db.added_mass_inf.is_some() {
            "present"
        } else {
            "absent"
        }
    )?;
    let hd: Vec<String> = db
        .heading_rad
        .iter()
        .map(|h| format!("{:.1}", h.to_degrees()))
        .collect();
    writeln!(
        out,
        "excitation: {} frequencies {:.4}..{:.4} rad/s, {} headings [{}] deg{}",
        db.exc_omega_rad_s.len(),
        db.exc_omega_rad_s[0],
        db.exc_omega_rad_s[db.exc_omega_rad_s.len() - 1],
        db.heading_rad.len(),
        hd.join(", "),
        if db.headings_cover_circle() {
            " (full circle)"
        } else {
            ""
        }
    )?;
    let report = check::check(sys);
    writeln!(
        out,
        "natural periods (undamped, diagonal terms: lowest w with C = w^2 (M + A(w))):"
    )?;
    for (i, t) in &report.natural_periods_s {
        writeln!(
            out,
            "  {:<20} T = {:8.3} s  (omega = {:.4} rad/s)",
            mode_label(sys, *i),
            t,
            2.0 * std::f64::consts::PI / t
        )?;
    }
    writeln!(
        out,
        "impulse response: dt = {} s, memory {:.1} s, high-frequency tail B ~ w^-{} beyond {:.4} rad/s",
        report.irf.dt_s,
        report.irf.duration_s(),
        shipcast::hydro::radiation::TAIL_POWER,
        w[w.len() - 1]
    )?;
    writeln!(
        out,
        "A_inf used: {}",
        match report.a_inf_source {
            shipcast::hydro::system::AInfSource::Database => "the database's (PER = 0)",
            shipcast::hydro::system::AInfSource::Ogilvie => "Ogilvie's estimate (median over w)",
        }
    )?;
    let mut kk = report.kk.clone();
    kk.sort_by(|a, b| b.added_mass_band.total_cmp(&a.added_mass_band));
    let worst = |f: fn(&shipcast::hydro::radiation::PairError) -> f64| kk.iter().map(f).fold(0.0, f64::max);
    let band = shipcast::hydro::radiation::KK_BAND_FRACTION * w[w.len() - 1];
    writeln!(
        out,
        "Kramers-Kronig (A, B rebuilt from K; error / sqrt(scale_ii scale_jj)): worst A {:.3} % up to {band:.3} rad/s, {:.3} % over all; worst B {:.3} %",
        100.0 * worst(|e| e.added_mass_band),
        100.0 * worst(|e| e.added_mass),
        100.0 * worst(|e| e.damping)
    )?;
    let og_band = report.kk_ogilvie.iter().map(|e| e.added_mass_band).fold(0.0, f64::max);
    writeln!(
        out,
        "  with Ogilvie's A_inf instead: worst A {:.3} % up to {band:.3} rad/s",
        100.0 * og_band
    )?;
    let shown = if all_pairs { kk.len() } else { kk.len().min(8) };
    for e in &kk[..shown] {
        writeln!(
            out,
            "  {:>2} {:>2} {:<16} {:<16} A {:7.3} % in band, {:7.3} % all (at {:.3} rad/s)  B {:7.3} %  Ogilvie A_inf spread {:7.3} %",
            e.i + 1,
            e.j + 1,
            mode_label(sys, e.i),
            mode_label(sys, e.j),
            100.0 * e.added_mass_band,
            100.0 * e.added_mass,
            e.added_mass_at_rad_s,
            100.0 * e.damping,
            100.0 * e.a_inf_spread
        )?;
    }
    if shown < kk.len() {
        writeln!(out, "  ... {} more pairs (--all-pairs)", kk.len() - shown)?;
    }
    let mut warnings = sys.warnings.clone();
    for (i, ws) in &report.negative_damping {
        let peak = db.damping.iter().map(|b| b[(*i, *i)]).fold(0.0, f64::max);
        let (k, low) = db
            .damping
            .iter()
            .enumerate()
            .map(|(k, b)| (k, b[(*i, *i)]))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap_or((0, 0.0));
        warnings.push(format!(
            "negative diagonal damping B({0},{0}) ({1}) at {2} frequencies in {3:.4}..{4:.4} rad/s, lowest {5:.4e} at {6:.4} rad/s ({7:.3} % of its peak): irregular frequencies, panels too coarse or numerical noise",
            i + 1,
            mode_label(sys, *i),
            ws.len(),
            ws[0],
            ws[ws.len() - 1],
            low,
            w[k],
            100.0 * low.abs() / peak.max(f64::MIN_POSITIVE)
        ));
    }
    for n in &loaded.notes {
        writeln!(out, "note: {n}")?;
    }
    if warnings.is_empty() {
        writeln!(out, "warnings: none")?;
    } else {
        writeln!(out, "warnings: {}", warnings.len())?;
        for wmsg in &warnings {
            writeln!(out, "  WARNING: {wmsg}")?;
        }
    }
    writeln!(out, "checked in {:.2} s", t0.elapsed().as_secs_f64())?;
    Ok(())
}

fn rao(args: &RaoArgs) -> Result<()> {
    if args.method == Method::Time {
        bail!("--method time is not implemented yet (it comes with the time-domain ROM); use --method frequency");
    }
    if args.speed != 0.0 {
        bail!(
            "--speed {}: the databases carry zero-speed data only; forward speed is not supported yet",
            args.speed
        );
    }
    let loaded = files::load_system(&args.system)?;
    let sys = &loaded.system;
    let omegas = match &args.omega {
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
    };
    let headings_deg: Vec<f64> = match &args.heading {
        Some(h) => {
            if let Some(bad) = h.iter().find(|v| !v.is_finite()) {
                bail!("--heading {bad}: not a finite angle in degrees");
            }
            h.clone()
        }
        None => sys.db.heading_rad.iter().map(|h| h.to_degrees()).collect(),
    };
    let solver = FrequencySolver::new(sys);
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    writeln!(out, "omega,heading_deg,mode,amplitude,phase_deg")?;
    for &w in &omegas {
        for &h in &headings_deg {
            let xi = solver
                .rao(w, h.to_radians())
                .with_context(|| format!("{}: omega {w} rad/s, heading {h} deg", args.system.display()))?;
            for (i, x) in xi.iter().enumerate() {
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
