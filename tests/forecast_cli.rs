//! `shipcast forecast`: output layout, the timing line, bad scenarios.

use crate::util::{repo, shipcast};

const SCENARIO: &str = "tests/data/scenarios/one-ship-components.toml";
/// Heave peak at least, m: the scenario's waves are 1 m and 0.5 m, so a ship within 10 cm never felt them.
const MIN_HEAVE_PEAK_M: f64 = 0.1;
/// 7 significant digits printed: rel, a and b each off by 5e-7 of themselves, at most 1e-6 of |a| + |b|.
const PRINTED_REL_TOL: f64 = 1e-6;
/// An absolute floor on that, for rows where both points are at zero.
const PRINTED_ABS_TOL: f64 = 1e-12;

#[test]
fn csv_forecast_and_timing_line() {
    let (ok, out, err) = shipcast(&["forecast", SCENARIO, "--repeat", "3"]);
    assert!(ok, "{err}");
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(
        lines[0],
        "t_s,carrier.surge_m,carrier.sway_m,carrier.heave_m,carrier.roll_deg,carrier.pitch_deg,carrier.yaw_deg"
    );
    // 60 s at 0.1 s: 601 rows, then the timing line
    assert_eq!(lines.len(), 1 + 601 + 1, "{}", lines.len());
    let last = lines[lines.len() - 1];
    let parts: Vec<&str> = last.split(' ').collect();
    assert!(
        parts.len() == 2 && parts[0].starts_with("forecast_ms_median=") && parts[1].starts_with("forecast_ms_p95="),
        "{last}"
    );
    for p in parts {
        let v: f64 = p.split('=').nth(1).unwrap().parse().unwrap();
        assert!(v > 0.0 && v.is_finite());
    }
    // every value finite, and heave moves
    let heave: Vec<f64> = lines[1..602]
        .iter()
        .map(|l| l.split(',').nth(3).unwrap().parse::<f64>().unwrap())
        .collect();
    assert!(heave.iter().all(|h| h.is_finite()));
    assert!(
        heave.iter().cloned().fold(0.0, f64::max) > MIN_HEAVE_PEAK_M,
        "heave barely moves"
    );
}

#[test]
fn json_forecast_to_a_file() {
    let out_path = std::env::temp_dir().join(format!("shipcast-forecast-{}.json", std::process::id()));
    let (ok, _, err) = shipcast(&[
        "forecast",
        SCENARIO,
        "--format",
        "json",
        "--out",
        out_path.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let text = std::fs::read_to_string(&out_path).unwrap();
    let _ = std::fs::remove_file(&out_path);
    let v: serde_json::Value =
        serde_json::from_str(&text).unwrap_or_else(|e| panic!("{e}: {}", &text[..120.min(text.len())]));
    assert_eq!(v["dt_s"], 0.1);
    assert_eq!(v["horizon_s"], 60.0);
    assert!(
        v["motion"]["carrier.heave_m"].is_array(),
        "{}",
        &text[..120.min(text.len())]
    );
    // the object's keys in the order they are written
    assert!(
        text.starts_with("{\"dt_s\":0.1,\"horizon_s\":60.0,\"predictable_horizon_s\":"),
        "{}",
        &text[..120.min(text.len())]
    );
}

#[test]
fn a_scenario_with_sea_and_components_is_refused() {
    let dir = std::env::temp_dir().join(format!("shipcast-scenario-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let text = std::fs::read_to_string(repo(SCENARIO)).unwrap().replace(
        "../../../config/vessels/ship/system.toml",
        repo("config/vessels/ship/system.toml").to_str().unwrap(),
    ) + "\n[sea]\nhs_m = 2.0\ntp_s = 8.0\nheading_deg = 180.0\ncomponents = 10\n";
    let path = dir.join("both.toml");
    std::fs::write(&path, text).unwrap();
    let (ok, _, err) = shipcast(&["forecast", path.to_str().unwrap()]);
    let _ = std::fs::remove_dir_all(&dir);
    assert!(
        !ok && err.contains("give either a [sea] table or [[component]] entries"),
        "{err}"
    );
}

#[test]
fn moored_forecast_has_points_relative_motions_and_connection_forces() {
    let (ok, out, err) = shipcast(&["forecast", "config/scenarios/two-ship-moored.toml", "--horizon", "30"]);
    assert!(ok, "{err}");
    let mut lines = out.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    for want in [
        "lighter.roll_deg",
        "crane_tip.z",
        "crane_tip.vz",
        "crane_tip.az",
        "hook_over_hatch.y",
        "fender_aft.force",
        "head_line.force",
    ] {
        assert!(header.contains(&want), "no column {want} in {header:?}");
    }
    let rows: Vec<Vec<f64>> = lines
        .filter(|l| !l.is_empty())
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 301);
    let col = |n: &str| header.iter().position(|h| *h == n).unwrap();
    // the relative motion is the difference of the two points
    for r in &rows {
        let rel = r[col("hook_over_hatch.y")];
        let (a, b) = (r[col("crane_tip.y")], r[col("lighter_hatch.y")]);
        // printed with 7 significant digits
        assert!(
            (rel - (a - b)).abs() <= PRINTED_REL_TOL * (a.abs() + b.abs()) + PRINTED_ABS_TOL,
            "{rel} vs {a} - {b}"
        );
        assert!(r[col("fender_aft.force")] >= 0.0 && r[col("head_line.force")] >= 0.0);
    }
}
