//! The command line's messages: each test pins a message a newcomer once met (issue 29) and says what
//! it used to be.

use crate::util::{repo, scratch_dir, shipcast};
use std::process::Command;

const SCENARIO: &str = "tests/data/scenarios/one-ship-components.toml";

/// Runs the binary with extra environment variables; returns (success, stderr).
fn shipcast_env(args: &[&str], env: &[(&str, &str)]) -> (bool, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_shipcast"))
        .args(args)
        .envs(env.iter().copied())
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("the shipcast binary runs");
    (out.status.success(), String::from_utf8_lossy(&out.stderr).into_owned())
}

/// Was: `--horizon -5` was taken for a flag; `--horizon=-5` was refused after the spin-up (20 s) with a
/// limit of 86400 s that contradicted the config's 3600 s.
#[test]
fn a_negative_forecast_length_is_refused_as_it_is_read_with_the_one_limit() {
    for args in [
        ["forecast", SCENARIO, "--horizon", "-5"],
        ["forecast", SCENARIO, "--horizon=-5", "--repeat=1"],
    ] {
        let (ok, _, err) = shipcast(&args);
        assert!(!ok);
        assert!(
            err.contains("invalid value '-5' for '--horizon")
                && err.contains("a forecast's length must be in (0, 3600] s"),
            "{err}"
        );
    }
    let (ok, _, err) = shipcast(&["forecast", SCENARIO, "--horizon", "4000"]);
    assert!(!ok && err.contains("(0, 3600] s"), "{err}");
}

fn config_with_system(dir: &std::path::Path, system: &str) -> std::path::PathBuf {
    let p = dir.join("shipcast.toml");
    std::fs::write(&p, format!("[system]\nfile = \"{system}\"\n")).unwrap();
    p
}

/// Was: `shipcast: error: /x/system.toml: No such file or directory (os error 2): No such file or
/// directory (os error 2)`, without the config key that named the file.
#[test]
fn a_missing_system_file_names_the_config_key_and_the_os_error_once() {
    let dir = scratch_dir("cli-nosystem");
    let cfg = config_with_system(&dir, "vessels/nope/system.toml");
    let (ok, _, err) = shipcast(&["run", "--config", cfg.to_str().unwrap()]);
    assert!(!ok);
    assert!(err.contains("[system] file = \"vessels/nope/system.toml\""), "{err}");
    assert_eq!(err.matches("os error 2").count(), 1, "{err}");
}

/// Was: `config/shipcast.toml: unknown field `periods` ...`: the file was blamed for a variable.
#[test]
fn a_misspelled_environment_variable_is_named_not_the_file() {
    let dir = scratch_dir("cli-env");
    let cfg = config_with_system(&dir, repo("config/vessels/ship/system.toml").to_str().unwrap());
    let (ok, err) = shipcast_env(
        &["run", "--config", cfg.to_str().unwrap()],
        &[("SHIPCAST_FORECAST__PERIODS", "2")],
    );
    assert!(!ok);
    assert!(
        err.starts_with("shipcast: error: environment variable SHIPCAST_FORECAST__PERIODS=\"2\": ")
            && err.contains("periods"),
        "{err}"
    );
    // a valid variable still overlays the file
    let (ok, err) = shipcast_env(
        &["run", "--config", cfg.to_str().unwrap()],
        &[("SHIPCAST_FORECAST__PERIOD_S", "-1")],
    );
    assert!(!ok && err.contains("forecast.period_s") && err.contains("-1"), "{err}");
}

/// Was: `0 messages (Bad magic number)` after a warning that the log "stops being readable".
#[test]
fn a_file_that_is_not_mcap_is_called_so() {
    let dir = scratch_dir("cli-notmcap");
    let p = dir.join("notes.mcap");
    std::fs::write(&p, "hello\n").unwrap();
    let (ok, _, err) = shipcast(&["replay", p.to_str().unwrap()]);
    assert!(!ok);
    assert!(
        err.contains("notes.mcap: not an MCAP log") && !err.contains("stops being readable"),
        "{err}"
    );
}

