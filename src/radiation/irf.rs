//! Radiation memory: the impulse response functions K(t), A_inf, and the Kramers-Kronig check.
//!
//! Relations (Cummins 1962; Ogilvie 1964; seed paper eqs. 5-6), for each DOF pair:
//!   K(t) = (2/pi) int_0^inf B(w) cos(w t) dw
//!   A(w) = A_inf - (1/w) int_0^inf K(t) sin(w t) dt
//!   B(w) = int_0^inf K(t) cos(w t) dt
//!
//! How shipcast evaluates them (documented choices, tested below):
//! - B(w) between database frequencies is linear; below the lowest it falls linearly to B(0) = 0; above
//!   the highest, w_N, it follows the damping tail [`DampingTail`] (sampled on nodes spaced by 10 % up to
//!   20 w_N, where it is cut): B_ij(w) = B_N,ij r^((p_i + p_j)/2) + D_ij (r^q - r^3) with r = w_N/w and
//!   q = TAIL_FAR_POWER = 2: the database's last damping B_N decaying as w^-p_i per DOF, plus a far part D that decays more
//!   slowly. p_i = 3 and D = 0 (the cubic tail) unless fitted: [`fit_tail`] chooses D (where the data
//!   ask for more damping above w_N) or p_i > 3 (where they ask for less) so that the added mass
//!   implied by K matches the database's A(w) with the BEM's own A_inf (Kramers-Kronig, least squares
//!   over the band). D is positive semi-definite and the near part a congruence of B_N, so the tail
//!   is passive.
//!   Why: a database that ends where a hull still radiates (the 120 m lighter at 1.6 rad/s) misses damping
//!   whose Kramers-Kronig image is an added-mass error across the band; its A(w) and A_inf still say how
//!   much is missing. Every cosine transform of this piecewise-linear B is exact (closed form per segment,
//!   [`pl_weights`]): no quadrature error, whatever t.
//! - K(t) is sampled on t = 0, dt, ..., T (dt default 0.05 s; T default pi / (smallest frequency
//!   spacing), the longest memory the database resolves, clamped to 30..600 s). It is used as zero past T.
//! - The sine and cosine transforms of K back to A and B treat K as linear between its samples, again
//!   exactly (Filon-type), so the check measures the database and the truncation, not the quadrature.
//! - A_inf: the database's PER = 0 rows, or Ogilvie's estimate: the median over the database
//!   frequencies of A(w) + (1/w) int_0^T K(t) sin(w t) dt, which makes A(w) and B(w) as the model sees
//!   them consistent. Its spread over w is reported (a flat estimate means a consistent database).

use crate::hydro::HydroDb;
use nalgebra::DMatrix;
use std::f64::consts::PI;

/// Exponent of the damping tail's near part, B_N (w_N/w)^TAIL_POWER.
pub const TAIL_POWER: i32 = 3;
/// Exponent of the damping tail's far part, D (w_N/w)^TAIL_FAR_POWER: a slower decay than the near
/// part's, so that a fitted D adds damping above w_N. The in-band fit barely depends on it (it sets
/// mostly int B / w^2); 2 put the fitted tail of the two-ship demo's lighter closest to a Capytaine run
/// of the same pair continued to 2.2 rad/s (`tools/bem/make_db.py --preset pair-fine`).
pub const TAIL_FAR_POWER: f64 = 2.0;
/// Largest fitted far level D_ii, in units of B_N,ii: the most that keeps the tail at or below B_N.
pub const TAIL_FAR_CAP: f64 = 3.0;
/// The tail is sampled up to this multiple of the highest database frequency.
pub const TAIL_END_FACTOR: f64 = 20.0;
/// Ratio between successive tail nodes.
pub const TAIL_NODE_RATIO: f64 = 1.1;

/// Shortest time step of a sampled K(t) and of the solvers that sample it, s: wave periods are seconds,
/// a millisecond resolves them a thousandfold; below it the taps only cost memory.
pub const MIN_DT_S: f64 = 1e-3;
/// Longest time step, s: Newmark's step must sample a 3 s wave period several times.
pub const MAX_DT_S: f64 = 1.0;
/// Longest radiation memory, s: K(t) of a floating body decays within minutes; an hour is more than
/// any database's frequency spacing resolves (pi / dw at dw = 0.001 rad/s).
pub const MAX_MEMORY_S: f64 = 3600.0;
/// Most samples of K(t) (memory / dt + 1): the convolution kernel of a 12-DOF system with this many
/// taps is 70 MB, and each forecast step reads all of them.
pub const MAX_TAPS: usize = 60_000;

/// A time grid of K(t) (step and memory) outside [`MIN_DT_S`]..[`MAX_DT_S`], (0, [`MAX_MEMORY_S`]] or
/// [`MAX_TAPS`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GridError {
    Dt(f64),
    Memory(f64),
    Taps { dt_s: f64, memory_s: f64 },
}

impl GridError {
    /// The option at fault: `dt_s` or `memory_s`.
    pub fn field(&self) -> &'static str {
        match self {
            GridError::Dt(_) => "dt_s",
            GridError::Memory(_) | GridError::Taps { .. } => "memory_s",
        }
    }
}

impl std::fmt::Display for GridError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            GridError::Dt(v) => write!(f, "the time step must be in [{MIN_DT_S}, {MAX_DT_S}] s, found {v:?}"),
            GridError::Memory(v) => write!(f, "the radiation memory must be in (0, {MAX_MEMORY_S}] s, found {v:?}"),
            GridError::Taps { dt_s, memory_s } => write!(
                f,
                "a {memory_s:?} s radiation memory at a {dt_s:?} s step is {:.0} taps, more than {MAX_TAPS}: \
                 lengthen the step or shorten the memory",
                (memory_s / dt_s).round() + 1.0
            ),
        }
    }
}

impl std::error::Error for GridError {}

/// Checks a time step alone.
pub fn check_dt(dt_s: f64) -> Result<(), GridError> {
    if (MIN_DT_S..=MAX_DT_S).contains(&dt_s) {
        Ok(())
    } else {
        Err(GridError::Dt(dt_s))
    }
}

