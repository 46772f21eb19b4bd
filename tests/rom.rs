//! The time-domain ROM: against the frequency domain of the same database (every mode and heading,
//! both radiation methods), against WEC-Sim's RM3 regularCIC run, free decay, convergence in dt,
//! divergence reported.

use crate::util::{RaoRow, parse_rao_csv, repo, shipcast};
use num_complex::Complex64;
use proptest::prelude::*;
use shipcast::hydro::VesselSystem;
use shipcast::radiation::history::Memory;
use shipcast::rom::{Forecast, ForecastRequest, Forecaster, RadiationMethod, RomOptions, TimeModel};
use shipcast::shell::files::load_system;
use shipcast::waves::WaveComponent;
use std::collections::HashMap;

/// The bar: time-domain RAO within 1 % of each curve's peak of the frequency-domain RAO.
const TD_FD_TOL: f64 = 0.01;
/// Curves that (nearly) vanish by symmetry, with a peak below this fraction of the same mode's largest
/// peak over all headings (pitch in beam seas on the one-ship demo: 1e-3, from mesh asymmetry; yaw in
/// beam seas: 5 %), are judged against that largest peak instead of their own. Measured: yaw in beam seas
/// at 0.35 rad/s is 3.4 % of its own small peak off the database's frequency domain, and the same off
/// the floor (`--method implied`): the database's yaw A and B are not quite Kramers-Kronig consistent.
const SMALL_CURVE: f64 = 0.1;

fn load(rel: &str) -> VesselSystem {
    load_system(&repo(rel)).unwrap().system
}

/// Worst |TD - FD| over each (mode, heading) curve, relative to that curve's FD peak.
fn td_against(system: &str, radiation: &str, reference: &str, dt: &str, heading: Option<&str>) -> (f64, String) {
    rao_against(system, "time", radiation, reference, dt, heading)
}

/// Worst |RAO by `method` - RAO by `reference`| over each (mode, heading) curve, relative to that curve's
/// peak by `reference`.
fn rao_against(
    system: &str,
    method: &str,
    radiation: &str,
    reference: &str,
    dt: &str,
    heading: Option<&str>,
) -> (f64, String) {
    let mut td_args = vec!["rao", system, "--method", method, "--radiation", radiation, "--dt", dt];
    let mut ref_args = vec![
        "rao",
        system,
        "--method",
        reference,
        "--radiation",
        radiation,
        "--dt",
        dt,
    ];
    if let Some(h) = heading {
        td_args.extend(["--heading", h]);
        ref_args.extend(["--heading", h]);
    }
    let (ok, td, err) = shipcast(&td_args);
    assert!(ok, "{err}");
    let (ok, fd, err) = shipcast(&ref_args);
    assert!(ok, "{err}");
    let (td, fd) = (parse_rao_csv(&td), parse_rao_csv(&fd));
    assert_eq!(td.len(), fd.len());
    let key = |r: &RaoRow| (r.mode, (r.heading_deg * 1000.0).round() as i64);
    let mut curves: HashMap<(usize, i64), Vec<(RaoRow, RaoRow)>> = HashMap::new();
    for (a, b) in td.iter().zip(&fd) {
        curves.entry(key(b)).or_default().push((*a, *b));
    }
    let mode_peak = |mode: usize| {
        fd.iter()
            .filter(|r| r.mode == mode)
            .map(|r| r.amplitude)
            .fold(0.0, f64::max)
    };
    let mut worst = (0.0, String::new());
    for ((mode, h), rows) in &curves {
        let peak = rows.iter().map(|(_, b)| b.amplitude).fold(0.0, f64::max);
        let scale = if peak >= SMALL_CURVE * mode_peak(*mode) {
            peak
        } else {
            mode_peak(*mode)
        };
        for (a, b) in rows {
            let ((ar, ai), (br, bi)) = (a.complex(), b.complex());
            let e = (ar - br).hypot(ai - bi) / scale;
            if e > worst.0 {
                worst = (
                    e,
                    format!("mode {mode} heading {} omega {:.4}", *h as f64 / 1000.0, b.omega),
                );
            }
        }
    }
    eprintln!(
        "{system} ({method}, {radiation}, dt {dt}) against {reference}: worst {:.3} % of the curve peak at {}",
        100.0 * worst.0,
        worst.1
    );
    worst
}

