//! State-space approximation of the radiation memory, passive and stable by construction (pure).
//!
//! The model: K_ss(s) = sum_k G_k H_k(s), with fixed band-pass terms, a = 2 z_k w_k, b = w_k^2:
//!   second order  H2(s) = a s / (s^2 + a s + b),                   Re H2(iw) = r(w)
//!   fourth order  H4(s) = (a s / 2)(s^2 + 2 a s + b) / (s^2 + a s + b)^2,   Re H4(iw) = r(w)^2
//! with r(w) = (a w)^2 / ((b - w^2)^2 + (a w)^2) in [0, 1] (z_k > 0: stable). Both are positive real
//! (stable, non-negative real part on the imaginary axis; H4's numerator is the one that makes its real
//! part exactly r^2, derived by matching coefficients), and the gain matrices G_k are symmetric positive
//! semi-definite: a sum of positive real terms with PSD weights is positive real, so the model is passive
//! by construction, and stable. The fourth-order terms fall off as w^-4 above their band, as hydrodynamic
//! damping does; second-order terms alone cannot follow a steep high-frequency decay with PSD weights.
//!
//! Fit: only the damping B(w) = Re K(iw) is fitted (weighted least squares over the database
//! frequencies, trapezoid weights so dense and sparse parts of a grid count by bandwidth); the added mass
//! follows by Kramers-Kronig, A_ss(w) = A_inf + Im K_ss(iw) / w, consistent with the IRF that the
//! convolution uses. Terms are chosen from a dictionary (centres spaced by DICT_RATIO from the lowest to
//! 1.5x the highest database frequency, damping ratios DICT_ZETAS) by non-negative least squares on each
//! diagonal entry (Lawson-Hanson: sparse), plus narrow terms placed greedily at the largest remaining
//! residual with a width from its half-maximum (gap resonances); the union of the terms used is then fitted
//! on the whole matrix with every G_k constrained PSD (accelerated projected gradient), and terms with a
//! negligible gain are dropped.
//!
//! Realization (states grouped by radiating DOF, as OpenFAST does): for term k and velocity DOF j, two
//! states (q, q') with q'' + 2 z_k w_k q' + w_k^2 q = v_j; the force is F = sum_k 2 z_k w_k G_k q'_k.

use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;

/// Dictionary: ratio between successive centre frequencies.
pub const DICT_RATIO: f64 = 1.08;
/// Dictionary: damping ratios at every centre (narrow terms follow steep slopes; wide ones fill humps).
pub const DICT_ZETAS: [f64; 3] = [0.03, 0.1, 0.3];
/// Projected-gradient iterations of the PSD gain fit: at most this many, stopping when a step changes
/// the gains by less than FISTA_STEP_TOL of their size.
pub const FISTA_MAX_ITERATIONS: usize = 3000;
pub const FISTA_STEP_TOL: f64 = 1e-7;
/// Terms whose gain is below this fraction of the largest are dropped.
pub const PRUNE: f64 = 1e-4;

/// Fitting options.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SsFitOptions {
    /// Stop adding narrow terms when the largest scaled residual is below this (fraction of the scale).
    pub tolerance: f64,
    /// Upper bound on the number of terms (broad + narrow).
    pub max_terms: usize,
}

impl Default for SsFitOptions {
    fn default() -> Self {
        SsFitOptions {
            tolerance: 0.005,
            max_terms: 40,
        }
    }
}

/// The shape of a band-pass term: centre, damping ratio, order (2 or 4).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Shape {
    pub omega_rad_s: f64,
    pub zeta: f64,
    pub fourth: bool,
}

impl Shape {
    /// Re H(i w).
    pub fn re(&self, w: f64) -> f64 {
        let r = band_pass_re(self.omega_rad_s, self.zeta, w);
        if self.fourth { r * r } else { r }
    }

    /// H(i w).
    pub fn h(&self, w: f64) -> Complex64 {
        let (num, den) = self.polynomials();
        let s = Complex64::new(0.0, w);
        let eval = |p: &[f64]| p.iter().rev().fold(Complex64::default(), |acc, c| acc * s + c);
        eval(&num) / eval(&den)
    }

