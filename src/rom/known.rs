//! The radiation force a forecast's start already owes: the convolution of the kernel with the
//! velocities up to t0 (the history and v0) at every lead of the run, by FFT (pure). It depends on
//! the start and the memory only, not on the waves, so a forecast computes it beside the wave force
//! ([`super::forecast`]).
//!
//! Units: velocities m/s or rad/s, the kernel's taps already weighted by the step (N or N m per unit
//! velocity), forces N or N m; DOF order as the model's active states (DESIGN.md section 1).

use super::Result;
use super::model::{Kernel, TimeModel};
use crate::radiation::history::Memory;
use num_complex::Complex64;
use rustfft::{Fft, FftPlanner};
use std::sync::Arc;

/// The known part of a run's radiation force, and the workspace it is computed in.
#[derive(Default)]
pub(super) struct KnownPart {
    /// `values[k * n + i]`: state i's force at step k (k = 0..=steps); empty for a model without a
    /// convolution.
    pub values: Vec<f64>,
    tmp: Vec<f64>,
    /// The kernel's spectra for the convolution with a history, built on first use at the lengths
    /// the last runs asked for (runs of other lengths keep their own), newest last; the forecast's own
    /// velocities are the stepper's ([`crate::radiation::partitioned`]).
    fft: Vec<HistoryFft>,
}

impl KnownPart {
    /// Whether a run from `v0` with `memory` has a known part to compute (a convolution with a
    /// history or a moving start).
    pub fn needed(model: &TimeModel, v0: &[f64], memory: &Memory) -> bool {
        matches!(
            (&model.kernel, memory),
            (Kernel::Convolution { .. }, Memory::Convolution { len, .. }) if *len > 0 || v0.iter().any(|v| *v != 0.0)
        )
    }

    /// The known part of a run of `steps` steps from `v0` with `memory` into [`Self::values`] (zeros
    /// where there is none).
    pub fn compute(&mut self, model: &TimeModel, v0: &[f64], memory: &Memory, steps: usize) -> Result<()> {
        let n = model.n();
        self.values.clear();
        if matches!(model.kernel, Kernel::Convolution { .. }) {
            self.values.resize((steps + 1) * n, 0.0);
        }
        if Self::needed(model, v0, memory) {
            let _span = tracing::trace_span!("history_part").entered();
            self.history_part(model, v0, memory, steps)?;
        }
        Ok(())
    }

    /// The radiation force from the velocities up to t0 (history and v0) at every step, by FFT:
    /// P[k] = sum_{m >= k} K~_m v_{k-m}.
    fn history_part(&mut self, model: &TimeModel, v0: &[f64], memory: &Memory, steps: usize) -> Result<()> {
        let Kernel::Convolution { taps, k, .. } = &model.kernel else {
            return Ok(());
        };
        let (taps, n) = (*taps, model.n());
        // the convolution's outputs at leads 1..=steps (within the kernel) are clear of the circular
        // wrap from a length of taps + steps on: a forecast shorter than the kernel needs no more
        let len = fft_len(taps + steps.min(taps.saturating_sub(1)));
        let f = match self.fft.iter().position(|f| f.len == len && f.n == n) {
            Some(i) => i,
            None => {
                if self.fft.len() == HISTORY_FFTS_KEPT {
                    self.fft.remove(0);
                }
                self.fft.push(HistoryFft::new(k, taps, n, len));
                self.fft.len() - 1
            }
        };
        let f = &mut self.fft[f];
        let mut tmp = std::mem::take(&mut self.tmp);
        tmp.resize(n, 0.0);
        f.known(taps, steps, &mut self.values, &mut tmp, |m, out| {
            if m == 0 {
                out.copy_from_slice(v0);
            } else {
                memory.velocity_ago(m - 1, n, out);
            }
        });
        self.tmp = tmp;
        Ok(())
    }
}

/// How many lengths of the kernel's spectra a forecaster keeps.
const HISTORY_FFTS_KEPT: usize = 3;

/// The smallest length of the form 2^a 3^b that is at least `min`: rustfft's mixed radices are about as
/// fast there per point as at a power of two, which it never exceeds (10 368 for the demo's forecast,
/// 10 286 at least, against 16 384).
fn fft_len(min: usize) -> usize {
    let mut best = min.next_power_of_two();
    let mut p3 = 1usize;
    while p3 < best {
        let mut m = p3;
        while m < min {
            m *= 2;
        }
        best = best.min(m);
        p3 *= 3;
    }
    best
}

struct HistoryFft {
    len: usize,
    /// Active states.
    n: usize,
    forward: Arc<dyn Fft<f64>>,
    inverse: Arc<dyn Fft<f64>>,
    /// The spectra of output pairs p (rows 2p and 2p + 1 of the kernel as one complex sequence,
    /// k_2p,j + i k_2p+1,j: the convolution's outputs are real, so one inverse FFT gives both as its real
    /// and imaginary parts), C-hat[(p * n + j) * len + f]. Half the products and memory of one spectrum
    /// per kernel entry.
    kernel: Vec<Complex64>,
    u: Vec<Complex64>,
    acc: Vec<Complex64>,
    scratch: Vec<Complex64>,
}

impl HistoryFft {
    /// Forward FFT of every input sequence in `u`.
    fn transform_inputs(&mut self, n: usize) {
        let len = self.len;
        for j in 0..n {
            self.forward
                .process_with_scratch(&mut self.u[j * len..(j + 1) * len], &mut self.scratch);
        }
    }