/// The bar against the floor: the frequency-domain solve of the time-domain model's own A and B
/// (`rao --method implied`), which a time-domain run converges to as dt -> 0.
const TD_FLOOR_TOL: f64 = 0.005;

#[test]
fn one_ship_time_domain_matches_frequency_domain_convolution() {
    // dt = 0.05 s: at 0.1 s the second-order step costs 0.45 % of peak at the heave resonance
    let (e, at) = td_against(
        "config/vessels/ship/system.toml",
        "convolution",
        "frequency",
        "0.05",
        None,
    );
    assert!(e <= TD_FD_TOL, "{e} at {at}");
}

#[test]
fn one_ship_time_domain_matches_its_floor_convolution() {
    let (e, at) = td_against(
        "config/vessels/ship/system.toml",
        "convolution",
        "implied",
        "0.05",
        None,
    );
    assert!(e <= TD_FLOOR_TOL, "{e} at {at}");
}

#[test]
fn one_ship_time_domain_matches_frequency_domain_state_space() {
    let (e, at) = td_against(
        "config/vessels/ship/system.toml",
        "state-space",
        "frequency",
        "0.05",
        None,
    );
    assert!(e <= TD_FD_TOL, "{e} at {at}");
}

#[test]
fn one_ship_time_domain_matches_its_floor_state_space() {
    let (e, at) = td_against(
        "config/vessels/ship/system.toml",
        "state-space",
        "implied",
        "0.05",
        None,
    );
    assert!(e <= TD_FLOOR_TOL, "{e} at {at}");
}

/// The headings the pair's dt 0.025 s time-domain tests run, of the database's 12 (all 12 took 6 min of
/// the test run): head and following seas, where both models' worst over all 12 was measured (lighter
/// sway at its coupled resonance), beam seas from either side (each hull sheltered in turn), and 150
/// deg, the worst oblique one.
const PAIR_TD_HEADINGS: &str = "0,90,150,180,270";

/// Two ships (the pair demo, every DOF, full coupling), state space, dt 0.025 s, every mode at
/// [`PAIR_TD_HEADINGS`]: the time domain against its own floor. Measured 0.442 % (lighter sway at its 1.23 rad/s coupled
/// resonance, head seas; second order in dt: 1.77 % at dt 0.05; heading 150 alone 0.24 %). Against the
/// database's frequency domain 1.80 % at the same resonance, the floor's 1.37 % plus this: not asserted,
/// the database is not Kramers-Kronig consistent there (see the floor tests below).
#[test]
fn two_ship_time_domain_matches_its_floor_state_space() {
    let (e, at) = td_against(
        "config/vessels/pair/system.toml",
        "state-space",
        "implied",
        "0.025",
        Some(PAIR_TD_HEADINGS),
    );
    assert!(e <= TD_FLOOR_TOL, "{e} at {at}");
}

/// The same for the convolution, every mode at [`PAIR_TD_HEADINGS`], dt 0.025 s (24 001 taps): measured 0.295 %
/// (lighter sway at its 1.23 rad/s coupled resonance, head seas; 0.293 % following seas). Against the
/// database's frequency domain 1.44 %, the floor's 1.14 % plus this (not asserted, as above). A run's own
/// velocities meet the kernel by partitioned FFTs (`rom::partitioned`); the direct sum they replaced took
/// about 13 min per heading.
#[test]
fn two_ship_time_domain_matches_its_floor_convolution() {
    let (e, at) = td_against(
        "config/vessels/pair/system.toml",
        "convolution",
        "implied",
        "0.025",
        Some(PAIR_TD_HEADINGS),
    );
    assert!(e <= TD_FLOOR_TOL, "{e} at {at}");
}

