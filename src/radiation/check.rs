//! Database checks behind `shipcast db check` (pure): natural periods, negative damping, the
//! Kramers-Kronig consistency of A(w), B(w) and A_inf, the asymmetry and passivity of the database, and
//! the state-space fit's errors. The radiation memory they check is built in [`super::memory`], as the
//! time-domain models build it.

use super::irf::{self as radiation, DampingTail, Irf, PairError};
use super::memory::{RadiationMemory, active_radiation, system_memory};
use super::statespace;
use crate::hydro::VesselSystem;
use crate::hydro::system::AInfSource;
use nalgebra::DMatrix;

/// What `db check` reports.
#[derive(Debug, Clone)]
pub struct CheckReport {
    /// (global mode index, natural period s) for active DOFs with positive restoring.
    pub natural_periods_s: Vec<(usize, f64)>,
    /// (global mode index, frequencies rad/s) where B_ii(w) < 0.
    pub negative_damping: Vec<(usize, Vec<f64>)>,
    /// A_inf as used by the time-domain model, and where it came from.
    pub a_inf: DMatrix<f64>,
    pub a_inf_source: AInfSource,
    pub irf: Irf,
    pub tail: DampingTail,
    /// The tail fit's worst added-mass residual in band (cubic, fitted), when fitted.
    pub tail_fit_residuals: Option<(f64, f64)>,
    /// Kramers-Kronig errors per DOF pair with the A_inf used (see [`radiation::kramers_kronig`]).
    pub kk: Vec<PairError>,
    /// The same with Ogilvie's A_inf, for comparison.
    pub kk_ogilvie: Vec<PairError>,
    /// Largest asymmetry of A(w) and of B(w): max |X_ij - X_ji| / sqrt(max|X_ii| max|X_jj|) (reciprocity
    /// makes both symmetric; a panel method's are not, by its discretization error).
    pub asymmetry_added_mass: f64,
    pub asymmetry_damping: f64,
    /// What making the database's damping passive changed (the time-domain models use the passive
    /// damping; radiated power is never negative, a BEM's B(w) can be slightly indefinite).
    pub passivity_repair: radiation::PassivityRepair,
}

/// max over w and i, j of |X_ij - X_ji| / sqrt(max_w |X_ii| max_w |X_jj|), over the DOFs that radiate
/// ([`radiation::radiating_dofs`]: a spar's yaw has a numerical-noise peak that would divide by nothing).
pub fn asymmetry(ms: &[DMatrix<f64>]) -> f64 {
    let peaks = radiation::diagonal_peaks(ms);
    let radiating = radiation::radiating_dofs(&peaks);
    let live = |i: usize| radiating[i];
    let mut worst = 0.0f64;
    for m in ms {
        for i in (0..m.nrows()).filter(|&i| live(i)) {
            for j in (0..i).filter(|&j| live(j)) {
                worst = worst.max((m[(i, j)] - m[(j, i)]).abs() / (peaks[i] * peaks[j]).sqrt());
            }
        }
    }
    worst
}

/// Chooses A_inf as the system file asks: the database's when present (unless told otherwise), else
/// Ogilvie's estimate.
pub fn choose_a_inf(sys: &VesselSystem, irf: &Irf) -> (DMatrix<f64>, AInfSource) {
    let want = sys.spec.a_inf.unwrap_or(if sys.db.added_mass_inf.is_some() {
        AInfSource::Database
    } else {
        AInfSource::Ogilvie
    });
    match (want, &sys.db.added_mass_inf) {
        (AInfSource::Database, Some(a)) => (a.clone(), AInfSource::Database),
        _ => (
            radiation::ogilvie_a_inf(&radiation::ogilvie_estimates(&sys.db, irf)),
            AInfSource::Ogilvie,
        ),
    }
}

/// The (damping, added mass) errors of a state-space model of the active DOFs' radiation (see
/// [`statespace::fit_errors`]), the added mass against the given A_inf.
pub fn state_space_errors(
    sys: &VesselSystem,
    model: &statespace::ModalModel,
    a_inf: &DMatrix<f64>,
    tail: &DampingTail,
) -> (f64, f64) {
    let r = active_radiation(sys, a_inf, tail);
    statespace::fit_errors(model, &sys.db.omega_rad_s, &r.damping, &r.added_mass, &r.a_inf)
}

pub fn check(sys: &VesselSystem) -> CheckReport {
    let db = &sys.db;
    let n = sys.n_modes();
    let natural = sys.natural_periods_s();
    let mut negative_damping = vec![];
    for i in 0..n {
        let ws: Vec<f64> = db
            .omega_rad_s
            .iter()
            .zip(&db.damping)
            .filter(|(_, b)| b[(i, i)] < 0.0)
            .map(|(w, _)| *w)
            .collect();
        if !ws.is_empty() {
            negative_damping.push((i, ws));
        }
    }
    let RadiationMemory {
        irf,
        tail,
        fit_residuals,
    } = system_memory(sys);
    let (a_inf, a_inf_source) = choose_a_inf(sys, &irf);
    let kk = radiation::kramers_kronig(db, &irf, &a_inf);
    let kk_ogilvie = match a_inf_source {
        AInfSource::Ogilvie => kk.clone(),
        AInfSource::Database => {
            let og = radiation::ogilvie_a_inf(&radiation::ogilvie_estimates(db, &irf));
            radiation::kramers_kronig(db, &irf, &og)
        }
    };
    CheckReport {
        natural_periods_s: natural,
        negative_damping,
        a_inf,
        a_inf_source,
        irf,
        tail,
        tail_fit_residuals: fit_residuals,
        kk,
        kk_ogilvie,
        asymmetry_added_mass: asymmetry(&db.added_mass),
        asymmetry_damping: asymmetry(&db.damping),
        passivity_repair: radiation::passive_damping(&db.damping).1,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn asymmetry_is_scaled_and_ignores_silent_dofs() {
        // DOF 0 and 1 radiate, DOF 2 is numerical noise: its coupling must not count
        let m = DMatrix::from_row_slice(3, 3, &[4.0, 0.3, 1e-9, 0.1, 1.0, 0.0, 0.0, 0.0, 1e-12]);
        let a = asymmetry(std::slice::from_ref(&m));
        // |0.3 - 0.1| / sqrt(4 * 1)
        assert!((a - 0.1).abs() < 1e-12, "{a}");
        assert_eq!(asymmetry(&[(&m + m.transpose()) * 0.5]), 0.0);
    }
}
