//! External and nonlinear models (issue 4): quadratic damping against the decrement law of a
//! linear-plus-quadratic oscillator, the U-tube tank against its closed-form two-DOF solution and on
//! the demo ship, lines and fenders (energy, a 30-minute moored run in beam seas).

use crate::util::{repo, scratch_dir, write_flat_database};
use nalgebra::{Matrix2, Vector2};
use num_complex::Complex64;
use proptest::prelude::*;
use shipcast::radiation::history::Memory;
use shipcast::rao::FrequencySolver;
use shipcast::rom::regular::{RegularOptions, time_domain_rao};
use shipcast::rom::{ForecastRequest, Forecaster, RomOptions, TimeModel};
use shipcast::shell::files::load_system;
use shipcast::waves::WaveComponent;
use std::f64::consts::PI;

/// The issue's bar for the roll decay against the decrement law.
const DECAY_TOL: f64 = 0.02;
/// Tank, frequency domain against the closed form: both solve the same 2 x 2 system.
const TANK_FD_TOL: f64 = 1e-9;
/// Tank, time domain against the closed form: dt = 0.05 s, second order, measured 0.03 %.
const TANK_TD_TOL: f64 = 0.003;
/// The linear law alone must miss by this many times `DECAY_TOL` (20 %): the quadratic term matters here.
const LINEAR_LAW_MISS: f64 = 10.0;
/// A tuned tank leaves this fraction of the bare roll peak: the seed reports about half, with margin.
const TUNED_ROLL_PEAK_RATIO: std::ops::Range<f64> = 0.3..0.6;
/// A detuned tank (0.16 or 1.23 rad/s, far from roll's 0.425) leaves at least this of the bare roll peak.
const DETUNED_ROLL_PEAK_RATIO: f64 = 0.85;
/// Aft fender's peak force at least, N: it was in contact (0.3 m pre-compression is worth more), no load bound.
const MIN_FENDER_PEAK_N: f64 = 1e5;
/// No growth: the last ten minutes' largest sway within 1.5 times the ten before's (random sea's scatter).
const MAX_SWAY_GROWTH: f64 = 1.5;

// flat one-body database: roll inertia 1e8 + added 2e7 kg m^2, C44 3e7 N m: w_n = 0.5 rad/s
const I44: f64 = 1.0e8;
const A44: f64 = 2.0e7;
const C44: f64 = 3.0e7;
const B44: f64 = 2.4e6; // 2 % of critical
const Q44: f64 = 3.0e7; // N m s^2
const X44: f64 = 1.0e6; // N m per metre of wave, beam seas

/// Writes `system.toml` for one box on the flat database in `dir`: its mass, then `body_keys` (more
/// keys of the body), then `sections` (connections, tanks).
fn box_system_file(dir: &std::path::Path, body_keys: &str, sections: &str) -> std::path::PathBuf {
    let text = format!(
        r#"
wamit = "flat"
rho = 1000.0
g = 9.81
water_depth = "infinite"
a_inf = "database"

[[body]]
name = "box"
position = [0.0, 0.0, 0.0]
mass_matrix = [
    [1e7, 0, 0, 0, 0, 0], [0, 1e7, 0, 0, 0, 0], [0, 0, 1e7, 0, 0, 0],
    [0, 0, 0, {I44:e}, 0, 0], [0, 0, 0, 0, 1e9, 0], [0, 0, 0, 0, 0, 1e9],
]
{body_keys}
{sections}"#
    );
    let p = dir.join("system.toml");
    std::fs::write(&p, text).unwrap();
    p
}

fn flat_system(dir: &std::path::Path, extra: &str, quadratic: bool) -> std::path::PathBuf {
    write_flat_database(
        dir,
        [1e6, 1e6, 1e6, A44, 1e9, 1e9],
        [0.0; 6],
        [0.0, 0.0, 1e7, C44, 1e9, 0.0],
        X44,
    );
    let q = if quadratic { Q44 } else { 0.0 };
    let body_keys = format!(
        r#"linear_damping = [
    [0, 0, 0, 0, 0, 0], [0, 0, 0, 0, 0, 0], [0, 0, 0, 0, 0, 0],
    [0, 0, 0, {B44:e}, 0, 0], [0, 0, 0, 0, 0, 0], [0, 0, 0, 0, 0, 0],
]
quadratic_damping = [0, 0, 0, {q:e}, 0, 0]
active_dofs = ["roll"]"#
    );
    box_system_file(dir, &body_keys, extra)
}