/// The floor a time-domain model of the pair converges to (the convolution's, `--method implied`)
/// against the database's frequency domain, every mode and heading. Measured 1.14 % (lighter sway at
/// its 1.23 rad/s heave resonance in head seas, where a 0.02 %-of-scale added-mass difference moves the
/// response 0.5 %; 0.61 % at heading 150); 6.7 % (lighter yaw in beam seas) before the database was
/// symmetrized and the damping tail fitted to its added mass. The 1 % is not met at that
/// resonance: this guards what is.
const PAIR_FLOOR_TOL: f64 = 0.0125;

#[test]
fn two_ship_floor_matches_frequency_domain_convolution() {
    let (e, at) = rao_against(
        "config/vessels/pair/system.toml",
        "implied",
        "convolution",
        "frequency",
        "0.05",
        None,
    );
    assert!(e <= PAIR_FLOOR_TOL, "{e} at {at}");
}

/// The state-space model's floor for the pair, every mode and heading. Measured 1.367 % (lighter sway at
/// its 1.23 rad/s resonance, following seas (heading 0), where the convolution's floor is 1.13 % and its
/// worst, head seas, 1.14 %: the database's inconsistency); 1.895 % (lighter yaw in beam seas at 0.05 rad/s, a tiny curve driven by the couplings'
/// added mass there) before passivity enforcement held the slow modes' residues (session 11: this test
/// fails without that); 3.34 % at dt 0.025 when the fit still followed the solver's step. The issue's
/// 1 % is not met at the resonance: this guards what is.
const PAIR_SS_FLOOR_TOL: f64 = 0.015;

#[test]
fn two_ship_floor_matches_frequency_domain_state_space() {
    let (e, at) = rao_against(
        "config/vessels/pair/system.toml",
        "implied",
        "state-space",
        "frequency",
        "0.05",
        None,
    );
    assert!(e <= PAIR_SS_FLOOR_TOL, "{e} at {at}");
}

/// Half a unit in the last place of `db check`'s floor, a percentage printed to 3 decimals (`{:.3} %`).
const FLOOR_PRINT_TOL_PCT: f64 = 0.0005;
/// Slack on top of that half unit for the round-off of the percentage's own arithmetic.
const FLOOR_ROUNDOFF_PCT: f64 = 1e-9;

/// `db check` reports each radiation method's floor against the frequency domain by the tests' metric
/// (its own implementation, `rom::floor`): the same figures as `rao --method implied` against `rao
/// --method frequency` compared here, to the printed precision.
#[test]
fn db_check_reports_the_floors_the_rao_command_shows() {
    let rel = "config/vessels/ship/system.toml";
    let (ok, out, err) = shipcast(&["db", "check", rel]);
    assert!(ok, "{err}");
    for (label, radiation) in [("convolution", "convolution"), ("state space", "state-space")] {
        let line = out
            .lines()
            .find(|l| l.trim_start().starts_with(label) && l.contains(" % ("))
            .unwrap_or_else(|| panic!("no {label} floor in {out}"));
        let reported: f64 = line
            .trim_start()
            .trim_start_matches(label)
            .split_whitespace()
            .next()
            .and_then(|v| v.parse().ok())
            .unwrap_or_else(|| panic!("no figure in {line}"));
        // the ship's IRF grid is the default 0.05 s, the step the convolution's floor is taken at
        let (e, at) = rao_against(rel, "implied", radiation, "frequency", "0.05", None);
        assert!(
            (reported - 100.0 * e).abs() <= FLOOR_PRINT_TOL_PCT + FLOOR_ROUNDOFF_PCT,
            "{line} vs {:.4} % at {at}",
            100.0 * e
        );
    }
}

/// The two radiation methods forecast the two-ship scenario (240 components, 300 s, dt 0.1 s) from the
/// same simulated measured past (`scenario::prepare`: the convolution's spin-up): worst difference over
/// the horizon / the convolution's peak. Measured: displacements of the modes with restoring (heave,
/// roll, pitch) 0.09-0.31 %; every velocity 0.10-0.84 %. Surge, sway and yaw drift apart (lighter sway
/// 13 %, 0.23 m in 300 s, a velocity offset of 0.8 mm/s): the state-space model's damping below the
/// database's lowest frequency (passivity enforcement leaves about 4.5e3 N s/m on the lighter's sway
/// where the database has about 0), printed here, not asserted.
const FORECAST_AGREE_TOL: f64 = 0.005;
const FORECAST_VELOCITY_AGREE_TOL: f64 = 0.01;

