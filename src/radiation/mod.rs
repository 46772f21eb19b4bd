//! Radiation (pure): how the water's memory of a hull's past motion enters the equations of motion.
//! The impulse response K(t) = (2/pi) int B(w) cos(w t) dw from the database's damping made passive,
//! with its tail and A_inf ([`irf`], DESIGN.md section 1, paper eqs. 5-6); the radiation memory the
//! time-domain models are built from and its length ([`memory`]); the modal (state-space) fit of it
//! ([`statespace`]) and its exact discrete step ([`modal`]); the convolution's taps in the frequency
//! domain for a run's own velocities ([`partitioned`]); the measured history a forecast starts from
//! ([`history`]); and `db check`'s Kramers-Kronig and floor checks ([`check`]).
//!
//! Conventions: SI units, exp(+i w t), DOF order surge..yaw per vessel (DESIGN.md section 1).

pub mod check;
pub mod history;
pub mod irf;
pub mod memory;
pub mod modal;
pub mod partitioned;
pub mod statespace;