/// Extrema of a sampled signal, refined by a parabola through the three samples around each.
fn extrema(x: &[f64]) -> Vec<f64> {
    let mut out = vec![x[0].abs()];
    for k in 1..x.len() - 1 {
        let (a, b, c) = (x[k - 1], x[k], x[k + 1]);
        if (b - a) * (c - b) < 0.0 {
            let den = a - 2.0 * b + c;
            let peak = if den != 0.0 {
                b - (a - c) * (a - c) / (8.0 * den)
            } else {
                b
            };
            out.push(peak.abs());
        }
    }
    out
}

#[test]
fn roll_decay_follows_the_decrement_law() {
    let dir = scratch_dir("roll-decay");
    let sys = load_system(&flat_system(&dir, "", true)).unwrap().system;
    let opts = RomOptions {
        dt_s: 0.05,
        ..RomOptions::default()
    };
    let m = TimeModel::new(&sys, opts).unwrap();
    let phi0 = 10f64.to_radians();
    let mem = Memory::new(&m);
    let req = ForecastRequest {
        x0: &[phi0],
        v0: &[0.0],
        memory: &mem,
        waves: &[],
        length_s: 150.0,
        ramp_s: 0.0,
        drift_velocity: None,
        track: None,
    };
    let mut fc = Forecaster::new();
    let f = fc.forecast(&m, &req).unwrap();
    let roll: Vec<f64> = (0..=f.steps).map(|k| f.at(k, 3)).collect();
    let peaks = extrema(&roll);
    // energy balance over half a cycle: d(phi)/dn = -(alpha phi + beta phi^2)
    let mt = I44 + A44;
    let w = (C44 / mt).sqrt();
    let alpha = PI * B44 / (2.0 * mt * w);
    let beta = 4.0 * Q44 / (3.0 * mt);
    let law = |n: f64, beta: f64| {
        let e = (-alpha * n).exp();
        alpha * phi0 * e / (alpha + beta * phi0 * (1.0 - e))
    };
    let mut worst = 0.0f64;
    let mut worst_linear = 0.0f64;
    for (n, p) in peaks.iter().enumerate().take(16) {
        let l = law(n as f64, beta);
        worst = worst.max((p - l).abs() / l);
        worst_linear = worst_linear.max((p - law(n as f64, 0.0)).abs() / law(n as f64, 0.0));
        eprintln!(
            "half cycle {n:2}: {:.4} deg, law {:.4} deg",
            p.to_degrees(),
            l.to_degrees()
        );
    }
    eprintln!(
        "worst {:.3} % (linear law alone: {:.1} %)",
        100.0 * worst,
        100.0 * worst_linear
    );
    assert!(peaks.len() >= 16);
    assert!(worst <= DECAY_TOL, "{worst}");
    // the quadratic term matters here: without it the law is far off
    assert!(worst_linear > LINEAR_LAW_MISS * DECAY_TOL, "{worst_linear}");
}

// tank: tuned to w_n = 0.5 rad/s, Q g = 10 % of C44
const C_TT: f64 = 3.0e6;
const A_TT: f64 = C_TT / 0.25;
const A_T4: f64 = 1.53e6;
const B_TT: f64 = 2.4e6;

fn tank_section() -> String {
    format!(
        "[[tank]]\nname = \"art\"\nbody = \"box\"\na_tt = {A_TT:e}\nb_tt = {B_TT:e}\nc_tt = {C_TT:e}\na_t4 = {A_T4:e}\nc_t4 = {C_TT:e}\n"
    )
}

/// The closed form: [[Z_rr, Z_rt], [Z_rt, Z_tt]] (phi, tau) = (X44, 0).
fn two_dof(w: f64) -> (Complex64, Complex64) {
    let c = |re: f64, im: f64| Complex64::new(re, im);
    let z = Matrix2::new(
        c(-w * w * (I44 + A44) + C44, w * B44),
        c(-w * w * A_T4 + C_TT, 0.0),
        c(-w * w * A_T4 + C_TT, 0.0),
        c(-w * w * A_TT + C_TT, w * B_TT),
    );
    let s = z.lu().solve(&Vector2::new(c(X44, 0.0), c(0.0, 0.0))).unwrap();
    (s[0], s[1])
}

