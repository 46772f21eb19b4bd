//! Validation against WEC-Sim's 3-DOF RM3 run (MHKiT's example data, `tests/data/wecsim-rm3-3dof/`):
//! surge, heave and pitch of both bodies, constant-coefficient radiation (A, B at the wave frequency),
//! regular wave H = 2.5 m, T = 8 s, ramp 100 s, dt 0.1 s, 400 s. The float slides on the spar: a bushing
//! (joint) plus a damper connection in `system.toml`.
//!
//! Forces are checked sample by sample on WEC-Sim's own states (independent of either integrator);
//! motions by running shipcast's time-domain model from rest.

use crate::util::repo;
use nalgebra::DMatrix;
use num_complex::Complex64;
use shipcast::radiation::history::Memory;
use shipcast::rom::{ForecastRequest, Forecaster, RadiationMethod, RomOptions, TimeModel};
use shipcast::shell::files::load_system;
use shipcast::waves::WaveComponent;

/// The bar for forces: 1 % of each series' peak.
const FORCE_TOL: f64 = 0.01;
/// The bar for motions after the ramp: 2 % of each series' peak (met by the float's heave).
const MOTION_TOL: f64 = 0.02;
/// Spar heave: WEC-Sim's carries a 1.6 mm mean offset (1.3 % of its peak) that no linear model has.
const SPAR_HEAVE_TOL: f64 = 0.025;
/// Surge and pitch: WEC-Sim's own output breaks the linear surge balance of the pair, sum of
/// (M a - F_total), by 51 kN at the wave frequency, in phase with the acceleration (10 % of the surge
/// excitation): its 3-DOF motions are not those of the linear equations it reports (issue 4's note);
/// shipcast's are, and sit 2.5 % (pitch) to 7.5 % (spar surge) from WEC-Sim's in amplitude.
const SURGE_PITCH_TOL: f64 = 0.15;
const AMPLITUDE_M: f64 = 1.25;
const RAMP_S: f64 = 100.0;
const DURATION_S: f64 = 400.0;

struct Reference {
    names: Vec<String>,
    rows: Vec<Vec<f64>>,
}

impl Reference {
    fn load() -> Reference {
        let text = std::fs::read_to_string(repo("tests/data/wecsim-rm3-3dof/rm3_3dof_regular_timeseries.csv"))
            .expect("reference CSV");
        let mut lines = text.lines();
        let names = lines.next().unwrap().split(',').map(String::from).collect();
        let rows = lines
            .filter(|l| !l.is_empty())
            .map(|l| l.split(',').map(|v| v.parse::<f64>().unwrap()).collect())
            .collect();
        Reference { names, rows }
    }
    fn col(&self, name: &str) -> Vec<f64> {
        let c = self
            .names
            .iter()
            .position(|n| n == name)
            .unwrap_or_else(|| panic!("column {name}"));
        self.rows.iter().map(|r| r[c]).collect()
    }
}

const BODIES: [&str; 2] = ["float", "spar"];
const DOFS: [(&str, usize); 3] = [("surge", 0), ("heave", 2), ("pitch", 4)];

/// Largest |a - b| over the samples from `from`, relative to the peak |b| there.
fn worst(a: &[f64], b: &[f64], from: usize) -> f64 {
    let peak = b[from..].iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let err = a[from..]
        .iter()
        .zip(&b[from..])
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    err / peak
}

fn model(radiation: RadiationMethod) -> (shipcast::hydro::VesselSystem, TimeModel) {
    let sys = load_system(&repo("tests/data/wecsim-rm3-3dof/system.toml"))
        .unwrap()
        .system;
    let opts = RomOptions {
        dt_s: 0.1,
        radiation,
        ..RomOptions::default()
    };
    let m = TimeModel::new(&sys, opts).unwrap();
    (sys, m)
}

fn wave() -> Vec<WaveComponent> {
    vec![WaveComponent {
        omega_rad_s: 2.0 * std::f64::consts::PI / 8.0,
        heading_rad: 0.0,
        amplitude_m: Complex64::new(AMPLITUDE_M, 0.0),
    }]
}