#[test]
fn two_ship_forecasts_from_the_same_past_agree() {
    use shipcast::shell::scenario::{Scenario, past_options, prepare};
    let sc = Scenario::load(&repo("config/scenarios/two-ship.toml")).unwrap();
    let sys = load_system(&sc.system).unwrap().system;
    let model = |radiation| TimeModel::new(&sys, RomOptions { radiation, ..sc.opts }).unwrap();
    let (cv, ss) = (model(RadiationMethod::Convolution), model(RadiationMethod::StateSpace));
    let past = TimeModel::new(&sys, past_options(ss.opts)).unwrap();
    let run = |m: &TimeModel| {
        let prep = prepare(&past, m, &sc.waves, sc.history_s).unwrap();
        Forecaster::new()
            .forecast(m, &prep.request(sc.length_s))
            .unwrap()
            .clone()
    };
    let (fc, fs) = (run(&cv), run(&ss));
    let nm = fc.n_modes;
    for (r, &i) in cv.active.iter().enumerate() {
        let worst = |a: &[f64], b: &[f64]| {
            let peak = (0..=fc.steps).map(|k| a[k * nm + i].abs()).fold(0.0, f64::max);
            let d = (0..=fc.steps)
                .map(|k| (a[k * nm + i] - b[k * nm + i]).abs())
                .fold(0.0, f64::max);
            d / peak
        };
        let (ex, ev) = (worst(&fc.x, &fs.x), worst(&fc.v, &fs.v));
        eprintln!(
            "{}: displacement {:.3} %, velocity {:.3} %",
            cv.labels[r],
            100.0 * ex,
            100.0 * ev
        );
        assert!(ev <= FORECAST_VELOCITY_AGREE_TOL, "{} velocity {ev}", cv.labels[r]);
        if sys.stiffness()[(i, i)] > 0.0 {
            assert!(ex <= FORECAST_AGREE_TOL, "{} displacement {ex}", cv.labels[r]);
        }
    }
}

/// A forecast sums its wave force beside the radiation force its start owes (the history's, on a
/// second thread): the same, to the bit, as the run with that force given, where the two follow each
/// other; and a second forecast by the same forecaster again.
#[test]
fn a_forecast_with_a_history_is_the_same_with_its_parts_beside_each_other_or_in_turn() {
    use shipcast::shell::scenario::{Scenario, past_options, prepare};
    let sc = Scenario::load(&repo("config/scenarios/two-ship-moored.toml")).unwrap();
    let sys = load_system(&sc.system).unwrap().system;
    let model = TimeModel::new(&sys, sc.opts).unwrap();
    let past = TimeModel::new(&sys, past_options(model.opts)).unwrap();
    let prep = prepare(&past, &model, &sc.waves, sc.history_s).unwrap();
    let req = prep.request(sc.length_s);
    assert!(
        matches!(prep.memory, shipcast::radiation::history::Memory::Convolution { len, .. } if len > 0),
        "the scenario's start has a history to convolve"
    );
    let mut fc = Forecaster::new();
    let beside = fc.forecast(&model, &req).unwrap().clone();
    let force = fc.force_for(&model, &req).unwrap();
    let in_turn = fc.forecast_forced(&model, &req, &force).unwrap().clone();
    let again = fc.forecast(&model, &req).unwrap().clone();
    for (name, other) in [("in turn", &in_turn), ("again", &again)] {
        assert_eq!(beside.steps, other.steps);
        assert!(
            beside.x == other.x && beside.v == other.v,
            "{name}: the forecasts differ"
        );
    }
    assert!(beside.x.iter().any(|x| *x != 0.0));
}

/// A run of the forecaster from (x0, v0) with no past motion.
fn run_from_rest_history(
    model: &TimeModel,
    x0: &[f64],
    v0: &[f64],
    waves: &[WaveComponent],
    length_s: f64,
    ramp_s: f64,
) -> shipcast::rom::Result<Forecast> {
    let mem = Memory::new(model);
    let mut fc = Forecaster::new();
    fc.forecast(
        model,
        &ForecastRequest {
            x0,
            v0,
            memory: &mem,
            waves,
            length_s,
            ramp_s,
            drift_velocity: None,
            track: None,
        },
    )
    .cloned()
}