/// Checks a memory length alone.
pub fn check_memory(memory_s: f64) -> Result<(), GridError> {
    if memory_s > 0.0 && memory_s <= MAX_MEMORY_S {
        Ok(())
    } else {
        Err(GridError::Memory(memory_s))
    }
}

/// Checks a time grid of K(t): the step, the memory and the number of samples they make. Every sampled
/// K (the IRF, the convolution's taps, the state-space fit's grid) is sized by a grid that passed it.
pub fn check_grid(dt_s: f64, memory_s: f64) -> Result<(), GridError> {
    check_dt(dt_s)?;
    check_memory(memory_s)?;
    if (memory_s / dt_s).round() + 1.0 > MAX_TAPS as f64 {
        return Err(GridError::Taps { dt_s, memory_s });
    }
    Ok(())
}

/// Weights w_k such that int f(x) trig(s x) dx over [x_0, x_last] = sum_k w_k f(x_k) for f linear between
/// the nodes x_k (ascending). `sine` selects sin instead of cos. Closed form per segment; 4-point
/// Gauss-Legendre where s h is small and the closed form would cancel.
pub fn pl_weights(nodes: &[f64], s: f64, sine: bool, out: &mut [f64]) {
    debug_assert_eq!(nodes.len(), out.len());
    out.iter_mut().for_each(|w| *w = 0.0);
    const GL_X: [f64; 4] = [
        -0.861_136_311_594_053,
        -0.339_981_043_584_856,
        0.339_981_043_584_856,
        0.861_136_311_594_053,
    ];
    const GL_W: [f64; 4] = [
        0.347_854_845_137_454,
        0.652_145_154_862_546,
        0.652_145_154_862_546,
        0.347_854_845_137_454,
    ];
    let trig = |x: f64| if sine { (s * x).sin() } else { (s * x).cos() };
    for k in 0..nodes.len().saturating_sub(1) {
        let (a, b) = (nodes[k], nodes[k + 1]);
        let h = b - a;
        if h <= 0.0 {
            continue;
        }
        let (left, right) = if (s * h).abs() < 0.2 {
            let (mut l, mut r) = (0.0, 0.0);
            for q in 0..4 {
                let u = 0.5 * (GL_X[q] + 1.0); // 0..1
                let f = trig(a + u * h) * GL_W[q] * 0.5 * h;
                l += f * (1.0 - u);
                r += f * u;
            }
            (l, r)
        } else {
            let (sa, ca) = (s * a).sin_cos();
            let (sb, cb) = (s * b).sin_cos();
            let s2h = s * s * h;
            if sine {
                (ca / s - (sb - sa) / s2h, -cb / s + (sb - sa) / s2h)
            } else {
                (-sa / s - (cb - ca) / s2h, sb / s + (cb - ca) / s2h)
            }
        };
        out[k] += left;
        out[k + 1] += right;
    }
}

/// Sampled impulse response functions of a database.
#[derive(Debug, Clone)]
pub struct Irf {
    /// Sample spacing, s.
    pub dt_s: f64,
    /// K(m dt) for m = 0..len, each n_modes x n_modes (row: force mode, column: velocity mode).
    pub k: Vec<DMatrix<f64>>,
}

impl Irf {
    pub fn duration_s(&self) -> f64 {
        self.dt_s * (self.k.len().saturating_sub(1)) as f64
    }
}

/// The damping above the database's last frequency (see the module documentation):
/// B_ij(w) = B_N,ij r^((p_i + p_j)/2) + D_ij (r^q - r^3), r = w_N/w <= 1.
#[derive(Debug, Clone, PartialEq)]
pub struct DampingTail {
    /// w_N, the database's last frequency, rad/s.
    pub omega_n_rad_s: f64,
    /// B(w_N), the database's last damping (as the models use it: made passive).
    pub b_n: DMatrix<f64>,
    /// p_i, each DOF's decay exponent of the near part: TAIL_POWER unless fitted (never less).
    pub near_power: Vec<f64>,
    /// D, the far level: zero for the cubic tail, positive semi-definite when fitted.
    pub far: DMatrix<f64>,
}

impl DampingTail {
    /// The cubic tail B_N (w_N/w)^3 from the last of `damping` sampled at `omegas`.
    pub fn cubic(omegas: &[f64], damping: &[DMatrix<f64>]) -> DampingTail {
        let n = damping.first().map(|b| b.nrows()).unwrap_or(0);
        DampingTail {
            omega_n_rad_s: omegas.last().copied().unwrap_or(1.0),
            b_n: damping.last().cloned().unwrap_or_else(|| DMatrix::zeros(n, n)),
            near_power: vec![TAIL_POWER as f64; n],
            far: DMatrix::zeros(n, n),
        }
    }

    /// The far part's shape at w >= w_N: (w_N/w)^q - (w_N/w)^3.
    fn far_shape(&self, omega_rad_s: f64) -> f64 {
        let r = self.omega_n_rad_s / omega_rad_s;
        r.powf(TAIL_FAR_POWER) - r.powi(TAIL_POWER)
    }

    /// B(w) for w >= w_N. The near part is S B_N S with S = diag(r^(p_i/2)), the far part D times a
    /// positive shape: both positive semi-definite when B_N and D are.
    pub fn at(&self, omega_rad_s: f64) -> DMatrix<f64> {
        let r = self.omega_n_rad_s / omega_rad_s;
        let s: Vec<f64> = self.near_power.iter().map(|p| r.powf(0.5 * p)).collect();
        let far = self.far_shape(omega_rad_s);
        DMatrix::from_fn(self.b_n.nrows(), self.b_n.ncols(), |i, j| {
            self.b_n[(i, j)] * s[i] * s[j] + self.far[(i, j)] * far
        })
    }

