//! Radiation memory as a small modal state-space model (pure): vector fitting with common poles,
//! balanced truncation, modal form, exact first-order-hold discretization.
//!
//! Conventions: K(s) is the radiation kernel of the active DOFs (force on DOF i per velocity of DOF j,
//! SI units: N/(m/s), N m/(rad/s), ...), K(iw) = B(w) + i w (A(w) - A_inf), strictly proper and symmetric.
//!
//! Pipeline (once per database and speed, on the system file's IRF grid: not per solver step):
//! 1. Scaling: every entry is divided by sqrt(s_i s_j), s_i = max_w B_ii, so that DOFs of different units
//!    weigh alike and the peak of every diagonal is 1.
//! 2. Vector fitting (Gustavsen & Semlyen 1999, relaxed: Gustavsen 2006; fast QR form: Deschrijver et al.
//!    2008) of the upper triangle (symmetric part) with one set of stable poles common to every entry,
//!    relocated as the zeros of the weighting function, unstable ones reflected into the left
//!    half-plane, none narrower than half the local frequency spacing; then the residues by linear least
//!    squares with K(0) = 0 exactly. The least-squares rows are real parts only: the database's damping,
//!    B(0) = 0 and B linear below the data, the IRF's damping tail above it (as the convolution sees B), so
//!    the fit's added mass follows by causality from that damping; the added mass still enters the
//!    pole relocation, where the weighting function multiplies the complex data K = B + i w (A - A_inf)
//!    (with the imaginary part zeroed, the relocation diverged on the one-ship demo).
//!    More pole pairs are tried until the fit meets the tolerance.
//! 3. A real realization of the fit (per pole, one state per DOF and per real coordinate of the pole),
//!    reduced by square-root balanced truncation (Gramians solved block by block, the controllability one
//!    exactly as a Kronecker product): the kept order is the smallest whose error bound, twice the sum of
//!    the dropped Hankel singular values, is below the tolerance. Stable in, stable out.
//! 4. Modal form of the reduced model (complex Schur, eigenvectors by back-substitution): complex modes
//!    xi_j' = lambda_j xi_j + b_j . v, force F = Re sum_j c_j xi_j (conjugate modes folded in: c_j carries a
//!    factor 2 for a complex pole, 1 for a real one).
//! 5. Passivity: the smallest eigenvalue of Re K_r(iw) (scaled) is found over a dense grid (uniform up to
//!    4 x the highest database frequency, plus points within a few half-widths of every pole); where it
//!    is negative the residues are perturbed (least-norm, slow modes held hardest: they set the added
//!    mass at low frequency, see `enforce_passivity`); if it is still negative, -min is reported as
//!    `cover` and the time-domain model adds cover x diag(s) to its linear damping, so the whole
//!    radiation + damping is dissipative at every frequency on that grid.
//!
//! Discretization over a step h with the input linear in time (first-order hold), exact for each mode:
//! xi_{k+1} = E xi_k + g0 beta_k + g1 beta_{k+1}, E = exp(lambda h), g1 = (E - 1 - lambda h)/(lambda^2 h),
//! g0 = (E - 1)/lambda - g1.

use super::irf::DampingTail;
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;

/// Pole pairs tried in turn until the vector fit meets its tolerance.
pub const PAIRS_TRIED: [usize; 5] = [12, 20, 28, 36, 48];
/// Vector-fitting pole relocations per try.
pub const VF_ITERATIONS: usize = 12;
/// A fitted pole's half-width |Re p| is at least this multiple of the frequency spacing around it: a
/// narrower one falls between the samples, where nothing checks its sign (on the one-ship demo, poles of
/// half-width 5e-4 rad/s at 0.025 rad/s spacing made Re K dip to -0.4 of the peak between samples).
pub const MIN_HALF_WIDTH: f64 = 0.5;
/// Passivity check grid: uniform points up to this multiple of the highest database frequency.
pub const CHECK_SPAN: f64 = 4.0;
pub const CHECK_POINTS: usize = 2000;
/// Passivity enforcement: the smallest eigenvalue of the scaled damping is lifted to this, at most this
/// many times.
pub const PASSIVITY_MARGIN: f64 = 1e-6;
pub const PASSIVITY_PASSES: usize = 30;
/// Rows below the lowest database frequency (0 included).
pub const LOW_ROWS: usize = 10;
/// Growth of the spacing between successive damping-tail rows beyond the data.
pub const TAIL_SPREAD: f64 = 1.1;
/// A pole whose imaginary part is below this fraction of its modulus is treated as real.
pub const REAL_POLE: f64 = 1e-9;
/// Balanced truncation: eigenvalues of a Gramian below this fraction of its largest are dropped from its
/// square-root factor (round-off).
pub const GRAMIAN_FLOOR: f64 = 1e-15;

/// Fitting options.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModalOptions {
    /// Largest scaled error of the fit over the database frequencies (both B and w (A - A_inf)).
    pub tolerance: f64,
    /// Balanced-truncation error bound (scaled units): twice the sum of the dropped Hankel singular values.
    pub reduction_tolerance: f64,
}

impl Default for ModalOptions {
    fn default() -> Self {
        ModalOptions {
            tolerance: 0.005,
            reduction_tolerance: 0.02,
        }
    }
}

/// A radiation model in modal form (see the module doc), SI units.
#[derive(Debug, Clone, PartialEq)]
pub struct ModalModel {
    /// Radiating DOFs.
    pub n: usize,
    /// One pole per mode (Im >= 0: a conjugate partner is implied when Im > 0), rad/s.
    pub poles: Vec<Complex64>,
    /// Input and output map (the kernel is symmetric), DOF-major: xi_j' = lambda_j xi_j + sum_i
    /// a[i * r + j] v_i, F_i = Re sum_j a[i * r + j] xi_j (factor 2 of complex modes included).
    pub a: Vec<Complex64>,
    /// Scales s_i = max_w B_ii of each DOF.
    pub scale: Vec<f64>,
    /// Passivity cover (scaled): what enforcement left negative; the time-domain model adds
    /// cover x diag(scale) to its damping.
    pub cover: f64,
    /// Passes of the passivity enforcement taken.
    pub passivity_passes: usize,
    /// Pole pairs of the vector fit, and its largest scaled error at the database frequencies.
    pub fit_pairs: usize,
    pub fit_error: f64,
    /// Order of the full realization before balanced truncation (real states) and its Hankel singular
    /// values (scaled), largest first.
    pub full_order: usize,
    pub hankel: Vec<f64>,
}

