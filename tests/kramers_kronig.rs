//! Kramers-Kronig consistency: A(w) rebuilt from the impulse response K(t) (shipcast's IRF of the
//! database's B(w)) against the BEM's own A(w), on the demo databases (Capytaine) and WEC-Sim's RM3
//! (WAMIT). Errors are max over w <= 0.8 w_max of |A_K - A| / sqrt(max|A_ii| max|A_jj|).

use shipcast::hydro::system::TailChoice;
use shipcast::hydro::{Dof, VesselSystem};
use shipcast::radiation::check::choose_a_inf;
use shipcast::radiation::irf::{kramers_kronig, ogilvie_a_inf, ogilvie_estimates};
use shipcast::radiation::memory::system_irf;
use shipcast::shell::files::load_system;

use crate::util::repo;

/// With Ogilvie's A_inf, every pair of every database: measured worst 1.14 % (RM3, float surge);
/// the rest is the modelled damping tail beyond the database's last frequency.
const KK_TOL_OGILVIE: f64 = 0.015;
/// Heave, roll and pitch pairs with the BEM's own A_inf: measured worst 2.7 % (RM3 spar roll and pitch;
/// its heave 0.52 %), 0.94 % on the demos (lighter heave); these modes carry restoring.
const KK_TOL_VERTICAL_DB_A_INF: f64 = 0.03;
/// Every pair with the BEM's own A_inf on WEC-Sim's RM3: measured worst 5.6 % (float roll-sway, where
/// WAMIT's A_inf is offset from its own A(w) by a constant: Ogilvie's estimate removes it).
const KK_TOL_ANY_DB_A_INF: f64 = 0.06;
/// Every pair with the BEM's own A_inf on the demos (symmetrized, with the fitted damping tail):
/// measured worst 1.15 % (pair: lighter heave - carrier sway at the 0.965 rad/s gap resonance), 0.44 %
/// (ship). With the cubic tail the pair was 3.3 % (the lighter's yaw, still radiating at 1.6 rad/s).
const KK_TOL_DEMO_DB_A_INF: f64 = 0.015;
/// The pair's lighter yaw with the cubic tail: measured 3.3 %; with the fitted tail 0.19 %.
const KK_LIGHTER_YAW_FITTED: f64 = 0.005;

fn load(rel: &str) -> VesselSystem {
    load_system(&repo(rel)).unwrap().system
}

fn vertical(i: usize) -> bool {
    matches!(Dof::of_index(i), Dof::Heave | Dof::Roll | Dof::Pitch)
}

fn check(rel: &str, tol_any_db: f64) {
    let sys = load(rel);
    let irf = system_irf(&sys);
    let (a_inf, _) = choose_a_inf(&sys, &irf);
    let og = ogilvie_a_inf(&ogilvie_estimates(&sys.db, &irf));
    let with_db = kramers_kronig(&sys.db, &irf, &a_inf);
    let with_og = kramers_kronig(&sys.db, &irf, &og);
    assert!(!with_db.is_empty());
    let worst = |v: &[shipcast::radiation::irf::PairError], f: &dyn Fn(usize, usize) -> bool| {
        v.iter()
            .filter(|e| f(e.i, e.j))
            .map(|e| e.added_mass_band)
            .fold(0.0, f64::max)
    };
    let vert = worst(&with_db, &|i, j| vertical(i) && vertical(j));
    let any = worst(&with_db, &|_, _| true);
    let ogw = worst(&with_og, &|_, _| true);
    eprintln!("{rel}: KK worst in band: vertical {vert:.4}, any {any:.4} (database A_inf), any {ogw:.4} (Ogilvie)");
    assert!(vert <= KK_TOL_VERTICAL_DB_A_INF, "{rel}: vertical {vert}");
    assert!(any <= tol_any_db, "{rel}: any {any}");
    assert!(ogw <= KK_TOL_OGILVIE, "{rel}: Ogilvie {ogw}");
}

#[test]
fn capytaine_one_ship_is_kramers_kronig_consistent() {
    check("config/vessels/ship/system.toml", KK_TOL_DEMO_DB_A_INF);
}

#[test]
fn capytaine_two_ships_are_kramers_kronig_consistent() {
    check("config/vessels/pair/system.toml", KK_TOL_DEMO_DB_A_INF);
}

#[test]
fn wamit_rm3_is_kramers_kronig_consistent() {
    check("tests/data/wecsim-rm3/system.toml", KK_TOL_ANY_DB_A_INF);
}

/// The pair database ends at 1.6 rad/s where the 120 m lighter still radiates in yaw: the cubic tail
/// leaves its added mass 3.3 % off across the band; the tail fitted to the database's A(w) and A_inf
/// restores it (and the test can fail: with the cubic tail it does).
#[test]
fn the_fitted_tail_makes_the_pair_consistent() {
    let mut sys = load("config/vessels/pair/system.toml");
    let yaw = |sys: &VesselSystem| {
        let irf = system_irf(sys);
        let (a_inf, _) = choose_a_inf(sys, &irf);
        let e = kramers_kronig(&sys.db, &irf, &a_inf);
        e.iter().find(|e| e.i == 11 && e.j == 11).unwrap().added_mass_band
    };
    let fitted = yaw(&sys);
    sys.spec.irf.tail = TailChoice::Cubic;
    let cubic = yaw(&sys);
    eprintln!("pair lighter yaw KK in band: cubic tail {cubic:.4}, fitted {fitted:.4}");
    assert!(fitted <= KK_LIGHTER_YAW_FITTED, "fitted {fitted}");
    assert!(cubic > KK_LIGHTER_YAW_FITTED, "cubic {cubic}");
}

#[test]
fn a_wrong_a_inf_is_caught() {
    // the check can fail: shift A_inf by 5 % of the heave scale and the heave pair must exceed tolerance
    let sys = load("tests/data/wecsim-rm3/system.toml");
    let irf = system_irf(&sys);
    let mut a = ogilvie_a_inf(&ogilvie_estimates(&sys.db, &irf));
    let scale = sys.db.added_mass.iter().map(|m| m[(2, 2)].abs()).fold(0.0, f64::max);
    a[(2, 2)] += 0.05 * scale;
    let e = kramers_kronig(&sys.db, &irf, &a);
    let heave = e.iter().find(|e| e.i == 2 && e.j == 2).unwrap();
    assert!(heave.added_mass_band > KK_TOL_OGILVIE, "{heave:?}");
}
