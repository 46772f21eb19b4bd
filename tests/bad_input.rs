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