impl ModalModel {
    /// Number of complex modes.
    pub fn modes(&self) -> usize {
        self.poles.len()
    }

    /// Number of real states the model is equivalent to (2 per complex pole, 1 per real one).
    pub fn real_order(&self) -> usize {
        self.poles.iter().map(|p| if is_real(*p) { 1 } else { 2 }).sum()
    }

    /// K_r(iw), n x n, SI units.
    pub fn kernel(&self, omega_rad_s: f64) -> DMatrix<Complex64> {
        let (n, r) = (self.n, self.modes());
        let s = Complex64::new(0.0, omega_rad_s);
        let mut k = DMatrix::from_element(n, n, Complex64::default());
        for j in 0..r {
            let p = self.poles[j];
            let (h, hc) = if is_real(p) {
                (1.0 / (s - p), None)
            } else {
                (0.5 / (s - p), Some(0.5 / (s - p.conj())))
            };
            for a in 0..n {
                for bb in 0..n {
                    let m = self.a[a * r + j] * self.a[bb * r + j];
                    k[(a, bb)] += match hc {
                        None => Complex64::new(m.re, 0.0) * h,
                        Some(hc) => m * h + m.conj() * hc,
                    };
                }
            }
        }
        k
    }

    /// The model's damping at zero frequency, Re K_ii(0) of each DOF in SI units: a drag on a steady
    /// drift. Radiation has none (B(0) = 0; the fit keeps K(0) = 0 exactly), but balanced truncation
    /// does not keep it and passivity enforcement then makes it positive.
    pub fn zero_frequency_damping(&self) -> Vec<f64> {
        let k = self.kernel(0.0);
        (0..self.n).map(|i| k[(i, i)].re).collect()
    }
}

pub fn is_real(p: Complex64) -> bool {
    p.im.abs() <= REAL_POLE * p.norm()
}

/// Fit quality as `db check` reports it: the largest scaled errors of B_r and of A_r (against the
/// given added mass and A_inf) over the frequencies.
pub fn fit_errors(
    model: &ModalModel,
    omegas: &[f64],
    damping: &[DMatrix<f64>],
    added_mass: &[DMatrix<f64>],
    a_inf: &DMatrix<f64>,
) -> (f64, f64) {
    let n = a_inf.nrows();
    let sb = super::irf::diagonal_peaks(damping);
    let sa = super::irf::diagonal_peaks(added_mass);
    let (mut eb, mut ea) = (0.0f64, 0.0f64);
    for ((w, b), a) in omegas.iter().zip(damping).zip(added_mass) {
        let k = model.kernel(*w);
        for i in 0..n {
            for j in 0..n {
                let (nb, na) = ((sb[i] * sb[j]).sqrt(), (sa[i] * sa[j]).sqrt());
                eb = eb.max((k[(i, j)].re - b[(i, j)]).abs() / nb);
                ea = ea.max((a_inf[(i, j)] + k[(i, j)].im / w - a[(i, j)]).abs() / na);
            }
        }
    }
    (eb, ea)
}

/// Why a fit could not be made.
#[derive(Debug, Clone, PartialEq)]
pub struct FitError(pub String);

/// The fit's rows: the data (damping and added mass), then B(0) = 0 and the IRF's damping tail beyond
/// the data (damping only: the added mass there is unknown), so the fit stays passive where the data
/// end. Returns the frequencies and, per row, (frequency index, false).
fn fit_rows(omegas: &[f64]) -> (Vec<f64>, Vec<(usize, bool)>) {
    let nw = omegas.len();
    let wn = omegas[nw - 1];
    let mut freqs: Vec<f64> = omegas.to_vec();
    let mut rows: Vec<(usize, bool)> = (0..nw).map(|k| (k, false)).collect();
    // B(0) = 0 and, below the data, B linear to 0 as the convolution's IRF integrates it (the low
    // frequencies set the zero-frequency added mass, hence the drift of modes without restoring)
    freqs.push(0.0);
    rows.push((nw, false));
    for k in 1..LOW_ROWS {
        rows.push((freqs.len(), false));
        freqs.push(omegas[0] * k as f64 / LOW_ROWS as f64);
    }
    // tail nodes as dense as the data at the band's edge, spreading out by TAIL_SPREAD per node (a
    // sparse tail lets a spurious lightly damped pole sit just above the band)
    let mut step = (wn - omegas[nw - 2]).max(1e-3 * wn);
    let mut x = wn + step;
    while x <= super::irf::TAIL_END_FACTOR * wn {
        rows.push((freqs.len(), false));
        freqs.push(x);
        step *= TAIL_SPREAD;
        x += step;
    }
    (freqs, rows)
}

/// The scaled kernel of each entry (i, j) of the upper triangle at each of `freqs` ([`fit_rows`]): the
/// symmetric parts of the data, B linear to 0 below it, the damping tail above it.
#[allow(clippy::too_many_arguments)]
fn fit_data(
    entries: &[(usize, usize)],
    freqs: &[f64],
    omegas: &[f64],
    damping: &[DMatrix<f64>],
    added_mass: &[DMatrix<f64>],
    a_inf: &DMatrix<f64>,
    tail: &DampingTail,
    sc: &dyn Fn(usize, usize) -> f64,
) -> Vec<Vec<Complex64>> {
    let nw = omegas.len();
    entries
        .iter()
        .map(|&(i, j)| {
            freqs
                .iter()
                .enumerate()
                .map(|(k, w)| {
                    if k < nw {
                        // the symmetric parts (a BEM's matrices are symmetric up to its discretization)
                        let b = 0.5 * (damping[k][(i, j)] + damping[k][(j, i)]);
                        let a = 0.5 * (added_mass[k][(i, j)] + added_mass[k][(j, i)]);
                        Complex64::new(b, w * (a - a_inf[(i, j)])) / sc(i, j)
                    } else if *w < omegas[0] {
                        let b = 0.5 * (damping[0][(i, j)] + damping[0][(j, i)]);
                        Complex64::new(b * w / omegas[0] / sc(i, j), 0.0)
                    } else {
                        let b = tail.at(*w);
                        Complex64::new(0.5 * (b[(i, j)] + b[(j, i)]) / sc(i, j), 0.0)
                    }
                })
                .collect()
        })
        .collect()
}

