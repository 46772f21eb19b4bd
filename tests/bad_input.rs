//! Bad input: every corrupt file or value gives a clear error naming the file, line or key, a non-zero
//! exit, and never a panic.

use crate::util::{repo, shipcast};
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};

static COUNTER: AtomicUsize = AtomicUsize::new(0);

/// A private copy of the one-ship demo database to corrupt.
fn scratch_copy() -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "shipcast-bad-input-{}-{}",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::SeqCst)
    ));
    std::fs::create_dir_all(&dir).unwrap();
    for f in ["system.toml", "ship.1", "ship.3", "ship.hst"] {
        std::fs::copy(repo("config/vessels/ship").join(f), dir.join(f)).unwrap();
    }
    dir
}

fn edit(path: &PathBuf, f: impl Fn(String) -> String) {
    let text = std::fs::read_to_string(path).unwrap();
    std::fs::write(path, f(text)).unwrap();
}

/// Replaces line `n` (1-based) of a file.
fn replace_line(path: &PathBuf, n: usize, with: &str) {
    edit(path, |t| {
        t.lines()
            .enumerate()
            .map(|(i, l)| if i + 1 == n { with.to_string() } else { l.to_string() })
            .collect::<Vec<_>>()
            .join("\n")
    });
}

fn expect_error(dir: &PathBuf, want: &[&str]) {
    let sys = dir.join("system.toml");
    let (ok, out, err) = shipcast(&["db", "check", sys.to_str().unwrap()]);
    assert!(!ok, "expected failure, got success:\n{out}");
    assert!(!err.contains("panicked"), "panic: {err}");
    for w in want {
        assert!(err.contains(w), "stderr lacks `{w}`:\n{err}");
    }
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn truncated_line_in_radiation_file() {
    let d = scratch_copy();
    replace_line(&d.join("ship.1"), 40, "  1.2566371e+02   1");
    expect_error(&d, &["ship.1:40:", "expected `PER I J Abar [Bbar]`"]);
}

#[test]
fn non_numeric_field_in_excitation_file() {
    let d = scratch_copy();
    replace_line(&d.join("ship.3"), 7, "1.2566371e+02 0.0 1 1.0 0.0 abc 0.0");
    expect_error(&d, &["ship.3:7:", "column 6 (Re X): expected a number, found `abc`"]);
}

#[test]
fn nan_in_hydrostatics() {
    let d = scratch_copy();
    replace_line(&d.join("ship.hst"), 15, "  3   3 NaN");
    expect_error(&d, &["ship.hst:15:", "not a finite number"]);
}

#[test]
fn mode_beyond_6n() {
    let d = scratch_copy();
    replace_line(&d.join("ship.1"), 80, "1.2566371e+02   7   1 1.0 1.0");
    expect_error(&d, &["ship.1:80:", "mode 7 is outside 1..6"]);
}

#[test]
fn missing_hst_file() {
    let d = scratch_copy();
    std::fs::remove_file(d.join("ship.hst")).unwrap();
    expect_error(&d, &["ship.hst", "No such file"]);
}

#[test]
fn non_symmetric_mass_matrix() {
    let d = scratch_copy();
    let rows: Vec<String> = (0..6)
        .map(|i| {
            let mut r = [0.0f64; 6];
            r[i] = 1.0e7;
            if i == 0 {
                r[4] = 5.0e6;
            }
            format!("{r:?}")
        })
        .collect();
    edit(&d.join("system.toml"), |t| {
        t.lines()
            .filter(|l| {
                !l.starts_with("mass =") && !l.starts_with("centre_of_gravity") && !l.starts_with("radii_of_gyration")
            })
            .collect::<Vec<_>>()
            .join("\n")
            + &format!("\nmass_matrix = [{}]\n", rows.join(", "))
    });
    expect_error(&d, &["body[0].mass_matrix: is not symmetric"]);
}

#[test]
fn non_positive_mass() {
    let d = scratch_copy();
    edit(&d.join("system.toml"), |t| {
        t.lines()
            .map(|l| {
                if l.starts_with("mass =") {
                    "mass = -1.0".to_string()
                } else {
                    l.to_string()
                }
            })
            .collect::<Vec<_>>()
            .join("\n")
    });
    expect_error(&d, &["body[0].mass: must be a positive mass"]);
}

#[test]
fn unknown_key_in_system_file() {
    let d = scratch_copy();
    edit(&d.join("system.toml"), |t| {
        t.replace("ulen = 1.0", "ulen = 1.0\nhydrodynamic_couplng = false")
    });
    expect_error(&d, &["system.toml:", "unknown field `hydrodynamic_couplng`"]);
}

#[test]
fn rao_outside_the_database_is_a_clear_error() {
    let (ok, _, err) = shipcast(&["rao", "config/vessels/ship/system.toml", "--omega", "3.0"]);
    assert!(!ok);
    assert!(
        err.contains("frequency 3 rad/s is outside the database's radiation range 0.0500..1.6000 rad/s"),
        "{err}"
    );
}

mod never_panics {
    use proptest::prelude::*;
    use shipcast::hydro::system::SystemSpec;
    use shipcast::hydro::wamit::{Scaling, read_excitation, read_hydrostatics, read_radiation};

    const S: Scaling = Scaling {
        rho: 1025.0,
        g: 9.81,
        ulen: 1.0,
    };

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]
        /// Arbitrary lines made of plausible tokens: the readers return Ok or Err, never panic.
        #[test]
        fn wamit_readers(lines in prop::collection::vec(
            prop::collection::vec(prop_oneof![
                Just("-1".to_string()), Just("0".to_string()), Just("NaN".to_string()), Just("x".to_string()),
                Just("1e400".to_string()), (-20i32..20).prop_map(|v| v.to_string()),
                (-1.0e3f64..1.0e3).prop_map(|v| format!("{v:e}")),
            ], 0..9), 0..12)) {
            let text = lines.iter().map(|l| l.join(" ")).collect::<Vec<_>>().join("\n");
            let _ = read_radiation(text.as_bytes(), "f.1", 12, S);
            let _ = read_excitation(text.as_bytes(), "f.3", 12, S);
            let _ = read_hydrostatics(text.as_bytes(), "f.hst", 12, S);
        }

        #[test]
        fn system_file(text in "[a-z_=\\[\\]\" 0-9.\n-]{0,200}") {
            let _ = SystemSpec::from_toml(&text, "s.toml");
        }
    }
}

