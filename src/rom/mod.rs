//! The reduced-order model: the generalized Cummins equations of N vessels in the time domain (pure).
//!
//! Equation of motion (DESIGN.md section 1, seed paper eq. 2), over the active DOFs:
//!   (M + A_inf) x'' + (B_lin + B_U U) x' + B_Q |x'| x' + (C + C_UQ U^2) x + int_0^T K(tau) x'(t - tau) dtau
//!       = F_wave(t)
//! Conventions: SI units; DOF order surge..yaw per vessel (vessel k owns 6k..6k+5); inactive DOFs are
//! held at zero; K(t) from the database's damping made passive ([`crate::radiation::irf`]); A_inf by
//! Ogilvie's relation from that same K (consistent with it), or the database's when the system file says
//! `a_inf = "database"`. Zero-speed database: K and X are those at U = 0, the
//! forcing runs at the encounter frequency.
//!
//! Time integration ([`stepper`]): Newmark's method with gamma = 1/2 and a chosen beta (1/4: average
//! acceleration, unconditionally stable, second order; 1/12: Fox-Goodwin, fourth order in the period for
//! the undamped part, stable for w dt < 2.45), fixed step dt. The radiation force at the new step is
//! split into what is known (history) and an instantaneous part D v_{k+1} folded into the implicit
//! matrix, so one radiation evaluation per step suffices and nothing is frozen. Nonlinear forces
//! (quadratic damping, mooring lines, fenders) are iterated to convergence within each step
//! (fixed point on the new acceleration; see [`stepper::NL_TOLERANCE`]).
//!
//! External models ([`crate::hydro::external`]): linear connections and per-body external stiffness
//! and damping are in C and B_lin; each anti-roll tank adds a state after the active body DOFs;
//! lines and fenders are nonlinear forces relative to their equilibrium value.
//!
//! Radiation memory two ways ([`crate::radiation::memory`]): direct convolution (trapezoid rule on K sampled at dt, the
//! reference; a run's own velocities meet the taps beyond one block by partitioned FFTs,
//! [`crate::radiation::partitioned`]) or the modal state-space model ([`crate::radiation::statespace`]: vector fit, balanced
//! truncation, passivity enforced) with its exact discrete update ([`crate::radiation::modal`]). The wave force, a sum of sinusoids
//! over the horizon, is evaluated by a non-uniform FFT when the field has many components
//! ([`sinusoids`]).

pub mod adjust;
mod build;
pub mod dense;
pub mod drift;
pub mod floor;
pub mod forecast;
mod known;
pub mod model;
pub mod outputs;
pub mod passivity;
pub mod regular;
pub mod sinusoids;
pub mod step;
pub mod stepper;

pub use forecast::{Forecast, ForecastRequest, Forecaster, Track};
pub use model::{OptionError, RadiationMethod, RomOptions, TimeModel};

/// Errors of the time-domain model.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// The state went non-finite or beyond the bound: which DOF, when.
    #[error("the motion of {dof} became {what} at t = {time_s:.3} s after the start: forecast abandoned")]
    Diverged {
        dof: String,
        time_s: f64,
        what: &'static str,
    },
    /// An input does not fit the model (sizes, non-finite values, options).
    #[error("{0}")]
    Input(String),
    #[error(transparent)]
    Hydro(#[from] crate::hydro::Error),
    #[error(transparent)]
    Option(#[from] model::OptionError),
}

pub type Result<T> = std::result::Result<T, Error>;