/// Fits the kernel K(iw) = B(w) + i w (A(w) - A_inf) at ascending `omegas` (n x n each, B passive) and
/// returns the reduced modal model.
pub fn fit(
    omegas: &[f64],
    damping: &[DMatrix<f64>],
    added_mass: &[DMatrix<f64>],
    a_inf: &DMatrix<f64>,
    tail: &DampingTail,
    opts: ModalOptions,
) -> Result<ModalModel, FitError> {
    let nw = omegas.len();
    let n = a_inf.nrows();
    if nw < 4 || n == 0 || damping.len() != nw || added_mass.len() != nw {
        return Err(FitError(format!(
            "{nw} frequencies and {n} DOFs: a state-space fit needs at least 4 frequencies"
        )));
    }
    // a DOF that does not radiate (damping zero or noise: `radiation::radiating_dofs`) takes the
    // smallest scale of one that does, so that nothing divides by zero
    let peaks = super::irf::diagonal_peaks(damping);
    let top = peaks.iter().copied().fold(0.0, f64::max);
    let scale: Vec<f64> = peaks.iter().map(|p| p.max(super::irf::NON_RADIATING * top)).collect();
    let sc = |i: usize, j: usize| (scale[i] * scale[j]).sqrt();
    // the upper triangle, scaled: entry e = (i, j), data[e][k]
    let entries: Vec<(usize, usize)> = (0..n).flat_map(|i| (i..n).map(move |j| (i, j))).collect();
    let wn = omegas[nw - 1];
    let (freqs, rows) = fit_rows(omegas);
    let data = fit_data(&entries, &freqs, omegas, damping, added_mass, a_inf, tail, &sc);
    if data.iter().flatten().any(|z| !(z.re.is_finite() && z.im.is_finite())) {
        return Err(FitError("the damping or added mass is not finite".into()));
    }
    let set = Rows {
        freqs: &freqs,
        rows: &rows,
        band: (omegas[0], wn),
    };
    let mut best: Option<(Vec<Complex64>, DMatrix<f64>, f64, usize)> = None;
    for pairs in PAIRS_TRIED {
        let poles = relocate(&set, &data, pairs);
        let (res, err) = residues(&set, &data, &poles);
        let better = best.as_ref().is_none_or(|b| err < b.2);
        if better {
            best = Some((poles, res, err, pairs));
        }
        if err <= opts.tolerance {
            break;
        }
    }
    let Some((poles, res, fit_error, fit_pairs)) = best else {
        return Err(FitError("no fit".into()));
    };
    // the full real realization
    let full = Realization::new(n, &poles, &res, &entries);
    let (ar, br, cr, hankel) = full.balanced_truncation(opts.reduction_tolerance);
    let (mpoles, mb, mc) = modal_form(&ar, &br, &cr)?;
    let grid = check_grid(&mpoles, wn);
    // the middle of the database's band on a log scale (0.28 rad/s on the pair demo), so the choice
    // scales with the database (a model-scale one has its frequencies higher by sqrt(scale))
    let low_band_rad_s = (omegas[0] * wn).sqrt();
    let (mb, mc, passes) = enforce_passivity(&mpoles, mb, mc, &grid, low_band_rad_s);
    let r = mpoles.len();
    // symmetric form a_j = sqrt(kappa_j) b_j (c_j = kappa_j b_j), unscaled: K = S^1/2 K~ S^1/2
    let kappa = kappas(&mb, &mc);
    let mut a = vec![Complex64::default(); n * r];
    for i in 0..n {
        let s = scale[i].sqrt();
        for j in 0..r {
            a[i * r + j] = kappa[j].sqrt() * mb[(j, i)] * s;
        }
    }
    let mut model = ModalModel {
        n,
        poles: mpoles,
        a,
        scale,
        cover: 0.0,
        passivity_passes: 0,
        fit_pairs,
        fit_error,
        full_order: full.order(),
        hankel,
    };
    model.passivity_passes = passes;
    model.cover = (-min_scaled_damping(&model, &grid)).max(0.0);
    Ok(model)
}

/// Where passivity is checked: uniform from 0 to CHECK_SPAN x the highest database frequency
/// (CHECK_POINTS + 1 points), plus points within 8 half-widths of every pole narrower than 4 grid spacings.
pub fn check_grid(poles: &[Complex64], omega_max: f64) -> Vec<f64> {
    let dw = CHECK_SPAN * omega_max / CHECK_POINTS as f64;
    // w = 0 included: a negative Re K(0) is a drag that pushes a free drift, and a grid beginning at dw
    // does not see it
    let mut grid: Vec<f64> = (0..=CHECK_POINTS).map(|k| k as f64 * dw).collect();
    for p in poles {
        let hw = p.re.abs().max(1e-9);
        if hw < 4.0 * dw {
            for k in -16..=16 {
                let w = p.im.abs() + k as f64 * 0.5 * hw;
                if w > 0.0 {
                    grid.push(w);
                }
            }
        }
    }
    grid.sort_by(f64::total_cmp);
    grid.dedup();
    grid
}

/// The residue matrices c_j b_j^T of a modal model (scaled), with each mode's frequency response.
fn scaled_kernel(poles: &[Complex64], b: &DMatrix<Complex64>, c: &DMatrix<Complex64>, w: f64) -> DMatrix<f64> {
    let n = b.ncols();
    let s = Complex64::new(0.0, w);
    let mut k = DMatrix::<f64>::zeros(n, n);
    for (j, p) in poles.iter().enumerate() {
        let (h1, h2) = (1.0 / (s - p), 1.0 / (s - p.conj()));
        for a in 0..n {
            for bb in 0..n {
                let m = c[(a, j)] * b[(j, bb)];
                k[(a, bb)] += if is_real(*p) {
                    (Complex64::new(m.re, 0.0) * h1).re
                } else {
                    (0.5 * m * h1 + 0.5 * m.conj() * h2).re
                };
            }
        }
    }
    (&k + k.transpose()) * 0.5
}

/// kappa_j with c_j = kappa_j b_j (least squares; exact for a symmetric kernel's residues).
fn kappas(b: &DMatrix<Complex64>, c: &DMatrix<Complex64>) -> Vec<Complex64> {
    let (r, n) = (b.nrows(), b.ncols());
    (0..r)
        .map(|j| {
            let bb: f64 = (0..n).map(|a| b[(j, a)].norm_sqr()).sum();
            let cb: Complex64 = (0..n).map(|a| c[(a, j)] * b[(j, a)].conj()).sum();
            if bb > 0.0 { cb / bb } else { Complex64::default() }
        })
        .collect()
}

