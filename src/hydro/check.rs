//! Database checks behind `shipcast db check` (pure): natural periods, negative damping, the
//! Kramers-Kronig consistency of A(w), B(w) and A_inf.

use super::modal;
use super::radiation::{self, DampingTail, Irf, PairError};
use super::system::{AInfSource, TailChoice};
use super::{Dof, VesselSystem};
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

/// The radiation memory the time-domain models use: K(t) on t = 0, dt, ..., duration from the
/// database's damping made passive and the damping tail the system file asks for (fitted to the BEM's
/// A_inf unless `irf.tail = "cubic"` or the database has none).
#[derive(Debug, Clone)]
pub struct RadiationMemory {
    pub irf: Irf,
    pub tail: DampingTail,
    /// The fit's worst added-mass residual in band (cubic tail, fitted tail), when fitted.
    pub fit_residuals: Option<(f64, f64)>,
}

pub fn radiation_memory(sys: &VesselSystem, dt_s: f64, duration_s: f64) -> RadiationMemory {
    let (b, _) = radiation::passive_damping(&sys.db.damping);
    radiation_memory_of(sys, &b, dt_s, duration_s)
}

/// The same from the given damping samples (at the database's frequencies).
pub fn radiation_memory_of(sys: &VesselSystem, b: &[DMatrix<f64>], dt_s: f64, duration_s: f64) -> RadiationMemory {
    let db = &sys.db;
    match (sys.spec.irf.tail, &db.added_mass_inf) {
        (TailChoice::Fitted, Some(a_inf)) => {
            let fit = radiation::fit_tail(&db.omega_rad_s, b, &db.added_mass, a_inf, dt_s, duration_s);
            RadiationMemory {
                irf: fit.irf,
                tail: fit.tail,
                fit_residuals: Some((fit.residual_cubic, fit.residual_fitted)),
            }
        }
        _ => {
            let tail = DampingTail::cubic(&db.omega_rad_s, b);
            RadiationMemory {
                irf: radiation::impulse_response_of(&db.omega_rad_s, b, &tail, dt_s, duration_s),
                tail,
                fit_residuals: None,
            }
        }
    }
}

/// The active DOFs' passive damping, added mass, A_inf and damping tail (the inputs of the radiation
/// models).
pub struct ActiveRadiation {
    pub damping: Vec<DMatrix<f64>>,
    pub added_mass: Vec<DMatrix<f64>>,
    pub a_inf: DMatrix<f64>,
    pub tail: DampingTail,
}

impl ActiveRadiation {
    /// The state-space fit of this radiation ([`modal::fit`]) at the database's frequencies `omegas`.
    pub fn fit(&self, omegas: &[f64], opts: modal::ModalOptions) -> Result<modal::ModalModel, modal::FitError> {
        modal::fit(omegas, &self.damping, &self.added_mass, &self.a_inf, &self.tail, opts)
    }
}

pub fn active_radiation(sys: &VesselSystem, a_inf: &DMatrix<f64>, tail: &DampingTail) -> ActiveRadiation {
    let act = sys.active_indices();
    let sub = |m: &DMatrix<f64>| DMatrix::from_fn(act.len(), act.len(), |r, c| m[(act[r], act[c])]);
    let b: Vec<DMatrix<f64>> = sys.db.damping.iter().map(sub).collect();
    let (b, _) = radiation::passive_damping(&b);
    ActiveRadiation {
        damping: b,
        added_mass: sys.db.added_mass.iter().map(sub).collect(),
        a_inf: sub(a_inf),
        tail: tail.sub(&act),
    }
}

/// A_inf as the time-domain models use it: the database's when the system file asks for it, else
/// Ogilvie's estimate from `irf` (consistent with the damping as the model sees it).
pub fn model_a_inf(sys: &VesselSystem, irf: &Irf) -> DMatrix<f64> {
    match (sys.spec.a_inf, &sys.db.added_mass_inf) {
        (Some(AInfSource::Database), Some(a)) => a.clone(),
        _ => radiation::ogilvie_a_inf(&radiation::ogilvie_estimates(&sys.db, irf)),
    }
}

/// The memory the state-space model is fitted from (the time-domain model and `db check` both call
/// this): the passive damping on the system file's IRF grid, never the solver's step.
pub fn state_space_memory(sys: &VesselSystem, duration_s: f64) -> RadiationMemory {
    radiation_memory(sys, sys.spec.irf.dt_s, duration_s)
}

/// The memory length the system file asks for (`irf.duration_s`), or the database's default
/// ([`radiation::default_duration_s`]).
pub fn memory_duration_s(sys: &VesselSystem) -> f64 {
    sys.spec
        .irf
        .duration_s
        .unwrap_or_else(|| radiation::default_duration_s(&sys.db))
}

/// The (damping, added mass) errors of a state-space model of the active DOFs' radiation (see
/// [`modal::fit_errors`]), the added mass against the given A_inf.
pub fn state_space_errors(
    sys: &VesselSystem,
    model: &modal::ModalModel,
    a_inf: &DMatrix<f64>,
    tail: &DampingTail,
) -> (f64, f64) {
    let r = active_radiation(sys, a_inf, tail);
    modal::fit_errors(model, &sys.db.omega_rad_s, &r.damping, &r.added_mass, &r.a_inf)
}

/// The memory of the database as it is (its damping not made passive, so the checks see the BEM's
/// data), with the configured (or default) time grid and damping tail.
pub fn system_memory(sys: &VesselSystem) -> RadiationMemory {
    radiation_memory_of(sys, &sys.db.damping, sys.spec.irf.dt_s, memory_duration_s(sys))
}

/// The IRF of [`system_memory`].
pub fn system_irf(sys: &VesselSystem) -> Irf {
    system_memory(sys).irf
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

/// `carrier.heave` style label of a 0-based global mode index.
pub fn mode_label(sys: &VesselSystem, i: usize) -> String {
    if i >= sys.n_modes() {
        let k = i - sys.n_modes();
        let name = sys.spec.external.tank_names.get(k).map(|s| s.as_str()).unwrap_or("?");
        return format!("{name}.tank_angle");
    }
    let body = sys.spec.bodies.get(i / 6).map(|b| b.name.as_str()).unwrap_or("?");
    format!("{body}.{}", Dof::of_index(i).name())
}

/// The output column of state `i` with its unit (`carrier.heave_m`, `carrier.roll_deg`,
/// `<tank>.tank_angle_deg`), as CSV and JSON outputs write it; [`output_value`] converts the value.
pub fn output_label(sys: &VesselSystem, i: usize) -> String {
    if i >= sys.n_modes() {
        return format!("{}_deg", mode_label(sys, i));
    }
    let body = sys.spec.bodies.get(i / 6).map(|b| b.name.as_str()).unwrap_or("?");
    format!("{body}.{}", Dof::of_index(i).output_name())
}

/// State `i`'s value (m or rad) in the unit of its [`output_label`] (m or deg; a tank angle in deg).
pub fn output_value(sys: &VesselSystem, i: usize, si: f64) -> f64 {
    if i >= sys.n_modes() {
        si.to_degrees()
    } else {
        Dof::of_index(i).to_output(si)
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
