//! The `shipcast` binary: argument parsing and wiring only (the work is in the library).
//!
//! Command-line handling in two stages (ripgrep's habit): clap's raw flags, close to what was typed,
//! then validated values ([`Omegas`], headings in radians) that build the real objects.

use anyhow::{Context, Result, bail};
use clap::{Args, Parser, Subcommand, ValueEnum};
use shipcast::files;
use shipcast::hydro::check::{self, mode_label};
use shipcast::hydro::radiation;
use shipcast::rao::FrequencySolver;
use shipcast::rom::model::Kernel;
use shipcast::rom::regular::{RegularOptions, time_domain_rao};
use shipcast::rom::{Forecaster, RadiationMethod, RomOptions, TimeModel, floor};
use shipcast::scenario::{Scenario, past_options, prepare};
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

/// `db check` warns when a radiation model's floor is off the database's frequency domain by more than
/// this fraction of a curve's peak: the bar for the time domain against the frequency domain.
const FLOOR_WARNING: f64 = 0.01;
/// `db check` warns when the database's A or B had to be repaired (made symmetric, or B made positive
/// semi-definite) by more than this fraction of a coupling's scale: the pair's unsymmetric couplings (up
/// to 3 % in A, 4 % in B) once moved its beam-sea lighter yaw RAO by 6 %; 1 % is a database problem.
const REPAIR_WARNING: f64 = 0.01;

mod cli;

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
    /// Forecast a scenario (system, sea, speed, history, horizon); with --repeat, time it.
    Forecast(ForecastArgs),
    /// The predictable horizon of a radar disc in a sea state; last line `horizon_s=<x>`.
    Horizon(cli::horizon::HorizonArgs),
    /// The forecasting daemon: iceoryx2 in and out, a forecast every period.
    Run(cli::daemon::RunArgs),
    /// The synthetic sea: true motion and sensor streams (published live with --publish).
    Simulate(cli::daemon::SimulateArgs),
    /// Print forecasts and status as they arrive (the reference subscriber).
    Watch(cli::daemon::WatchArgs),
    /// The operator's terminal view: motion and forecast per channel, limits, quiet windows, inputs.
    Console(cli::console::ConsoleArgs),
    /// One command to try it: the synthetic sea, the daemon and a live view of forecasts and skill.
    Demo(cli::daemon::DemoArgs),
    /// A recorded log through the daemon's engine; with --report, skill against lead time.
    Replay(cli::replay::ReplayArgs),
    /// External CSV recordings (motion, wave probes) written as a log for `replay`.
    Import(cli::replay::ImportArgs),
}

#[derive(Args, Debug)]
struct ForecastArgs {
    /// The scenario file (e.g. config/scenarios/two-ship.toml).
    scenario: PathBuf,
    /// Forecast length, s, in (0, 3600] (default: the scenario's).
    #[arg(long, allow_negative_numbers = true, value_parser = forecast_length)]
    horizon: Option<f64>,
    /// Run the forecast N times and print the median and p95 wall time of one, as the last line.
    #[arg(long, allow_negative_numbers = true, default_value_t = 1)]
    repeat: usize,
    /// Radiation memory (default: the scenario's).
    #[arg(long, value_enum)]
    radiation: Option<Radiation>,
    /// Output format.
    #[arg(long, value_enum, default_value = "csv")]
    format: Format,
    /// Write the forecast here instead of stdout.
    #[arg(long)]
    out: Option<PathBuf>,
}

/// `--horizon`: checked as it is read, before any work.
fn forecast_length(s: &str) -> Result<f64, String> {
    let max = shipcast::rom::forecast::MAX_FORECAST_LENGTH_S;
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 && v <= max => Ok(v),
        Ok(v) => Err(format!("{v} s: a forecast's length must be in (0, {max}] s")),
        Err(_) => Err(format!("`{s}` is not a number of seconds")),
    }
}

#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    Csv,
    Json,
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
    /// Solve the frequency domain of the time-domain model itself (A and B implied by its radiation
    /// memory): the floor the time domain converges to.
    Implied,
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
    #[arg(long, allow_negative_numbers = true, default_value_t = 0.0)]
    speed: f64,
    /// Radiation memory of the time-domain model.
    #[arg(long, value_enum, default_value = "convolution")]
    radiation: Radiation,
    /// Time step of the time-domain model, s. Default: the daemon's, 100 steps in the system's
    /// shortest natural period (in whole 0.005 s, at most 0.1 s; `db check` prints it).
    #[arg(long, allow_negative_numbers = true)]
    dt: Option<f64>,
}

