//! Radiation memory state: what the model needs of the past velocities (pure).
//!
//! Convolution: the last `taps` velocity samples at the solver step (newest last). State space: the
//! modal states after the newest sample, their input then, and that sample. Either is built sample by
//! sample with [`Memory::push`] (the daemon does this as measurements arrive, once per sample) or from a
//! whole history with [`Memory::from_history`].

use crate::rom::model::{Kernel, TimeModel};
use crate::rom::{Error, Result};

#[derive(Debug, Clone, PartialEq)]
pub enum Memory {
    Convolution {
        /// Ring buffer of velocities, `taps` x n, `head` is the slot of the next sample.
        ring: Vec<f64>,
        head: usize,
        len: usize,
    },
    StateSpace {
        /// The modes' states after the newest sample: r real parts, then r imaginary parts.
        states: Vec<f64>,
        /// The modes' input b . v of the newest sample, laid out as `states`.
        beta: Vec<f64>,
        last_v: Vec<f64>,
        started: bool,
    },
}

impl Memory {
    /// At rest: no past motion.
    pub fn new(model: &TimeModel) -> Memory {
        let n = model.n();
        match &model.kernel {
            Kernel::Convolution { taps, .. } => Memory::Convolution {
                ring: vec![0.0; taps * n],
                head: 0,
                len: 0,
            },
            Kernel::StateSpace { step, .. } => Memory::StateSpace {
                states: vec![0.0; 2 * step.r],
                beta: vec![0.0; 2 * step.r],
                last_v: vec![0.0; n],
                started: false,
            },
        }
    }

    /// Velocities sampled at the model's dt, oldest first, the last one at the forecast start.
    pub fn from_history(model: &TimeModel, velocities: &[Vec<f64>]) -> Result<Memory> {
        let mut m = Memory::new(model);
        for v in velocities {
            m.push(model, v)?;
        }
        Ok(m)
    }

    /// Appends one velocity sample (active DOFs, m/s or rad/s), one step after the previous.
    pub fn push(&mut self, model: &TimeModel, v: &[f64]) -> Result<()> {
        let n = model.n();
        if v.len() != n {
            return Err(Error::Input(format!(
                "velocity sample has {} values, the model {} active DOFs",
                v.len(),
                n
            )));
        }
        if let Some(i) = v.iter().position(|x| !x.is_finite()) {
            return Err(Error::Input(format!("velocity of {} is not finite", model.labels[i])));
        }
        match (self, &model.kernel) {
            (Memory::Convolution { ring, head, len }, Kernel::Convolution { taps, .. }) => {
                ring[*head * n..(*head + 1) * n].copy_from_slice(v);
                *head = (*head + 1) % taps;
                *len = (*len + 1).min(*taps);
            }
            (
                Memory::StateSpace {
                    states,
                    beta,
                    last_v,
                    started,
                },
                Kernel::StateSpace { step, .. },
            ) => {
                step.feed(states, beta, v, *started);
                last_v.copy_from_slice(v);
                *started = true;
            }
            _ => return Err(Error::Input("memory and model use different radiation methods".into())),
        }
        Ok(())
    }

    /// The velocity `m` samples before the newest (m = 0: the newest), zero before the first.
    pub fn velocity_ago(&self, m: usize, n: usize, out: &mut [f64]) {
        match self {
            Memory::Convolution { ring, head, len } => {
                let taps = ring.len() / n.max(1);
                if m >= *len || taps == 0 {
                    out.iter_mut().for_each(|x| *x = 0.0);
                } else {
                    let slot = (head + taps - 1 - m) % taps;
                    out.copy_from_slice(&ring[slot * n..(slot + 1) * n]);
                }
            }
            Memory::StateSpace { last_v, started, .. } => {
                if m == 0 && *started {
                    out.copy_from_slice(last_v);
                } else {
                    out.iter_mut().for_each(|x| *x = 0.0);
                }
            }
        }
    }
}
