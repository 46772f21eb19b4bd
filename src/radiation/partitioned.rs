//! Uniformly partitioned convolution of the radiation kernel with the velocities of a run (pure).
//!
//! At every step k the stepper needs P_k = sum_{m >= 1} K~_m s_{k-m}, with K~_m the weighted kernel taps
//! of [`crate::rom::model::Kernel::Convolution`] (n x n, m = 0..taps-1) and s_j the velocities of the run
//! (s_0 = 0: the start's own velocity and the history before it are the caller's `known` part). Summed
//! directly that is n^2 (taps - 1) multiply-adds per step: 3.5 million for the two-ship pair at
//! dt = 0.025 s (24 001 taps), and the step streams the whole kernel (27.6 MB) from memory.
//!
//! Here taps 1..B-1 stay a direct sum (the stepper's, over its last B - 1 velocities) and taps from B on
//! are cut into partitions of B taps, p = 1..P (partition p holds taps pB..pB+B-1), applied by
//! overlap-save FFTs of length 2B once every B steps with a frequency-domain delay line of the inputs'
//! spectra (uniformly partitioned overlap-save). For output block d (steps dB..dB+B-1), partition p
//! needs the inputs of blocks d-p-1 and d-p only, all known when block d starts:
//!   y_d = last B of IFFT( sum_p H_p X_{d-p} ),  X_c = FFT(s over blocks c-1 and c),  H_p = FFT(taps of p).
//! The spectra are those of real sequences: bins 0..=B are kept and the rest is their conjugate.
//!
//! Cost per step: n^2 (B - 1) direct multiply-adds plus about 4 n^2 taps / B in the spectra (and 2n FFTs
//! of 2B per block): B is chosen near 2 sqrt(taps), where the two balance. The result equals the direct
//! sum to rounding (a unit test checks it).

use multiversion::multiversion;
use multiversion::target::target_cfg_f;
use num_complex::Complex64;
use rustfft::{Fft, FftPlanner};
use std::sync::Arc;

/// The kernel's partitions in the frequency domain (built once per model).
#[derive(Clone)]
pub struct Partitions {
    /// Block length B (a power of two): taps below it are summed directly.
    pub block: usize,
    /// Number of partitions P (taps B..taps-1); zero when the kernel is shorter than a block.
    pub parts: usize,
    /// The longest run they serve (`usize::MAX`: every run; see [`Partitions::reaching`]).
    pub steps: usize,
    n: usize,
    /// Kept bins of the spectra: B + 1.
    bins: usize,
    forward: Arc<dyn Fft<f64>>,
    inverse: Arc<dyn Fft<f64>>,
    /// H_p(i, j) at bin f: `h_re/h_im[(((p - 1) * n + i) * n + j) * bins + f]`.
    h_re: Vec<f64>,
    h_im: Vec<f64>,
}

impl std::fmt::Debug for Partitions {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Partitions")
            .field("block", &self.block)
            .field("parts", &self.parts)
            .field("n", &self.n)
            .finish_non_exhaustive()
    }
}

/// The block length for a kernel of `taps` taps: the power of two nearest 2 sqrt(taps), 16 to 1024.
pub fn block_for(taps: usize) -> usize {
    let ideal = 2.0 * (taps.max(1) as f64).sqrt();
    let exp = ideal.log2().round().clamp(4.0, 10.0) as u32;
    1usize << exp
}

/// The block length for a run of at most `steps` steps with a kernel of `taps` taps: [`block_for`] of
/// the shorter. A run shorter than the kernel only meets the partitions its own length reaches
/// (output block d uses partitions up to d), so the spectra cost less and the balance with the direct
/// sum moves to shorter blocks. Measured on the demo pair (8 572 taps): the daemon's 1 714-step
/// forecast makes a whole tick (`cargo bench --bench tick`) 29 ms at 64, 44 ms at the kernel's 256;
/// `rao --method time` at dt 0.025 s (24 001 taps, runs to a steady state) is fastest at 256.
pub fn block_for_run(taps: usize, steps: usize) -> usize {
    block_for(taps.min(steps))
}

impl Partitions {
    /// The partitions of `k` (`k[(i * taps + m) * n + j]`), blocks of `block` taps (a power of two).
    pub fn new(k: &[f64], taps: usize, n: usize, block: usize) -> Partitions {
        Self::reaching(k, taps, n, block, usize::MAX)
    }

