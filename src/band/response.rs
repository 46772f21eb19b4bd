//! The model's response table: |H| of every mode over frequency and relative heading, and its group
//! delay.

use super::*;
use crate::rom::Result;
use crate::rom::model::TimeModel;
use std::f64::consts::TAU;

/// Frequencies of the response table (uniform over the database's excitation range): fine enough for
/// a roll resonance with 5 % of critical damping over a 0.2..2 rad/s range.
pub(super) const TABLE_OMEGAS: usize = 240;
/// Headings of the response table (every 10 deg).
pub(super) const TABLE_HEADINGS: usize = 36;

/// |H| of every mode on a grid of frequency and relative heading, interpolated bilinearly (heading
/// wrapping around the circle) and squared: a response vanishes linearly through a heading where the
/// hull's symmetry cancels it (pitch and heave in beam seas, roll in head seas), which interpolating
/// |H|^2 would overstate between the grid's headings (by the ratio of the step to the offset: 5 times
/// at 2 deg off beam on a 10 deg grid). Zero outside the frequency range, as the forecast leaves out
/// the waves the database does not cover.
#[derive(Debug, Clone, PartialEq)]
pub struct ResponseTable {
    pub(super) omega_rad_s: Vec<f64>,
    pub(super) n_modes: usize,
    /// |H|: gain[(iw * TABLE_HEADINGS + ib) * n_modes + i], m/m or rad/m.
    pub(super) gain: Vec<f64>,
    /// The response's group delay, same layout, s (0..[`MAX_GROUP_DELAY_S`]).
    pub(super) delay_s: Vec<f64>,
}

/// The model's radiation kernel ([`TimeModel::kernels_at`]) at the response table's frequencies: made
/// once per radiation memory, it serves every model that shares it (the in-situ tuning's, which
/// `TimeModel::adjusted` makes from the model as built with its memory unchanged).
#[derive(Debug, Clone, PartialEq)]
pub struct TableKernels {
    omega_rad_s: Vec<f64>,
    kernel: Vec<nalgebra::DMatrix<num_complex::Complex64>>,
}

impl TableKernels {
    pub fn of(model: &TimeModel) -> TableKernels {
        let omega_rad_s = table_omegas(model);
        TableKernels {
            kernel: model.kernels_at(&omega_rad_s),
            omega_rad_s,
        }
    }

    /// Whether `model`'s kernel at the middle frequency is the one kept (to rounding): a model with
    /// another radiation memory is caught at the cost of one frequency's transform.
    fn probe_agrees(&self, model: &TimeModel) -> bool {
        let i = self.omega_rad_s.len() / 2;
        let (Some(w), Some(kept)) = (self.omega_rad_s.get(i), self.kernel.get(i)) else {
            return false;
        };
        let k = model.kernel_at(*w);
        let scale = kept.iter().map(|v| v.norm()).fold(0.0, f64::max);
        k.shape() == kept.shape()
            && k.iter()
                .zip(kept.iter())
                .all(|(a, b)| (a - b).norm() <= KERNEL_PROBE_REL_TOL * scale)
    }
}

/// Kernels agree to this share of their largest entry: the same memory summed in another order.
const KERNEL_PROBE_REL_TOL: f64 = 1e-9;

/// The table's frequencies: uniform over the database's excitation range.
fn table_omegas(model: &TimeModel) -> Vec<f64> {
    let ws = &model.db.exc_omega_rad_s;
    let (w0, w1) = (ws[0], ws[ws.len() - 1]);
    (0..TABLE_OMEGAS)
        .map(|i| w0 + (w1 - w0) * i as f64 / (TABLE_OMEGAS - 1) as f64)
        .collect()
}

impl ResponseTable {
    /// The table of a model's own response (`TimeModel::implied_rao`); a heading the database does not
    /// cover has no response (the forecast leaves its waves out too).
    pub fn of(model: &TimeModel) -> Result<ResponseTable> {
        Self::with_kernels(model, &TableKernels::of(model))
    }