/// The local minima of the smallest eigenvalue of the scaled damping below `level` over `grid`:
/// (frequency, eigenvalue, eigenvector).
fn violations(
    poles: &[Complex64],
    b: &DMatrix<Complex64>,
    c: &DMatrix<Complex64>,
    grid: &[f64],
    level: f64,
) -> Vec<(f64, f64, DVector<f64>)> {
    let lows: Vec<(f64, DVector<f64>)> = grid
        .iter()
        .map(|w| {
            let e = scaled_kernel(poles, b, c, *w).symmetric_eigen();
            let (ix, lo) = e
                .eigenvalues
                .iter()
                .copied()
                .enumerate()
                .fold((0, f64::INFINITY), |a, x| if x.1 < a.1 { x } else { a });
            (lo, e.eigenvectors.column(ix).into_owned())
        })
        .collect();
    let mut out = vec![];
    for k in 0..lows.len() {
        let lo = lows[k].0;
        let left = if k > 0 { lows[k - 1].0 } else { f64::INFINITY };
        let right = if k + 1 < lows.len() {
            lows[k + 1].0
        } else {
            f64::INFINITY
        };
        if lo < level && lo <= left && lo <= right {
            out.push((grid[k], lo, lows[k].1.clone()));
        }
    }
    out
}

/// Passivity enforcement by residue perturbation (after Gustavsen & Semlyen 2001, kept symmetric):
/// each mode's residue c_j b_j^T is written kappa_j b_j b_j^T (a symmetric kernel's residues are), and
/// the b_j are moved by the weighted least-norm step that lifts the smallest eigenvalue of the scaled
/// damping at every local violation to PASSIVITY_MARGIN (first order), repeated until none is left or
/// PASSIVITY_PASSES. Weights: a mode's share of the kernel, |kappa| |b|^2 / |Re lambda|, times
/// 1 + (w_low / |lambda|)^2 with w_low = `low_band_rad_s`: a residue change dr at pole lambda moves the
/// added mass at low frequency by about dr / |lambda|^2 (r / (iw - lambda) to first order in w), and the
/// response of a DOF without restoring is its mass there, so slow modes pay for that leverage.
/// Re K(0) is not held at zero: K(0) = 0 with Re K >= 0 beside it asks a PSD curvature at w = 0 that the
/// low band's tiny damping does not have, and the enforcement does not converge with it.
fn enforce_passivity(
    poles: &[Complex64],
    mut b: DMatrix<Complex64>,
    mut c: DMatrix<Complex64>,
    grid: &[f64],
    low_band_rad_s: f64,
) -> (DMatrix<Complex64>, DMatrix<Complex64>, usize) {
    let (r, n) = (b.nrows(), b.ncols());
    let mut passes = 0;
    for _ in 0..PASSIVITY_PASSES {
        let viol = violations(poles, &b, &c, grid, 0.0);
        if viol.is_empty() {
            break;
        }
        passes += 1;
        let kappa = kappas(&b, &c);
        // unknowns: Re and Im of delta b_ja, index (j n + a) 2 + part
        let nu = 2 * n * r;
        let m = viol.len();
        let mut g = DMatrix::<f64>::zeros(m, nu);
        let mut d = DVector::<f64>::zeros(m);
        for (k, (w, lo, q)) in viol.iter().enumerate() {
            let s = Complex64::new(0.0, *w);
            for j in 0..r {
                let p = poles[j];
                let beta: Complex64 = (0..n).map(|a| b[(j, a)] * q[a]).sum();
                let h1 = 1.0 / (s - p);
                let gj = if is_real(p) {
                    2.0 * kappa[j] * beta * h1.re
                } else {
                    kappa[j] * beta * (h1 + (1.0 / (s - p.conj())).conj())
                };
                for a in 0..n {
                    g[(k, (j * n + a) * 2)] = gj.re * q[a];
                    g[(k, (j * n + a) * 2 + 1)] = -gj.im * q[a];
                }
            }
            d[k] = PASSIVITY_MARGIN - lo;
        }
        let winv: Vec<f64> = (0..r)
            .map(|j| {
                let bb: f64 = (0..n).map(|a| b[(j, a)].norm_sqr()).sum();
                let rho = kappa[j].norm() * bb / poles[j].re.abs().max(1e-12);
                let leverage = 1.0 + low_band_rad_s.powi(2) / poles[j].norm_sqr().max(1e-300);
                1.0 / (rho * leverage).max(1e-300)
            })
            .collect();
        let gw = DMatrix::from_fn(m, nu, |k, u| g[(k, u)] * winv[u / (2 * n)]);
        let mut ggt = &gw * g.transpose();
        let ridge = 1e-12 * ggt.diagonal().max().max(f64::MIN_POSITIVE);
        for k in 0..m {
            ggt[(k, k)] += ridge;
        }
        let Some(y) = ggt.lu().solve(&d) else { break };
        let dx = gw.transpose() * y;
        for j in 0..r {
            for a in 0..n {
                b[(j, a)] += Complex64::new(dx[(j * n + a) * 2], dx[(j * n + a) * 2 + 1]);
            }
            for a in 0..n {
                c[(a, j)] = kappa[j] * b[(j, a)];
            }
        }
    }
    (b, c, passes)
}

/// The smallest eigenvalue of the scaled Re K_r(iw) over `grid`.
pub fn min_scaled_damping(model: &ModalModel, grid: &[f64]) -> f64 {
    let n = model.n;
    let mut lo = f64::INFINITY;
    for w in grid {
        let k = model.kernel(*w);
        let m = DMatrix::from_fn(n, n, |i, j| {
            0.5 * (k[(i, j)].re + k[(j, i)].re) / (model.scale[i] * model.scale[j]).sqrt()
        });
        lo = lo.min(m.symmetric_eigen().eigenvalues.min());
    }
    lo
}

/// Real basis of the poles: for a real pole one function 1/(s-p); for a pair (p, conj p) two,
/// 1/(s-p) + 1/(s-p*) and i/(s-p) - i/(s-p*) (coefficients c1, c2 = residue c1 + i c2 at p).
fn basis(poles: &[Complex64], s: Complex64) -> Vec<Complex64> {
    let mut out = Vec::with_capacity(2 * poles.len());
    for p in poles {
        if is_real(*p) {
            out.push(1.0 / (s - p.re));
        } else {
            let (a, b) = (1.0 / (s - p), 1.0 / (s - p.conj()));
            out.push(a + b);
            out.push(Complex64::i() * (a - b));
        }
    }
    out
}

/// The real rows of a fit: frequency index and part (false: real, true: imaginary).
struct Rows<'a> {
    freqs: &'a [f64],
    rows: &'a [(usize, bool)],
    /// The database's band, where the starting poles go.
    band: (f64, f64),
}