// ---- WEC-Sim RM3 regularCIC ----

/// The bars.
const RM3_STEADY_TOL: f64 = 0.01;
const RM3_RECORD_TOL: f64 = 0.02;

#[test]
fn wecsim_rm3_regular_cic_run() {
    let sys = load("tests/data/wecsim-rm3/system.toml");
    let model = TimeModel::new(
        &sys,
        RomOptions {
            dt_s: 0.1,
            ..RomOptions::default()
        },
    )
    .unwrap();
    let w = 2.0 * std::f64::consts::PI / 8.0;
    let waves = [WaveComponent {
        omega_rad_s: w,
        heading_rad: 0.0,
        amplitude_m: Complex64::new(1.25, 0.0),
    }];
    let zeros = vec![0.0; model.n()];
    let f = run_from_rest_history(&model, &zeros, &zeros, &waves, 200.0, 100.0).unwrap();
    // steady state over the last 6 periods (152..200 s): least squares on cos, sin, 1
    for (mode, amp_ref, ph_ref) in [(2usize, 0.98395, -24.83f64), (8, 0.12408, -43.31)] {
        let ks: Vec<usize> = (1520..=2000).collect();
        let (mut c, mut s) = (0.0, 0.0);
        let mean = ks.iter().map(|k| f.at(*k, mode)).sum::<f64>() / ks.len() as f64;
        for k in &ks {
            let t = *k as f64 * 0.1;
            c += (f.at(*k, mode) - mean) * (w * t).cos();
            s += (f.at(*k, mode) - mean) * (w * t).sin();
        }
        let x = Complex64::new(c, -s) * (2.0 / ks.len() as f64);
        let r = Complex64::from_polar(amp_ref, ph_ref.to_radians());
        let e = (x - r).norm() / amp_ref;
        eprintln!(
            "RM3 mode {}: {:.5} m / {:.2} deg against {amp_ref} / {ph_ref}: {:.3} %",
            mode + 1,
            x.norm(),
            x.arg().to_degrees(),
            100.0 * e
        );
        assert!(e <= RM3_STEADY_TOL, "mode {}: {e}", mode + 1);
    }
    // the 0-200 s record against WEC-Sim's heave.csv
    let text = std::fs::read_to_string(repo("tests/data/wecsim-rm3/regression/regularCIC/heave.csv")).unwrap();
    let rows: Vec<Vec<f64>> = text
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| l.split(',').map(|v| v.trim().parse().unwrap()).collect())
        .collect();
    for (col, mode) in [(1usize, 2usize), (2, 8)] {
        let peak = rows.iter().map(|r| r[col].abs()).fold(0.0, f64::max);
        let worst = rows
            .iter()
            .map(|r| {
                let k = (r[0] / 0.1).round() as usize;
                (f.at(k, mode) - r[col]).abs()
            })
            .fold(0.0, f64::max);
        eprintln!(
            "RM3 record mode {}: worst {:.4} m of peak {:.4} m ({:.2} %)",
            mode + 1,
            worst,
            peak,
            100.0 * worst / peak
        );
        assert!(worst <= RM3_RECORD_TOL * peak, "mode {}: {worst} of {peak}", mode + 1);
    }
}

// ---- free decay: energy never grows ----

fn energy(model: &TimeModel, x: &[f64], v: &[f64]) -> f64 {
    let n = model.n();
    let mut e = 0.0;
    for i in 0..n {
        for j in 0..n {
            e += 0.5 * v[i] * model.mass[(i, j)] * v[j]
                + 0.25 * x[i] * (model.stiffness[(i, j)] + model.stiffness[(j, i)]) * x[j];
        }
    }
    e
}

/// Relative growth allowed: discrete trapezoid radiation is passive to O(dt^2), not exactly.
const ENERGY_GROWTH_TOL: f64 = 1e-6;
/// Energy left after 200 s of free decay, at most: a loose bar that catches damping gone missing, not its amount.
const MAX_DECAYED_ENERGY_FRACTION: f64 = 0.2;

