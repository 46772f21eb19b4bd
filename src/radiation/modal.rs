//! The exact discrete update of a modal radiation model ([`crate::radiation::statespace`]) over the solver's step,
//! laid out for the stepper's inner loop (pure).
//!
//! Each complex mode xi' = lambda xi + beta(t) with beta = b . v linear over the step (first-order hold,
//! the velocity is the input): xi_{k+1} = E xi_k + g0 beta_k + g1 beta_{k+1}, E = exp(lambda h),
//! g1 = (E - 1 - lambda h) / (lambda^2 h), g0 = (E - 1) / lambda - g1 (series for small |lambda h|).
//! The force is F = Re sum_j c_j xi_j.
//!
//! The stepper keeps the states one half-update ahead, with everything but the newest input
//! (y_{k+1} = E xi_k + g0 beta_k, all the force at the new step needs before the new velocity is known),
//! and moves them on with one call per step ([`ModalStep::advance`]: the input and update in one pass
//! over the modes, the force in a second):
//! y_{k+2} = E (y_{k+1} + g1 beta_{k+1}) + g0 beta_{k+1} = E y_{k+1} + h beta_{k+1}, h = E g1 + g0.

use crate::radiation::statespace::ModalModel;
use crate::rom::dense::{self, madd};
use multiversion::multiversion;
use multiversion::target::target_cfg_f;
use nalgebra::DMatrix;
use num_complex::Complex64;

/// exp(p h), g0, g1 of the first-order-hold update of x' = p x + u (series for small |p h|).
fn foh(p: Complex64, h: f64) -> (Complex64, Complex64, Complex64) {
    let z = p * h;
    let e = z.exp();
    let (i0, i1) = if z.norm() < 1e-3 {
        (
            h * (1.0 + z / 2.0 + z * z / 6.0 + z * z * z / 24.0),
            h * h * (0.5 + z / 6.0 + z * z / 24.0 + z * z * z / 120.0),
        )
    } else {
        ((e - 1.0) / p, (e - 1.0 - z) / (p * p))
    };
    let g1 = i1 / h;
    (e, i0 - g1, g1)
}

/// A modal model's discrete update, laid out for vectorization over modes (structure of arrays).
#[derive(Debug, Clone, PartialEq)]
pub struct ModalStep {
    /// Modes (the model's, padded with inert ones to a multiple of [`LANES`]) and DOFs.
    pub r: usize,
    pub n: usize,
    pub e_re: Vec<f64>,
    pub e_im: Vec<f64>,
    pub g0_re: Vec<f64>,
    pub g0_im: Vec<f64>,
    pub g1_re: Vec<f64>,
    pub g1_im: Vec<f64>,
    /// h = E g1 + g0: the new input's weight in the fused update ([`ModalStep::advance`]).
    pub h_re: Vec<f64>,
    pub h_im: Vec<f64>,
    /// DOF-major n x r.
    pub a_re: Vec<f64>,
    pub a_im: Vec<f64>,
    /// The output map [Re A | -Im A] (n x 2r) column by column, columns padded to `n_pad` rows
    /// ([`dense`]): F = this times the states (r real parts, then r imaginary parts).
    pub n_pad: usize,
    pub out_cols: Vec<f64>,
}

impl ModalStep {
    /// The exact discrete update of `model` over a step of `dt_s` (first-order hold on the input).
    pub fn new(model: &ModalModel, dt_s: f64) -> ModalStep {
        // inert modes (no coupling, E = 0) pad the count to whole blocks: the kernels have no tails
        let modes = model.modes();
        let r = modes.div_ceil(LANES) * LANES;
        let n = model.n;
        let padded = |v: Vec<f64>| -> Vec<f64> {
            (0..n)
                .flat_map(|i| (0..r).map(move |j| (i, j)))
                .map(|(i, j)| if j < modes { v[i * modes + j] } else { 0.0 })
                .collect()
        };
        let mut d = ModalStep {
            r,
            n,
            e_re: vec![0.0; r],
            e_im: vec![0.0; r],
            g0_re: vec![0.0; r],
            g0_im: vec![0.0; r],
            g1_re: vec![0.0; r],
            g1_im: vec![0.0; r],
            h_re: vec![0.0; r],
            h_im: vec![0.0; r],
            a_re: padded(model.a.iter().map(|z| z.re).collect()),
            a_im: padded(model.a.iter().map(|z| z.im).collect()),
            n_pad: dense::pad(n),
            out_cols: vec![],
        };
        d.out_cols = dense::columns(&DMatrix::from_fn(n, 2 * r, |i, c| {
            if c < r {
                d.a_re[i * r + c]
            } else {
                -d.a_im[i * r + c - r]
            }
        }));
        for (j, p) in model.poles.iter().enumerate() {
            let (e, g0, g1) = foh(*p, dt_s);
            d.e_re[j] = e.re;
            d.e_im[j] = e.im;
            d.g0_re[j] = g0.re;
            d.g0_im[j] = g0.im;
            d.g1_re[j] = g1.re;
            d.g1_im[j] = g1.im;
            let h = e * g1 + g0;
            d.h_re[j] = h.re;
            d.h_im[j] = h.im;
        }
        d
    }