    /// (numerator, denominator) coefficients, lowest power first; the denominator is monic.
    pub fn polynomials(&self) -> (Vec<f64>, Vec<f64>) {
        let a = 2.0 * self.zeta * self.omega_rad_s;
        let b = self.omega_rad_s * self.omega_rad_s;
        if self.fourth {
            (
                vec![0.0, a * b / 2.0, a * a, a / 2.0],
                vec![b * b, 2.0 * a * b, a * a + 2.0 * b, 2.0 * a, 1.0],
            )
        } else {
            (vec![0.0, a], vec![b, a, 1.0])
        }
    }

    /// Number of states per velocity DOF.
    pub fn order(&self) -> usize {
        if self.fourth { 4 } else { 2 }
    }
}

/// One band-pass term with its gain matrix.
#[derive(Debug, Clone, PartialEq)]
pub struct SsTerm {
    pub shape: Shape,
    /// Symmetric PSD, n x n (force mode i from velocity mode j).
    pub gain: DMatrix<f64>,
}

/// A fitted state-space radiation model.
#[derive(Debug, Clone, PartialEq)]
pub struct SsModel {
    pub terms: Vec<SsTerm>,
    /// Largest scaled damping error over the fitted frequencies (after the PSD projection).
    pub fit_error: f64,
}

impl SsModel {
    /// K_ss(i w) = B_ss(w) + i w (A_ss(w) - A_inf).
    pub fn kernel(&self, w: f64) -> DMatrix<Complex64> {
        let n = self.terms.first().map(|t| t.gain.nrows()).unwrap_or(0);
        let mut k = DMatrix::from_element(n, n, Complex64::default());
        for t in &self.terms {
            let h = t.shape.h(w);
            k.zip_apply(&t.gain, |a, g| *a += h * g);
        }
        k
    }

    /// Number of states for `n` radiating DOFs.
    pub fn n_states(&self) -> usize {
        let n = self.terms.first().map(|t| t.gain.nrows()).unwrap_or(0);
        n * self.terms.iter().map(|t| t.shape.order()).sum::<usize>()
    }
}

fn band_pass_re(w0: f64, zeta: f64, w: f64) -> f64 {
    let a = 2.0 * zeta * w0 * w;
    let d = w0 * w0 - w * w;
    a * a / (d * d + a * a)
}

/// Fits the model to damping samples `damping[k]` at ascending `omegas[k]` (n x n each, passive).
pub fn fit(omegas: &[f64], damping: &[DMatrix<f64>], opts: SsFitOptions) -> SsModel {
    fit_with_added_mass(omegas, damping, None, opts)
}