fn free_decay_never_gains_energy(method: RadiationMethod, heave_m: f64, roll_rad: f64, pitch_rad: f64) {
    thread_local! {
        static MODELS: std::cell::RefCell<HashMap<bool, TimeModel>> = std::cell::RefCell::new(HashMap::new());
    }
    let conv = method == RadiationMethod::Convolution;
    let model = MODELS.with(|m| {
        m.borrow_mut()
            .entry(conv)
            .or_insert_with(|| {
                let sys = load("config/vessels/ship/system.toml");
                TimeModel::new(
                    &sys,
                    RomOptions {
                        radiation: method,
                        ..RomOptions::default()
                    },
                )
                .unwrap()
            })
            .clone()
    });
    let mut x0 = vec![0.0; model.n()];
    x0[2] = heave_m;
    x0[3] = roll_rad;
    x0[4] = pitch_rad;
    let v0 = vec![0.0; model.n()];
    let f = run_from_rest_history(&model, &x0, &v0, &[], 200.0, 0.0).unwrap();
    let e0 = energy(&model, &x0, &v0);
    let act = |k: usize, a: &[f64]| -> Vec<f64> { model.active.iter().map(|&i| a[k * f.n_modes + i]).collect() };
    let mut max = 0.0f64;
    for k in 0..=f.steps {
        max = max.max(energy(&model, &act(k, &f.x), &act(k, &f.v)));
    }
    let end = energy(&model, &act(f.steps, &f.x), &act(f.steps, &f.v));
    assert!(max <= e0 * (1.0 + ENERGY_GROWTH_TOL), "energy grew: {max} > {e0}");
    assert!(end < MAX_DECAYED_ENERGY_FRACTION * e0, "no decay: {end} of {e0}");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(12))]
    #[test]
    fn free_decay_energy_never_grows_convolution(h in -2.0f64..2.0, r in -0.2f64..0.2, p in -0.05f64..0.05) {
        prop_assume!(h.abs() + r.abs() + p.abs() > 1e-3);
        free_decay_never_gains_energy(RadiationMethod::Convolution, h, r, p);
    }

    #[test]
    fn free_decay_energy_never_grows_state_space(h in -2.0f64..2.0, r in -0.2f64..0.2, p in -0.05f64..0.05) {
        prop_assume!(h.abs() + r.abs() + p.abs() > 1e-3);
        free_decay_never_gains_energy(RadiationMethod::StateSpace, h, r, p);
    }
}

/// The state-space radiation is fitted once per database (and speed), on the system file's IRF grid:
/// its kernel and A_inf are the same at every solver step. Refitted per step (sessions 1-6), the pair's
/// floor moved from 1.9 % to 3.3 % of peak off the frequency domain between dt = 0.05 s and 0.025 s.
#[test]
fn the_state_space_fit_does_not_depend_on_the_solver_step() {
    let sys = load("config/vessels/ship/system.toml");
    let model = |dt: f64| {
        TimeModel::new(
            &sys,
            RomOptions {
                dt_s: dt,
                radiation: RadiationMethod::StateSpace,
                ..RomOptions::default()
            },
        )
        .unwrap()
    };
    let (a, b) = (model(0.025), model(0.1));
    assert_eq!(a.mass, b.mass, "M + A_inf");
    for w in [0.05, 0.3, 0.7, 1.2, 1.6, 3.0] {
        assert_eq!(a.kernel_at(w), b.kernel_at(w), "K_r(i {w})");
    }
}

/// One unit in the last place of `db check`'s zero-frequency damping, a percentage printed to 4 decimals.
const ZERO_FREQUENCY_DAMPING_PRINT_TOL_PCT: f64 = 1e-4;