/// The reference's state (12 modes) at sample k, from its position or velocity columns.
fn state(r: &Reference, what: &str) -> Vec<Vec<f64>> {
    let mut out = vec![vec![0.0; 12]; r.rows.len()];
    for (b, body) in BODIES.iter().enumerate() {
        for (d, j) in DOFS {
            for (k, v) in r.col(&format!("{body}_{what}_{d}")).into_iter().enumerate() {
                out[k][6 * b + j] = v;
            }
        }
    }
    out
}

#[test]
fn forces_sample_by_sample_match_wecsim() {
    let r = Reference::load();
    let omega = 2.0 * std::f64::consts::PI / 8.0;
    let (sys, m) = model(RadiationMethod::Constant { omega_rad_s: omega });
    assert_eq!(m.active, vec![0, 2, 4, 6, 8, 10]);
    // excitation through the forecaster's own wave-force path
    let mem = Memory::new(&m);
    let z = vec![0.0; m.n()];
    let waves = wave();
    let req = ForecastRequest {
        x0: &z,
        v0: &z,
        memory: &mem,
        waves: &waves,
        length_s: DURATION_S,
        ramp_s: RAMP_S,
        drift_velocity: None,
        track: None,
    };
    let force = Forecaster::new().force_for(&m, &req).unwrap();
    let n = m.n();
    let x = state(&r, "pos");
    let v = state(&r, "vel");
    let c: &DMatrix<f64> = &sys.db.restoring;
    let mut report = vec![];
    for (b, body) in BODIES.iter().enumerate() {
        for (row, (d, j)) in DOFS.iter().enumerate() {
            let i = 6 * b + j;
            let ours: Vec<f64> = (0..r.rows.len()).map(|k| force[k * n + 3 * b + row]).collect();
            let e = worst(&ours, &r.col(&format!("{body}_Fexc_{d}")), 0);
            report.push((format!("{body} excitation {d}"), e));
            // restoring: WEC-Sim's column is the reaction +C x
            let ours: Vec<f64> = x.iter().map(|xk| (0..12).map(|l| c[(i, l)] * xk[l]).sum()).collect();
            let reference = r.col(&format!("{body}_FrestoringOut_{d}"));
            if reference.iter().any(|f| f.abs() > 0.0) {
                report.push((format!("{body} restoring {d}"), worst(&ours, &reference, 0)));
            }
        }
    }
    // the damper: the connection's axial force (tension positive) is WEC-Sim's PTO force
    let mut f = vec![];
    let ours: Vec<f64> = x
        .iter()
        .zip(&v)
        .map(|(xk, vk)| {
            sys.spec.external.connection_forces(xk, vk, &mut f);
            f[1]
        })
        .collect();
    report.push((
        "damper".into(),
        worst(&ours, &r.col("pto_forceInternalMechanics_heave"), 0),
    ));
    for (what, e) in &report {
        eprintln!("{what:<24} worst error {:.4} % of peak", 100.0 * e);
    }
    for (what, e) in &report {
        assert!(*e <= FORCE_TOL, "{what}: {:.3} % of peak", 100.0 * e);
    }
}

#[test]
fn motions_after_the_ramp_match_wecsim() {
    let r = Reference::load();
    let omega = 2.0 * std::f64::consts::PI / 8.0;
    let (_, m) = model(RadiationMethod::Constant { omega_rad_s: omega });
    let mut fc = Forecaster::new();
    let f = fc.from_rest(&m, &wave(), DURATION_S, RAMP_S).unwrap();
    let from = (RAMP_S / 0.1) as usize;
    let mut report = vec![];
    for (b, body) in BODIES.iter().enumerate() {
        for (d, j) in DOFS {
            let ours: Vec<f64> = (0..r.rows.len()).map(|k| f.at(k, 6 * b + j)).collect();
            report.push((
                format!("{body} {d}"),
                worst(&ours, &r.col(&format!("{body}_pos_{d}")), from),
            ));
        }
    }
    for (what, e) in &report {
        eprintln!("{what:<14} worst error after the ramp {:.4} % of peak", 100.0 * e);
    }
    for (what, e) in &report {
        let tol = match what.as_str() {
            "float heave" => MOTION_TOL,
            "spar heave" => SPAR_HEAVE_TOL,
            _ => SURGE_PITCH_TOL,
        };
        assert!(*e <= tol, "{what}: {:.3} % of peak", 100.0 * e);
    }
}