    /// The nodes beyond w_N on which the IRF samples the tail.
    pub fn nodes(&self) -> Vec<f64> {
        let mut out = vec![];
        let mut x = self.omega_n_rad_s * TAIL_NODE_RATIO;
        while x <= TAIL_END_FACTOR * self.omega_n_rad_s {
            out.push(x);
            x *= TAIL_NODE_RATIO;
        }
        out
    }

    /// The tail of the DOFs `idx` only.
    pub fn sub(&self, idx: &[usize]) -> DampingTail {
        let n = idx.len();
        let pick = |m: &DMatrix<f64>| DMatrix::from_fn(n, n, |r, c| m[(idx[r], idx[c])]);
        DampingTail {
            omega_n_rad_s: self.omega_n_rad_s,
            b_n: pick(&self.b_n),
            near_power: idx.iter().map(|&i| self.near_power[i]).collect(),
            far: pick(&self.far),
        }
    }

    /// max_i D_ii / B_N,ii over the DOFs with damping at w_N: how far the fit added damping.
    pub fn far_ratio(&self) -> f64 {
        (0..self.b_n.nrows())
            .filter(|&i| self.b_n[(i, i)] > 0.0)
            .map(|i| self.far[(i, i)] / self.b_n[(i, i)])
            .fold(0.0, f64::max)
    }

    /// The largest fitted near exponent: how far the fit took damping away.
    pub fn max_near_power(&self) -> f64 {
        self.near_power.iter().copied().fold(TAIL_POWER as f64, f64::max)
    }
}

/// The frequency nodes and damping values the IRF integrates: 0, the data, and the tail.
fn damping_nodes(omegas: &[f64], damping: &[DMatrix<f64>], tail: &DampingTail) -> (Vec<f64>, Vec<DMatrix<f64>>) {
    let n = tail.b_n.nrows();
    let mut w = vec![0.0];
    let mut b = vec![DMatrix::zeros(n, n)];
    w.extend_from_slice(omegas);
    b.extend(damping.iter().cloned());
    for x in tail.nodes() {
        w.push(x);
        b.push(tail.at(x));
    }
    (w, b)
}

/// max_w |M_ii(w)| for each i: the scale of each DOF in a frequency-dependent matrix (at least the
/// smallest positive number, so it can divide).
pub fn diagonal_peaks(ms: &[DMatrix<f64>]) -> Vec<f64> {
    let n = ms.first().map(|m| m.nrows()).unwrap_or(0);
    (0..n)
        .map(|i| {
            ms.iter()
                .map(|m| m[(i, i)].abs())
                .fold(0.0, f64::max)
                .max(f64::MIN_POSITIVE)
        })
        .collect()
}

/// A DOF whose peak damping is below this fraction of the largest DOF's does not radiate (a spar's yaw):
/// its damping is numerical noise, which scaling by its own peak would blow up.
pub const NON_RADIATING: f64 = 1e-9;

/// Which DOFs radiate: peak damping (`diagonal_peaks`) above [`NON_RADIATING`] of the largest.
pub fn radiating_dofs(peaks: &[f64]) -> Vec<bool> {
    let top = peaks.iter().copied().fold(0.0, f64::max);
    peaks.iter().map(|p| *p > NON_RADIATING * top).collect()
}

/// What [`passive_damping`] changed: how far a database's damping was from passive.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PassivityRepair {
    /// Frequencies at which the symmetric part of B(w) had a negative eigenvalue.
    pub frequencies: usize,
    /// The largest change of an entry, relative to its scale sqrt(max_w B_ii max_w B_jj).
    pub largest: f64,
    /// The index of the frequency where it was made.
    pub at: usize,
}

/// The database's damping made passive: at each frequency the symmetric part of B(w) over the DOFs that
/// radiate ([`radiating_dofs`]) is projected onto the positive semi-definite matrices (negative
/// eigenvalues, from irregular frequencies or numerical noise, set to zero; eigen-decomposition in
/// coordinates scaled by sqrt(max_w B_ii) so translations and rotations weigh alike). The entries of a
/// DOF that does not radiate, noise, are left as they are: in its own scale that noise is of order one
/// and would move the others. A passive B keeps every radiation model built from it from creating
/// energy (radiated power, v^T B v / 2, is never negative). Returns the damping and what was changed.
pub fn passive_damping(damping: &[DMatrix<f64>]) -> (Vec<DMatrix<f64>>, PassivityRepair) {
    let peaks = diagonal_peaks(damping);
    let live: Vec<usize> = radiating_dofs(&peaks)
        .iter()
        .enumerate()
        .filter_map(|(i, r)| r.then_some(i))
        .collect();
    let n = live.len();
    let scale: Vec<f64> = live.iter().map(|i| peaks[*i].sqrt()).collect();
    let mut repair = PassivityRepair::default();
    let out = damping
        .iter()
        .enumerate()
        .map(|(k, b)| {
            let (l, sc) = (&live, &scale);
            let sym = DMatrix::from_fn(n, n, |i, j| 0.5 * (b[(l[i], l[j])] + b[(l[j], l[i])]) / (sc[i] * sc[j]));
            let eig = sym.clone().symmetric_eigen();
            if eig.eigenvalues.iter().all(|v| *v >= 0.0) {
                return b.clone();
            }
            let clipped = eig.eigenvalues.map(|v| v.max(0.0));
            let fixed = &eig.eigenvectors * DMatrix::from_diagonal(&clipped) * eig.eigenvectors.transpose();
            let change = (&fixed - &sym).amax();
            repair.frequencies += 1;
            if change > repair.largest {
                repair.largest = change;
                repair.at = k;
            }
            let mut out = b.clone();
            for i in 0..n {
                for j in 0..n {
                    out[(l[i], l[j])] = fixed[(i, j)] * sc[i] * sc[j];
                }
            }
            out
        })
        .collect();
    (out, repair)
}

/// Default memory length: pi / (smallest frequency spacing), clamped to 30..600 s.
pub fn default_duration_s(db: &HydroDb) -> f64 {
    let dw = db
        .omega_rad_s
        .windows(2)
        .map(|p| p[1] - p[0])
        .fold(f64::INFINITY, f64::min);
    if dw.is_finite() && dw > 0.0 {
        (PI / dw).clamp(30.0, 600.0)
    } else {
        60.0
    }
}