impl Rows<'_> {
    /// The real matrix with one row per fit row: entry m of row (k, part) is part of f(k, m).
    fn matrix(&self, cols: usize, f: impl Fn(usize, usize) -> Complex64) -> DMatrix<f64> {
        DMatrix::from_fn(self.rows.len(), cols, |row, m| {
            let (k, im) = self.rows[row];
            let z = f(k, m);
            if im { z.im } else { z.re }
        })
    }

    /// The spacing of the fit's frequencies around `w`.
    fn spacing(&self, w: f64) -> f64 {
        let mut sorted: Vec<f64> = self.freqs.to_vec();
        sorted.sort_by(f64::total_cmp);
        let k = sorted.partition_point(|x| *x < w).clamp(1, sorted.len() - 1);
        let lo = sorted[k] - sorted[k - 1];
        let hi = if k + 1 < sorted.len() {
            sorted[k + 1] - sorted[k]
        } else {
            lo
        };
        lo.max(hi)
    }

    fn basis(&self, poles: &[Complex64]) -> Vec<Vec<Complex64>> {
        self.freqs
            .iter()
            .map(|w| basis(poles, Complex64::new(0.0, *w)))
            .collect()
    }
}

/// Starting poles: `pairs` lightly damped pairs spread evenly over the data's band.
fn start_poles(band: (f64, f64), pairs: usize) -> Vec<Complex64> {
    let (lo, hi) = band;
    (0..pairs)
        .map(|k| {
            let w = lo + (hi - lo) * (k as f64 + 0.5) / pairs as f64;
            Complex64::new(-w / 100.0, w)
        })
        .collect()
}

/// Relaxed vector fitting: relocated poles (Im >= 0, one per pair) after VF_ITERATIONS passes.
fn relocate(set: &Rows, data: &[Vec<Complex64>], pairs: usize) -> Vec<Complex64> {
    let nw = set.freqs.len();
    let ne = data.len();
    let mut poles = start_poles(set.band, pairs);
    for _ in 0..VF_ITERATIONS {
        let phi = set.basis(&poles);
        let np = phi[0].len();
        // Phi (real rows x np) and its orthogonal complement's projector, once for every entry
        let a1 = set.matrix(np, |k, m| phi[k][m]);
        let q1 = a1.clone().qr().q();
        // stacked R22 blocks of every entry: the sigma unknowns (np + 1: coefficients, then d)
        let mut stack: Vec<f64> = vec![];
        let mut rows = 0;
        for f in data {
            let a2 = set.matrix(np + 1, |k, m| if m < np { -f[k] * phi[k][m] } else { -f[k] });
            let proj = &a2 - &q1 * (q1.transpose() * &a2);
            let r22 = proj.qr().r();
            for rr in 0..r22.nrows() {
                stack.extend(r22.row(rr).iter());
                rows += 1;
            }
        }
        // relaxation: the mean of Re sigma over the frequencies is 1
        let scale_row = data
            .iter()
            .map(|f| f.iter().map(|z| z.norm_sqr()).sum::<f64>())
            .sum::<f64>()
            .sqrt()
            / (nw as f64 * ne as f64).sqrt();
        let mut relax = vec![0.0; np + 1];
        for row in &phi {
            for m in 0..np {
                relax[m] += row[m].re;
            }
        }
        relax[np] = nw as f64;
        let mut a = DMatrix::from_row_slice(rows, np + 1, &stack);
        a = a.insert_row(rows, 0.0);
        let mut y = DVector::zeros(rows + 1);
        for m in 0..=np {
            a[(rows, m)] = relax[m] * scale_row;
        }
        y[rows] = nw as f64 * scale_row;
        // column scaling for conditioning
        let norms: Vec<f64> = (0..=np).map(|m| a.column(m).norm().max(f64::MIN_POSITIVE)).collect();
        for m in 0..=np {
            let nm = norms[m];
            a.column_mut(m).scale_mut(1.0 / nm);
        }
        let Ok(x) = a.svd(true, true).solve(&y, 1e-14) else {
            break;
        };
        let coef: Vec<f64> = (0..=np).map(|m| x[m] / norms[m]).collect();
        let d = coef[np];
        let d = if d.abs() < 1e-8 { 1e-8_f64.copysign(d) } else { d };
        // zeros of sigma: eig(A - b c^T / d) of the real realization of the basis
        let mut am = DMatrix::<f64>::zeros(np, np);
        let mut bv = DVector::<f64>::zeros(np);
        let mut m = 0;
        for p in &poles {
            if is_real(*p) {
                am[(m, m)] = p.re;
                bv[m] = 1.0;
                m += 1;
            } else {
                am[(m, m)] = p.re;
                am[(m, m + 1)] = p.im;
                am[(m + 1, m)] = -p.im;
                am[(m + 1, m + 1)] = p.re;
                bv[m] = 2.0;
                m += 2;
            }
        }
        let cv = DVector::from_fn(np, |k, _| coef[k]);
        let z = am - &bv * cv.transpose() / d;
        let eig = z.complex_eigenvalues();
        let mut next: Vec<Complex64> = vec![];
        for e in eig.iter() {
            let mut e = *e;
            if e.re > 0.0 {
                e.re = -e.re;
            }
            // no narrower than the data can see: half-width at least MIN_HALF_WIDTH x the local spacing
            e.re = e.re.min(-MIN_HALF_WIDTH * set.spacing(e.im.abs()));
            if is_real(e) {
                next.push(Complex64::new(e.re, 0.0));
            } else if e.im > 0.0 {
                next.push(e);
            }
        }
        if next.is_empty() {
            break;
        }
        next.sort_by(|a, b| a.im.total_cmp(&b.im));
        poles = next;
    }
    poles
}

/// Residues with the poles fixed (linear least squares, every entry at once): the coefficient matrix
/// (basis functions x entries) and the largest scaled error over the data.
fn residues(set: &Rows, data: &[Vec<Complex64>], poles: &[Complex64]) -> (DMatrix<f64>, f64) {
    let phi = set.basis(poles);
    let np = phi[0].len();
    let a = set.matrix(np, |k, m| phi[k][m]);
    let y = set.matrix(data.len(), |k, e| data[e][k]);
    // K(0) = 0 exactly (no damping of a steady drift, as the data's B(0) = 0 and the convolution's K
    // integrate to): residues r = N z with N spanning the null space of the row phi(0)
    let phi0 = DVector::from_iterator(np, basis(poles, Complex64::default()).iter().map(|z| z.re));
    let null = null_space_of_row(&phi0);
    let sol = (&a * &null)
        .svd(true, true)
        .solve(&y, 1e-13)
        .map(|z| &null * z)
        .unwrap_or_else(|_| DMatrix::zeros(np, data.len()));
    // the largest error at a database frequency (both parts)
    let fit = &a * &sol;
    let mut err = vec![0.0f64; set.freqs.len() * data.len()];
    for (row, &(k, _)) in set.rows.iter().enumerate() {
        for e in 0..data.len() {
            let d = fit[(row, e)] - y[(row, e)];
            err[k * data.len() + e] += d * d;
        }
    }
    let inband = set.freqs.iter().position(|w| *w == 0.0).unwrap_or(set.freqs.len());
    let worst = err[..inband * data.len()].iter().copied().fold(0.0, f64::max).sqrt();
    (sol, worst)
}

