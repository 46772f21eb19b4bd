//! The choice of `irf.passivity` made per database by what it costs (pure): where a database's damping
//! B(w) is indefinite (a BEM's irregular frequencies, a gap's resonances), both ways of building the
//! radiation memory from it (the projection onto passive damping, or the damping as it is) are built as
//! convolution models, each one's in-band floor (its implied RAO against the database's own frequency
//! domain, [`super::floor`]) measured, and the stable one with the lowest floor taken. A system file that
//! says `irf.passivity` keeps its choice.
//!
//! Conventions: the floor is the fraction of each (state, heading) curve's peak, in the database's
//! frequency range, over its headings (DESIGN.md section 1: exp(+i w t), per metre of amplitude).

use super::floor::{implied_table, worst_curve_error};
use super::{RadiationMethod, RomOptions, TimeModel};
use crate::hydro::VesselSystem;
use crate::hydro::system::Passivity;

/// A repair (the projection's largest change of an entry, relative to its scale) below this changes
/// nothing a floor could tell apart: no choice is made, the default kept (BEM round-off: 2e-5 on the
/// demos' truths).
pub const CHOICE_MIN_REPAIR: f64 = 1e-3;

/// Each choice's floor (or why it has none: an unstable model, an error) and the one taken.
#[derive(Debug, Clone, PartialEq)]
pub struct PassivityChoice {
    pub floors: Vec<(Passivity, Result<f64, String>)>,
    pub taken: Passivity,
}

/// The name a system file gives a choice.
pub fn name(p: Passivity) -> &'static str {
    match p {
        Passivity::Project => "project",
        Passivity::None => "none",
    }
}

/// The choice for `sys` when its file leaves `irf.passivity` unsaid and its damping is indefinite
/// beyond [`CHOICE_MIN_REPAIR`] somewhere (None otherwise: nothing to choose). Where neither choice gives a floor, the default
/// (project) is kept.
pub fn choose(sys: &VesselSystem) -> Option<PassivityChoice> {
    if sys.spec.irf.passivity_given
        || crate::radiation::irf::passive_damping(&sys.db.damping).1.largest < CHOICE_MIN_REPAIR
    {
        return None;
    }
    let (lo, hi) = sys.db.omega_range();
    let omegas: Vec<f64> = sys
        .db
        .omega_rad_s
        .iter()
        .copied()
        .filter(|w| (lo..=hi).contains(w))
        .collect();
    let headings = &sys.db.heading_rad;
    let reference = crate::rao::FrequencySolver::new(sys).table(&omegas, headings);
    let floors: Vec<(Passivity, Result<f64, String>)> = [Passivity::Project, Passivity::None]
        .into_iter()
        .map(|p| {
            let floor = match &reference {
                Err(e) => Err(format!("no frequency domain to judge it against: {e}")),
                Ok(fd) => floor_of(sys, p, &omegas, headings, fd),
            };
            (p, floor)
        })
        .collect();
    let taken = floors
        .iter()
        .filter_map(|(p, f)| f.as_ref().ok().map(|f| (*p, *f)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map_or(Passivity::Project, |(p, _)| p);
    Some(PassivityChoice { floors, taken })
}

/// The in-band floor of the convolution model of `sys` with passivity `p` (an error: it cannot be
/// built, or its free motion grows).
fn floor_of(
    sys: &VesselSystem,
    p: Passivity,
    omegas: &[f64],
    headings: &[f64],
    reference: &super::floor::RaoTable,
) -> Result<f64, String> {
    let mut s = sys.clone();
    s.spec.irf.passivity = p;
    let opts = RomOptions {
        dt_s: sys.spec.irf.dt_s,
        radiation: RadiationMethod::Convolution,
        ..RomOptions::default()
    };
    let model = TimeModel::new(&s, opts).map_err(|e| e.to_string())?;
    let table = implied_table(&model, omegas, headings).map_err(|e| e.to_string())?;
    Ok(worst_curve_error(&table, reference).map_or(0.0, |e| e.fraction))
}
