//! Validation against Capytaine of the excitation between stored headings (issue 27, item 3): the
//! barge's 24 x 8 x 3 m box with its reference point 40 m from the BEM origin, the database at 0, 15,
//! ..., 180 deg only, and Capytaine's own RAO solved directly at the headings half-way between
//! (7.5 ... 172.5 deg) and at five in the half the database does not hold (187.5 ... 352.5 deg, which
//! shipcast completes by port-starboard symmetry). Made by `python3 tools/bem/make_db.py --preset
//! offset-box tests/data/capytaine-offset-box` (Capytaine 3.0.0, 13 s). The frequency-domain RAO
//! (`shipcast rao`), at Capytaine's frequencies (on the database's grid: only the heading is
//! interpolated), against Capytaine's, every mode, relative to each curve's peak over 0.3-2.5 rad/s.
//!
//! Before the excitation was referred to the body (linear in heading on the values referred to the
//! origin, which turn by k 40 cos(beta) between stored headings) the same comparison was 82 % (surge),
//! 98 % (pitch) and 149 % (yaw) off at 7.5-172.5 deg, and the other half was refused.

use crate::util::{RaoRow, parse_rao_csv, rao_worst, repo, shipcast};

const SYSTEM: &str = "tests/data/capytaine-offset-box/system.toml";
const CAPYTAINE_RAO: &str = "tests/data/capytaine-offset-box/capytaine_rao.csv";
/// The headings compared: none of them stored in the database.
const OFF_GRID_DEG: &str =
    "7.5,22.5,37.5,52.5,67.5,82.5,97.5,112.5,127.5,142.5,157.5,172.5,187.5,217.5,262.5,307.5,352.5";
/// Bands and their tolerances, the error growing with k L (the heading dependence of a hull's
/// excitation has harmonics up to about k L / 2, which a 15 deg grid resolves less well as the waves
/// shorten). Measured, worst mode: 0.91 % (surge, 82.5 deg, 1.5 rad/s); 2.96 % (surge, 97.5 deg,
/// 2.0 rad/s); 12.3 % (yaw, 97.5 deg, 2.5 rad/s: 10 m waves on a 24 m hull, k L / 2 = 7.6).
const BANDS: [(f64, f64, f64); 3] = [(0.3, 1.5, 0.015), (1.5, 2.0, 0.04), (2.0, 2.5, 0.15)];

#[test]
fn off_grid_headings_of_a_body_away_from_the_origin_match_capytaine() {
    let off: Vec<f64> = OFF_GRID_DEG.split(',').map(|h| h.parse().unwrap()).collect();
    let capytaine: Vec<RaoRow> = parse_rao_csv(&std::fs::read_to_string(repo(CAPYTAINE_RAO)).unwrap())
        .into_iter()
        .filter(|r| (0.3..=2.5).contains(&r.omega) && off.contains(&r.heading_deg))
        .collect();
    let mut omegas: Vec<f64> = capytaine.iter().map(|r| r.omega).collect();
    omegas.sort_by(f64::total_cmp);
    omegas.dedup();
    let omegas = omegas.iter().map(|w| w.to_string()).collect::<Vec<_>>().join(",");
    let (ok, out, err) = shipcast(&["rao", SYSTEM, "--heading", OFF_GRID_DEG, "--omega", &omegas]);
    assert!(ok, "{err}");
    let ours = parse_rao_csv(&out);
    for (lo, hi, tol) in BANDS {
        let (e, at) = rao_worst(&ours, &capytaine, lo..=hi);
        eprintln!(
            "offset box, off-grid headings, {lo}-{hi} rad/s: {:.2} % of a curve's peak off Capytaine ({at})",
            100.0 * e
        );
        assert!(e <= tol, "{lo}-{hi} rad/s: {:.2} % at {at}", 100.0 * e);
    }
}

/// `db check` says how the headings are completed and interpolated, which passivity choice the models
/// use, and the convolution's floor with the other one (this database's B is indefinite at 27 of its
/// 70 frequencies, by 0.02 % of its scale).
#[test]
fn db_check_says_what_it_mirrored_and_the_floor_of_each_passivity_choice() {
    let (ok, out, err) = shipcast(&["db", "check", SYSTEM]);
    assert!(ok, "{err}");
    assert!(
        out.contains("24 headings") && out.contains("by port-starboard symmetry"),
        "{out}"
    );
    assert!(
        out.contains("interpolated referred to each body's position, cubic in heading"),
        "{out}"
    );
    assert!(out.contains("indefinite at 27 of 70 frequencies; the models use it with the negative eigenvalues set to zero (irf.passivity = \"project\"), largest change"), "{out}");
    assert!(out.contains("  convolution, irf.passivity = \"none\" "), "{out}");
}