/// Up to this many frequencies, [`transform_irf`] sums each one's weighted samples in place; more are
/// one matrix product with the memory stacked once.
const DIRECT_TRANSFORMS: usize = 4;

/// Stacks n x n matrices as rows of an (len x n^2) matrix (column-major flattening of each).
fn stack(ms: &[DMatrix<f64>], n: usize) -> DMatrix<f64> {
    // row by row: each matrix read once, in its own (column-major) order
    let mut out = DMatrix::zeros(ms.len(), n * n);
    for (r, m) in ms.iter().enumerate() {
        for (c, v) in m.as_slice().iter().take(n * n).enumerate() {
            out[(r, c)] = *v;
        }
    }
    out
}

fn unstack(m: &DMatrix<f64>, n: usize) -> Vec<DMatrix<f64>> {
    (0..m.nrows())
        .map(|r| DMatrix::from_fn(n, n, |i, j| m[(r, j * n + i)]))
        .collect()
}

/// K(t) on t = 0, dt, ..., duration, from the database's damping as it is and the cubic tail.
pub fn impulse_response(db: &HydroDb, dt_s: f64, duration_s: f64) -> Irf {
    let tail = DampingTail::cubic(&db.omega_rad_s, &db.damping);
    impulse_response_of(&db.omega_rad_s, &db.damping, &tail, dt_s, duration_s)
}

/// K(t) on t = 0, dt, ..., duration from damping samples `damping[k]` at `omegas[k]` (ascending) and the
/// tail beyond them.
pub fn impulse_response_of(
    omegas: &[f64],
    damping: &[DMatrix<f64>],
    tail: &DampingTail,
    dt_s: f64,
    duration_s: f64,
) -> Irf {
    let (w, b) = damping_nodes(omegas, damping, tail);
    irf_of_nodes(&w, &b, tail.b_n.nrows(), dt_s, duration_s)
}

/// K(t) = (2/pi) int B cos(w t) dw for B linear between the nodes `w` (zero outside them).
fn irf_of_nodes(w: &[f64], b: &[DMatrix<f64>], n: usize, dt_s: f64, duration_s: f64) -> Irf {
    let nt = (duration_s / dt_s).round() as usize + 1;
    let mut weights = DMatrix::zeros(nt, w.len());
    let mut row = vec![0.0; w.len()];
    for m in 0..nt {
        pl_weights(w, m as f64 * dt_s, false, &mut row);
        for (k, v) in row.iter().enumerate() {
            weights[(m, k)] = v * 2.0 / PI;
        }
    }
    let kt = weights * stack(b, n);
    Irf {
        dt_s,
        k: unstack(&kt, n),
    }
}

/// The outcome of [`fit_tail`].
#[derive(Debug, Clone)]
pub struct TailFit {
    pub tail: DampingTail,
    /// K(t) with the fitted tail.
    pub irf: Irf,
    /// Worst |A_K(w) - A(w)| / sqrt(sA_i sA_j) over the band and every pair with the target A_inf:
    /// with the cubic tail, and with the fitted one.
    pub residual_cubic: f64,
    pub residual_fitted: f64,
}

/// Near exponents the fit tries for a DOF whose data ask for less damping than the cubic tail.
const NEAR_POWERS: [f64; 9] = [3.0, 3.5, 4.0, 5.0, 6.0, 8.0, 10.0, 13.0, 16.0];

/// The far part never lifts the tail above the data's last damping: B_N r^3 + D r^2 (1 - r) <= B_N
/// for r = w_N/w in (0, 1] needs D_ii <= TAIL_FAR_CAP B_N,ii; enforced by the congruence S D S (S
/// diagonal, so D stays PSD). Without it a database whose A_inf is off by a constant (WEC-Sim's RM3)
/// makes the fit invent a damping bump orders of magnitude above its last value.
fn capped_far(far: &DMatrix<f64>, cubic: &DampingTail) -> DMatrix<f64> {
    let n = far.nrows();
    let cap: Vec<f64> = (0..n)
        .map(|i| {
            let (d, b) = (far[(i, i)], TAIL_FAR_CAP * cubic.b_n[(i, i)].max(0.0));
            if d > b { (b / d).sqrt() } else { 1.0 }
        })
        .collect();
    DMatrix::from_fn(n, n, |i, j| cap[i] * far[(i, j)] * cap[j])
}

/// Per DOF, the near exponent of [`NEAR_POWERS`] whose added-mass image (`images`, in that order) best
/// fits its diagonal residual `r0`, for the DOFs whose data ask for less damping above w_N (not
/// `wants`); the cubic's [`TAIL_POWER`] for the others.
fn near_powers(r0: &[DMatrix<f64>], images: &[Vec<f64>], wants: &[bool], cubic: &DampingTail) -> Vec<f64> {
    (0..wants.len())
        .map(|i| {
            let b = cubic.b_n[(i, i)];
            if wants[i] || b <= 0.0 {
                return TAIL_POWER as f64;
            }
            let misfit = |g: &[f64]| -> f64 { r0.iter().zip(g).map(|(r, gk)| (r[(i, i)] - b * gk).powi(2)).sum() };
            NEAR_POWERS
                .iter()
                .zip(images)
                .map(|(p, g)| (*p, misfit(g)))
                .min_by(|x, y| x.1.total_cmp(&y.1))
                .map(|(p, _)| p)
                .unwrap_or(TAIL_POWER as f64)
        })
        .collect()
}