    /// Feeds the next velocity sample `v` to the states `x` (r real parts, then r imaginary parts) whose
    /// input of the previous sample is `beta` (laid out alike): the whole update when `started`, else
    /// only the input (a history at rest before `v`).
    pub fn feed(&self, x: &mut [f64], beta: &mut [f64], v: &[f64], started: bool) {
        let (xr, xi) = x.split_at_mut(self.r);
        let (br, bi) = beta.split_at_mut(self.r);
        if started {
            self.propagate(xr, xi, br, bi);
        }
        self.input(v, br, bi);
        if started {
            self.absorb(xr, xi, br, bi);
        }
    }

    /// beta = A^T v (the symmetric map `a`) into (re, im).
    pub fn input(&self, v: &[f64], re: &mut [f64], im: &mut [f64]) {
        input_kernel(self.r, self.n, &self.a_re, &self.a_im, v, re, im);
    }

    /// xi <- E xi + g0 beta (the part of the update known before the new input).
    pub fn propagate(&self, xr: &mut [f64], xi: &mut [f64], br: &[f64], bi: &[f64]) {
        rotate_kernel(self.r, &self.e_re, &self.e_im, &self.g0_re, &self.g0_im, xr, xi, br, bi);
    }

    /// xi <- xi + g1 beta (the new input's part).
    pub fn absorb(&self, xr: &mut [f64], xi: &mut [f64], br: &[f64], bi: &[f64]) {
        absorb_kernel(self.r, &self.g1_re, &self.g1_im, xr, xi, br, bi);
    }

    /// F = Re A xi into `out` (the first n entries) from the states `x` (r real parts, then r
    /// imaginary parts).
    pub fn output(&self, x: &[f64], out: &mut [f64]) {
        // the column-major product of [`dense`]: no horizontal sum per DOF
        dense::gemv(self.n_pad, &self.out_cols, &x[..2 * self.r], &mut out[..self.n]);
    }

    /// The stepper's update, one call per step: from the states `x` held one half-update ahead
    /// (E xi_k + g0 beta_k) and the new velocity `v`, the next such states (E x + h beta(v)), and the
    /// force they give, F = Re A x, into `out` (the first n entries).
    pub fn advance(&self, v: &[f64], x: &mut [f64], out: &mut [f64]) {
        advance_kernel(self, v, x);
        self.output(x, out);
    }

    /// The instantaneous matrix D = Re(A diag(g1) A^T): F_{k+1} = (known part) + D v_{k+1}.
    pub fn instantaneous(&self) -> DMatrix<f64> {
        let r = self.r;
        DMatrix::from_fn(self.n, self.n, |a, bb| {
            (0..r)
                .map(|j| {
                    let c = Complex64::new(self.a_re[a * r + j], self.a_im[a * r + j]);
                    let g = Complex64::new(self.g1_re[j], self.g1_im[j]);
                    let b = Complex64::new(self.a_re[bb * r + j], self.a_im[bb * r + j]);
                    (c * g * b).re
                })
                .sum()
        })
    }
}

// The inner loops, compiled for AVX2 + FMA as well as the baseline and chosen at run time
// (`multiversion`): they are most of a state-space forecast's time. They are written so that LLVM packs
// them into full-width registers: independent accumulators per lane, summed lane by lane at the end, no
// closures (a closure that is not inlined loses the version's compile-time constants) and no tails (the
// modes are padded to whole blocks).

/// Modes per block of the kernels: four AVX registers of f64, four independent multiply-add chains.
pub const LANES: usize = 16;