/// Was: `replay --publish LOG` took the log's path for the service prefix (and then missed the log).
#[test]
fn replay_publish_does_not_swallow_the_log() {
    let (ok, _, err) = shipcast(&["replay", "--publish", "/nonexistent/run.mcap"]);
    assert!(!ok);
    assert!(
        err.contains("/nonexistent/run.mcap") && !err.contains("required arguments"),
        "{err}"
    );
}

/// Was: `--config` had no help text on six subcommands.
#[test]
fn every_subcommand_with_a_config_says_what_it_is_and_where_it_is_looked_for() {
    for sub in ["run", "simulate", "watch", "demo", "console", "replay", "import"] {
        let (ok, out, err) = shipcast(&[sub, "--help"]);
        assert!(ok, "{sub}: {err}");
        let line = out
            .lines()
            .find(|l| l.contains("--config <FILE>"))
            .unwrap_or_else(|| panic!("{sub}: {out}"));
        assert!(line.contains("The configuration file"), "{sub}: {line}");
        assert!(out.contains("/etc/shipcast/shipcast.toml"), "{sub}: {out}");
    }
}

/// Was: roll, pitch and yaw were rad in the forecast CSV and JSON, degrees in config, console and import.
#[test]
fn forecast_columns_carry_their_units_and_rotations_are_degrees() {
    let (ok, out, err) = shipcast(&["forecast", SCENARIO, "--horizon", "10"]);
    assert!(ok, "{err}");
    let mut lines = out.lines();
    assert_eq!(
        lines.next().unwrap(),
        "t_s,carrier.surge_m,carrier.sway_m,carrier.heave_m,carrier.roll_deg,carrier.pitch_deg,carrier.yaw_deg"
    );
    let (ok, json, err) = shipcast(&["forecast", SCENARIO, "--horizon", "10", "--format", "json"]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    let deg = &v["motion"]["carrier.pitch_deg"];
    let csv_pitch: Vec<f64> = out
        .lines()
        .skip(1)
        .filter(|l| !l.starts_with("forecast_ms"))
        .map(|l| l.split(',').nth(5).unwrap().parse().unwrap())
        .collect();
    assert_eq!(deg.as_array().unwrap().len(), csv_pitch.len());
    assert!(
        csv_pitch.iter().any(|p| p.abs() > 0.01),
        "pitch in degrees barely moves"
    );
}

/// Was: a scenario's `history_s` had no upper bound (the spin-up's buffers are sized by it).
#[test]
fn a_scenario_history_beyond_the_longest_run_is_refused_with_the_key() {
    let system = repo("config/vessels/ship/system.toml");
    let text = std::fs::read_to_string(repo(SCENARIO))
        .unwrap()
        .replace("../../../config/vessels/ship/system.toml", system.to_str().unwrap())
        .replace("history_s = 120.0", "history_s = 1e9");
    let path = scratch_dir("scenario-history").join("scenario.toml");
    std::fs::write(&path, text).unwrap();
    let (ok, _, err) = shipcast(&["forecast", path.to_str().unwrap()]);
    assert!(!ok);
    assert!(err.contains("history_s") && err.contains("at most 3600 s"), "{err}");
}

/// Was: `run` started (and forecast) with an `[operation]` channel the system does not have; only a
/// console or a report said so, later.
#[test]
fn run_refuses_an_operation_channel_the_system_does_not_have() {
    let dir = scratch_dir("cli-channel");
    let cfg = config_with_system(&dir, repo("config/vessels/ship/system.toml").to_str().unwrap());
    let text = std::fs::read_to_string(&cfg).unwrap();
    std::fs::write(
        &cfg,
        format!("{text}\n[operation]\nchannels = [{{ name = \"carrier.rool\", limit = 2.0 }}]\n"),
    )
    .unwrap();
    let (ok, _, err) = shipcast(&["run", "--config", cfg.to_str().unwrap()]);
    assert!(
        !ok && err.contains("operation.channels[0].name") && err.contains("rool"),
        "{err}"
    );
}