/// As [`fit`], and when `added` = (A(w) per frequency, A_inf) is given, the gains also fit
/// Im K(iw) = w (A(w) - A_inf) (scaled by the damping scale), so that the model's added mass follows
/// the data locally and not only through its damping's Hilbert transform.
pub fn fit_with_added_mass(
    omegas: &[f64],
    damping: &[DMatrix<f64>],
    added: Option<(&[DMatrix<f64>], &DMatrix<f64>)>,
    opts: SsFitOptions,
) -> SsModel {
    let nw = omegas.len();
    let n = damping.first().map(|b| b.nrows()).unwrap_or(0);
    if nw < 2 || n == 0 {
        return SsModel {
            terms: vec![],
            fit_error: 0.0,
        };
    }
    // trapezoid weights
    let wts: Vec<f64> = (0..nw)
        .map(|i| {
            let lo = if i == 0 { omegas[0] } else { omegas[i - 1] };
            let hi = if i + 1 == nw { omegas[nw - 1] } else { omegas[i + 1] };
            (0.5 * (hi - lo)).max(1e-12)
        })
        .collect();
    let scale = super::radiation::diagonal_peaks(damping);
    let sc = |i: usize, j: usize| (scale[i] * scale[j]).sqrt();
    // dictionary
    let mut dict: Vec<Shape> = vec![];
    let (lo, hi) = (omegas[0].max(1e-3), 1.5 * omegas[nw - 1]);
    let mut c = lo;
    while c <= hi {
        for z in DICT_ZETAS {
            for fourth in [false, true] {
                dict.push(Shape {
                    omega_rad_s: c,
                    zeta: z,
                    fourth,
                });
            }
        }
        c *= DICT_RATIO;
    }
    // per diagonal entry: NNLS on the dictionary, then narrow terms at the largest residuals
    let mut chosen: Vec<Shape> = vec![];
    for i in 0..n {
        let b: Vec<f64> = damping.iter().map(|m| m[(i, i)] / scale[i]).collect();
        let mut terms = dict.clone();
        for _ in 0..opts.max_terms {
            let g = nnls_fit(omegas, &wts, &b, &terms, 0.5 * opts.tolerance);
            let resid: Vec<f64> = (0..nw)
                .map(|w| {
                    let f: f64 = terms.iter().zip(&g).map(|(t, gk)| gk * t.re(omegas[w])).sum();
                    (f - b[w]).abs()
                })
                .collect();
            let (imax, rmax) = resid
                .iter()
                .copied()
                .enumerate()
                .fold((0, 0.0), |a, b| if b.1 > a.1 { b } else { a });
            // a narrow term at the largest residual, as wide as the residual's peak at half maximum
            let mut l = imax;
            while l > 0 && resid[l] > 0.5 * rmax {
                l -= 1;
            }
            let mut r = imax;
            while r + 1 < nw && resid[r] > 0.5 * rmax {
                r += 1;
            }
            let width = (omegas[r] - omegas[l]).max(omegas[(imax + 1).min(nw - 1)] - omegas[imax.saturating_sub(1)]);
            let new = Shape {
                omega_rad_s: omegas[imax],
                zeta: (0.5 * width / omegas[imax]).clamp(0.002, 0.5),
                fourth: false,
            };
            if rmax <= 0.5 * opts.tolerance || terms.contains(&new) || terms.len() >= dict.len() + opts.max_terms {
                let gmax = g.iter().copied().fold(0.0, f64::max);
                chosen.extend(
                    terms
                        .iter()
                        .zip(&g)
                        .filter(|(_, gk)| **gk > PRUNE * gmax)
                        .map(|(t, _)| *t),
                );
                break;
            }
            terms.push(new);
        }
    }
    chosen.sort_by(|a, b| {
        a.omega_rad_s
            .total_cmp(&b.omega_rad_s)
            .then(a.zeta.total_cmp(&b.zeta))
            .then(a.fourth.cmp(&b.fourth))
    });
    chosen.dedup();
    let mut terms = chosen;
    let mut scaled = psd_gains(omegas, &wts, damping, added, &terms, &sc);
    // drop negligible terms and refit
    let gmax = scaled.iter().map(|g| g.amax()).fold(0.0, f64::max);
    if scaled.iter().any(|g| g.amax() <= PRUNE * gmax) {
        terms = terms
            .into_iter()
            .zip(&scaled)
            .filter(|(_, g)| g.amax() > PRUNE * gmax)
            .map(|(t, _)| t)
            .collect();
        scaled = psd_gains(omegas, &wts, damping, added, &terms, &sc);
    }
    let out: Vec<SsTerm> = terms
        .iter()
        .zip(scaled)
        .map(|(shape, g)| SsTerm {
            shape: *shape,
            gain: DMatrix::from_fn(n, n, |i, j| g[(i, j)] * sc(i, j)),
        })
        .collect();
    let fit_error = {
        let gs: Vec<DMatrix<f64>> = out.iter().map(|t| t.gain.clone()).collect();
        residual(omegas, damping, &terms, &gs, &sc)
            .into_iter()
            .fold(0.0, f64::max)
    };
    SsModel { terms: out, fit_error }
}

