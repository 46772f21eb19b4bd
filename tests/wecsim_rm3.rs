//! Validation against WEC-Sim's RM3 case (`tests/data/wecsim-rm3/`, from ../shared/reference): a real
//! WAMIT v7.2 database of a two-body point absorber; heave of each body, no hydrodynamic coupling, a
//! linear damper c = 1.2e6 N s/m between the bodies (system-level damping entries on modes 3 and 9).

use crate::util::{parse_rao_csv, shipcast};

/// The bar for the exact frequency-domain values.
const FD_TOL: f64 = 0.003;
/// Wave amplitude of the reference runs, m (H = 2.5 m).
const AMPLITUDE_M: f64 = 1.25;

#[test]
fn frequency_domain_heave_at_8_s_matches_reference() {
    let omega = 2.0 * std::f64::consts::PI / 8.0;
    let (ok, out, err) = shipcast(&[
        "rao",
        "tests/data/wecsim-rm3/system.toml",
        "--method",
        "frequency",
        "--heading",
        "0",
        "--omega",
        &format!("{omega}"),
    ]);
    assert!(ok, "{err}");
    let rows = parse_rao_csv(&out);
    // reference README: exact frequency-domain solve of the same WAMIT data, per 1.25 m amplitude
    for (mode, amp_ref, phase_ref) in [(3, 0.98395, -24.83), (9, 0.12408, -43.31)] {
        let r = rows.iter().find(|r| r.mode == mode).unwrap();
        let (re, im) = r.complex();
        let p = f64::to_radians(phase_ref);
        let err = (re * AMPLITUDE_M - amp_ref * p.cos()).hypot(im * AMPLITUDE_M - amp_ref * p.sin()) / amp_ref;
        eprintln!(
            "mode {mode}: {:.5} m / {:.2} deg, reference {amp_ref} / {phase_ref}: error {:.3e}",
            r.amplitude * AMPLITUDE_M,
            r.phase_deg,
            err
        );
        assert!(err <= FD_TOL, "mode {mode}: error {err}");
    }
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
    let (ok, out, err) = shipcast(&[
        "rao",
        "tests/data/wecsim-rm3/system.toml",
        "--method",
        "time",
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
            "time domain mode {mode}: {:.5} m / {:.2} deg, reference {amp_ref} / {phase_ref}: error {:.3e}",
            r.amplitude * AMPLITUDE_M,
            r.phase_deg,
            err
        );
        assert!(err <= TD_TOL, "mode {mode}: error {err}");
    }
}
