//! Database checks behind `shipcast db check` (pure): natural periods, negative damping, the
//! Kramers-Kronig consistency of A(w), B(w) and A_inf.

use super::modal;
use super::radiation::{self, Irf, PairError};
use super::system::AInfSource;
use super::{Dof, VesselSystem};
use nalgebra::DMatrix;
use std::f64::consts::PI;

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
    /// Kramers-Kronig errors per DOF pair with the A_inf used (see [`radiation::kramers_kronig`]).
    pub kk: Vec<PairError>,
    /// The same with Ogilvie's A_inf, for comparison.
    pub kk_ogilvie: Vec<PairError>,
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

/// The active DOFs' passive damping, added mass and A_inf (the inputs of the radiation models).
pub fn active_radiation(
    sys: &VesselSystem,
    a_inf: &DMatrix<f64>,
) -> (Vec<DMatrix<f64>>, Vec<DMatrix<f64>>, DMatrix<f64>) {
    let act = sys.active_indices();
    let sub = |m: &DMatrix<f64>| DMatrix::from_fn(act.len(), act.len(), |r, c| m[(act[r], act[c])]);
    let b: Vec<DMatrix<f64>> = sys.db.damping.iter().map(sub).collect();
    let (b, _) = radiation::passive_damping(&b);
    (b, sys.db.added_mass.iter().map(sub).collect(), sub(a_inf))
}

/// The state-space fit of the active DOFs' radiation as the time-domain model makes it (see
/// [`modal::fit`]), and its (damping, added mass) errors, the added mass against the given A_inf.
pub fn state_space(sys: &VesselSystem, a_inf: &DMatrix<f64>) -> Result<(modal::ModalModel, f64, f64), modal::FitError> {
    let (b, a, ai) = active_radiation(sys, a_inf);
    let model = modal::fit(&sys.db.omega_rad_s, &b, &a, &ai, modal::ModalOptions::default())?;
    let (eb, ea) = modal::fit_errors(&model, &sys.db.omega_rad_s, &b, &a, &ai);
    Ok((model, eb, ea))
}

/// The IRF of a system with its configured (or default) time grid.
pub fn system_irf(sys: &VesselSystem) -> Irf {
    let dur = sys
        .spec
        .irf
        .duration_s
        .unwrap_or_else(|| radiation::default_duration_s(&sys.db));
    radiation::impulse_response(&sys.db, sys.spec.irf.dt_s, dur)
}

pub fn check(sys: &VesselSystem) -> CheckReport {
    let db = &sys.db;
    let n = sys.n_modes();
    let mass = sys.mass_matrix();
    let c = sys.stiffness();
    let mut natural = vec![];
    for i in sys.active_indices() {
        if c[(i, i)] <= 0.0 {
            continue;
        }
        // lowest root of f(w) = C_ii - w^2 (M_ii + A_ii(w)) over the database frequencies (A can swing
        // through gap resonances, so no fixed-point iteration); outside the range use A(w_min) / A_inf
        let f = |w: f64, a: f64| c[(i, i)] - w * w * (mass[(i, i)] + a);
        let ws = &db.omega_rad_s;
        let fs: Vec<f64> = ws.iter().zip(&db.added_mass).map(|(w, a)| f(*w, a[(i, i)])).collect();
        let w = if fs[0] <= 0.0 {
            (c[(i, i)] / (mass[(i, i)] + db.added_mass_zero.as_ref().unwrap_or(&db.added_mass[0])[(i, i)])).sqrt()
        } else if let Some(k) = fs.windows(2).position(|p| p[0] > 0.0 && p[1] <= 0.0) {
            ws[k] + (ws[k + 1] - ws[k]) * fs[k] / (fs[k] - fs[k + 1])
        } else {
            let a = db.added_mass_inf.as_ref().unwrap_or(&db.added_mass[ws.len() - 1])[(i, i)];
            (c[(i, i)] / (mass[(i, i)] + a)).sqrt()
        };
        if w.is_finite() && w > 0.0 {
            natural.push((i, 2.0 * PI / w));
        }
    }
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
    let irf = system_irf(sys);
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
        kk,
        kk_ogilvie,
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