/// Non-negative weighted least squares of b(w) on the band-pass terms (Lawson & Hanson 1974, ch. 23),
/// stopped as soon as the largest residual is below `tol`: the terms enter one at a time, the most
/// useful first, so stopping early keeps the model small.
fn nnls_fit(omegas: &[f64], wts: &[f64], b: &[f64], terms: &[Shape], tol: f64) -> Vec<f64> {
    let (nw, nt) = (omegas.len(), terms.len());
    let a = DMatrix::from_fn(nw, nt, |i, k| terms[k].re(omegas[i]) * wts[i].sqrt());
    let y = DVector::from_fn(nw, |i, _| b[i] * wts[i].sqrt());
    let done = |x: &DVector<f64>| {
        (0..nw).all(|i| {
            let f: f64 = (0..nt)
                .filter(|k| x[*k] != 0.0)
                .map(|k| x[k] * terms[k].re(omegas[i]))
                .sum();
            (f - b[i]).abs() <= tol
        })
    };
    nnls(&a, &y, done)
}

/// Lawson-Hanson active-set NNLS: min |A x - y| subject to x >= 0, stopping early when `done(x)`.
pub fn nnls(a: &DMatrix<f64>, y: &DVector<f64>, done: impl Fn(&DVector<f64>) -> bool) -> Vec<f64> {
    let nt = a.ncols();
    let mut x = DVector::zeros(nt);
    let mut passive = vec![false; nt];
    let tol = 1e-12 * a.norm() * y.norm().max(f64::MIN_POSITIVE);
    let solve_passive = |passive: &[bool]| -> DVector<f64> {
        let idx: Vec<usize> = (0..nt).filter(|k| passive[*k]).collect();
        let sub = DMatrix::from_fn(a.nrows(), idx.len(), |i, c| a[(i, idx[c])]);
        let sol = sub
            .clone()
            .svd(true, true)
            .solve(y, 1e-14)
            .unwrap_or_else(|_| DVector::zeros(idx.len()));
        let mut z = DVector::zeros(nt);
        for (c, k) in idx.iter().enumerate() {
            z[*k] = sol[c];
        }
        z
    };
    for _ in 0..3 * nt {
        let w = a.transpose() * (y - a * &x);
        let cand = (0..nt)
            .filter(|k| !passive[*k] && w[*k] > tol)
            .max_by(|p, q| w[*p].total_cmp(&w[*q]));
        let Some(t) = cand else { break };
        passive[t] = true;
        loop {
            let z = solve_passive(&passive);
            if (0..nt).filter(|k| passive[*k]).all(|k| z[k] > 0.0) {
                x = z;
                break;
            }
            // step back to the feasible boundary
            let mut alpha = f64::INFINITY;
            for k in (0..nt).filter(|k| passive[*k] && z[*k] <= 0.0) {
                alpha = alpha.min(x[k] / (x[k] - z[k]));
            }
            x = &x + (z - &x) * alpha;
            for k in 0..nt {
                if passive[k] && x[k] <= 1e-15 {
                    passive[k] = false;
                    x[k] = 0.0;
                }
            }
            if !passive.iter().any(|p| *p) {
                break;
            }
        }
        if done(&x) {
            break;
        }
    }
    x.iter().map(|v| v.max(0.0)).collect()
}

/// Projection of a symmetric matrix onto the PSD cone (negative eigenvalues set to zero).
fn project_psd(g: &DMatrix<f64>) -> DMatrix<f64> {
    let sym = (g + g.transpose()) * 0.5;
    let eig = sym.symmetric_eigen();
    if eig.eigenvalues.iter().all(|l| *l >= 0.0) {
        return (g + g.transpose()) * 0.5;
    }
    let clipped = eig.eigenvalues.map(|l| l.max(0.0));
    &eig.eigenvectors * DMatrix::from_diagonal(&clipped) * eig.eigenvectors.transpose()
}