/// Appends a section to the one-ship system file and expects `db check` to refuse it.
fn refuses_section(section: &str, want: &[&str]) {
    let d = scratch_copy();
    edit(&d.join("system.toml"), |t| format!("{t}\n{section}"));
    expect_error(&d, want);
}

const SPRING: &str = "[[connection]]\nname = \"pto\"\nkind = \"spring_damper\"\nbody_a = \"carrier\"\npoint_a_m = [0.0, 0.0, 0.0]\nbody_b = \"earth\"\npoint_b_m = [0.0, 0.0, -50.0]\n";

#[test]
fn negative_connection_stiffness() {
    refuses_section(
        &format!("{SPRING}stiffness_n_m = -1.0e5\n"),
        &[
            "connection[0].stiffness_n_m",
            "must be a finite number >= 0, found -100000",
        ],
    );
}

#[test]
fn fender_curve_that_is_not_monotonic() {
    refuses_section(
        "[[connection]]\nname = \"f\"\nkind = \"fender\"\nbody_a = \"carrier\"\npoint_a_m = [0.0, 15.0, 0.0]\nbody_b = \"earth\"\npoint_b_m = [0.0, 16.0, 0.0]\nnormal = [0.0, -1.0, 0.0]\ncurve = [[0.5, 3.0e5], [1.0, 2.0e5]]\n",
        &["connection[0].curve", "not monotonic"],
    );
}

#[test]
fn point_on_an_unknown_body() {
    refuses_section(
        "[[point]]\nname = \"crane_tip\"\nbody = \"barge\"\nposition_m = [0.0, 10.0, 25.0]\n",
        &["point[0].body", "names no body: `barge`", "carrier"],
    );
}

#[test]
fn key_of_another_connection_kind() {
    refuses_section(
        &format!("{SPRING}normal = [0.0, 1.0, 0.0]\n"),
        &["connection[0].normal", "is not a key of a `spring_damper` connection"],
    );
}

#[test]
fn tank_that_capsizes_the_ship() {
    refuses_section(
        "[[tank]]\nname = \"art\"\nbody = \"carrier\"\na_tt = 1.0e8\nc_tt = 1.0e9\na_t4 = 1.0e7\nc_t4 = 1.0e9\n",
        &["tank[0]", "exceeds the roll restoring"],
    );
}

/// A database line replaced: `db check` refuses it within `timeout_s` (a hang is a failure too).
fn expect_error_within(dir: &PathBuf, timeout_s: u64, want: &[&str]) {
    use std::process::{Command, Stdio};
    let sys = dir.join("system.toml");
    let mut child = Command::new(env!("CARGO_BIN_EXE_shipcast"))
        .args(["db", "check", sys.to_str().unwrap()])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let t0 = std::time::Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if t0.elapsed().as_secs() > timeout_s {
            let _ = child.kill();
            let _ = child.wait();
            panic!("`db check` still running after {timeout_s} s");
        }
        std::thread::sleep(std::time::Duration::from_millis(100));
    };
    let mut err = String::new();
    std::io::Read::read_to_string(child.stderr.as_mut().unwrap(), &mut err).unwrap();
    assert!(!status.success(), "expected failure");
    assert!(!err.contains("panicked"), "panic: {err}");
    for w in want {
        assert!(err.contains(w), "stderr lacks `{w}`:\n{err}");
    }
    let _ = std::fs::remove_dir_all(dir);
}