#[test]
fn tank_matches_the_closed_form_two_dof_solution() {
    let dir = scratch_dir("tank-2dof");
    let sys = load_system(&flat_system(&dir, &tank_section(), false)).unwrap().system;
    assert_eq!(sys.n_states(), 7);
    let omegas = [0.3, 0.45, 0.5, 0.55, 0.8];
    let fd = FrequencySolver::new(&sys);
    let m = TimeModel::new(
        &sys,
        RomOptions {
            dt_s: 0.05,
            ..RomOptions::default()
        },
    )
    .unwrap();
    let td = time_domain_rao(&m, PI / 2.0, &omegas, RegularOptions::default()).unwrap();
    for (iw, &w) in omegas.iter().enumerate() {
        let (phi, tau) = two_dof(w);
        let x = fd.rao(w, PI / 2.0).unwrap();
        let scale = phi.norm().max(tau.norm());
        let e_fd = (x[3] - phi).norm().max((x[6] - tau).norm()) / scale;
        let t = &td.rao[iw];
        let e_td = (t[3] - phi).norm().max((t[6] - tau).norm()) / scale;
        eprintln!(
            "w {w}: roll {:.4e} rad/m, tank {:.4e} rad/m; FD error {e_fd:.2e}, TD error {e_td:.2e}",
            phi.norm(),
            tau.norm()
        );
        assert!(e_fd <= TANK_FD_TOL, "w {w}: {e_fd}");
        assert!(e_td <= TANK_TD_TOL, "w {w}: {e_td}");
    }
}

/// Peak of the beam-sea roll RAO of the demo ship over 0.3..0.6 rad/s, with an optional tank.
fn ship_roll_peak(tank: &str) -> f64 {
    let dir = scratch_dir(&format!("ship-tank-{}", tank.len()));
    let base = std::fs::read_to_string(repo("config/vessels/ship/system.toml")).unwrap();
    let stem = repo("config/vessels/ship/ship");
    let text = base.replace("wamit = \"ship\"", &format!("wamit = \"{}\"", stem.display())) + tank;
    let p = dir.join("system.toml");
    std::fs::write(&p, text).unwrap();
    let sys = load_system(&p).unwrap().system;
    let fd = FrequencySolver::new(&sys);
    (0..=300)
        .map(|k| 0.3 + 0.001 * k as f64)
        .map(|w| fd.rao(w, PI / 2.0).unwrap()[3].norm())
        .fold(0.0, f64::max)
}

fn ship_tank(duct_height_m: f64) -> String {
    // 24 m between reservoirs 3 m wide, 6 m long, fluid 2 m above the duct, duct 2 m above the
    // reference point (the waterline): 170 t of water with the tuned duct, 0.5 % of the displacement
    format!(
        "\n[[tank]]\nname = \"art\"\nbody = \"carrier\"\nreservoir_spacing_m = 24.0\nreservoir_width_m = 3.0\nlength_m = 6.0\nduct_height_m = {duct_height_m}\nfluid_height_m = 2.0\nduct_below_roll_axis_m = -2.0\ndamping_ratio = 0.2\n"
    )
}

#[test]
fn tuned_tank_halves_the_roll_peak_and_a_detuned_one_does_little() {
    let bare = ship_roll_peak("");
    // tuned: w_t^2 = g / (h_r + b_r w / (2 h_d)) = the roll natural frequency, 0.4251 rad/s
    let h_d = 3.0 * 24.0 / (2.0 * (9.81 / 0.4251f64.powi(2) - 2.0));
    let tuned = ship_roll_peak(&ship_tank(h_d));
    // detuned: a 0.1 m duct puts the fluid at 0.16 rad/s, an 8 m one at 1.23 rad/s
    let low = ship_roll_peak(&ship_tank(0.1));
    let high = ship_roll_peak(&ship_tank(8.0));
    eprintln!(
        "roll RAO peak: bare {bare:.4} rad/m, tuned tank {tuned:.4} ({:.0} %), detuned low {low:.4} ({:.0} %), high {high:.4} ({:.0} %)",
        100.0 * tuned / bare,
        100.0 * low / bare,
        100.0 * high / bare
    );
    assert!(
        TUNED_ROLL_PEAK_RATIO.contains(&(tuned / bare)),
        "the seed reports about half"
    );
    assert!(low / bare > DETUNED_ROLL_PEAK_RATIO && high / bare > DETUNED_ROLL_PEAK_RATIO);
}