/// beta = A^T v for the block of modes j..j + LANES, accumulated over the DOFs in registers.
#[inline(always)]
fn block_input<const FMA: bool>(
    r: usize,
    j: usize,
    a_re: &[f64],
    a_im: &[f64],
    v: &[f64],
) -> ([f64; LANES], [f64; LANES]) {
    let (mut br, mut bi) = ([0.0f64; LANES], [0.0f64; LANES]);
    for (i, vi) in v.iter().enumerate() {
        let (ar, ai) = (&a_re[i * r + j..i * r + j + LANES], &a_im[i * r + j..i * r + j + LANES]);
        for l in 0..LANES {
            br[l] = madd::<FMA>(ar[l], *vi, br[l]);
            bi[l] = madd::<FMA>(ai[l], *vi, bi[l]);
        }
    }
    (br, bi)
}

#[multiversion(targets("x86_64+avx2+fma", "x86_64+avx"))]
fn input_kernel(r: usize, n: usize, a_re: &[f64], a_im: &[f64], v: &[f64], re: &mut [f64], im: &mut [f64]) {
    const FMA: bool = target_cfg_f!(target_feature = "fma");
    let (re, im, v) = (&mut re[..r], &mut im[..r], &v[..n]);
    for j in (0..r).step_by(LANES) {
        let (br, bi) = block_input::<FMA>(r, j, a_re, a_im, v);
        re[j..j + LANES].copy_from_slice(&br);
        im[j..j + LANES].copy_from_slice(&bi);
    }
}

#[allow(clippy::too_many_arguments)]
#[multiversion(targets("x86_64+avx2+fma", "x86_64+avx"))]
fn rotate_kernel(
    r: usize,
    e_re: &[f64],
    e_im: &[f64],
    g_re: &[f64],
    g_im: &[f64],
    xr: &mut [f64],
    xi: &mut [f64],
    br: &[f64],
    bi: &[f64],
) {
    let (xr, xi, br, bi) = (&mut xr[..r], &mut xi[..r], &br[..r], &bi[..r]);
    let (er, ei, gr, gi) = (&e_re[..r], &e_im[..r], &g_re[..r], &g_im[..r]);
    for j in 0..r {
        let (a, b) = (xr[j], xi[j]);
        xr[j] = er[j] * a - ei[j] * b + gr[j] * br[j] - gi[j] * bi[j];
        xi[j] = er[j] * b + ei[j] * a + gr[j] * bi[j] + gi[j] * br[j];
    }
}

#[multiversion(targets("x86_64+avx2+fma", "x86_64+avx"))]
fn absorb_kernel(r: usize, g_re: &[f64], g_im: &[f64], xr: &mut [f64], xi: &mut [f64], br: &[f64], bi: &[f64]) {
    let (xr, xi, br, bi) = (&mut xr[..r], &mut xi[..r], &br[..r], &bi[..r]);
    let (gr, gi) = (&g_re[..r], &g_im[..r]);
    for j in 0..r {
        xr[j] += gr[j] * br[j] - gi[j] * bi[j];
        xi[j] += gr[j] * bi[j] + gi[j] * br[j];
    }
}