/// Regression: an added mass of 1e300 once hung `db check` in an SVD.
#[test]
fn added_mass_of_1e300_is_refused_with_its_line() {
    let d = scratch_copy();
    replace_line(&d.join("ship.1"), 123, "8.3775804e+01   3   3 1.0e+300 5.2570544e+03");
    expect_error_within(&d, 60, &["ship.1:123:", "Abar", "1e300"]);
}

#[test]
fn excitation_of_1e30_is_beyond_physical_bounds() {
    let d = scratch_copy();
    replace_line(
        &d.join("ship.3"),
        3,
        "1.2566371e+02 0.0000000e+00   3 1.0e+30 0.0 1.0e+30 0.0",
    );
    expect_error_within(&d, 60, &["ship.3:3:", "Re X"]);
}

#[test]
fn restoring_of_1e40_is_beyond_physical_bounds() {
    let d = scratch_copy();
    let hst = std::fs::read_to_string(d.join("ship.hst")).unwrap();
    let n = hst
        .lines()
        .position(|l| l.split_whitespace().take(2).eq(["3", "3"]))
        .unwrap()
        + 1;
    replace_line(&d.join("ship.hst"), n, "  3   3 1.0e+40");
    expect_error_within(&d, 60, &[&format!("ship.hst:{n}:"), "Cbar"]);
}

/// Regression: a radiation file cut at a line end once passed `db check`.
#[test]
fn radiation_file_cut_at_a_line_end_is_refused() {
    let d = scratch_copy();
    // the last frequency keeps 18 of its 36 pairs
    edit(&d.join("ship.1"), |t| {
        let lines: Vec<&str> = t.lines().collect();
        lines[..lines.len() - 18].join("\n") + "\n"
    });
    expect_error(&d, &["ship.1", "period 3.9269908 s", "has no entry for modes 4 1"]);
}

/// Regression: an excitation file cut at a line end once passed `db check`.
#[test]
fn excitation_file_cut_at_a_line_end_is_refused() {
    let d = scratch_copy();
    // the last heading of the last frequency keeps 2 of its 6 modes
    edit(&d.join("ship.3"), |t| {
        let lines: Vec<&str> = t.lines().collect();
        lines[..lines.len() - 4].join("\n") + "\n"
    });
    expect_error(&d, &["ship.3", "period 3.9269908 s", "has no entry for mode 3"]);
}

/// The shipped `config/shipcast.toml` with `key = value` set in `[section]`, loaded (no environment).
fn config_with(section: &str, key: &str, value: &str) -> Result<(), String> {
    config_with_env(section, key, value, &[])
}

fn config_with_env(section: &str, key: &str, value: &str, env: &[(&str, &str)]) -> Result<(), String> {
    let text = std::fs::read_to_string(repo("config/shipcast.toml")).unwrap();
    let mut out = vec![];
    let mut inside = false;
    let mut done = false;
    for l in text.lines() {
        let t = l.trim_start();
        if t.starts_with('[') && !t.starts_with("[[") {
            inside = t.starts_with(&format!("[{section}]"));
            out.push(l.to_string());
            if inside && !text.contains(&format!("\n{key} =")) && !text.contains(&format!("\n# {key} =")) {
                out.push(format!("{key} = {value}"));
                done = true;
            }
            continue;
        }
        let stripped = t.trim_start_matches("# ");
        if inside && !done && (stripped.starts_with(&format!("{key} ")) || stripped.starts_with(&format!("{key}="))) {
            out.push(format!("{key} = {value}"));
            done = true;
        } else {
            out.push(l.to_string());
        }
    }
    assert!(done, "no [{section}] in config/shipcast.toml");
    let dir = std::env::temp_dir().join(format!(
        "shipcast-bad-config-{}-{}",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::SeqCst)
    ));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("shipcast.toml");
    std::fs::write(&path, out.join("\n")).unwrap();
    let env: Vec<(String, String)> = env.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect();
    let r = shipcast::shell::config::load_with_env(&path, &env)
        .map(|_| ())
        .map_err(|e| e.to_string());
    let _ = std::fs::remove_dir_all(&dir);
    r
}

fn refused(r: Result<(), String>, want: &[&str]) {
    let err = r.expect_err("the configuration was accepted");
    for w in want {
        assert!(err.contains(w), "`{err}` lacks `{w}`");
    }
}