/// Gains (in scaled coordinates) minimizing the weighted damping error subject to every G_k PSD:
/// accelerated projected gradient (FISTA) on the normal equations, from the projected least-squares
/// solution.
fn psd_gains(
    omegas: &[f64],
    wts: &[f64],
    damping: &[DMatrix<f64>],
    added: Option<(&[DMatrix<f64>], &DMatrix<f64>)>,
    terms: &[Shape],
    sc: &dyn Fn(usize, usize) -> f64,
) -> Vec<DMatrix<f64>> {
    let (nw, nt) = (omegas.len(), terms.len());
    let n = damping[0].nrows();
    let h = DMatrix::from_fn(nw, nt, |i, k| terms[k].re(omegas[i]));
    let hi = DMatrix::from_fn(
        nw,
        nt,
        |i, k| if added.is_some() { terms[k].h(omegas[i]).im } else { 0.0 },
    );
    let normal = DMatrix::from_fn(nt, nt, |k, l| {
        (0..nw)
            .map(|i| wts[i] * (h[(i, k)] * h[(i, l)] + hi[(i, k)] * hi[(i, l)]))
            .sum::<f64>()
    });
    let scaled: Vec<DMatrix<f64>> = damping
        .iter()
        .map(|b| DMatrix::from_fn(n, n, |i, j| b[(i, j)] / sc(i, j)))
        .collect();
    // Im K = w (A - A_inf), in the same scaled units
    let scaled_im: Vec<DMatrix<f64>> = match added {
        Some((a, a_inf)) => a
            .iter()
            .zip(omegas)
            .map(|(a, w)| DMatrix::from_fn(n, n, |i, j| w * (a[(i, j)] - a_inf[(i, j)]) / sc(i, j)))
            .collect(),
        None => vec![DMatrix::zeros(n, n); nw],
    };
    let r: Vec<DMatrix<f64>> = (0..nt)
        .map(|k| {
            let mut m = DMatrix::zeros(n, n);
            for i in 0..nw {
                m += &scaled[i] * (wts[i] * h[(i, k)]) + &scaled_im[i] * (wts[i] * hi[(i, k)]);
            }
            m
        })
        .collect();
    let lip = normal
        .clone()
        .symmetric_eigen()
        .eigenvalues
        .max()
        .max(f64::MIN_POSITIVE);
    let grad = |g: &[DMatrix<f64>]| -> Vec<DMatrix<f64>> {
        (0..nt)
            .map(|k| {
                let mut m = -&r[k];
                for l in 0..nt {
                    m += &g[l] * normal[(k, l)];
                }
                m
            })
            .collect()
    };
    // start: unconstrained least squares (scaled), projected
    let ls = solve_gains(omegas, wts, &scaled, terms);
    let mut x: Vec<DMatrix<f64>> = ls.iter().map(project_psd).collect();
    let mut y = x.clone();
    let mut t = 1.0f64;
    for _ in 0..FISTA_MAX_ITERATIONS {
        let gy = grad(&y);
        let xn: Vec<DMatrix<f64>> = y
            .iter()
            .zip(&gy)
            .map(|(yk, gk)| project_psd(&(yk - gk / lip)))
            .collect();
        let tn = 0.5 * (1.0 + (1.0 + 4.0 * t * t).sqrt());
        let step: f64 = xn
            .iter()
            .zip(&x)
            .map(|(a, b)| (a - b).norm_squared())
            .sum::<f64>()
            .sqrt();
        let size: f64 = xn
            .iter()
            .map(|a| a.norm_squared())
            .sum::<f64>()
            .sqrt()
            .max(f64::MIN_POSITIVE);
        y = xn.iter().zip(&x).map(|(a, b)| a + (a - b) * ((t - 1.0) / tn)).collect();
        x = xn;
        t = tn;
        if step < FISTA_STEP_TOL * size {
            break;
        }
    }
    x
}

/// Weighted least squares for the gains of fixed terms, every matrix entry at once (one normal matrix).
fn solve_gains(omegas: &[f64], wts: &[f64], damping: &[DMatrix<f64>], terms: &[Shape]) -> Vec<DMatrix<f64>> {
    let (nw, nt) = (omegas.len(), terms.len());
    let n = damping[0].nrows();
    let h = DMatrix::from_fn(nw, nt, |i, k| terms[k].re(omegas[i]) * wts[i].sqrt());
    let mut normal = h.transpose() * &h;
    let ridge = 1e-10 * normal.trace() / nt as f64;
    for k in 0..nt {
        normal[(k, k)] += ridge;
    }
    let rhs_data = DMatrix::from_fn(nw, n * n, |i, c| damping[i][(c % n, c / n)] * wts[i].sqrt());
    let rhs = h.transpose() * rhs_data;
    let sol = match normal.clone().cholesky() {
        Some(ch) => ch.solve(&rhs),
        None => normal.lu().solve(&rhs).unwrap_or_else(|| DMatrix::zeros(nt, n * n)),
    };
    (0..nt)
        .map(|k| DMatrix::from_fn(n, n, |i, j| sol[(k, j * n + i)]))
        .collect()
}