/// `db check` reports the state-space model the time domain runs (session 6 reported a fit to the raw
/// damping: on RM3, whose BEM damping is not passive, 40 states and 1.98 % where the model has 32 and
/// 0.87 %).
#[test]
fn db_check_reports_the_state_space_model_that_runs() {
    let rel = "tests/data/wecsim-rm3/system.toml";
    let (ok, out, err) = shipcast(&["db", "check", rel]);
    assert!(ok, "{err}");
    let reported: usize = number_after(&out, "state-space radiation", "balanced-truncated to ");
    let model = TimeModel::new(
        &load(rel),
        RomOptions {
            radiation: RadiationMethod::StateSpace,
            ..RomOptions::default()
        },
    )
    .unwrap();
    assert_eq!(reported, model.memory_size());
    // and its damping at zero frequency, the largest over a DOF's peak
    let reported: f64 = number_after(&out, "damping at zero frequency", "largest ");
    let shipcast::rom::model::Kernel::StateSpace { model: ss, .. } = &model.kernel else {
        panic!("not a state-space model");
    };
    let largest = ss
        .zero_frequency_damping()
        .iter()
        .zip(&ss.scale)
        .map(|(k, s)| (k / s).abs())
        .fold(0.0, f64::max);
    assert!(largest > 0.0);
    assert!(
        (reported - 100.0 * largest).abs() < ZERO_FREQUENCY_DAMPING_PRINT_TOL_PCT,
        "reported {reported} %, model {} %",
        100.0 * largest
    );
}

/// The number that follows `marker` on the line of `out` that starts (indentation aside) with `line_start`.
fn number_after<T: std::str::FromStr>(out: &str, line_start: &str, marker: &str) -> T {
    let line = out
        .lines()
        .find(|l| l.trim_start().starts_with(line_start))
        .unwrap_or_else(|| panic!("no line starting {line_start:?} in {out}"));
    line.split(marker)
        .nth(1)
        .and_then(|r| r.split_whitespace().next())
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("no number after {marker:?} in {line}"))
}

// ---- convergence in dt, and divergence reported ----

/// Observed order at least: a second-order scheme, from dt 0.1 and 0.05 against dt 0.0125; a margin below 2.
const MIN_OBSERVED_ORDER: f64 = 1.7;

#[test]
fn halving_dt_shrinks_the_error_at_second_order() {
    // RM3 float and spar heave at T = 8 s against the time-domain steady state at a tiny step
    let sys = load("tests/data/wecsim-rm3/system.toml");
    let w = 2.0 * std::f64::consts::PI / 8.0;
    let run = |dt: f64| {
        let model = TimeModel::new(
            &sys,
            RomOptions {
                dt_s: dt,
                memory_s: Some(60.0),
                ..RomOptions::default()
            },
        )
        .unwrap();
        let waves = [WaveComponent {
            omega_rad_s: w,
            heading_rad: 0.0,
            amplitude_m: Complex64::new(1.0, 0.0),
        }];
        let zeros = vec![0.0; model.n()];
        let f = run_from_rest_history(&model, &zeros, &zeros, &waves, 160.0, 40.0).unwrap();
        f.at(f.steps, 2)
    };
    let reference = run(0.0125);
    let e1 = (run(0.1) - reference).abs();
    let e2 = (run(0.05) - reference).abs();
    let rate = (e1 / e2).log2();
    eprintln!("heave at t = 160 s: error {e1:.3e} at dt 0.1, {e2:.3e} at dt 0.05: order {rate:.2}");
    assert!(rate > MIN_OBSERVED_ORDER, "observed order {rate}");
}

#[test]
fn a_diverging_state_is_reported_with_its_dof_and_time() {
    let mut sys = load("config/vessels/ship/system.toml");
    sys.spec.extra_stiffness[(2, 2)] = -1e12; // heave restoring made strongly negative
    let model = TimeModel::new(&sys, RomOptions::default()).unwrap();
    let mut x0 = vec![0.0; model.n()];
    x0[2] = 0.01;
    let v0 = vec![0.0; model.n()];
    let err = run_from_rest_history(&model, &x0, &v0, &[], 300.0, 0.0)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("carrier.heave") && err.contains("unbounded") && err.contains("t = "),
        "{err}"
    );
}