/// An orthonormal basis (columns) of the vectors orthogonal to `row`.
fn null_space_of_row(row: &DVector<f64>) -> DMatrix<f64> {
    let np = row.len();
    let nrm = row.norm();
    if nrm == 0.0 {
        return DMatrix::identity(np, np);
    }
    // Householder reflector taking row / |row| to e_1: its other columns span the complement
    let mut u = row / nrm;
    u[0] += if u[0] >= 0.0 { 1.0 } else { -1.0 };
    let h = DMatrix::identity(np, np) - &u * u.transpose() * (2.0 / u.norm_squared());
    h.columns(1, np - 1).into_owned()
}

/// The real realization of a pole-residue fit: per pole block p of size d_p (1 real, 2 complex) and
/// per DOF alpha, states (p, a, alpha) at offset(p) + a n + alpha; A = S_p (x) I_n, B = e_1 (x) I_n,
/// C_p = residue (real pole) or [2 Re R, -2 Im R] (pair).
struct Realization {
    n: usize,
    /// The small blocks S_p.
    s: Vec<DMatrix<f64>>,
    /// Output map, n x order.
    c: DMatrix<f64>,
    offsets: Vec<usize>,
}

impl Realization {
    fn new(n: usize, poles: &[Complex64], res: &DMatrix<f64>, entries: &[(usize, usize)]) -> Realization {
        let mut s = vec![];
        let mut offsets = vec![];
        let mut off = 0;
        let mut cols: Vec<(usize, usize, bool)> = vec![]; // (basis index, offset, complex)
        let mut m = 0;
        for p in poles {
            offsets.push(off);
            if is_real(*p) {
                s.push(DMatrix::from_element(1, 1, p.re));
                cols.push((m, off, false));
                m += 1;
                off += n;
            } else {
                s.push(DMatrix::from_row_slice(2, 2, &[p.re, -p.im, p.im, p.re]));
                cols.push((m, off, true));
                m += 2;
                off += 2 * n;
            }
        }
        let mut c = DMatrix::zeros(n, off);
        for (e, &(i, j)) in entries.iter().enumerate() {
            for &(m, off, complex) in &cols {
                for (a, b) in [(i, j), (j, i)] {
                    if complex {
                        // residue R = c1 + i c2; y = 2 (Re R x1 - Im R x2)
                        c[(a, off + b)] = 2.0 * res[(m, e)];
                        c[(a, off + n + b)] = -2.0 * res[(m + 1, e)];
                    } else {
                        c[(a, off + b)] = res[(m, e)];
                    }
                }
            }
        }
        Realization { n, s, c, offsets }
    }

    fn order(&self) -> usize {
        self.c.ncols()
    }

    /// Dense A (order x order).
    fn a_dense(&self) -> DMatrix<f64> {
        let n = self.n;
        let mut a = DMatrix::zeros(self.order(), self.order());
        for (s, &off) in self.s.iter().zip(&self.offsets) {
            for r in 0..s.nrows() {
                for c in 0..s.ncols() {
                    for al in 0..n {
                        a[(off + r * n + al, off + c * n + al)] = s[(r, c)];
                    }
                }
            }
        }
        a
    }

    /// Dense B (order x n).
    fn b_dense(&self) -> DMatrix<f64> {
        let n = self.n;
        let mut b = DMatrix::zeros(self.order(), n);
        for &off in &self.offsets {
            for al in 0..n {
                b[(off + al, al)] = 1.0;
            }
        }
        b
    }