/// Scaled Frobenius residual of the damping fit at each frequency.
fn residual(
    omegas: &[f64],
    damping: &[DMatrix<f64>],
    terms: &[Shape],
    gains: &[DMatrix<f64>],
    sc: &dyn Fn(usize, usize) -> f64,
) -> Vec<f64> {
    let n = damping[0].nrows();
    omegas
        .iter()
        .zip(damping)
        .map(|(w, b)| {
            let mut fit = DMatrix::zeros(n, n);
            for (t, g) in terms.iter().zip(gains) {
                fit += g * t.re(*w);
            }
            let mut s = 0.0;
            for i in 0..n {
                for j in 0..n {
                    let e = (fit[(i, j)] - b[(i, j)]) / sc(i, j);
                    s += e * e;
                }
            }
            (s / n as f64).sqrt()
        })
        .collect()
}

/// Exact discretization of one term's states over a step dt with the input v linear in time (first-order
/// hold): x_{k+1} = phi x_k + gamma0 v_k + gamma1 v_{k+1}, force contribution gain * (c . x). The states
/// are the controllable canonical form of the term's transfer function (x = q, q', q'', ... with the
/// denominator's differential equation driven by v). Van Loan's block exponential of
/// [[A, b, 0], [0, 0, 1/dt], [0, 0, 0]] dt.
#[derive(Debug, Clone, PartialEq)]
pub struct DiscreteTerm {
    pub order: usize,
    /// Row-major order x order.
    pub phi: Vec<f64>,
    pub gamma0: Vec<f64>,
    pub gamma1: Vec<f64>,
    /// Output coefficients (the numerator).
    pub c: Vec<f64>,
}

pub fn discretize(shape: &Shape, dt_s: f64) -> DiscreteTerm {
    let (num, den) = shape.polynomials();
    let m = shape.order();
    let mut big = DMatrix::<f64>::zeros(m + 2, m + 2);
    for i in 0..m - 1 {
        big[(i, i + 1)] = 1.0;
    }
    for j in 0..m {
        big[(m - 1, j)] = -den[j];
    }
    big[(m - 1, m)] = 1.0;
    big[(m, m + 1)] = 1.0 / dt_s;
    let e = (big * dt_s).exp();
    let mut phi = vec![0.0; m * m];
    for i in 0..m {
        for j in 0..m {
            phi[i * m + j] = e[(i, j)];
        }
    }
    let ga: Vec<f64> = (0..m).map(|i| e[(i, m)]).collect();
    let gb: Vec<f64> = (0..m).map(|i| e[(i, m + 1)]).collect();
    DiscreteTerm {
        order: m,
        phi,
        gamma0: ga.iter().zip(&gb).map(|(a, b)| a - b).collect(),
        gamma1: gb,
        c: num[..m].to_vec(),
    }
}