/// Fits the damping tail so that the added mass implied by K, A_inf - (1/w) int K sin, matches the
/// database's `added_mass` in the band w <= KK_BAND_FRACTION w_N given the BEM's `a_inf`:
/// 1. with the cubic tail, the residual r_ij(w) = (Ogilvie estimate - A_inf)_ij (symmetric parts);
/// 2. the far level D by linear least squares per DOF pair (K is linear in D: r ~ D g(w), g the added
///    mass image of the far shape); DOFs whose own D_ii comes out negative get none, and D is projected
///    onto the PSD matrices (scaled by sqrt(max_w B_ii)) and capped at TAIL_FAR_CAP B_N,ii;
/// 3. for those DOFs (their data ask for less damping above w_N), the near exponent p_i from
///    NEAR_POWERS that best fits their diagonal residual.
///
/// `damping` should be passive ([`passive_damping`]). K is sampled as the models sample it (`dt_s`,
/// `duration_s`), so the fit removes the residual they see.
pub fn fit_tail(
    omegas: &[f64],
    damping: &[DMatrix<f64>],
    added_mass: &[DMatrix<f64>],
    a_inf: &DMatrix<f64>,
    dt_s: f64,
    duration_s: f64,
) -> TailFit {
    let cubic = DampingTail::cubic(omegas, damping);
    let irf0 = impulse_response_of(omegas, damping, &cubic, dt_s, duration_s);
    let n = cubic.b_n.nrows();
    let wn = cubic.omega_n_rad_s;
    let band: Vec<usize> = (0..omegas.len())
        .filter(|&k| omegas[k] <= KK_BAND_FRACTION * wn)
        .collect();
    let band_w: Vec<f64> = band.iter().map(|&k| omegas[k]).collect();
    let scale_a = diagonal_peaks(added_mass);
    let sym = |m: &DMatrix<f64>| (m + m.transpose()) * 0.5;
    let a_inf_sym = sym(a_inf);
    // residual per band frequency, symmetric, and its worst scaled entry
    let residual = |irf: &Irf| -> Vec<DMatrix<f64>> {
        let est = ogilvie_estimates_of(omegas, added_mass, irf);
        band.iter().map(|&k| sym(&est[k]) - &a_inf_sym).collect()
    };
    let worst = |r: &[DMatrix<f64>]| {
        r.iter()
            .flat_map(|m| (0..n).flat_map(move |i| (0..n).map(move |j| (i, j, m[(i, j)]))))
            .map(|(i, j, v)| v.abs() / (scale_a[i] * scale_a[j]).sqrt())
            .fold(0.0, f64::max)
    };
    let r0 = residual(&irf0);
    let residual_cubic = worst(&r0);
    // the added-mass image g(w) = -(1/w) int k sin of a unit damping `shape` beyond w_N
    let nodes: Vec<f64> = std::iter::once(wn).chain(cubic.nodes()).collect();
    let image = |shape: &dyn Fn(f64) -> f64| -> Vec<f64> {
        let h: Vec<DMatrix<f64>> = nodes.iter().map(|&x| DMatrix::from_element(1, 1, shape(x))).collect();
        let k = irf_of_nodes(&nodes, &h, 1, dt_s, duration_s);
        transform_irf(&k, &band_w, true)
            .iter()
            .zip(&band_w)
            .map(|(s, w)| -s[(0, 0)] / w)
            .collect()
    };
    let lsq = |g: &[f64], i: usize, j: usize| {
        let gg: f64 = g.iter().map(|x| x * x).sum();
        let rg: f64 = r0.iter().zip(g).map(|(r, gk)| r[(i, j)] * gk).sum();
        if gg > 0.0 { rg / gg } else { 0.0 }
    };
    let g_far = image(&|x| cubic.far_shape(x));
    let far_raw = DMatrix::from_fn(n, n, |i, j| lsq(&g_far, i, j));
    let wants: Vec<bool> = (0..n).map(|i| far_raw[(i, i)] > 0.0).collect();
    // DOFs that ask for less damping get no far part, their couplings included (the projection would
    // otherwise hand them damping from their couplings)
    let far_raw = DMatrix::from_fn(n, n, |i, j| if wants[i] && wants[j] { far_raw[(i, j)] } else { 0.0 });
    let far = if far_raw.iter().all(|v| v.is_finite()) {
        psd_part(&far_raw, &diagonal_peaks(damping))
    } else {
        DMatrix::zeros(n, n)
    };
    let far = capped_far(&far, &cubic);
    // near exponents for the DOFs that ask for less damping: B_N,ii (r^p - r^3) has image g_p
    let images: Vec<Vec<f64>> = NEAR_POWERS
        .iter()
        .map(|&p| image(&|x: f64| (wn / x).powf(p) - (wn / x).powi(TAIL_POWER)))
        .collect();
    let near_power = near_powers(&r0, &images, &wants, &cubic);
    let tail = DampingTail {
        near_power,
        far,
        ..cubic
    };
    let irf = impulse_response_of(omegas, damping, &tail, dt_s, duration_s);
    let residual_fitted = worst(&residual(&irf));
    TailFit {
        tail,
        irf,
        residual_cubic,
        residual_fitted,
    }
}

/// The positive semi-definite part of the symmetric `m`, in coordinates scaled by sqrt(`peaks`).
fn psd_part(m: &DMatrix<f64>, peaks: &[f64]) -> DMatrix<f64> {
    let n = m.nrows();
    let s: Vec<f64> = peaks.iter().map(|p| p.sqrt()).collect();
    let scaled = DMatrix::from_fn(n, n, |i, j| 0.5 * (m[(i, j)] + m[(j, i)]) / (s[i] * s[j]));
    let eig = scaled.symmetric_eigen();
    let clipped = eig.eigenvalues.map(|l| l.max(0.0));
    let p = &eig.eigenvectors * DMatrix::from_diagonal(&clipped) * eig.eigenvectors.transpose();
    DMatrix::from_fn(n, n, |i, j| 0.5 * (p[(i, j)] + p[(j, i)]) * s[i] * s[j])
}