    /// The partitions a run of at most `steps` steps meets (those of taps up to `steps`): the same
    /// outputs as [`Partitions::new`]'s for such a run, with less to build and keep.
    pub fn reaching(k: &[f64], taps: usize, n: usize, block: usize, steps: usize) -> Partitions {
        let len = 2 * block;
        let bins = block + 1;
        let parts = taps.saturating_sub(1).min(steps) / block;
        let mut planner = FftPlanner::new();
        let forward = planner.plan_fft_forward(len);
        let inverse = planner.plan_fft_inverse(len);
        let mut h_re = vec![0.0; parts * n * n * bins];
        let mut h_im = vec![0.0; parts * n * n * bins];
        let mut buf = vec![Complex64::default(); len];
        let mut scratch = vec![Complex64::default(); forward.get_inplace_scratch_len()];
        for p in 1..=parts {
            for i in 0..n {
                for j in 0..n {
                    buf.iter_mut().for_each(|c| *c = Complex64::default());
                    for (q, c) in buf[..block].iter_mut().enumerate() {
                        let m = p * block + q;
                        if m < taps {
                            *c = Complex64::new(k[(i * taps + m) * n + j], 0.0);
                        }
                    }
                    forward.process_with_scratch(&mut buf, &mut scratch);
                    let at = (((p - 1) * n + i) * n + j) * bins;
                    for (f, c) in buf[..bins].iter().enumerate() {
                        h_re[at + f] = c.re;
                        h_im[at + f] = c.im;
                    }
                }
            }
        }
        Partitions {
            block,
            parts,
            steps,
            n,
            bins,
            forward,
            inverse,
            h_re,
            h_im,
        }
    }
}

/// The state of one run: the inputs' last two blocks, their spectra and the current block's output.
#[derive(Debug, Clone, Default)]
pub struct PartitionedRun {
    /// Samples pushed since [`PartitionedRun::reset`].
    count: usize,
    /// Per DOF j the last 2B inputs in time order: `window[j * 2B + q]`; the block being filled is [B, 2B).
    window: Vec<f64>,
    /// Spectra X_c of the input windows, a ring of P slots: `x_re/x_im[(slot * n + j) * bins + f]`.
    x_re: Vec<f64>,
    x_im: Vec<f64>,
    /// The partitions' part of the outputs of the current block: `tail[r * n + i]`.
    tail: Vec<f64>,
    acc_re: Vec<f64>,
    acc_im: Vec<f64>,
    buf: Vec<Complex64>,
    scratch: Vec<Complex64>,
}

impl PartitionedRun {
    /// Sizes the workspace for `parts` (allocates only when it grows) and starts with no input.
    pub fn reset(&mut self, parts: &Partitions) {
        let (n, b, bins) = (parts.n, parts.block, parts.bins);
        self.count = 0;
        self.window.clear();
        self.window.resize(n * 2 * b, 0.0);
        self.tail.clear();
        self.tail.resize(b * n, 0.0);
        // the ring is read only where this run has written it
        self.x_re.resize(parts.parts * n * bins, 0.0);
        self.x_im.resize(parts.parts * n * bins, 0.0);
        self.acc_re.resize(bins, 0.0);
        self.acc_im.resize(bins, 0.0);
        self.buf.resize(2 * b, Complex64::default());
        let s = parts
            .forward
            .get_inplace_scratch_len()
            .max(parts.inverse.get_inplace_scratch_len());
        self.scratch.resize(s, Complex64::default());
    }

    /// The partitions' part of output `t`: sum over taps m >= B of K~_m s_{t-m} (n values). `t` must be
    /// in the block after the last complete input block: `count` rounded down to a multiple of B.
    pub fn tail(&self, parts: &Partitions, t: usize) -> &[f64] {
        let n = parts.n;
        let r = t % parts.block;
        &self.tail[r * n..(r + 1) * n]
    }

    /// Appends input s_count (n values); at the end of a block, computes the next block's outputs.
    pub fn push(&mut self, parts: &Partitions, s: &[f64]) {
        let (n, b, bins) = (parts.n, parts.block, parts.bins);
        if parts.parts == 0 {
            self.count += 1;
            return;
        }
        let r = self.count % b;
        for (j, v) in s.iter().enumerate().take(n) {
            self.window[j * 2 * b + b + r] = *v;
        }
        self.count += 1;
        if r + 1 < b {
            return;
        }
        // block c is complete: its window's spectrum into the ring
        let c = self.count / b - 1;
        let slot = c % parts.parts;
        for j in 0..n {
            let w = &mut self.window[j * 2 * b..(j + 1) * 2 * b];
            for (z, x) in self.buf.iter_mut().zip(w.iter()) {
                *z = Complex64::new(*x, 0.0);
            }
            parts.forward.process_with_scratch(&mut self.buf, &mut self.scratch);
            let at = (slot * n + j) * bins;
            for (f, z) in self.buf[..bins].iter().enumerate() {
                self.x_re[at + f] = z.re;
                self.x_im[at + f] = z.im;
            }
            // the block just completed becomes the window's first half
            w.copy_within(b..2 * b, 0);
        }
        // output block d = c + 1 from partitions p = 1..min(P, d)
        let d = c + 1;
        let pmax = parts.parts.min(d);
        let scale = 1.0 / (2 * b) as f64;
        for i in 0..n {
            self.acc_re.iter_mut().for_each(|a| *a = 0.0);
            self.acc_im.iter_mut().for_each(|a| *a = 0.0);
            for p in 1..=pmax {
                let slot = (d - p) % parts.parts;
                for j in 0..n {
                    let h = (((p - 1) * n + i) * n + j) * bins;
                    let x = (slot * n + j) * bins;
                    cmac(
                        &parts.h_re[h..h + bins],
                        &parts.h_im[h..h + bins],
                        &self.x_re[x..x + bins],
                        &self.x_im[x..x + bins],
                        &mut self.acc_re,
                        &mut self.acc_im,
                    );
                }
            }
            // the full spectrum from its first half (the sequence is real), then back
            for f in 0..bins {
                self.buf[f] = Complex64::new(self.acc_re[f], self.acc_im[f]);
            }
            for f in 1..b {
                self.buf[2 * b - f] = self.buf[f].conj();
            }
            parts.inverse.process_with_scratch(&mut self.buf, &mut self.scratch);
            for q in 0..b {
                self.tail[q * n + i] = self.buf[b + q].re * scale;
            }
        }
    }
}