/// Fit quality as `db check` reports it: the largest scaled errors of B_ss and of A_ss (against the
/// given added mass and A_inf) over the frequencies.
pub fn fit_errors(
    model: &SsModel,
    omegas: &[f64],
    damping: &[DMatrix<f64>],
    added_mass: &[DMatrix<f64>],
    a_inf: &DMatrix<f64>,
) -> (f64, f64) {
    let n = a_inf.nrows();
    let sb: Vec<f64> = (0..n)
        .map(|i| damping.iter().map(|b| b[(i, i)].abs()).fold(0.0, f64::max))
        .collect();
    let sa: Vec<f64> = (0..n)
        .map(|i| added_mass.iter().map(|a| a[(i, i)].abs()).fold(0.0, f64::max))
        .collect();
    let (mut eb, mut ea) = (0.0f64, 0.0f64);
    for ((w, b), a) in omegas.iter().zip(damping).zip(added_mass) {
        let k = model.kernel(*w);
        for i in 0..n {
            for j in 0..n {
                let (nb, na) = ((sb[i] * sb[j]).sqrt(), (sa[i] * sa[j]).sqrt());
                if nb > 0.0 {
                    eb = eb.max((k[(i, j)].re - b[(i, j)]).abs() / nb);
                }
                if na > 0.0 {
                    ea = ea.max((a_inf[(i, j)] + k[(i, j)].im / w - a[(i, j)]).abs() / na);
                }
            }
        }
    }
    (eb, ea)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(f: impl Fn(f64) -> f64) -> (Vec<f64>, Vec<DMatrix<f64>>) {
        let ws: Vec<f64> = (1..=300).map(|k| k as f64 * 0.01).collect();
        let bs = ws.iter().map(|w| DMatrix::from_element(1, 1, f(*w))).collect();
        (ws, bs)
    }

    #[test]
    fn fits_a_broad_hump_and_a_narrow_resonance() {
        let (ws, bs) = sample(|w| {
            1e6 * band_pass_re(0.9, 0.35, w) + 4e5 * band_pass_re(1.7, 0.01, w) // a 'gap resonance'
        });
        let m = fit(&ws, &bs, SsFitOptions::default());
        assert!(m.fit_error < 0.01, "fit error {}", m.fit_error);
        assert!(
            m.terms.iter().all(|t| t.gain[(0, 0)] >= 0.0 && t.shape.zeta > 0.0),
            "passive, stable"
        );
    }

    #[test]
    fn model_is_passive_at_every_frequency() {
        // two coupled DOFs with a PSD damping matrix
        let ws: Vec<f64> = (1..=200).map(|k| k as f64 * 0.01).collect();
        let bs: Vec<DMatrix<f64>> = ws
            .iter()
            .map(|w| {
                let a = band_pass_re(0.8, 0.3, *w);
                let b = band_pass_re(1.2, 0.2, *w);
                DMatrix::from_row_slice(2, 2, &[a + b, 0.8 * a, 0.8 * a, a + 2.0 * b])
            })
            .collect();
        let m = fit(&ws, &bs, SsFitOptions::default());
        for k in 0..2000 {
            let w = 0.002 + k as f64 * 0.002;
            let re = m.kernel(w).map(|c| c.re);
            let min = re.symmetric_eigenvalues().min();
            assert!(min >= -1e-12, "Re K(i{w}) has eigenvalue {min}");
        }
    }

    #[test]
    fn fourth_order_term_has_the_squared_real_part() {
        let sh = Shape {
            omega_rad_s: 0.9,
            zeta: 0.15,
            fourth: true,
        };
        for w in [0.1, 0.5, 0.9, 1.3, 4.0] {
            let r = band_pass_re(0.9, 0.15, w);
            assert!((sh.h(w).re - r * r).abs() < 1e-12, "{w}");
        }
    }

    #[test]
    fn discretization_matches_the_continuous_step_response() {
        // H2 with a unit input ramped from 0 to 1 over the first step, then held: the force output is
        // a q'(t); compare q(10 s) with the exact ramp response of q'' + a q' + b q = v
        let sh = Shape {
            omega_rad_s: 1.3,
            zeta: 0.1,
            fourth: false,
        };
        let dt = 0.1;
        let d = discretize(&sh, dt);
        let mut x = [0.0f64; 2];
        for k in 0..100 {
            let v0 = if k == 0 { 0.0 } else { 1.0 };
            let nx: Vec<f64> = (0..2)
                .map(|i| d.phi[i * 2] * x[0] + d.phi[i * 2 + 1] * x[1] + d.gamma0[i] * v0 + d.gamma1[i])
                .collect();
            x = [nx[0], nx[1]];
        }
        let (w, z) = (1.3f64, 0.1f64);
        let wd = w * (1.0 - z * z).sqrt();
        let step = |t: f64| (1.0 - (-z * w * t).exp() * ((wd * t).cos() + z * w / wd * (wd * t).sin())) / (w * w);
        let n = 10000;
        let ramp: f64 = (0..n)
            .map(|i| step(10.0 - (i as f64 + 0.5) * dt / n as f64))
            .sum::<f64>()
            / n as f64;
        assert!((x[0] - ramp).abs() < 1e-10, "{} vs {ramp}", x[0]);
    }
}
