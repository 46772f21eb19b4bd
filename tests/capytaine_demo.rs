//! Validation against Capytaine: the demo databases in `config/vessels/` were written by
//! `tools/bem/make_db.py` with Capytaine 3.0, which also wrote its own motion RAO
//! (`capytaine_rao.csv`, conjugated to exp(+i w t)). `shipcast rao --method frequency` must reproduce it.

use crate::util::{RaoRow, parse_rao_csv, repo, shipcast};
use std::collections::HashMap;

/// The bar: each curve (mode, heading over w) within 0.5 % of its peak.
const CURVE_TOL: f64 = 0.005;
/// Curves that vanish by symmetry (e.g. sway in head seas of one ship) have peaks of 1e-15: compare
/// those against this fraction of the largest peak of the same unit (m/m or rad/m) instead.
const NUMERICAL_ZERO: f64 = 1e-9;

fn compare(system: &str, capytaine: &str) {
    let (ok, out, err) = shipcast(&["rao", system, "--method", "frequency"]);
    assert!(ok, "shipcast rao failed: {err}");
    let ours = parse_rao_csv(&out);
    let theirs = parse_rao_csv(&std::fs::read_to_string(repo(capytaine)).unwrap());
    assert_eq!(ours.len(), theirs.len(), "same (omega, heading, mode) rows");
    // curves: (mode, heading) -> rows
    let key = |r: &RaoRow| (r.mode, (r.heading_deg * 1000.0).round() as i64);
    let mut curves: HashMap<(usize, i64), Vec<(RaoRow, RaoRow)>> = HashMap::new();
    for (a, b) in ours.iter().zip(&theirs) {
        // the .1/.3 files store periods to 8 digits: omega agrees to about 1e-8 relative
        assert!(
            (a.omega - b.omega).abs() < 1e-6 * b.omega
                && a.mode == b.mode
                && (a.heading_deg - b.heading_deg).abs() < 1e-9,
            "row order differs: {a:?} vs {b:?}"
        );
        curves.entry(key(b)).or_default().push((*a, *b));
    }
    let unit_peak = |rotation: bool| {
        theirs
            .iter()
            .filter(|r| ((r.mode - 1) % 6 >= 3) == rotation)
            .map(|r| r.amplitude)
            .fold(0.0, f64::max)
    };
    let (peak_m, peak_rad) = (unit_peak(false), unit_peak(true));
    let mut worst = (0.0, None);
    for ((mode, _), rows) in &curves {
        let peak = rows.iter().map(|(_, b)| b.amplitude).fold(0.0, f64::max);
        let floor = NUMERICAL_ZERO * if (mode - 1) % 6 >= 3 { peak_rad } else { peak_m };
        let scale = peak.max(floor);
        for (a, b) in rows {
            let (ar, ai) = a.complex();
            let (br, bi) = b.complex();
            let e = (ar - br).hypot(ai - bi) / scale;
            if e > worst.0 {
                worst = (e, Some(*b));
            }
        }
    }
    eprintln!(
        "{system}: {} curves, worst difference {:.3e} of the curve peak at {:?}",
        curves.len(),
        worst.0,
        worst.1
    );
    assert!(
        worst.0 <= CURVE_TOL,
        "{system}: {:.4} % of peak at {:?}",
        100.0 * worst.0,
        worst.1
    );
}

#[test]
fn one_ship_matches_capytaine_rao() {
    compare(
        "config/vessels/ship/system.toml",
        "config/vessels/ship/capytaine_rao.csv",
    );
}

#[test]
fn two_ships_side_by_side_match_capytaine_rao() {
    compare(
        "config/vessels/pair/system.toml",
        "config/vessels/pair/capytaine_rao.csv",
    );
}