/// One body moored to the earth by four lines and pushed by two fenders; no damping anywhere.
fn moored_box(dir: &std::path::Path) -> std::path::PathBuf {
    write_flat_database(
        dir,
        [1e6, 2e6, 3e6, A44, 1e9, 1e8],
        [0.0; 6],
        [0.0, 0.0, 1e7, C44, 1e9, 0.0],
        0.0,
    );
    let lines: String = [(30.0, 10.0, 60.0, 30.0), (30.0, -10.0, 60.0, -30.0), (-30.0, 10.0, -60.0, 30.0), (-30.0, -10.0, -60.0, -30.0)]
        .iter()
        .enumerate()
        .map(|(k, (x, y, ex, ey))| {
            let l: f64 = ((ex - x) * (ex - x) + (ey - y) * (ey - y) + 100.0f64).sqrt();
            format!(
                "[[connection]]\nname = \"line{k}\"\nkind = \"mooring_line\"\nbody_a = \"box\"\npoint_a_m = [{x}, {y}, 0.0]\nbody_b = \"earth\"\npoint_b_m = [{ex}, {ey}, -10.0]\nunstretched_length_m = {}\ntension_polynomial = [2.0e5, 1.0e5]\n\n",
                l - 0.2
            )
        })
        .collect();
    let fenders = "[[connection]]\nname = \"fender0\"\nkind = \"fender\"\nbody_a = \"box\"\npoint_a_m = [10.0, 10.0, 0.0]\nbody_b = \"earth\"\npoint_b_m = [10.0, 12.0, 0.0]\nnormal = [0.0, -1.0, 0.0]\ninitial_compression_m = 0.05\ncurve = [[0.2, 1.0e5], [0.5, 5.0e5]]\n\n[[connection]]\nname = \"fender1\"\nkind = \"fender\"\nbody_a = \"box\"\npoint_a_m = [-10.0, 10.0, 0.0]\nbody_b = \"earth\"\npoint_b_m = [-10.0, 12.0, 0.0]\nnormal = [0.0, -1.0, 0.0]\ninitial_compression_m = 0.0\ncurve = [[0.2, 1.0e5], [0.5, 5.0e5]]\n";
    box_system_file(dir, "", &format!("{lines}{fenders}"))
}

/// Energy drift allowed over 200 s of undamped motion with lines and fenders: Newmark's average
/// acceleration conserves it for linear systems; the kinks of slack lines and fender contact cost a
/// little (measured below 0.1 %).
const ENERGY_TOL: f64 = 0.005;

proptest! {
    #![proptest_config(ProptestConfig { cases: 8, ..ProptestConfig::default() })]
    #[test]
    fn lines_and_fenders_conserve_energy_without_damping(
        v in prop::array::uniform6(-0.3f64..0.3),
    ) {
        let dir = scratch_dir("moored-energy");
        let sys = load_system(&moored_box(&dir)).unwrap().system;
        let ext = sys.spec.external.clone();
        let m = TimeModel::new(&sys, RomOptions { dt_s: 0.05, ..RomOptions::default() }).unwrap();
        prop_assert!(m.external.is_some());
        let mem = Memory::new(&m);
        let v0 = [v[0], v[1], v[2], 0.1 * v[3], 0.01 * v[4], 0.01 * v[5]];
        let x0 = [0.0; 6];
        let req = ForecastRequest { x0: &x0, v0: &v0, memory: &mem, waves: &[], length_s: 200.0, ramp_s: 0.0, drift_velocity: None, track: None };
        let mut fc = Forecaster::new();
        let f = fc.forecast(&m, &req).unwrap();
        let energy = |k: usize| {
            let x = &f.x[k * 6..k * 6 + 6];
            let v = &f.v[k * 6..k * 6 + 6];
            let mut e = ext.potential_energy(x);
            for i in 0..6 {
                for j in 0..6 {
                    e += 0.5 * v[i] * m.mass[(i, j)] * v[j] + 0.5 * x[i] * m.stiffness[(i, j)] * x[j];
                }
            }
            e
        };
        let e0 = energy(0);
        let worst = (0..=f.steps).map(|k| (energy(k) - e0).abs()).fold(0.0, f64::max) / e0;
        // the fenders and lines did work: they were engaged at some point
        prop_assert!(worst <= ENERGY_TOL, "energy drift {worst} of {e0} J");
    }
}