/// acc += h x over the bins (complex, split real and imaginary parts so the loop vectorizes).
#[multiversion(targets("x86_64+avx2+fma", "x86_64+avx"))]
fn cmac(h_re: &[f64], h_im: &[f64], x_re: &[f64], x_im: &[f64], acc_re: &mut [f64], acc_im: &mut [f64]) {
    const FMA: bool = target_cfg_f!(target_feature = "fma");
    let m = h_re
        .len()
        .min(h_im.len())
        .min(x_re.len())
        .min(x_im.len())
        .min(acc_re.len())
        .min(acc_im.len());
    let (h_re, h_im, x_re, x_im) = (&h_re[..m], &h_im[..m], &x_re[..m], &x_im[..m]);
    let (acc_re, acc_im) = (&mut acc_re[..m], &mut acc_im[..m]);
    for f in 0..m {
        let (hr, hi, xr, xi) = (h_re[f], h_im[f], x_re[f], x_im[f]);
        acc_re[f] = crate::rom::dense::madd::<FMA>(hr, xr, crate::rom::dense::madd::<FMA>(-hi, xi, acc_re[f]));
        acc_im[f] = crate::rom::dense::madd::<FMA>(hr, xi, crate::rom::dense::madd::<FMA>(hi, xr, acc_im[f]));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rounding of FFTs of length up to 2048 against a direct sum, relative to the sum of |terms|.
    const FFT_ROUNDING: f64 = 1e-12;

    fn lcg(seed: &mut u64) -> f64 {
        *seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((*seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
    }

    /// The partitioned tail plus the direct taps 1..B-1 equal the direct sum over every tap, at every
    /// step, for kernels shorter and longer than the run and not a whole number of blocks.
    #[test]
    fn partitioned_equals_the_direct_sum() {
        let mut seed = 7;
        for (taps, n, block, steps) in [
            (1000, 3, 64, 700),
            (333, 2, 16, 900),
            (40, 2, 64, 200),
            (129, 1, 16, 400),
        ] {
            let k: Vec<f64> = (0..n * taps * n).map(|_| lcg(&mut seed)).collect();
            let s: Vec<Vec<f64>> = (0..steps)
                .map(|j| {
                    if j == 0 {
                        vec![0.0; n]
                    } else {
                        (0..n).map(|_| lcg(&mut seed)).collect()
                    }
                })
                .collect();
            // every partition, and only those a run of `steps` reaches
            for parts in [
                Partitions::new(&k, taps, n, block),
                Partitions::reaching(&k, taps, n, block, steps),
            ] {
                let mut run = PartitionedRun::default();
                run.reset(&parts);
                for t in 0..steps {
                    // output t: s_0..s_{t-1} pushed
                    for i in 0..n {
                        let (mut exact, mut size, mut direct) = (0.0, 0.0, 0.0);
                        for m in 1..taps.min(t + 1) {
                            for j in 0..n {
                                let term = k[(i * taps + m) * n + j] * s[t - m][j];
                                exact += term;
                                size += term.abs();
                                if m < block {
                                    direct += term;
                                }
                            }
                        }
                        let got = direct + run.tail(&parts, t)[i];
                        assert!(
                            (got - exact).abs() <= FFT_ROUNDING * size.max(1.0),
                            "taps {taps} block {block} t {t} i {i}: {got} against {exact}"
                        );
                    }
                    run.push(&parts, &s[t]);
                }
            }
        }
    }

    #[test]
    fn block_length_grows_as_the_square_root_of_the_taps() {
        assert_eq!(block_for(1), 16);
        assert_eq!(block_for(6001), 128);
        assert_eq!(block_for(24_001), 256);
        assert_eq!(block_for(10_000_000), 1024);
        // a run shorter than the kernel: by its own length
        assert_eq!(block_for_run(8572, 1714), 64);
        assert_eq!(block_for_run(24_001, 100_000), 256);
    }
}
