//! The `shipcast` binary: argument parsing and wiring only (the work is in the library, the longer
//! subcommands' handling in [`cli`]).
//!
//! Command-line handling in two stages (ripgrep's habit): clap's raw flags, close to what was typed,
//! then validated values (e.g. frequencies, headings in radians) that build the real objects.

use anyhow::Result;
use clap::{Parser, Subcommand};
use shipcast::shell::files;
use shipcast::shell::report::DbCheck;
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

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
    Rao(cli::rao::RaoArgs),
    /// Forecast a scenario (system, sea, speed, history, length); with --repeat, time it.
    Forecast(cli::forecast::ForecastArgs),
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
    /// The ship-to-ship link: this host's services bridged to the other ship's over Zenoh ([link];
    /// built with `--features link`).
    Link(cli::link::LinkArgs),
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

/// Logs to stderr: `RUST_LOG` if set, else `level`; human-readable or JSON lines. At debug level the
/// daemon's spans say where each forecast's time went (`RUST_LOG=info,shipcast=debug`).
fn init_logging(level: &str, json: bool) {
    // iceoryx2 logs through tracing; its warnings (e.g. "no config file, defaults used") are noise here
    let filter = tracing_subscriber::EnvFilter::try_from_default_env()
        .unwrap_or_else(|_| format!("{level},iceoryx2_bb_loggers=error").into());
    // the daemon's debug spans (input, tick, forecast, band, publish) log their busy time on close
    let b = tracing_subscriber::fmt()
        .with_span_events(tracing_subscriber::fmt::format::FmtSpan::CLOSE)
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
        Command::Run(a) => match cli::load_config(&a.config) {
            Ok(cfg) => {
                init_logging(&cfg.log.level, cfg.log.format == "json");
                Some(cli::daemon::run(cfg))
            }
            Err(e) => Some(Err(e)),
        },
        Command::Link(a) => match cli::load_config(&a.config) {
            Ok(cfg) => {
                init_logging(&cfg.log.level, cfg.log.format == "json");
                Some(cli::link::run(cfg))
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
        Command::Rao(args) => cli::rao::run(&args),
        Command::Forecast(args) => cli::forecast::run(&args),
        Command::Horizon(args) => cli::horizon::run(&args),
        Command::Run(_) => Ok(()),
        Command::Simulate(args) => cli::daemon::simulate(&args),
        Command::Watch(args) => cli::daemon::watch(&args),
        Command::Demo(args) => cli::daemon::demo(&args),
        Command::Console(_) | Command::Link(_) => Ok(()),
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

/// `db check`: the report of a system file and its database, and the time it took.
fn db_check(path: &std::path::Path, all_pairs: bool) -> Result<()> {
    let t0 = std::time::Instant::now();
    let loaded = files::load_system(path)?;
    let report = DbCheck::new(&loaded, path, all_pairs);
    let mut out = std::io::stdout().lock();
    write!(out, "{report}")?;
    writeln!(out, "checked in {:.2} s", t0.elapsed().as_secs_f64())?;
    Ok(())
}