/// beta = A^T v a block of modes at a time ([`block_input`]), then x <- E x + h beta on the block
/// while beta is in registers.
#[multiversion(targets("x86_64+avx2+fma", "x86_64+avx"))]
fn advance_kernel(s: &ModalStep, v: &[f64], x: &mut [f64]) {
    const FMA: bool = target_cfg_f!(target_feature = "fma");
    let (r, n) = (s.r, s.n);
    let (xr, xi) = x[..2 * r].split_at_mut(r);
    let v = &v[..n];
    let (a_re, a_im) = (&s.a_re[..n * r], &s.a_im[..n * r]);
    let (er, ei, hr, hi) = (&s.e_re[..r], &s.e_im[..r], &s.h_re[..r], &s.h_im[..r]);
    for j in (0..r).step_by(LANES) {
        let (br, bi) = block_input::<FMA>(r, j, a_re, a_im, v);
        let (xr, xi) = (&mut xr[j..j + LANES], &mut xi[j..j + LANES]);
        let (er, ei, hr, hi) = (
            &er[j..j + LANES],
            &ei[j..j + LANES],
            &hr[j..j + LANES],
            &hi[j..j + LANES],
        );
        for l in 0..LANES {
            let (a, b) = (xr[l], xi[l]);
            xr[l] = er[l] * a - ei[l] * b + hr[l] * br[l] - hi[l] * bi[l];
            xi[l] = er[l] * b + ei[l] * a + hr[l] * bi[l] + hi[l] * br[l];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The discrete update is exact for a constant and for a ramp input.
    #[test]
    fn first_order_hold_is_exact_for_a_ramp() {
        for p in [
            Complex64::new(-0.2, 1.1),
            Complex64::new(-1e-6, 0.5),
            Complex64::new(-0.7, 0.0),
        ] {
            let h = 0.1;
            let (e, g0, g1) = foh(p, h);
            // x' = p x + t from x(0) = 0: x(t) = (e^{pt} - 1 - p t) / p^2
            let exact = |t: f64| ((p * t).exp() - 1.0 - p * t) / (p * p);
            let mut x = Complex64::default();
            for k in 0..50 {
                x = e * x + g0 * (k as f64 * h) + g1 * ((k + 1) as f64 * h);
            }
            let want = exact(50.0 * h);
            assert!((x - want).norm() <= 1e-9 * want.norm().max(1e-9), "{p}: {x} vs {want}");
        }
    }

    /// The padded, dispatched kernels (input, propagate, absorb, output, and the stepper's fused
    /// advance) equal the update written directly in complex numbers, for a mode count that is not a
    /// whole number of blocks and a DOF count that is not a whole number of output rows.
    #[test]
    fn kernels_equal_the_complex_update() {
        let (n, r) = (5, 21);
        let wave = |k: usize, f: f64| (f * k as f64).sin();
        let model = ModalModel {
            n,
            poles: (0..r)
                .map(|j| Complex64::new(-0.05 - 0.01 * j as f64, 0.1 * j as f64))
                .collect(),
            a: (0..n * r).map(|k| Complex64::new(wave(k, 0.7), wave(k, 1.3))).collect(),
            scale: vec![1.0; n],
            cover: 0.0,
            passivity_passes: 0,
            fit_pairs: 0,
            fit_error: 0.0,
            full_order: 2 * r,
            hankel: vec![],
        };
        let h = 0.1;
        let step = ModalStep::new(&model, h);
        assert_eq!(step.r % LANES, 0);
        let (mut x, mut beta) = (vec![0.0; 2 * step.r], vec![0.0; 2 * step.r]);
        // the stepper's fused form, one half-update ahead (E xi + g0 beta)
        let mut y = vec![0.0; 2 * step.r];
        let mut xi = vec![Complex64::default(); r];
        let mut b_prev = vec![Complex64::default(); r];
        let (mut out, mut out_y) = (vec![0.0; n], vec![0.0; n]);
        for k in 0..30 {
            let v: Vec<f64> = (0..n).map(|i| wave(k * n + i, 0.37)).collect();
            step.feed(&mut x, &mut beta, &v, k > 0);
            if k == 0 {
                y.copy_from_slice(&x);
                let (yr, yi) = y.split_at_mut(step.r);
                let (br, bi) = beta.split_at_mut(step.r);
                step.propagate(yr, yi, br, bi);
                step.output(&y, &mut out_y);
            } else {
                step.advance(&v, &mut y, &mut out_y);
            }
            let b: Vec<Complex64> = (0..r)
                .map(|j| (0..n).map(|i| model.a[i * r + j] * v[i]).sum())
                .collect();
            let mut ahead = vec![Complex64::default(); r];
            for j in 0..r {
                let (e, g0, g1) = foh(model.poles[j], h);
                // at rest before the first sample: the state at it is zero
                xi[j] = if k > 0 {
                    e * xi[j] + g0 * b_prev[j] + g1 * b[j]
                } else {
                    Complex64::default()
                };
                ahead[j] = e * xi[j] + g0 * b[j];
            }
            b_prev = b;
            step.output(&x, &mut out);
            for i in 0..n {
                for (what, got, states) in [("state", out[i], &xi), ("fused, ahead", out_y[i], &ahead)] {
                    let want: f64 = (0..r).map(|j| (model.a[i * r + j] * states[j]).re).sum();
                    assert!(
                        (got - want).abs() <= 1e-12 * (1.0 + want.abs()),
                        "{what}, step {k}, DOF {i}: {got} vs {want}"
                    );
                }
            }
        }
    }
}