/// A model adjusted by nothing steps as the built one; one adjusted by a row's damping and stiffness
/// is the model built with them (the step's matrices agree); a row out of range is refused.
#[test]
fn an_adjusted_model_is_the_model_built_with_the_change() {
    use shipcast::rom::adjust::RowChange;
    let sys = load("config/vessels/barge/system.toml");
    let opts = RomOptions::default();
    let model = TimeModel::new(&sys, opts).unwrap();
    let same = model.adjusted(&[]).unwrap();
    assert_eq!(same.cols_s_inv, model.cols_s_inv);
    let row = model.labels.iter().position(|l| l.ends_with("roll")).unwrap();
    let i = model.active[row];
    let (db44, dc44) = (1.0e7, 2.0e7);
    let mut sys2 = sys.clone();
    sys2.spec.bodies[i / 6].linear_damping[(i % 6, i % 6)] += db44;
    sys2.spec.bodies[i / 6].linear_stiffness[(i % 6, i % 6)] += dc44;
    let rebuilt = TimeModel::new(&sys2, opts).unwrap();
    let adj = model
        .adjusted(&[RowChange {
            row,
            damping: db44,
            stiffness: dc44,
            ..RowChange::default()
        }])
        .unwrap();
    for (a, b) in adj.cols_s_inv.iter().zip(&rebuilt.cols_s_inv) {
        assert!((a - b).abs() <= 1e-9 * (1.0 + b.abs()), "{a} vs {b}");
    }
    assert!((adj.damping[(row, row)] - rebuilt.damping[(row, row)]).abs() <= 1e-6 * db44);
    assert!(
        model
            .adjusted(&[RowChange {
                row: 99,
                ..RowChange::default()
            }])
            .is_err()
    );
}

/// The sampled memory's transform at many frequencies at once (one matrix product) is each
/// frequency's own (summed in place), to rounding.
#[test]
fn the_kernel_at_many_frequencies_is_each_frequency_s_kernel() {
    /// The same sums in another order.
    const SUM_ORDER_REL_TOL: f64 = 1e-12;
    let model = TimeModel::new(&load("config/vessels/barge/system.toml"), RomOptions::default()).unwrap();
    let omegas: Vec<f64> = (0..9).map(|i| 0.2 + 0.3 * i as f64).collect();
    let many = model.kernels_at(&omegas);
    assert_eq!(many.len(), omegas.len());
    let scale = many.iter().flat_map(|k| k.iter()).map(|v| v.norm()).fold(0.0, f64::max);
    assert!(scale > 0.0);
    for (w, k) in omegas.iter().zip(&many) {
        let one = model.kernel_at(*w);
        let off = (&one - k).iter().map(|v| v.norm()).fold(0.0, f64::max);
        assert!(off <= SUM_ORDER_REL_TOL * scale, "K(i {w}): {off} of {scale}");
    }
}

/// A tuned model (the built one with added roll damping and stiffness, its memory unchanged) makes the
/// same response table from the built model's kernels as from its own; kernels of another memory (the
/// same database at another step) are not taken.
#[test]
fn a_response_table_takes_the_kernels_of_its_own_memory_only() {
    use shipcast::band::{ResponseTable, TableKernels};
    use shipcast::rom::adjust::RowChange;
    let sys = load("config/vessels/barge/system.toml");
    let model = TimeModel::new(&sys, RomOptions::default()).unwrap();
    let kernels = TableKernels::of(&model);
    let row = model.labels.iter().position(|l| l.ends_with("roll")).unwrap();
    let tuned = model
        .adjusted(&[RowChange {
            row,
            damping: 3.0e7,
            quadratic: 1.0e8,
            stiffness: -2.0e7,
        }])
        .unwrap();
    let own = ResponseTable::of(&tuned).unwrap();
    assert_eq!(ResponseTable::with_kernels(&tuned, &kernels).unwrap(), own);
    assert_ne!(own, ResponseTable::of(&model).unwrap(), "the tuning changes the table");
    let other = TimeModel::new(
        &sys,
        RomOptions {
            dt_s: 0.5 * model.opts.dt_s,
            memory_s: Some(60.0),
            ..model.opts
        },
    )
    .unwrap();
    assert_eq!(
        ResponseTable::with_kernels(&other, &kernels).unwrap(),
        ResponseTable::of(&other).unwrap()
    );
}