    /// Square-root balanced truncation: (A_r, B_r, C_r) and the Hankel singular values.
    /// Truncation, not singular perturbation: the latter keeps the fit's K(0) = 0 but moves the same
    /// error to infinite frequency as a feedthrough D_r = -C_2 A_22^-1 B_2 of both signs, a damping that
    /// no residue reaches.
    fn balanced_truncation(&self, tol: f64) -> (DMatrix<f64>, DMatrix<f64>, DMatrix<f64>, Vec<f64>) {
        let n = self.n;
        let nb = self.s.len();
        let dims: Vec<usize> = self.s.iter().map(|s| s.nrows()).collect();
        let small_off: Vec<usize> = dims
            .iter()
            .scan(0, |acc, d| {
                let o = *acc;
                *acc += d;
                Some(o)
            })
            .collect();
        let ns: usize = dims.iter().sum();
        // controllability: P = X (x) I_n, S_p X_pq + X_pq S_q^T + e1 e1^T = 0
        let mut x = DMatrix::zeros(ns, ns);
        for p in 0..nb {
            for q in 0..nb {
                let rhs = DMatrix::from_fn(dims[p], dims[q], |a, b| if a == 0 && b == 0 { -1.0 } else { 0.0 });
                let sol = sylvester(&self.s[p], &self.s[q].transpose(), &rhs);
                x.view_mut((small_off[p], small_off[q]), (dims[p], dims[q]))
                    .copy_from(&sol);
            }
        }
        let lx = sqrt_factor(&((&x + x.transpose()) * 0.5));
        // observability: A^T Q + Q A + C^T C = 0, per (p, q) and per DOF pair (alpha, beta)
        let order = self.order();
        let ctc = self.c.transpose() * &self.c;
        let mut qm = DMatrix::zeros(order, order);
        for p in 0..nb {
            for q in 0..nb {
                let (dp, dq) = (dims[p], dims[q]);
                let op = sylvester_operator(&self.s[p].transpose(), &self.s[q]);
                let lu = op.lu();
                for al in 0..n {
                    for be in 0..n {
                        let rhs = DVector::from_fn(dp * dq, |k, _| {
                            let (a, b) = (k % dp, k / dp);
                            -ctc[(self.offsets[p] + a * n + al, self.offsets[q] + b * n + be)]
                        });
                        let y = lu.solve(&rhs).unwrap_or_else(|| DVector::zeros(dp * dq));
                        for k in 0..dp * dq {
                            let (a, b) = (k % dp, k / dp);
                            qm[(self.offsets[p] + a * n + al, self.offsets[q] + b * n + be)] = y[k];
                        }
                    }
                }
            }
        }
        let lq = sqrt_factor(&((&qm + qm.transpose()) * 0.5));
        // Lp = Lx (x) I_n: column (c, beta); rows of the full order
        let kp = lx.ncols() * n;
        let mut lp = DMatrix::zeros(order, kp);
        for p in 0..nb {
            for a in 0..dims[p] {
                for col in 0..lx.ncols() {
                    let v = lx[(small_off[p] + a, col)];
                    for al in 0..n {
                        lp[(self.offsets[p] + a * n + al, col * n + al)] = v;
                    }
                }
            }
        }
        let m = lq.transpose() * &lp;
        let svd = m.svd(true, true);
        let (Some(u), Some(vt)) = (svd.u, svd.v_t) else {
            return (DMatrix::zeros(0, 0), DMatrix::zeros(0, n), DMatrix::zeros(n, 0), vec![]);
        };
        // sort singular values descending (nalgebra does not promise an order)
        let mut idx: Vec<usize> = (0..svd.singular_values.len()).collect();
        idx.sort_by(|a, b| svd.singular_values[*b].total_cmp(&svd.singular_values[*a]));
        let hankel: Vec<f64> = idx.iter().map(|k| svd.singular_values[*k]).collect();
        let total_tail: Vec<f64> = {
            let mut t = vec![0.0; hankel.len() + 1];
            for k in (0..hankel.len()).rev() {
                t[k] = t[k + 1] + hankel[k];
            }
            t
        };
        let top = hankel.first().copied().unwrap_or(0.0);
        let mut r = hankel.len();
        for k in 1..=hankel.len() {
            if 2.0 * total_tail[k] <= tol || hankel[k - 1] <= 1e-13 * top {
                r = k;
                break;
            }
        }
        let tr = DMatrix::from_fn(kp, r, |row, c| vt[(idx[c], row)] / hankel[c].sqrt());
        let tl = DMatrix::from_fn(lq.ncols(), r, |row, c| u[(row, idx[c])] / hankel[c].sqrt());
        let t_right = &lp * tr;
        let t_left = &lq * tl;
        let ar = t_left.transpose() * (self.a_dense() * &t_right);
        let br = t_left.transpose() * self.b_dense();
        let cr = &self.c * t_right;
        (ar, br, cr, hankel)
    }
}

/// (I (x) A + B^T (x) I) for A X + X B = rhs, column-major vec.
fn sylvester_operator(a: &DMatrix<f64>, b: &DMatrix<f64>) -> DMatrix<f64> {
    let (m, k) = (a.nrows(), b.nrows());
    DMatrix::from_fn(m * k, m * k, |row, col| {
        let (i, j) = (row % m, row / m);
        let (p, q) = (col % m, col / m);
        let mut v = 0.0;
        if j == q {
            v += a[(i, p)];
        }
        if i == p {
            v += b[(q, j)];
        }
        v
    })
}

/// Solves A X + X B = rhs (small).
fn sylvester(a: &DMatrix<f64>, b: &DMatrix<f64>, rhs: &DMatrix<f64>) -> DMatrix<f64> {
    let (m, k) = (a.nrows(), b.nrows());
    let op = sylvester_operator(a, b);
    let v = DVector::from_fn(m * k, |row, _| rhs[(row % m, row / m)]);
    let x = op.lu().solve(&v).unwrap_or_else(|| DVector::zeros(m * k));
    DMatrix::from_fn(m, k, |i, j| x[j * m + i])
}

/// L with L L^T = M (symmetric PSD up to round-off): eigenvectors scaled by the square roots of the
/// eigenvalues above GRAMIAN_FLOOR of the largest.
fn sqrt_factor(m: &DMatrix<f64>) -> DMatrix<f64> {
    let eig = m.clone().symmetric_eigen();
    let top = eig.eigenvalues.iter().copied().fold(0.0, f64::max);
    let keep: Vec<usize> = (0..eig.eigenvalues.len())
        .filter(|k| eig.eigenvalues[*k] > GRAMIAN_FLOOR * top)
        .collect();
    DMatrix::from_fn(m.nrows(), keep.len(), |r, c| {
        eig.eigenvectors[(r, keep[c])] * eig.eigenvalues[keep[c]].sqrt()
    })
}

type Modal = (Vec<Complex64>, DMatrix<Complex64>, DMatrix<Complex64>);

