//! The radiation memory the time-domain models are built from (pure): K(t) with its damping tail from
//! the database's damping made passive ([`radiation_memory`]), its length ([`memory_duration_s`]), A_inf
//! as the models use it ([`model_a_inf`]), and the active DOFs' radiation the state-space model is
//! fitted to ([`state_space_memory`], [`active_radiation`]). The time-domain model
//! ([`crate::rom::TimeModel`]) and `db check`'s report ([`super::check`]) both read it from here, so the
//! report describes the model that runs.

use super::irf::{self as radiation, DampingTail, Irf};
use super::statespace;
use crate::hydro::VesselSystem;
use crate::hydro::system::{AInfSource, Passivity, TailChoice};
use nalgebra::DMatrix;

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

/// [`RadiationMemory`] on t = 0, `dt_s`, ..., `duration_s` from the database's damping as the system
/// file's `irf.passivity` has it ([`model_damping`]).
pub fn radiation_memory(sys: &VesselSystem, dt_s: f64, duration_s: f64) -> RadiationMemory {
    radiation_memory_of(sys, &model_damping(sys, &sys.db.damping), dt_s, duration_s)
}

/// The damping the time-domain models are built from: `b` made passive
/// ([`radiation::passive_damping`]), or as it is with `irf.passivity = "none"`.
pub fn model_damping(sys: &VesselSystem, b: &[DMatrix<f64>]) -> Vec<DMatrix<f64>> {
    match sys.spec.irf.passivity {
        Passivity::Project => radiation::passive_damping(b).0,
        Passivity::None => b.to_vec(),
    }
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
    /// The state-space fit of this radiation ([`statespace::fit`]) at the database's frequencies `omegas`.
    pub fn fit(
        &self,
        omegas: &[f64],
        opts: statespace::ModalOptions,
    ) -> Result<statespace::ModalModel, statespace::FitError> {
        statespace::fit(omegas, &self.damping, &self.added_mass, &self.a_inf, &self.tail, opts)
    }
}

pub fn active_radiation(sys: &VesselSystem, a_inf: &DMatrix<f64>, tail: &DampingTail) -> ActiveRadiation {
    let act = sys.active_indices();
    let sub = |m: &DMatrix<f64>| DMatrix::from_fn(act.len(), act.len(), |r, c| m[(act[r], act[c])]);
    let b: Vec<DMatrix<f64>> = sys.db.damping.iter().map(sub).collect();
    let b = model_damping(sys, &b);
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

/// The memory of the database as it is (its damping not made passive, so the checks see the BEM's
/// data), with the configured (or default) time grid and damping tail.
pub fn system_memory(sys: &VesselSystem) -> RadiationMemory {
    radiation_memory_of(sys, &sys.db.damping, sys.spec.irf.dt_s, memory_duration_s(sys))
}

/// The IRF of [`system_memory`].
pub fn system_irf(sys: &VesselSystem) -> Irf {
    system_memory(sys).irf
}