    /// `acc` = len x (the linear convolutions of the inputs with rows 2p (real part) and 2p + 1
    /// (imaginary part) of the kernel), by the spectra.
    fn output(&mut self, p: usize, n: usize) {
        let len = self.len;
        self.acc.iter_mut().for_each(|c| *c = Complex64::default());
        for j in 0..n {
            let kh = &self.kernel[(p * n + j) * len..(p * n + j + 1) * len];
            let uh = &self.u[j * len..(j + 1) * len];
            for ((a, kk), uu) in self.acc.iter_mut().zip(kh).zip(uh) {
                *a += kk * uu;
            }
        }
        self.inverse.process_with_scratch(&mut self.acc, &mut self.scratch);
    }

    /// `known[kk * n + i]` for kk in 1..=steps (within the kernel): the force at lead kk from the
    /// velocities up to t0, sum_{m >= kk} K~_m v_{kk-m}; `velocity(m, out)` writes the velocity m steps
    /// before t0 (`tmp`: n values of scratch).
    fn known(
        &mut self,
        taps: usize,
        steps: usize,
        known: &mut [f64],
        tmp: &mut [f64],
        mut velocity: impl FnMut(usize, &mut [f64]),
    ) {
        let (len, n) = (self.len, self.n);
        // u_j[p]: p = taps-1 is v0, p = taps-1-m is the velocity m steps before t0
        self.u.iter_mut().for_each(|c| *c = Complex64::default());
        for m in 0..taps {
            velocity(m, tmp);
            for j in 0..n {
                self.u[j * len + taps - 1 - m] = Complex64::new(tmp[j], 0.0);
            }
        }
        self.transform_inputs(n);
        let scale = 1.0 / len as f64;
        for p in 0..n.div_ceil(2) {
            self.output(p, n);
            let (i, i2) = (2 * p, 2 * p + 1);
            for kk in 1..=steps.min(taps - 1) {
                let y = self.acc[kk + taps - 1] * scale;
                known[kk * n + i] = y.re;
                if i2 < n {
                    known[kk * n + i2] = y.im;
                }
            }
        }
    }

    /// Spectra of the weighted kernel's taps, zero-padded to `len`.
    fn new(k: &[f64], taps: usize, n: usize, len: usize) -> HistoryFft {
        let mut planner = FftPlanner::new();
        let forward = planner.plan_fft_forward(len);
        let inverse = planner.plan_fft_inverse(len);
        let pairs = n.div_ceil(2);
        let mut kernel = vec![Complex64::default(); pairs * n * len];
        let mut scratch =
            vec![Complex64::default(); forward.get_inplace_scratch_len().max(inverse.get_inplace_scratch_len())];
        for p in 0..pairs {
            let (i, i2) = (2 * p, 2 * p + 1);
            for j in 0..n {
                let s = &mut kernel[(p * n + j) * len..(p * n + j + 1) * len];
                for m in 0..taps.min(len) {
                    let im = if i2 < n { k[(i2 * taps + m) * n + j] } else { 0.0 };
                    s[m] = Complex64::new(k[(i * taps + m) * n + j], im);
                }
                forward.process_with_scratch(s, &mut scratch);
            }
        }
        HistoryFft {
            len,
            n,
            forward,
            inverse,
            kernel,
            u: vec![Complex64::default(); n * len],
            acc: vec![Complex64::default(); len],
            scratch,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The history's force by FFT at the run's length against the direct sum, for runs shorter than
    /// the kernel, as long and longer, with an odd number of states (a pair's imaginary half unused).
    #[test]
    fn the_history_s_force_by_a_run_length_fft_is_the_direct_sum() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand::rngs::StdRng::seed_from_u64(3);
        let (taps, n) = (57, 3);
        let k: Vec<f64> = (0..n * taps * n).map(|_| rng.random::<f64>() - 0.5).collect();
        let past: Vec<Vec<f64>> = (0..taps)
            .map(|_| (0..n).map(|_| rng.random::<f64>() - 0.5).collect())
            .collect();
        for steps in [1, 10, 56, 57, 200] {
            // the least length clear of the wrap, and the one a forecast takes
            let least = taps + steps.min(taps - 1);
            for len in [least, fft_len(least)] {
                let mut f = HistoryFft::new(&k, taps, n, len);
                let mut known = vec![f64::NAN; (steps + 1) * n];
                let mut tmp = vec![0.0; n];
                f.known(taps, steps, &mut known, &mut tmp, |m, out| {
                    out.copy_from_slice(&past[m])
                });
                for kk in 1..=steps.min(taps - 1) {
                    for i in 0..n {
                        let direct: f64 = (kk..taps)
                            .map(|m| (0..n).map(|j| k[(i * taps + m) * n + j] * past[m - kk][j]).sum::<f64>())
                            .sum();
                        let got = known[kk * n + i];
                        assert!(
                            (got - direct).abs() < 1e-12,
                            "steps {steps} lead {kk} state {i}: {got} against {direct}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn fft_lengths_are_2_and_3_smooth_and_the_least_such() {
        let smooth = |mut m: usize| {
            for p in [2, 3] {
                while m.is_multiple_of(p) {
                    m /= p;
                }
            }
            m == 1
        };
        for min in 1..3000 {
            let len = fft_len(min);
            assert!(len >= min && smooth(len), "{min}: {len}");
            assert!((min..len).all(|m| !smooth(m)), "{min}: {len}");
        }
        assert_eq!(fft_len(10_286), 10_368);
    }
}