/// Modal form of a real (A, B, C): poles with Im >= 0, B_m (r x n) and C_m (n x r, factor 2 of complex
/// modes included).
fn modal_form(a: &DMatrix<f64>, b: &DMatrix<f64>, c: &DMatrix<f64>) -> Result<Modal, FitError> {
    let r = a.nrows();
    let n = b.ncols();
    if r == 0 {
        return Ok((vec![], DMatrix::zeros(0, n), DMatrix::zeros(n, 0)));
    }
    let ac = a.map(|x| Complex64::new(x, 0.0));
    let (q, t) = nalgebra::linalg::Schur::try_new(ac, 1e-15, 10_000)
        .ok_or_else(|| FitError("the reduced model's Schur decomposition did not converge".into()))?
        .unpack();
    // eigenvectors of the upper triangular T by back-substitution
    let mut y = DMatrix::from_element(r, r, Complex64::default());
    let tiny = 1e-14 * t.iter().map(|z| z.norm()).fold(0.0, f64::max).max(1e-300);
    for k in 0..r {
        y[(k, k)] = Complex64::new(1.0, 0.0);
        for j in (0..k).rev() {
            let mut s = Complex64::default();
            for l in j + 1..=k {
                s += t[(j, l)] * y[(l, k)];
            }
            let mut d = t[(j, j)] - t[(k, k)];
            if d.norm() < tiny {
                d = Complex64::new(tiny, 0.0);
            }
            y[(j, k)] = -s / d;
        }
    }
    let mut v = q * y;
    for k in 0..r {
        let nrm = v.column(k).norm();
        if nrm > 0.0 {
            v.column_mut(k).scale_mut(1.0 / nrm);
        }
    }
    let vinv = v
        .clone()
        .try_inverse()
        .ok_or_else(|| FitError("the reduced model is defective (no eigenvector basis)".into()))?;
    let bm = &vinv * b.map(|x| Complex64::new(x, 0.0));
    let cm = c.map(|x| Complex64::new(x, 0.0)) * &v;
    let mut keep = vec![];
    for k in 0..r {
        let p = t[(k, k)];
        if is_real(p) {
            keep.push((k, 1.0));
        } else if p.im > 0.0 {
            keep.push((k, 2.0));
        }
    }
    let poles = keep
        .iter()
        .map(|(k, _)| {
            let p = t[(*k, *k)];
            if is_real(p) { Complex64::new(p.re, 0.0) } else { p }
        })
        .collect();
    let bo = DMatrix::from_fn(keep.len(), n, |j, i| bm[(keep[j].0, i)]);
    let co = DMatrix::from_fn(n, keep.len(), |i, j| cm[(i, keep[j].0)] * keep[j].1);
    Ok((poles, bo, co))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Re K(0) worked by hand: a real mode g / (s + a) gives g / a; a complex one, 0.5 c^2 / (s - p) +
    /// its conjugate, gives Re(-c^2 / p).
    #[test]
    fn zero_frequency_damping_is_the_kernel_at_zero() {
        let (g, a): (f64, f64) = (3.0, 0.5);
        let (c, p) = (Complex64::new(1.0, 0.5), Complex64::new(-0.2, 0.8));
        let model = ModalModel {
            n: 2,
            poles: vec![Complex64::new(-a, 0.0), p],
            // DOF-major: DOF 0 sees only the real mode, DOF 1 only the complex one
            a: vec![
                Complex64::new(g.sqrt(), 0.0),
                Complex64::default(),
                Complex64::default(),
                c,
            ],
            scale: vec![1.0, 1.0],
            cover: 0.0,
            passivity_passes: 0,
            fit_pairs: 0,
            fit_error: 0.0,
            full_order: 3,
            hankel: vec![],
        };
        let k0 = model.zero_frequency_damping();
        assert!((k0[0] - g / a).abs() < 1e-12, "{k0:?}");
        assert!((k0[1] - (-c * c / p).re).abs() < 1e-12, "{k0:?}");
    }

    /// A known passive 2 x 2 kernel, three band-pass terms with PSD gains (K(0) = 0, as radiation's):
    /// the fit, reduction and passivity enforcement reproduce it. Measured worst 2.0e-4 of the scale with
    /// fit and reduction tolerances of 1e-3 (the default reduction, 0.02, drops the weak narrow term).
    #[test]
    fn recovers_a_known_rational_kernel() {
        const TOL: f64 = 1e-3;
        let terms = [
            (0.4, 0.1, [1.0, 0.3, 0.5]),
            (1.0, 0.3, [2.0, -0.5, 1.0]),
            (1.3, 0.01, [0.05, 0.04, 0.05]),
        ];
        let k = |w: f64| {
            let s = Complex64::new(0.0, w);
            let mut m = DMatrix::from_element(2, 2, Complex64::default());
            for (w0, z, g) in &terms {
                let h = 2.0 * z * w0 * s / (s * s + 2.0 * z * w0 * s + w0 * w0);
                m[(0, 0)] += h * g[0];
                m[(0, 1)] += h * g[1];
                m[(1, 0)] += h * g[1];
                m[(1, 1)] += h * g[2];
            }
            m
        };
        let ws: Vec<f64> = (1..=2000).map(|i| i as f64 * 0.006).collect();
        let b: Vec<DMatrix<f64>> = ws.iter().map(|w| k(*w).map(|z| z.re)).collect();
        let ai = DMatrix::from_element(2, 2, 1.0);
        let a: Vec<DMatrix<f64>> = ws.iter().map(|w| k(*w).map(|z| z.im / w) + &ai).collect();
        let opts = ModalOptions {
            tolerance: 0.001,
            reduction_tolerance: 0.001,
        };
        let tail = DampingTail::cubic(&ws, &b);
        let m = fit(&ws, &b, &a, &ai, &tail, opts).unwrap();
        let scale = super::super::irf::diagonal_peaks(&b);
        let mut worst = 0.0f64;
        for w in &ws {
            let (kt, kf) = (k(*w), m.kernel(*w));
            for i in 0..2 {
                for j in 0..2 {
                    worst = worst.max((kt[(i, j)] - kf[(i, j)]).norm() / (scale[i] * scale[j]).sqrt());
                }
            }
        }
        eprintln!(
            "known kernel: worst scaled error {worst:.2e}, {} modes, cover {}",
            m.modes(),
            m.cover
        );
        assert!(worst < TOL, "worst scaled error {worst}, {} modes", m.modes());
        assert!(m.poles.iter().all(|p| p.re < 0.0));
        assert!(m.cover == 0.0, "passivity left to the cover: {}", m.cover);
    }

    /// A DOF with no damping at all (one that does not radiate) is fitted as zero, not divided by its
    /// zero scale; data that are not finite are refused (an SVD of NaN did not return).
    #[test]
    fn a_dof_without_damping_fits_as_zero_and_non_finite_data_are_refused() {
        let ws: Vec<f64> = (1..=400).map(|i| i as f64 * 0.01).collect();
        let h = |w: f64| {
            let s = Complex64::new(0.0, w);
            2.0 * 0.2 * s / (s * s + 2.0 * 0.2 * s + 1.0)
        };
        let b: Vec<DMatrix<f64>> = ws
            .iter()
            .map(|w| DMatrix::from_fn(2, 2, |i, j| if i + j == 0 { h(*w).re } else { 0.0 }))
            .collect();
        let a: Vec<DMatrix<f64>> = ws
            .iter()
            .map(|w| DMatrix::from_fn(2, 2, |i, j| if i + j == 0 { 1.0 + h(*w).im / w } else { 0.0 }))
            .collect();
        let ai = DMatrix::from_fn(2, 2, |i, j| if i + j == 0 { 1.0 } else { 0.0 });
        let tail = DampingTail::cubic(&ws, &b);
        let m = fit(&ws, &b, &a, &ai, &tail, ModalOptions::default()).expect("a fit");
        for w in [0.1, 1.0, 3.0] {
            let k = m.kernel(w);
            assert!(k[(1, 1)].norm() < 1e-12 && k[(0, 1)].norm() < 1e-12, "w {w}: {k}");
            assert!(
                (k[(0, 0)] - h(w)).norm() < 0.01,
                "w {w}: {} against {}",
                k[(0, 0)],
                h(w)
            );
        }
        let mut bad = b.clone();
        bad[7][(0, 0)] = f64::NAN;
        assert!(fit(&ws, &bad, &a, &ai, &tail, ModalOptions::default()).is_err());
    }
}