    /// [`ResponseTable::of`] with the kernels made before, for a model with the same radiation memory
    /// (kernels of another model's frequencies or size are made afresh).
    pub fn with_kernels(model: &TimeModel, kernels: &TableKernels) -> Result<ResponseTable> {
        let omega_rad_s = table_omegas(model);
        let n = model.n();
        let fits = kernels.omega_rad_s == omega_rad_s
            && kernels.kernel.iter().all(|k| k.shape() == (n, n))
            && kernels.probe_agrees(model);
        let made;
        let kernel = if fits {
            &kernels.kernel
        } else {
            made = model.kernels_at(&omega_rad_s);
            &made
        };
        let n_modes = model.n_modes;
        let mut rao = Vec::with_capacity(TABLE_OMEGAS * TABLE_HEADINGS * n_modes);
        for (&w, k) in omega_rad_s.iter().zip(kernel) {
            for ib in 0..TABLE_HEADINGS {
                let beta = TAU * ib as f64 / TABLE_HEADINGS as f64;
                match model.implied_rao_with(k, w, beta) {
                    Ok(r) => rao.extend(r),
                    Err(crate::rom::Error::Hydro(crate::hydro::Error::OutOfRange(_))) => {
                        rao.extend(std::iter::repeat_n(num_complex::Complex64::default(), n_modes))
                    }
                    Err(e) => return Err(e),
                }
            }
        }
        let gain = rao.iter().map(|r| r.norm()).collect();
        // -d arg H / d w by the phase change between neighbouring frequencies (one-sided at the ends)
        let at = |iw: usize, ib: usize, i: usize| rao[(iw * TABLE_HEADINGS + ib) * n_modes + i];
        let dw = omega_rad_s[1] - omega_rad_s[0];
        let mut delay_s = Vec::with_capacity(rao.len());
        for iw in 0..TABLE_OMEGAS {
            let (lo, hi) = (iw.saturating_sub(1), (iw + 1).min(TABLE_OMEGAS - 1));
            for ib in 0..TABLE_HEADINGS {
                for i in 0..n_modes {
                    let turn = (at(hi, ib, i) * at(lo, ib, i).conj()).arg();
                    let d = -turn / ((hi - lo) as f64 * dw);
                    delay_s.push(if d.is_finite() {
                        d.clamp(0.0, MAX_GROUP_DELAY_S)
                    } else {
                        0.0
                    });
                }
            }
        }
        Ok(ResponseTable {
            omega_rad_s,
            n_modes,
            gain,
            delay_s,
        })
    }

    /// |H|^2 of every mode at a frequency and a relative heading into `gain2`, and the group delay
    /// into `delay_s` (n_modes values each).
    pub fn gain2_into(&self, omega_rad_s: f64, heading_rad: f64, gain2: &mut [f64], delay_s: &mut [f64]) {
        gain2.fill(0.0);
        delay_s.fill(0.0);
        let ws = &self.omega_rad_s;
        if !(omega_rad_s >= ws[0] && omega_rad_s <= ws[ws.len() - 1] && heading_rad.is_finite()) {
            return;
        }
        let dw = ws[1] - ws[0];
        let fw = ((omega_rad_s - ws[0]) / dw).min((ws.len() - 1) as f64 - 1e-12);
        let iw = fw.floor() as usize;
        let aw = fw - iw as f64;
        let fb = heading_rad.rem_euclid(TAU) / TAU * TABLE_HEADINGS as f64;
        let ib = (fb.floor() as usize).min(TABLE_HEADINGS - 1);
        let ab = fb - ib as f64;
        let ib1 = (ib + 1) % TABLE_HEADINGS;
        let n = self.n_modes;
        for (wi, wa) in [(iw, 1.0 - aw), (iw + 1, aw)] {
            for (bi, ba) in [(ib, 1.0 - ab), (ib1, ab)] {
                let c = wa * ba;
                if c == 0.0 {
                    continue;
                }
                let at = (wi * TABLE_HEADINGS + bi) * n;
                for (o, g) in gain2.iter_mut().zip(&self.gain[at..at + n]) {
                    *o += c * g;
                }
                for (o, d) in delay_s.iter_mut().zip(&self.delay_s[at..at + n]) {
                    *o += c * d;
                }
            }
        }
        for g in gain2.iter_mut() {
            *g *= *g;
        }
    }
}