/// int_0^T K(t) trig(w t) dt at each w, K linear between samples; one n x n matrix per w.
pub fn transform_irf(irf: &Irf, omegas: &[f64], sine: bool) -> Vec<DMatrix<f64>> {
    let n = irf.k.first().map(|k| k.nrows()).unwrap_or(0);
    let t: Vec<f64> = (0..irf.k.len()).map(|m| m as f64 * irf.dt_s).collect();
    if omegas.len() <= DIRECT_TRANSFORMS {
        // summed in place: no stacked copy of the whole memory for a few frequencies
        let mut row = vec![0.0; t.len()];
        return omegas
            .iter()
            .map(|&w| {
                pl_weights(&t, w, sine, &mut row);
                let mut out = DMatrix::<f64>::zeros(n, n);
                for (v, k) in row.iter().zip(&irf.k) {
                    out.iter_mut().zip(k.iter()).for_each(|(o, x)| *o += v * x);
                }
                out
            })
            .collect();
    }
    let mut weights = DMatrix::zeros(omegas.len(), t.len());
    let mut row = vec![0.0; t.len()];
    for (i, &w) in omegas.iter().enumerate() {
        pl_weights(&t, w, sine, &mut row);
        for (m, v) in row.iter().enumerate() {
            weights[(i, m)] = *v;
        }
    }
    unstack(&(weights * stack(&irf.k, n)), n)
}

/// Ogilvie's A_inf estimate at each database frequency: A(w) + (1/w) int K sin.
pub fn ogilvie_estimates(db: &HydroDb, irf: &Irf) -> Vec<DMatrix<f64>> {
    ogilvie_estimates_of(&db.omega_rad_s, &db.added_mass, irf)
}

/// Ogilvie's A_inf estimate at each of `omegas` from the added mass there.
pub fn ogilvie_estimates_of(omegas: &[f64], added_mass: &[DMatrix<f64>], irf: &Irf) -> Vec<DMatrix<f64>> {
    let sines = transform_irf(irf, omegas, true);
    added_mass
        .iter()
        .zip(omegas)
        .zip(sines)
        .map(|((a, w), s)| a + s / *w)
        .collect()
}

/// Entry-wise median of the Ogilvie estimates.
pub fn ogilvie_a_inf(estimates: &[DMatrix<f64>]) -> DMatrix<f64> {
    let (r, c) = estimates[0].shape();
    DMatrix::from_fn(r, c, |i, j| {
        let mut v: Vec<f64> = estimates.iter().map(|m| m[(i, j)]).collect();
        v.sort_by(f64::total_cmp);
        let h = v.len() / 2;
        if v.len() % 2 == 1 {
            v[h]
        } else {
            0.5 * (v[h - 1] + v[h])
        }
    })
}

/// The Kramers-Kronig band: frequencies up to this fraction of the highest database frequency. Above it,
/// A(w) rebuilt from K depends on the modelled damping tail more than on the BEM's own data.
pub const KK_BAND_FRACTION: f64 = 0.8;

/// Kramers-Kronig consistency of one DOF pair.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairError {
    /// 0-based global indices.
    pub i: usize,
    pub j: usize,
    /// max_w |A_K(w) - A(w)| / sqrt(sA_i sA_j), sA_i = max_w |A_ii(w)|.
    pub added_mass: f64,
    /// Frequency of that maximum, rad/s.
    pub added_mass_at_rad_s: f64,
    /// The same maximum over the band w <= KK_BAND_FRACTION w_max.
    pub added_mass_band: f64,
    /// max_w |B_K(w) - B(w)| / sqrt(sB_i sB_j), sB_i = max_w |B_ii(w)|.
    pub damping: f64,
    /// Spread of the Ogilvie A_inf estimate over w, same scale as `added_mass`.
    pub a_inf_spread: f64,
}

