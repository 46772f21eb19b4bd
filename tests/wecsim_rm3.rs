//! Validation against WEC-Sim's RM3 case (`tests/data/wecsim-rm3/`, from ../shared/reference): a real
//! WAMIT v7.2 database of a two-body point absorber; heave of each body, no hydrodynamic coupling, a
//! linear damper c = 1.2e6 N s/m between the bodies (system-level damping entries on modes 3 and 9).

use crate::util::{parse_rao_csv, shipcast};

/// The bar for the exact frequency-domain values.
const FD_TOL: f64 = 0.003;
/// Wave amplitude of the reference runs, m (H = 2.5 m).
const AMPLITUDE_M: f64 = 1.25;

/// Runs `shipcast rao` on the RM3 system at T = 8 s with `method` and checks both heave RAOs against
/// the exact frequency-domain reference (README of the reference data, per 1.25 m amplitude).
fn heave_at_8_s(method: &str, tol: f64) -> Vec<crate::util::RaoRow> {
    let (ok, out, err) = shipcast(&[
        "rao",
        "tests/data/wecsim-rm3/system.toml",
        "--method",
        method,
        "--heading",
        "0",
        "--omega",
        "0.785398",
    ]);
    assert!(ok, "{err}");
    let rows = parse_rao_csv(&out);
    for (mode, amp_ref, phase_ref) in [(3, 0.98395, -24.83), (9, 0.12408, -43.31)] {
        let r = rows.iter().find(|r| r.mode == mode).unwrap();
        let (re, im) = r.complex();
        let p = f64::to_radians(phase_ref);
        let err = (re * AMPLITUDE_M - amp_ref * p.cos()).hypot(im * AMPLITUDE_M - amp_ref * p.sin()) / amp_ref;
        eprintln!(
            "{method} mode {mode}: {:.5} m / {:.2} deg, reference {amp_ref} / {phase_ref}: error {:.3e}",
            r.amplitude * AMPLITUDE_M,
            r.phase_deg,
            err
        );
        assert!(err <= tol, "{method} mode {mode}: error {err}");
    }
    rows
}

#[test]
fn frequency_domain_heave_at_8_s_matches_reference() {
    let rows = heave_at_8_s("frequency", FD_TOL);
    // inactive modes are held at zero
    assert!(
        rows.iter()
            .filter(|r| r.mode != 3 && r.mode != 9)
            .all(|r| r.amplitude == 0.0)
    );
}

/// Time-domain steady state against the exact frequency-domain values: the time step's error
/// (dt = 0.1 s, second order) and the IRF's, measured 0.2 % on this case.
const TD_TOL: f64 = 0.005;

#[test]
fn time_domain_heave_at_8_s_with_the_damper_as_a_connection() {
    heave_at_8_s("time", TD_TOL);
}

/// The float's heave |H|^2 at 0.8 rad/s, at least, (m/m)^2: a response, not zeros (0.79 m/m at 0.785 rad/s).
const MIN_HEAVE_GAIN2: f64 = 0.01;

/// Was: the band's response table failed as a whole on a heading the database does not cover, so a
/// single-heading database (RM3: 0 deg only) published every forecast with horizon 0 and a band of
/// zeros. Now the uncovered headings have no response, and the covered one has RM3's heave.
#[test]
fn wecsim_rm3_single_heading_database_has_a_band() {
    let sys = shipcast::shell::files::load_system(&crate::util::repo("tests/data/wecsim-rm3/system.toml"))
        .unwrap()
        .system;
    let model = shipcast::rom::TimeModel::new(&sys, shipcast::rom::RomOptions::default()).unwrap();
    let table = shipcast::band::ResponseTable::of(&model).expect("a table for a one-heading database");
    let n = model.n_modes;
    let (mut g2, mut delay) = (vec![0.0; n], vec![0.0; n]);
    // heave of the float at 0.8 rad/s, head-on (0 deg): the database's heading
    table.gain2_into(0.8, 0.0, &mut g2, &mut delay);
    assert!(g2[2] > MIN_HEAVE_GAIN2, "{g2:?}");
    // 90 deg: not in the database, no response
    table.gain2_into(0.8, std::f64::consts::FRAC_PI_2, &mut g2, &mut delay);
    assert_eq!(g2[2], 0.0);
}