#[test]
fn two_ships_moored_together_stay_stable_in_beam_seas_for_30_minutes() {
    let sys = load_system(&repo("config/vessels/pair/moored.toml")).unwrap().system;
    let m = TimeModel::new(&sys, RomOptions::default()).unwrap();
    let sea = shipcast::waves::sea::SeaState {
        hs_m: 2.0,
        tp_s: 9.0,
        gamma: 3.3,
        heading_rad: PI / 2.0,
        spreading: shipcast::waves::sea::Spreading::LongCrested,
        components: 200,
        omega_min_rad_s: 0.3,
        omega_max_rad_s: 1.5,
        seed: 7,
    };
    let waves: Vec<WaveComponent> = shipcast::waves::sea::realize(&sea);
    let mut fc = Forecaster::new();
    let f = fc
        .from_rest(&m, &waves, 1800.0, 60.0)
        .expect("30 minutes without divergence");
    let d = shipcast::rom::outputs::derived(&sys.spec.external, f);
    let col = |n: &str| d.column(n).unwrap_or_else(|| panic!("{n}"));
    let max_of = |c: usize| (0..=f.steps).map(|k| d.at(k, c)).fold(f64::MIN, f64::max);
    let min_of = |c: usize| (0..=f.steps).map(|k| d.at(k, c)).fold(f64::MAX, f64::min);
    for name in [
        "fender_aft",
        "fender_fwd",
        "head_line",
        "stern_line",
        "fwd_spring",
        "aft_spring",
    ] {
        let c = col(&format!("{name}.force"));
        eprintln!("{name}: force {:.0} .. {:.0} kN", min_of(c) / 1e3, max_of(c) / 1e3);
        assert!(min_of(c) >= 0.0, "{name} pulled or pushed the wrong way");
    }
    // the fenders did work: they were loaded and unloaded
    assert!(max_of(col("fender_aft.force")) > MIN_FENDER_PEAK_N);
    let rel = col("hook_over_hatch.y");
    eprintln!("hook over hatch, sway: {:.2} .. {:.2} m", min_of(rel), max_of(rel));
    for (i, l) in ["carrier.sway", "carrier.roll", "lighter.sway", "lighter.roll"]
        .iter()
        .enumerate()
    {
        let mode = [1, 3, 7, 9][i];
        let worst = (0..=f.steps).map(|k| f.at(k, mode).abs()).fold(0.0, f64::max);
        eprintln!("{l}: largest {worst:.3}");
    }
    // no growth: the last ten minutes are no larger than the ten before (the mooring modes are
    // damped by radiation, the roll dampers and the lines)
    let third = f.steps / 3;
    let amp = |a: usize, b: usize| (a..b).map(|k| d.at(k, rel).abs()).fold(0.0, f64::max);
    eprintln!(
        "hook over hatch, largest sway: minutes 10-20 {:.2} m, 20-30 {:.2} m",
        amp(third, 2 * third),
        amp(2 * third, f.steps)
    );
    assert!(amp(2 * third, f.steps) < MAX_SWAY_GROWTH * amp(third, 2 * third));
}

/// The implied RAO (the floor) linearizes lines and fenders at equilibrium as the frequency-domain solver
/// does: with the radiation held at one frequency's A and B, the two are the same equations there. Before
/// the fix the floor left the connections out: `db check` on the moored pair said 155 % (carrier sway).
#[test]
fn the_floor_of_a_moored_pair_linearizes_its_lines_and_fenders_as_the_frequency_domain() {
    // round-off of two LU solves of the same 12 x 12 system
    const SAME: f64 = 1e-9;
    let sys = load_system(&repo("config/vessels/pair/moored.toml")).unwrap().system;
    let fd = FrequencySolver::new(&sys);
    for (w, heading_deg) in [(0.3, 90.0), (0.575, 90.0), (0.8, 180.0)] {
        let model = TimeModel::new(
            &sys,
            RomOptions {
                radiation: shipcast::rom::RadiationMethod::Constant { omega_rad_s: w },
                ..RomOptions::default()
            },
        )
        .unwrap();
        let h = f64::to_radians(heading_deg);
        let implied = model.implied_rao(w, h).unwrap();
        let exact = fd.rao(w, h).unwrap();
        let peak = exact.iter().map(|z| z.norm()).fold(0.0, f64::max);
        for (i, (a, b)) in implied.iter().zip(exact.iter()).enumerate() {
            assert!(
                (a - b).norm() <= SAME * peak,
                "state {i} at {w} rad/s, heading {heading_deg}: implied {a}, frequency domain {b}"
            );
        }
    }
}