#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
enum Radiation {
    /// Direct convolution of the impulse response with the velocity history.
    Convolution,
    /// The passive state-space fit.
    StateSpace,
}

impl From<Radiation> for RadiationMethod {
    fn from(r: Radiation) -> Self {
        match r {
            Radiation::Convolution => RadiationMethod::Convolution,
            Radiation::StateSpace => RadiationMethod::StateSpace,
        }
    }
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

/// Logs to stderr: `RUST_LOG` if set, else `level`; human-readable or JSON lines.
fn init_logging(level: &str, json: bool) {
    // iceoryx2 logs through tracing; its warnings (e.g. "no config file, defaults used") are noise here
    let filter = tracing_subscriber::EnvFilter::try_from_default_env()
        .unwrap_or_else(|_| format!("{level},iceoryx2_bb_loggers=error").into());
    let b = tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr);
    if json {
        b.json().init();
    } else {
        b.init();
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Run(a) => match cli::daemon::load_config(&a.config) {
            Ok(cfg) => {
                init_logging(&cfg.log.level, cfg.log.format == "json");
                Some(cli::daemon::run(cfg))
            }
            Err(e) => Some(Err(e)),
        },
        // a full-screen view: logs would tear it
        Command::Console(a) => Some(cli::console::run(a)),
        Command::Simulate(_) | Command::Watch(_) | Command::Demo(_) => {
            init_logging("info", false);
            None
        }
        _ => {
            init_logging("warn", false);
            None
        }
    };
    let result = match result {
        Some(r) => r,
        None => dispatch(cli.command),
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

fn dispatch(command: Command) -> Result<()> {
    match command {
        Command::Db {
            command: DbCommand::Check { system, all_pairs },
        } => db_check(&system, all_pairs),
        Command::Rao(args) => rao(&args),
        Command::Forecast(args) => forecast(&args),
        Command::Horizon(args) => cli::horizon::run(&args),
        Command::Run(_) => Ok(()),
        Command::Simulate(args) => cli::daemon::simulate(&args),
        Command::Watch(args) => cli::daemon::watch(&args),
        Command::Demo(args) => cli::daemon::demo(&args),
        Command::Console(_) => Ok(()),
        Command::Replay(args) => cli::replay::run(&args),
        Command::Import(args) => cli::replay::import(&args),
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
    external_summary(&mut out, sys)?;
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
        "default solver step (the daemon's forecast.dt_s and rao --dt when not set): {}",
        shipcast::rom::step::default_step(sys).describe(sys)
    )?;
    writeln!(
        out,
        "impulse response: dt = {} s, memory {:.1} s, the database's damping; beyond w_N = {:.4} rad/s B_ij = B_N,ij (w_N/w)^((p_i + p_j)/2) + D_ij [(w_N/w)^{} - (w_N/w)^{}]",
        report.irf.dt_s,
        report.irf.duration_s(),
        w[w.len() - 1],
        radiation::TAIL_FAR_POWER,
        radiation::TAIL_POWER,
    )?;
    match report.tail_fit_residuals {
        Some((cubic, fitted)) => writeln!(
            out,
            "  fitted to the database's A(w) and A_inf (p = [{}], largest D_ii / B_N,ii {:.3}): worst added-mass residual in band {:.3} % with the cubic tail (p = 3, D = 0), {:.3} % fitted",
            report
                .tail
                .near_power
                .iter()
                .map(|p| format!("{p}"))
                .collect::<Vec<_>>()
                .join(" "),
            report.tail.far_ratio(),
            100.0 * cubic,
            100.0 * fitted
        )?,
        None => writeln!(
            out,
            "  p = 3, D = 0 (the cubic tail: {})",
            if sys.spec.irf.tail == shipcast::hydro::system::TailChoice::Cubic {
                "irf.tail = \"cubic\""
            } else {
                "the database has no A_inf to fit it to"
            }
        )?,
    }
    writeln!(
        out,
        "A_inf used: {}",
        match report.a_inf_source {
            shipcast::hydro::system::AInfSource::Database => "the database's (PER = 0)",
            shipcast::hydro::system::AInfSource::Ogilvie => "Ogilvie's estimate (median over w)",
        }
    )?;
    writeln!(
        out,
        "asymmetry (reciprocity makes A and B symmetric): largest |X_ij - X_ji| / sqrt(X_ii X_jj) {:.3} % in A, {:.3} % in B{}",
        100.0 * report.asymmetry_added_mass,
        100.0 * report.asymmetry_damping,
        if report.asymmetry_added_mass.max(report.asymmetry_damping) > 0.0 {
            " (the state-space model uses the symmetric parts)"
        } else {
            ""
        }
    )?;
    let repair = report.passivity_repair;
    if repair.frequencies == 0 {
        writeln!(
            out,
            "passivity (radiated power >= 0 makes B positive semi-definite): B(w) is, at every frequency"
        )?;
    } else {
        writeln!(
            out,
            "passivity (radiated power >= 0 makes B positive semi-definite): B(w) indefinite at {} of {} frequencies; the models use it with the negative eigenvalues set to zero, largest change {:.4} % of sqrt(peak B_ii peak B_jj) at {:.4} rad/s",
            repair.frequencies,
            w.len(),
            100.0 * repair.largest,
            w[repair.at]
        )?;
    }
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
    // the models the time domain runs, on the system file's IRF grid: the state-space fit's report,
    // then each method's floor against the database's frequency domain
    let t_fit = std::time::Instant::now();
    let model_opts = |radiation| RomOptions {
        dt_s: sys.spec.irf.dt_s,
        radiation,
        ..RomOptions::default()
    };
    let ss_model = TimeModel::new(sys, model_opts(RadiationMethod::StateSpace));
    match &ss_model {
        Ok(
            m @ TimeModel {
                kernel: Kernel::StateSpace { model: ss, .. },
                ..
            },
        ) => {
            let mem = check::state_space_memory(sys, check::memory_duration_s(sys));
            let (eb, ea) = check::state_space_errors(sys, ss, &check::model_a_inf(sys, &mem.irf), &mem.tail);
            let n_hsv = ss.hankel.len().min(ss.real_order() + 1);
            writeln!(
                out,
                "state-space radiation (active DOFs): vector fit with {} pole pairs (largest scaled error {:.3} %), {} states balanced-truncated to {} ({} modes; next Hankel singular value {:.2e} of {:.2e}), fitted in {:.2} s; damping error {:.3} %, added mass error {:.3} % (largest, scaled); passivity cover {:.4} % of the peak damping",
                ss.fit_pairs,
                100.0 * ss.fit_error,
                ss.full_order,
                ss.real_order(),
                ss.modes(),
                ss.hankel.get(n_hsv.saturating_sub(1)).copied().unwrap_or(0.0),
                ss.hankel.first().copied().unwrap_or(0.0),
                t_fit.elapsed().as_secs_f64(),
                100.0 * eb,
                100.0 * ea,
                100.0 * ss.cover
            )?;
            writeln!(out, "  {}", drift_drag_line(sys, m, ss))?;
        }
        Ok(_) => writeln!(out, "state-space radiation: not built")?,
        Err(e) => writeln!(out, "state-space radiation: no fit: {e}")?,
    }
    let (lo, hi) = db.omega_range();
    let omegas: Vec<f64> = w.iter().copied().filter(|x| *x >= lo && *x <= hi).collect();
    let fd = FrequencySolver::new(sys).table(&omegas, &db.heading_rad);
    writeln!(
        out,
        "time-domain floor (the frequency-domain solve with the A(w), B(w) each radiation model implies: what a time-domain run converges to as dt -> 0) against the database's frequency domain; worst |difference| / curve peak, every mode and heading:"
    )?;
    for (name, model) in [
        (
            "convolution",
            TimeModel::new(sys, model_opts(RadiationMethod::Convolution)),
        ),
        ("state space", ss_model),
    ] {
        let floor = model.and_then(|m| floor::implied_table(&m, &omegas, &db.heading_rad));
        match (&fd, floor) {
            (Ok(fd), Ok(floor)) => match floor::worst_curve_error(&floor, fd) {
                Some(e) => {
                    writeln!(
                        out,
                        "  {name:<12} {:.3} % ({}, heading {:.1} deg, {:.4} rad/s)",
                        100.0 * e.fraction,
                        mode_label(sys, e.state),
                        db.heading_rad[e.heading].to_degrees(),
                        omegas[e.omega]
                    )?;
                    if e.fraction > FLOOR_WARNING {
                        let why = if name == "convolution" {
                            "the database's A, B and A_inf are not Kramers-Kronig consistent enough there (see the table above: frequency resolution, range, panels)"
                        } else {
                            "the fit's error adds to the database's inconsistency (compare the convolution's floor)"
                        };
                        warnings.push(format!(
                            "the {name} model's floor is {:.2} % of a curve's peak off the database's frequency domain ({} at {:.4} rad/s): no time step brings the time domain closer; {why}",
                            100.0 * e.fraction,
                            mode_label(sys, e.state),
                            omegas[e.omega]
                        ));
                    }
                }
                None => writeln!(out, "  {name:<12} no response to compare")?,
            },
            (Err(e), _) => writeln!(out, "  {name:<12} no frequency-domain solve: {e}")?,
            (_, Err(e)) => writeln!(out, "  {name:<12} no floor: {e}")?,
        }
    }
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
    // a coupling whose two BEM estimates differ by more than 1 % of its scale: seen to move a sensitive
    // RAO (the pair's beam-sea lighter yaw) by 6 % before the demo databases were symmetrized
    let asym = report.asymmetry_added_mass.max(report.asymmetry_damping);
    if asym > REPAIR_WARNING {
        warnings.push(format!(
            "A(w) or B(w) unsymmetric by up to {:.2} % of sqrt(X_ii X_jj): the two BEM estimates of a coupling disagree (panels too coarse?); a passive time-domain model follows only the symmetric part (tools/bem/make_db.py writes it)",
            100.0 * asym
        ));
    }
    if repair.largest > REPAIR_WARNING {
        warnings.push(format!(
            "B(w) far from positive semi-definite (up to {:.2} % of sqrt(peak B_ii peak B_jj) removed at {:.4} rad/s): the BEM radiates negative power there (irregular frequencies, panels too coarse?); the time-domain models see the repaired damping, the frequency domain the database's",
            100.0 * repair.largest,
            w[repair.at]
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

fn forecast(args: &ForecastArgs) -> Result<()> {
    let mut sc = Scenario::load(&args.scenario)?;
    if let Some(h) = args.horizon {
        sc.horizon_s = h;
    }
    if let Some(r) = args.radiation {
        sc.opts.radiation = r.into();
    }
    if args.repeat == 0 {
        bail!("--repeat must be at least 1");
    }
    let loaded = files::load_system(&sc.system)?;
    let sys = &loaded.system;
    let t_build = std::time::Instant::now();
    let model = TimeModel::new(sys, sc.opts).with_context(|| sc.system.display().to_string())?;
    let build_s = t_build.elapsed().as_secs_f64();
    // the simulated measured past is the convolution's, whatever method forecasts
    let past_opts = past_options(sc.opts);
    let past = if past_opts == sc.opts {
        None
    } else {
        Some(TimeModel::new(sys, past_opts).with_context(|| sc.system.display().to_string())?)
    };
    let prep =
        prepare(past.as_ref().unwrap_or(&model), &model, &sc.waves, sc.history_s).context("spin-up of the history")?;
    let mut fc = Forecaster::new();
    let req = prep.request(sc.horizon_s);
    let mut times_ms = vec![];
    for _ in 0..args.repeat {
        let t = std::time::Instant::now();
        fc.forecast(&model, &req)?;
        times_ms.push(t.elapsed().as_secs_f64() * 1e3);
    }
    let f = fc.forecast(&model, &req)?;
    let labels: Vec<String> = (0..sys.n_states()).map(|i| check::output_label(sys, i)).collect();
    let value = |k: usize, i: usize| check::output_value(sys, i, f.at(k, i));
    let extra = shipcast::rom::outputs::derived(&sys.spec.external, f);
    let horizons = scenario_horizons(sys, &sc, &prep.waves);
    let mut text = String::new();
    match args.format {
        Format::Csv => {
            text.push_str("t_s");
            for l in labels.iter().chain(&extra.names) {
                text.push(',');
                text.push_str(l);
            }
            text.push('\n');
            for k in 0..=f.steps {
                text.push_str(&format!("{:.3}", k as f64 * f.dt_s));
                for i in 0..f.n_modes {
                    text.push_str(&format!(",{:.6e}", value(k, i)));
                }
                for c in 0..extra.names.len() {
                    text.push_str(&format!(",{:.6e}", extra.at(k, c)));
                }
                text.push('\n');
            }
        }
        Format::Json => {
            let series = |n: usize, name: &dyn Fn(usize) -> String, at: &dyn Fn(usize, usize) -> f64| -> String {
                (0..n)
                    .map(|i| {
                        let v: Vec<String> = (0..=f.steps).map(|k| format!("{:.6e}", at(k, i))).collect();
                        format!("\"{}\":[{}]", name(i), v.join(","))
                    })
                    .collect::<Vec<_>>()
                    .join(",")
            };
            let motion = series(f.n_modes, &|i| labels[i].clone(), &value);
            let derived = series(extra.names.len(), &|c| extra.names[c].clone(), &|k, c| extra.at(k, c));
            text.push_str(&format!(
                "{{\"dt_s\":{},\"horizon_s\":{},\"predictable_horizon_s\":{{{}}},\"radiation\":\"{:?}\",\"skipped_components\":{},\"motion\":{{{motion}}},\"points\":{{{derived}}}}}\n",
                f.dt_s,
                f.steps as f64 * f.dt_s,
                horizons
                    .iter()
                    .map(|(n, h)| format!("\"{n}\":{}", if h.is_finite() { format!("{h:.1}") } else { "null".into() }))
                    .collect::<Vec<_>>()
                    .join(","),
                sc.opts.radiation,
                f.skipped_components,
            ));
        }
    }
    let mut out = std::io::stdout().lock();
    match &args.out {
        Some(p) => std::fs::write(p, &text).with_context(|| format!("writing {}", p.display()))?,
        None => out.write_all(text.as_bytes())?,
    }
    eprintln!(
        "shipcast forecast: {} ({} active DOFs, {} wave components, {:?} radiation, memory {}), horizon {} s at dt {} s; model built in {:.2} s",
        args.scenario.display(),
        model.n(),
        prep.waves.len(),
        sc.opts.radiation,
        model.memory_size(),
        sc.horizon_s,
        sc.opts.dt_s,
        build_s
    );
    eprintln!(
        "predictable horizon ({}): {}",
        match sc.radar_radius_m {
            Some(r) => format!("radar disc of {r} m around the origin"),
            None => "the sea is known everywhere".into(),
        },
        horizons
            .iter()
            .map(|(n, h)| format!("{n} {h:.1} s"))
            .collect::<Vec<_>>()
            .join(", ")
    );
    if args.repeat > 1 {
        times_ms.sort_by(f64::total_cmp);
        let median = times_ms[times_ms.len() / 2];
        let p95 = times_ms[((times_ms.len() as f64 * 0.95).ceil() as usize).clamp(1, times_ms.len()) - 1];
        writeln!(out, "forecast_ms_median={median:.3} forecast_ms_p95={p95:.3}")?;
    }
    Ok(())
}

/// What `db check` says of the state-space model's damping at zero frequency: the largest over a DOF's
/// peak damping, and the shortest time constant (M + A_inf)_ii / K_ii(0) of a DOF without restoring
/// (a steady drift, which radiation does not damp, slowed down by the model).
fn drift_drag_line(
    sys: &shipcast::hydro::VesselSystem,
    m: &TimeModel,
    ss: &shipcast::hydro::modal::ModalModel,
) -> String {
    let k0 = ss.zero_frequency_damping();
    let largest = (0..k0.len()).max_by(|&a, &b| (k0[a] / ss.scale[a]).abs().total_cmp(&(k0[b] / ss.scale[b]).abs()));
    let free = (0..k0.len())
        .filter(|&i| m.stiffness_linearized[(i, i)] == 0.0 && k0[i] > 0.0)
        .map(|i| (i, m.mass[(i, i)] / k0[i]))
        .min_by(|a, b| a.1.total_cmp(&b.1));
    let mut line = String::from(
        "damping at zero frequency (radiation has none; balanced truncation loses the fit's K(0) = 0 and passivity enforcement makes it positive):",
    );
    if let Some(i) = largest {
        line += &format!(
            " largest {:.4} % of the peak damping ({}, {:.3e} SI)",
            100.0 * k0[i] / ss.scale[i],
            mode_label(sys, m.active[i]),
            k0[i]
        );
    }
    match free {
        Some((i, t)) => {
            line += &format!(
                "; a free drift slowed with time constant {t:.0} s at the shortest ({}, (M + A_inf) / K(0))",
                mode_label(sys, m.active[i])
            )
        }
        None => line += "; no DOF without restoring is damped at zero frequency",
    }
    line
}

/// The system file's external models, as `db check` prints them.
fn external_summary(out: &mut impl Write, sys: &shipcast::hydro::VesselSystem) -> Result<()> {
    use shipcast::hydro::external::ConnectionKind;
    let ext = &sys.spec.external;
    let body = |b: Option<usize>| {
        b.map(|k| sys.spec.bodies[k].name.clone())
            .unwrap_or_else(|| "earth".into())
    };
    if ext.connections.is_empty() && ext.tanks.is_empty() && ext.points.is_empty() {
        return Ok(());
    }
    let n = sys.n_states();
    let zero = vec![0.0; n];
    let mut f = vec![];
    ext.connection_forces(&zero, &zero, &mut f);
    for (c, f0) in ext.connections.iter().zip(&f) {
        let kind = match &c.kind {
            ConnectionKind::SpringDamper { .. } => "spring-damper",
            ConnectionKind::Bushing { .. } => "bushing",
            ConnectionKind::MooringLine { .. } => "mooring line",
            ConnectionKind::Fender { .. } => "fender",
        };
        writeln!(
            out,
            "connection {}: {kind}, {} -> {}, force at equilibrium {:.4e} N",
            c.name,
            body(c.a.body),
            body(c.b.body),
            f0
        )?;
    }
    let mut net = vec![0.0; n];
    ext.nonlinear_force(&zero, &zero, &mut net);
    let worst = net.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if worst > 0.0 {
        writeln!(
            out,
            "  lines and fenders at equilibrium: largest net generalized force {worst:.4e} (taken as balanced by the mean loads; the model works about it)"
        )?;
    }
    for (t, name) in ext.tanks.iter().zip(&ext.tank_names) {
        writeln!(
            out,
            "tank {name} on {}: fluid natural frequency {:.4} rad/s (T = {:.2} s), a_tt {:.4e}, b_tt {:.4e}, c_tt {:.4e}, a_t4 {:.4e}, c_t4 {:.4e}",
            sys.spec.bodies[t.body].name,
            t.natural_frequency_rad_s(),
            2.0 * std::f64::consts::PI / t.natural_frequency_rad_s(),
            t.a_tt,
            t.b_tt,
            t.c_tt,
            t.a_t4,
            t.c_t4
        )?;
    }
    for p in &ext.points {
        writeln!(
            out,
            "point {} on {} at ({:.3}, {:.3}, {:.3}) m",
            p.name, sys.spec.bodies[p.body].name, p.point_m.x, p.point_m.y, p.point_m.z
        )?;
    }
    for r in &ext.relative_motions {
        writeln!(
            out,
            "relative motion {}: {} - {}",
            r.name, ext.points[r.a].name, ext.points[r.b].name
        )?;
    }
    Ok(())
}

/// The predictable horizon of each vessel in a scenario: the sea at t0 seen over the scenario's radar
/// disc around the origin (infinite without one), each vessel at its reference point.
fn scenario_horizons(
    sys: &shipcast::hydro::VesselSystem,
    sc: &Scenario,
    waves: &[shipcast::waves::WaveComponent],
) -> Vec<(String, f64)> {
    use shipcast::waves::field::{Region, WaveField};
    let region = match sc.radar_radius_m {
        Some(r) => Region::Disc {
            centre_m: [0.0, 0.0],
            radius_m: r,
        },
        None => Region::Everywhere,
    };
    let field = WaveField::from_components(waves, sys.spec.g_m_s2, sys.spec.water_depth_m, region);
    sys.spec
        .bodies
        .iter()
        .map(|b| {
            let h = shipcast::waves::horizon::of_field(
                &field,
                [b.position_m.x, b.position_m.y],
                [sc.opts.speed_m_s, 0.0],
                0.0,
            );
            (b.name.clone(), h.horizon_s)
        })
        .collect()
}

fn rao(args: &RaoArgs) -> Result<()> {
    if args.method != Method::Time && args.speed != 0.0 {
        bail!(
            "--speed {}: the frequency-domain solver is for zero speed; use --method time",
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
        Method::Time => {
            let t0 = std::time::Instant::now();
            let opts = RomOptions {
                dt_s,
                radiation: args.radiation.into(),
                speed_m_s: args.speed,
                ..RomOptions::default()
            };
            let model = TimeModel::new(sys, flag_checked(opts)?).with_context(context)?;
            let mut table = vec![];
            for &h in &headings_deg {
                let r = time_domain_rao(&model, h.to_radians(), &omegas, RegularOptions::default())
                    .with_context(|| format!("{}: heading {h} deg", args.system.display()))?;
                tracing::info!(heading_deg = h, settled_s = r.settled_s, "steady state reached");
                table.push(r.rao);
            }
            eprintln!(
                "shipcast rao: time domain, {:?} radiation (memory {}), dt {} s: {} headings x {} frequencies in {:.2} s",
                opts.radiation,
                model.memory_size(),
                opts.dt_s,
                headings_deg.len(),
                omegas.len(),
                t0.elapsed().as_secs_f64()
            );
            table
        }
    };
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