/// Regression: a negative memory once ran with no radiation memory.
#[test]
fn negative_memory_s_is_refused() {
    refused(
        config_with("forecast", "memory_s", "-5.0"),
        &["forecast.memory_s", "-5"],
    );
}

/// Regression: a memory of 1e9 s once aborted on allocation.
#[test]
fn memory_s_of_1e9_is_refused() {
    refused(
        config_with("forecast", "memory_s", "1e9"),
        &["forecast.memory_s", "1000000000"],
    );
}

/// Regression: a NaN history margin once grew the history without bound.
#[test]
fn nan_history_margin_is_refused() {
    refused(
        config_with("forecast", "history_margin_s", "nan"),
        &["forecast.history_margin_s", "NaN"],
    );
}

/// Regression: a period of 1e20 s once panicked.
#[test]
fn period_s_of_1e20_is_refused() {
    refused(
        config_with("forecast", "period_s", "1e20"),
        &["forecast.period_s", "[0.05, 60]"],
    );
}

/// Regression: a period of 1e400 (beyond an f64) was refused as "floating-point number overflowed"
/// without the key or the line.
#[test]
fn a_number_beyond_a_float_is_refused_naming_its_key_and_line() {
    refused(
        config_with("forecast", "period_s", "1e400"),
        &["forecast.period_s", "shipcast.toml:", "overflow"],
    );
}

/// Regression: `SHIPCAST_FORECAST__PERIOD_S=-1` was blamed on the config file.
#[test]
fn a_value_out_of_bounds_from_the_environment_names_the_variable() {
    let err = config_with_env("forecast", "period_s", "1.0", &[("SHIPCAST_FORECAST__PERIOD_S", "-1")])
        .expect_err("the configuration was accepted");
    assert!(
        err.contains("environment variable SHIPCAST_FORECAST__PERIOD_S=\"-1\"") && err.contains("forecast.period_s"),
        "{err}"
    );
}

/// Regression: a period of 1e-12 s once panicked.
#[test]
fn period_s_of_1e_12_is_refused() {
    refused(
        config_with("forecast", "period_s", "1e-12"),
        &["forecast.period_s", "[0.05, 60]"],
    );
}

/// Regression: `horizon_s = true` was once taken as one second.
#[test]
fn horizon_s_true_is_refused_as_a_boolean() {
    refused(
        config_with("forecast", "horizon_s", "true"),
        &["forecast.horizon_s", "boolean"],
    );
    // and from the environment
    refused(
        config_with_env(
            "forecast",
            "horizon_s",
            "120.0",
            &[("SHIPCAST_FORECAST__HORIZON_S", "true")],
        ),
        &["SHIPCAST_FORECAST__HORIZON_S", "forecast.horizon_s"],
    );
}

/// Regression: an unknown log level was once accepted and nothing logged.
#[test]
fn log_level_loud_is_refused() {
    refused(config_with("log", "level", "\"loud\""), &["log.level", "loud"]);
    // a directive is a level
    config_with("log", "level", "\"shipcast=debug,warn\"").unwrap();
}

/// Regression: an invalid service prefix was once reported without its key.
#[test]
fn invalid_service_prefix_is_refused_with_its_key() {
    refused(
        config_with("ipc", "service_prefix", "\"iox2://shipcast\""),
        &["ipc.service_prefix", "iox2://shipcast"],
    );
}

/// Regression: an IMU rate of 1e9 Hz was once accepted.
#[test]
fn imu_rate_of_1e9_hz_is_refused() {
    refused(
        config_with("simulate.imu", "rate_hz", "1e9"),
        &["simulate.imu.rate_hz", "1000"],
    );
}

/// Regression: 1e9 sea components were once accepted.
#[test]
fn sea_components_of_1e9_are_refused() {
    refused(
        config_with("simulate.sea", "components", "1000000000"),
        &["simulate.sea.components", "10000"],
    );
}

/// Regression: a time step of 1e-7 s once aborted `rao` on allocation.
#[test]
fn rao_time_step_of_1e_7_is_refused_before_allocating() {
    let (ok, _, err) = shipcast(&[
        "rao",
        "config/vessels/ship/system.toml",
        "--method",
        "time",
        "--dt",
        "1e-7",
    ]);
    assert!(!ok);
    assert!(!err.contains("memory allocation"), "{err}");
    assert!(
        err.contains("--dt") && err.contains("1e-7") && err.contains("0.001"),
        "{err}"
    );
}

#[test]
fn the_shipped_configurations_are_within_bounds() {
    for f in [
        "config/shipcast.toml",
        "config/one-ship.toml",
        "tests/data/replay-v1/shipcast.toml",
    ] {
        shipcast::shell::config::load_with_env(&repo(f), &[]).unwrap_or_else(|e| panic!("{e}"));
    }
}
