//! The forecast's band and trusted span (pure): how wide a forecast's band is and over which leads
//! it is trusted, the model error learnt from past forecasts, the start's error (the sensor's bias
//! or a heel), and the normal distribution's tails. Files: `response` (the model's response table),
//! `span` (the band and the span of one forecast), `model_error` (learning from checks),
//! `start` (the start's error and heel), `coupling` (what a coupled vessel's unknown start adds),
//! `normal`.
//!
//! A forecast knows a wave component only over the leads at which the water that brings it to the
//! vessel had been observed (`waves::horizon::known_leads`: for a radar, while that water was inside
//! the observed region at the observation time; for a probe, while it passed the probe within the
//! fitted window). Outside that span the component the forecast carries is a guess whose phase is
//! unrelated to the sea's, so the error it leaves has the variance of the forecast's and the sea's parts
//! together: twice its own, [`UNKNOWN_ERROR_FACTOR`]. Each component's response variance is
//! 0.5 |a|^2 |H(w_e, beta)|^2, H the model's own motion RAO (`TimeModel::implied_rao`: its radiation
//! memory, damping, restoring, connections linearized) at the encounter frequency w_e = |w - k U cos beta|
//! and the heading relative to the vessel. A component that becomes known only at a lead s > 0 (a
//! probe far up-wave) leaves the response wrong for longer: the guess the forecast carried before s
//! rings on in the motion for about the response's group delay tau = -d arg H / d w (at a resonance
//! 1 / (zeta w_n), the decay time of its amplitude), so its error variance falls from its whole to
//! nothing over s..s + tau, linearly (the area of exp(-2 (t - s) / tau)). The end of its span is not
//! moved: the error of the waves after it grows from there. A component unknown from the start (the
//! waves inside a radar's blind zone, or from where nothing was observed) errs by nothing at lead 0,
//! where the measured state holds the response to every wave before it: its error builds up as the
//! response to a force switched on then, linearly over [`ONSET_DELAY_TIMES`] tau. The standard deviation of each series
//! at lead t is then
//!
//!   sigma^2(t) = k^2(t) (2 sum_c u_c(t) v_c + e^2 sum_c v_c),  u_c(t) = 1 unknown, 0 known, the ramps between
//!
//! with e the model error as a fraction of the motion's own standard deviation (config
//! `forecast.model_error` until [`ModelError`] has learnt it from the daemon's past forecasts), and
//! k the band's scale, learnt from the same checks so that [`BAND_QUANTILE`] of them fall inside the
//! 90 % band (errors are not normal; 1 until learnt), never narrower than the sensor's noise. The ratio sigma(t) / (k(t) sqrt(sum_c v_c)) is the
//! normalized RMS error the forecast expects at t (the scale is the band's, for its coverage: for
//! the narrow-band errors of a resonant roll it is about 0.85); a vessel's forecast is trusted over the longest run
//! of leads (the earliest of equal ones) at which that ratio is at most `forecast.trusted_nrmse` for
//! each of heave, roll and pitch that moves enough to matter ([`SIGNIFICANT`]), with the learnt e^2
//! taken [`SPAN_CONFIDENCE_Z`] of its standard errors up (a span opens where the error is known to be
//! small), and none past the leads at which it has been learnt (a prior no forecast has been checked
//! against opens no span): the initial state can make the first seconds trusted and a radar's blind
//! zone the next ones not.
//!
//! Conventions (DESIGN.md section 1): DOF order surge, sway, heave, roll, pitch, yaw per vessel, m and
//! rad; headings of waves relative to the vessel's +x, travel-to, counterclockwise; series-major output
//! as on the wire (6 series per vessel, steps + 1 values each).

mod coupling;
mod model_error;
mod normal;
mod response;
mod span;
mod start;
#[cfg(test)]
mod tests;

pub use coupling::*;
pub use model_error::*;
pub use normal::*;
pub use response::*;
pub use span::*;
pub use start::*;