/// The Kramers-Kronig check: A(w) and B(w) rebuilt from K against the database's, per DOF pair whose
/// scale is non-zero.
pub fn kramers_kronig(db: &HydroDb, irf: &Irf, a_inf: &DMatrix<f64>) -> Vec<PairError> {
    let n = db.n_modes;
    let sines = transform_irf(irf, &db.omega_rad_s, true);
    let cosines = transform_irf(irf, &db.omega_rad_s, false);
    let estimates = ogilvie_estimates(db, irf);
    let scale = |ms: &[DMatrix<f64>], i: usize| ms.iter().map(|m| m[(i, i)].abs()).fold(0.0, f64::max);
    let sa: Vec<f64> = (0..n).map(|i| scale(&db.added_mass, i)).collect();
    let sb: Vec<f64> = (0..n).map(|i| scale(&db.damping, i)).collect();
    let band_top = KK_BAND_FRACTION * db.omega_rad_s.last().copied().unwrap_or(0.0);
    let mut out = vec![];
    for i in 0..n {
        for j in 0..n {
            let (na, nb) = ((sa[i] * sa[j]).sqrt(), (sb[i] * sb[j]).sqrt());
            if !(na > 0.0 && nb > 0.0) {
                continue;
            }
            let mut e = PairError {
                i,
                j,
                added_mass: 0.0,
                added_mass_at_rad_s: 0.0,
                added_mass_band: 0.0,
                damping: 0.0,
                a_inf_spread: 0.0,
            };
            let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
            for (k, w) in db.omega_rad_s.iter().enumerate() {
                let ak = a_inf[(i, j)] - sines[k][(i, j)] / w;
                let ea = (ak - db.added_mass[k][(i, j)]).abs() / na;
                if *w <= band_top {
                    e.added_mass_band = e.added_mass_band.max(ea);
                }
                if ea > e.added_mass {
                    e.added_mass = ea;
                    e.added_mass_at_rad_s = *w;
                }
                e.damping = e.damping.max((cosines[k][(i, j)] - db.damping[k][(i, j)]).abs() / nb);
                lo = lo.min(estimates[k][(i, j)]);
                hi = hi.max(estimates[k][(i, j)]);
            }
            e.a_inf_spread = (hi - lo) / na;
            out.push(e);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hydro::wamit::{Excitation, Radiation};
    use num_complex::Complex64;

    #[test]
    fn passive_damping_removes_only_the_negative_part_and_says_how_much() {
        // DOF 0 in m/s, DOF 1 in rad/s (scales 4 and 9): at the second frequency the coupling 7 exceeds
        // sqrt(4 * 9) = 6, an eigenvalue below zero
        let ok = DMatrix::from_row_slice(2, 2, &[4.0, 1.0, 1.0, 9.0]);
        let bad = DMatrix::from_row_slice(2, 2, &[4.0, 7.0, 7.0, 9.0]);
        let (out, repair) = passive_damping(&[ok.clone(), bad.clone(), ok.clone()]);
        assert_eq!(out[0], ok);
        assert_eq!(out[2], ok);
        assert_eq!((repair.frequencies, repair.at), (1, 1));
        let lowest = out[1].clone().symmetric_eigen().eigenvalues.min();
        assert!(lowest.abs() < 1e-12 * 9.0, "projected onto the boundary: {lowest}");
        // scaled, [[1, 7/6], [7/6, 1]] has eigenvalues 13/6 and -1/6: clipping the latter changes every
        // entry by 1/12
        assert!((repair.largest - 1.0 / 12.0).abs() < 1e-12, "{repair:?}");
        let (_, none) = passive_damping(std::slice::from_ref(&ok));
        assert_eq!(none, PassivityRepair::default());
        // a third DOF that does not radiate (a spar's yaw): its noise, indefinite in its own scale, is
        // left alone and not counted as a repair
        let noisy = DMatrix::from_row_slice(3, 3, &[4.0, 1.0, 1e-9, 1.0, 9.0, 0.0, 1e-9, 0.0, -1e-14]);
        let (out, repair) = passive_damping(std::slice::from_ref(&noisy));
        assert_eq!(repair, PassivityRepair::default());
        assert_eq!(out[0], noisy);
    }

    #[test]
    fn pl_weights_are_exact_for_linear_functions() {
        // int_0^3 (2 + x) cos(1.7 x) dx and sin, analytically
        let nodes = [0.0, 0.4, 1.1, 2.0, 3.0];
        let f: Vec<f64> = nodes.iter().map(|x| 2.0 + x).collect();
        let s = 1.7;
        let prim_cos = |x: f64| (2.0 + x) * (s * x).sin() / s + (s * x).cos() / (s * s);
        let prim_sin = |x: f64| -(2.0 + x) * (s * x).cos() / s + (s * x).sin() / (s * s);
        let mut w = [0.0; 5];
        pl_weights(&nodes, s, false, &mut w);
        let got: f64 = w.iter().zip(&f).map(|(a, b)| a * b).sum();
        assert!((got - (prim_cos(3.0) - prim_cos(0.0))).abs() < 1e-12, "{got}");
        pl_weights(&nodes, s, true, &mut w);
        let got: f64 = w.iter().zip(&f).map(|(a, b)| a * b).sum();
        assert!((got - (prim_sin(3.0) - prim_sin(0.0))).abs() < 1e-12, "{got}");
        // small s h uses Gauss-Legendre: still exact to rounding for s = 1e-3
        pl_weights(&nodes, 1e-3, false, &mut w);
        let got: f64 = w.iter().zip(&f).map(|(a, b)| a * b).sum();
        let s: f64 = 1e-3;
        let exact = (2.0 + 3.0) * (s * 3.0).sin() / s + (s * 3.0).cos() / (s * s) - 1.0 / (s * s);
        assert!((got - exact).abs() < 1e-9, "{got} vs {exact}");
    }

    /// A one-mode database whose damping is a lightly damped resonance B(w) = b w^2 ... sampled finely.
    fn resonant_db() -> HydroDb {
        let n = 6;
        // B(w) = c w^2 exp(-(w/w0)^2): smooth, decays, zero at w = 0
        let ws: Vec<f64> = (1..=400).map(|k| k as f64 * 0.01).collect();
        let bfun = |w: f64| 1000.0 * w * w * (-(w / 1.0f64).powi(2)).exp();
        let mut a = vec![];
        let mut b = vec![];
        for &w in &ws {
            let mut bm = DMatrix::zeros(n, n);
            bm[(2, 2)] = bfun(w);
            b.push(bm);
            a.push(DMatrix::zeros(n, n));
        }
        let rad = Radiation {
            omega_rad_s: ws.clone(),
            added_mass: a,
            damping: b,
            added_mass_zero: None,
            added_mass_inf: None,
        };
        let exc = Excitation {
            omega_rad_s: ws.clone(),
            heading_deg: vec![0.0],
            values: vec![Complex64::default(); ws.len() * n],
            n_modes: n,
        };
        HydroDb::new(rad, exc, DMatrix::zeros(n, n), "t").unwrap()
    }

    #[test]
    fn irf_transforms_back_to_the_damping() {
        let db = resonant_db();
        let irf = impulse_response(&db, 0.05, 60.0);
        let back = transform_irf(&irf, &db.omega_rad_s, false);
        let peak = db.damping.iter().map(|m| m[(2, 2)]).fold(0.0, f64::max);
        let worst = db
            .damping
            .iter()
            .zip(&back)
            .map(|(b, k)| (b[(2, 2)] - k[(2, 2)]).abs())
            .fold(0.0, f64::max);
        // K is smooth and has decayed by 60 s; linear-in-t error of dt = 0.05 s dominates
        assert!(worst < 1e-3 * peak, "worst {worst} of peak {peak}");
        // K(0) = (2/pi) int B dw = (2/pi) * 1000 * sqrt(pi)/4 for this B (w0 = 1), tail negligible
        let k0 = 2.0 / PI * 1000.0 * PI.sqrt() / 4.0;
        assert!(
            (irf.k[0][(2, 2)] - k0).abs() < 2e-3 * k0,
            "{} vs {k0}",
            irf.k[0][(2, 2)]
        );
    }

    #[test]
    fn kramers_kronig_of_a_consistent_pair_is_small() {
        // Build A(w) from B(w) by the KK relation itself, then check that the check finds it consistent.
        let mut db = resonant_db();
        let irf = impulse_response(&db, 0.05, 60.0);
        let sines = transform_irf(&irf, &db.omega_rad_s, true);
        let a_inf = 5000.0;
        for (k, w) in db.omega_rad_s.clone().iter().enumerate() {
            db.added_mass[k][(2, 2)] = a_inf - sines[k][(2, 2)] / w;
        }
        let mut ainf = DMatrix::zeros(6, 6);
        ainf[(2, 2)] = a_inf;
        let e = kramers_kronig(&db, &irf, &ainf);
        assert_eq!(e.len(), 1);
        assert!(e[0].added_mass < 1e-12, "{e:?}");
        let est = ogilvie_a_inf(&ogilvie_estimates(&db, &irf));
        assert!((est[(2, 2)] - a_inf).abs() < 1e-9 * a_inf);
        // and it notices an inconsistent A_inf
        ainf[(2, 2)] = 1.1 * a_inf;
        let e = kramers_kronig(&db, &irf, &ainf);
        assert!(e[0].added_mass > 0.05, "{e:?}");
    }

    /// Two coupled DOFs whose damping goes on past the database's last frequency w_N = 1: DOF 0 decays
    /// as w^-2 (slower than the cubic tail: damping is missing), DOF 1 as exp(-w^2/0.3) (faster: the
    /// cubic tail adds too much). A(w) is made from the whole B by the relations themselves.
    /// (frequencies, damping, added mass, A_inf) of a test database.
    type TestDb = (Vec<f64>, Vec<DMatrix<f64>>, Vec<DMatrix<f64>>, DMatrix<f64>);

    fn truncated_pair() -> TestDb {
        let b = |w: f64| {
            let b0 = 1000.0 * w * w / (1.0 + w * w).powi(2);
            let b1 = 1000.0 * w * w * (-w * w / 0.3).exp();
            let c = 0.3 * (b0 * b1).sqrt();
            DMatrix::from_row_slice(2, 2, &[b0, c, c, b1])
        };
        let full_w: Vec<f64> = (1..=4000).map(|k| k as f64 * 0.01).collect();
        let full_b: Vec<DMatrix<f64>> = full_w.iter().map(|w| b(*w)).collect();
        // the full B decays to ~0.6 % of its peak by 40 rad/s (DOF 0): its own cubic tail is negligible
        let tail = DampingTail::cubic(&full_w, &full_b);
        let irf = impulse_response_of(&full_w, &full_b, &tail, 0.05, 60.0);
        let a_inf = DMatrix::from_row_slice(2, 2, &[5000.0, 100.0, 100.0, 3000.0]);
        let ws: Vec<f64> = (1..=100).map(|k| k as f64 * 0.01).collect();
        let sines = transform_irf(&irf, &ws, true);
        let a: Vec<DMatrix<f64>> = sines.iter().zip(&ws).map(|(s, w)| &a_inf - s / *w).collect();
        (ws.clone(), ws.iter().map(|w| b(*w)).collect(), a, a_inf)
    }

    #[test]
    fn the_fitted_tail_restores_the_missing_damping() {
        let (ws, b, a, a_inf) = truncated_pair();
        let fit = fit_tail(&ws, &b, &a, &a_inf, 0.05, 60.0);
        // the cubic tail leaves an added-mass residual; the fit removes most of it
        assert!(fit.residual_cubic > 0.01, "{}", fit.residual_cubic);
        assert!(
            fit.residual_fitted < 0.25 * fit.residual_cubic,
            "{} vs {}",
            fit.residual_fitted,
            fit.residual_cubic
        );
        let t = &fit.tail;
        // more damping where it decays slowly, less where it decays fast
        assert!(t.far[(0, 0)] > 0.0 && t.near_power[0] == TAIL_POWER as f64, "{t:?}");
        assert!(t.near_power[1] > TAIL_POWER as f64 && t.far[(1, 1)] == 0.0, "{t:?}");
        // and what it adds is near what is missing: the true B at 2 w_N against the tail there
        let b0 = |w: f64| 1000.0 * w * w / (1.0 + w * w).powi(2);
        let (cubic_at_2, fitted_at_2) = (b0(1.0) / 8.0, t.at(2.0)[(0, 0)]);
        assert!(
            (fitted_at_2 - b0(2.0)).abs() < 0.5 * (cubic_at_2 - b0(2.0)).abs(),
            "true {} cubic {cubic_at_2} fitted {fitted_at_2}",
            b0(2.0)
        );
    }

    #[test]
    fn the_fitted_tail_is_passive_and_continuous() {
        let (ws, b, a, a_inf) = truncated_pair();
        let t = fit_tail(&ws, &b, &a, &a_inf, 0.05, 60.0).tail;
        // B(w_N) itself at the join
        assert!((t.at(1.0) - b.last().unwrap()).amax() < 1e-9 * b.last().unwrap().amax());
        for k in 0..400 {
            let w = 1.0 + 0.05 * k as f64;
            let m = t.at(w);
            let lowest = m.clone().symmetric_eigen().eigenvalues.min();
            assert!(lowest >= -1e-12 * m.amax(), "w {w}: {m}");
        }
    }

    #[test]
    fn a_database_without_missing_damping_keeps_the_cubic_tail_close() {
        // B decays fast (exp) and is negligible at w_N: there is nothing to fit, the tail stays tiny
        let db = resonant_db();
        let ws = db.omega_rad_s.clone();
        let irf = impulse_response(&db, 0.05, 60.0);
        let sines = transform_irf(&irf, &ws, true);
        let mut ainf = DMatrix::zeros(6, 6);
        ainf[(2, 2)] = 5000.0;
        let a: Vec<DMatrix<f64>> = sines.iter().zip(&ws).map(|(s, w)| &ainf - s / *w).collect();
        let fit = fit_tail(&ws, &db.damping, &a, &ainf, 0.05, 60.0);
        assert!(fit.residual_fitted <= fit.residual_cubic + 1e-12);
        assert!(fit.tail.far.amax() <= 1e-6 * 1000.0, "{:?}", fit.tail.far);
    }
}
