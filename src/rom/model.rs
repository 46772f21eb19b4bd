//! The assembled time-domain model of a vessel system over its active DOFs (pure).

use super::{Error, Result};
use crate::hydro::{HydroDb, VesselSystem};
use crate::radiation::irf;
use crate::radiation::memory::{
    RadiationMemory, active_radiation, memory_duration_s, model_a_inf, radiation_memory, state_space_memory,
};
use crate::radiation::modal::ModalStep;
use crate::radiation::partitioned::{Partitions, block_for};
use crate::radiation::statespace::{ModalModel, ModalOptions};
use nalgebra::DMatrix;

/// How the radiation memory is evaluated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RadiationMethod {
    /// Direct convolution of K with the velocity history (the reference).
    Convolution,
    /// The passive state-space fit with its exact discrete update.
    StateSpace,
    /// No memory: A(w) and B(w) of one frequency as constant coefficients (WEC-Sim's `regular` runs;
    /// right only in a regular wave of that frequency, after the transient).
    Constant { omega_rad_s: f64 },
}

/// Integration parameters (plain `Copy`; every field documents unit and default).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RomOptions {
    /// Time step, s. Default 0.1 s.
    pub dt_s: f64,
    /// Newmark beta (gamma = 1/2). Default 1/4 (average acceleration, unconditionally stable).
    pub beta: f64,
    /// Radiation memory method. Default convolution.
    pub radiation: RadiationMethod,
    /// Forward speed along +x of every vessel, m/s. Default 0.
    pub speed_m_s: f64,
    /// Memory length of the convolution, s. Default: the IRF's (pi / smallest frequency spacing,
    /// 30..600 s) or the system file's `irf.duration_s`.
    pub memory_s: Option<f64>,
    /// State-space fit tolerance (largest scaled damping error). Default 0.005.
    pub ss_tolerance: f64,
}

impl Default for RomOptions {
    fn default() -> Self {
        RomOptions {
            dt_s: 0.1,
            beta: 0.25,
            radiation: RadiationMethod::Convolution,
            speed_m_s: 0.0,
            memory_s: None,
            ss_tolerance: 0.005,
        }
    }
}

/// Largest |forward speed|, m/s: 50 knots, beyond any ship the zero-speed database stands for.
pub const MAX_SPEED_M_S: f64 = 25.0;

/// An option of [`RomOptions`] out of range: the field and why.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{field}: {msg}")]
pub struct OptionError {
    /// `dt_s`, `memory_s`, `beta`, `speed_m_s` or `ss_tolerance`.
    pub field: &'static str,
    pub msg: String,
}

impl RomOptions {
    /// The one check of the options, for every caller (the configuration, the CLI, scenarios and
    /// [`TimeModel::new`]): the step in [`irf::MIN_DT_S`]..[`irf::MAX_DT_S`], the memory (when
    /// given) in (0, [`irf::MAX_MEMORY_S`]] and at most [`irf::MAX_TAPS`] steps long, beta in
    /// (0, 1/2], |speed| at most [`MAX_SPEED_M_S`], the fit tolerance in (0, 1).
    pub fn validate(&self) -> std::result::Result<(), OptionError> {
        let grid = |e: irf::GridError| OptionError {
            field: e.field(),
            msg: e.to_string(),
        };
        irf::check_dt(self.dt_s).map_err(grid)?;
        if let Some(m) = self.memory_s {
            irf::check_grid(self.dt_s, m).map_err(grid)?;
        }
        if !(self.beta > 0.0 && self.beta <= 0.5) {
            return Err(OptionError {
                field: "beta",
                msg: format!("Newmark beta must be in (0, 0.5], found {:?}", self.beta),
            });
        }
        if !(self.speed_m_s.is_finite() && self.speed_m_s.abs() <= MAX_SPEED_M_S) {
            return Err(OptionError {
                field: "speed_m_s",
                msg: format!(
                    "the forward speed must be in [-{MAX_SPEED_M_S}, {MAX_SPEED_M_S}] m/s, found {:?}",
                    self.speed_m_s
                ),
            });
        }
        if !(self.ss_tolerance > 0.0 && self.ss_tolerance < 1.0) {
            return Err(OptionError {
                field: "ss_tolerance",
                msg: format!(
                    "the state-space fit tolerance must be in (0, 1), found {:?}",
                    self.ss_tolerance
                ),
            });
        }
        Ok(())
    }
}

/// The radiation memory of a model, ready for stepping.
#[derive(Debug, Clone)]
pub enum Kernel {
    /// `k[(i * taps + m) * n + j] = dt w_m K_m(i, j)`, trapezoid weights w_0 = w_last = 1/2; `parts`: the
    /// taps from one block on in the frequency domain, for a run's own velocities ([`crate::radiation::partitioned`]).
    Convolution {
        taps: usize,
        k: Vec<f64>,
        parts: std::sync::Arc<Partitions>,
    },
    /// The fitted modal model and its exact discrete update at the solver's step.
    StateSpace {
        model: Box<ModalModel>,
        step: Box<ModalStep>,
    },
}

impl Kernel {
    /// The measured velocities the convolution reads (its taps); None for the state-space model,
    /// whose modal states carry the memory.
    pub fn taps(&self) -> Option<usize> {
        match self {
            Kernel::Convolution { taps, .. } => Some(*taps),
            Kernel::StateSpace { .. } => None,
        }
    }

    /// The fitted modal model of the state-space radiation; None for the convolution.
    pub fn modal_model(&self) -> Option<&ModalModel> {
        match self {
            Kernel::Convolution { .. } => None,
            Kernel::StateSpace { model, .. } => Some(model),
        }
    }
}

/// Scratch for [`TimeModel::nonlinear_force`].
#[derive(Debug, Clone, Default)]
pub struct NlScratch {
    x: Vec<f64>,
    v: Vec<f64>,
    f: Vec<f64>,
}

/// The free motion of a stable model loses energy to radiation and damping; a drift mode keeps its
/// kinetic energy: more than this growth is instability ([`TimeModel::new`] with `irf.passivity = "none"`).
pub const FREE_MOTION_GROWTH: f64 = 1.5;

/// Time-domain model over the active DOFs. Matrices are n x n with n = number of active DOFs, in the
/// order of `active` (global 0-based mode indices).
#[derive(Debug, Clone)]
pub struct TimeModel {
    /// Number of states: 6N body modes then one per tank.
    pub n_modes: usize,
    /// Active states (global indices): the active body DOFs, then every tank.
    pub active: Vec<usize>,
    /// `body.dof` label of each active DOF.
    pub labels: Vec<String>,
    pub opts: RomOptions,
    /// M + A_inf.
    pub mass: DMatrix<f64>,
    /// (M + A_inf)^-1.
    pub mass_inv: DMatrix<f64>,
    /// B_lin + B_U U.
    pub damping: DMatrix<f64>,
    /// C + C_UQ U^2 (with system-level entries).
    pub stiffness: DMatrix<f64>,
    /// The same with the nonlinear connections (lines, fenders) linearized at equilibrium, as the
    /// frequency-domain solver has them: the linear equations of the implied RAO (the floor).
    pub stiffness_linearized: DMatrix<f64>,
    /// The modes of (M + A_inf, the linearized stiffness) with little or no restoring ([`super::drift`]).
    pub drift_modes: Vec<super::drift::DriftMode>,
    /// B_Q, when any entry is non-zero.
    pub quadratic: Option<DMatrix<f64>>,
    /// The nonlinear connections (mooring lines, fenders), when there are any.
    pub external: Option<crate::hydro::external::External>,
    /// Their generalized force at equilibrium (n_modes), subtracted (see [`crate::hydro::external`]).
    pub nl_offset: Vec<f64>,
    /// Number of active body DOFs: they come first in `active`, the tank states after them.
    pub n_hydro: usize,
    pub kernel: Kernel,
    /// The step's matrices, column by column with columns padded to `n_pad` rows for its inner loop
    /// ([`super::dense`]): [B + D | C] (n x 2n; D the instantaneous radiation matrix,
    /// F_rad(t_k+1) = P + D v_k+1) and S^-1 = [M + dt/2 (B + D) + beta dt^2 C]^-1.
    pub n_pad: usize,
    pub cols_bdc: Vec<f64>,
    pub cols_s_inv: Vec<f64>,
    /// The database (for the excitation), with the system's g and depth.
    pub db: HydroDb,
    pub g_m_s2: f64,
    pub water_depth_m: Option<f64>,
    /// The convolution's IRF (active DOFs, unweighted) for the implied frequency response.
    irf: Option<irf::Irf>,
}

/// The convolution's kernel: K's taps at the solver's step `dt` weighted by the trapezoidal rule, over
/// the `n` active states (`hyd` reads a hydrodynamic matrix there, zero on tank states), and the
/// instantaneous part (tap 0).
fn convolution_kernel(
    irf_all: &irf::Irf,
    hyd: &dyn Fn(&DMatrix<f64>, usize, usize) -> f64,
    n: usize,
    dt: f64,
) -> (Kernel, DMatrix<f64>) {
    let taps = irf_all.k.len();
    let mut k = vec![0.0; n * taps * n];
    for (m, km) in irf_all.k.iter().enumerate() {
        let w = if m == 0 || m + 1 == taps { 0.5 } else { 1.0 };
        for i in 0..n {
            for j in 0..n {
                k[(i * taps + m) * n + j] = dt * w * hyd(km, i, j);
            }
        }
    }
    let d = DMatrix::from_fn(n, n, |i, j| k[(i * taps) * n + j]);
    let parts = std::sync::Arc::new(Partitions::new(&k, taps, n, block_for(taps)));
    (Kernel::Convolution { taps, k, parts }, d)
}

/// K over the `n` active states (unweighted) on the solver's step `dt`.
fn active_irf(irf_all: &irf::Irf, hyd: &dyn Fn(&DMatrix<f64>, usize, usize) -> f64, n: usize, dt: f64) -> irf::Irf {
    irf::Irf {
        dt_s: dt,
        k: irf_all
            .k
            .iter()
            .map(|km| DMatrix::from_fn(n, n, |r, c| hyd(km, r, c)))
            .collect(),
    }
}

/// The state-space kernel: the passive fit of the active DOFs' radiation (A_inf `a_inf_all`, damping
/// tail `tail`) with its exact step, and its instantaneous part; the fit's passivity cover is added to
/// `damping`.
fn state_space_kernel(
    sys: &VesselSystem,
    a_inf_all: &DMatrix<f64>,
    tail: &irf::DampingTail,
    opts: &RomOptions,
    n: usize,
    damping: &mut DMatrix<f64>,
) -> Result<(Kernel, DMatrix<f64>)> {
    let nh = sys.active_indices().len();
    let dt = opts.dt_s;
    let model = active_radiation(sys, a_inf_all, tail)
        .fit(
            &sys.db.omega_rad_s,
            ModalOptions {
                tolerance: opts.ss_tolerance,
                ..ModalOptions::default()
            },
        )
        .map_err(|e| Error::Input(format!("state-space radiation: {}", e.0)))?;
    let step = ModalStep::new(&model, dt);
    let di = step.instantaneous();
    let mut d = DMatrix::zeros(n, n);
    d.view_mut((0, 0), (nh, nh)).copy_from(&di);
    // passivity cover: constant damping where the fit's Re K dips below zero (see radiation::statespace)
    for i in 0..nh {
        damping[(i, i)] += model.cover * model.scale[i];
    }
    // A_inf as the convolution's (Ogilvie's from the IRF unless the system file asks for the
    // database's): the fit reproduces the same damping and tail, so the same K; an Ogilvie
    // estimate from the fitted kernel would carry the fit's error into the added mass
    Ok((
        Kernel::StateSpace {
            model: Box::new(model),
            step: Box::new(step),
        },
        d,
    ))
}

/// The radiation memory a model of `opts` runs, sampled where it is fitted: the convolution samples K
/// at the solver's step; the state-space model is fitted once per database (and speed) on the system
/// file's IRF grid (`irf.dt_s`), so it, its tail and its A_inf do not move with the solver's step (a
/// fit at each step would move the model's floor with dt). The IRF is from passive damping and the
/// damping tail.
fn sampled_memory(sys: &VesselSystem, opts: &RomOptions) -> Result<RadiationMemory> {
    let memory_s = opts.memory_s.unwrap_or_else(|| memory_duration_s(sys));
    // the grids K is sampled on: the solver's (convolution) and the system file's (state-space fit)
    let grid_dt = match opts.radiation {
        RadiationMethod::StateSpace => sys.spec.irf.dt_s,
        _ => opts.dt_s,
    };
    irf::check_grid(grid_dt, memory_s).map_err(|e| OptionError {
        field: e.field(),
        msg: e.to_string(),
    })?;
    Ok(match opts.radiation {
        RadiationMethod::StateSpace => state_space_memory(sys, memory_s),
        _ => radiation_memory(sys, opts.dt_s, memory_s),
    })
}

/// The inverses of the implicit step's matrix S = M + B dt / 2 + C beta dt^2 (`damping`: B with the
/// instantaneous radiation damping) and of the mass M (+ A_inf), which must be positive definite.
fn step_inverses(
    mass: &DMatrix<f64>,
    damping: &DMatrix<f64>,
    stiffness: &DMatrix<f64>,
    opts: &RomOptions,
) -> Result<(DMatrix<f64>, DMatrix<f64>)> {
    let dt = opts.dt_s;
    let s = mass + damping * (dt / 2.0) + stiffness * (opts.beta * dt * dt);
    let s_inv = s
        .try_inverse()
        .ok_or_else(|| Error::Input("the implicit step matrix is singular (no mass on an active DOF?)".into()))?;
    let mass_inv = mass
        .clone()
        .try_inverse()
        .ok_or_else(|| Error::Input("the mass matrix M + A_inf is singular".into()))?;
    if mass.clone().cholesky().is_none() {
        return Err(Error::Input(
            "M + A_inf (with the tanks' fluid) is not positive definite: check the tank coefficients a_tt, a_t4".into(),
        ));
    }
    Ok((s_inv, mass_inv))
}

impl TimeModel {
    /// The model of `sys` with `opts`, assembled; [`TimeModel::new`] (`rom/build.rs`) checks it.
    pub(super) fn assemble(sys: &VesselSystem, opts: RomOptions) -> Result<TimeModel> {
        opts.validate()?;
        let active = sys.active_states();
        let nh = sys.active_indices().len();
        if nh == 0 {
            return Err(Error::Input("no active DOF in the system".into()));
        }
        let n = active.len();
        let nm = sys.n_modes();
        // hydrodynamic matrices are n_modes x n_modes: zero beyond (tank states)
        let hyd = |m: &DMatrix<f64>, r: usize, c: usize| {
            let (i, j) = (active[r], active[c]);
            if i < nm && j < nm { m[(i, j)] } else { 0.0 }
        };
        let sub = |m: &DMatrix<f64>| DMatrix::from_fn(n, n, |r, c| m[(active[r], active[c])]);
        let dt = opts.dt_s;
        let u = opts.speed_m_s;
        let RadiationMemory { irf: irf_all, tail, .. } = sampled_memory(sys, &opts)?;
        // A_inf: Ogilvie's estimate from the same K unless the system file insists on the database's
        // (Ogilvie's is consistent with the K the model runs, so its floor is the closer one)
        let a_inf_all = model_a_inf(sys, &irf_all);
        let terms = sys.linear_terms();
        let pad = |m: &DMatrix<f64>| sys.pad_states(m);
        let mut mass = sub(&(&terms.mass + pad(&a_inf_all)));
        let damping = sub(&(&terms.damping + pad(&(sys.body_matrix(|b| &b.speed_damping) * u))));
        let stiffness = sub(&(&terms.stiffness + pad(&(sys.body_matrix(|b| &b.speed_restoring) * (u * u)))));
        let q = sub(&pad(&sys.body_matrix(|b| &b.quadratic_damping)));
        let quadratic = if q.iter().any(|v| *v != 0.0) { Some(q) } else { None };
        let mut damping = damping;
        let (kernel, d_inst) = match opts.radiation {
            RadiationMethod::Constant { omega_rad_s } => {
                let (a, b) = sys.db.radiation_at(omega_rad_s)?;
                mass = sub(&(&terms.mass + pad(&a)));
                damping += sub(&pad(&b));
                (
                    Kernel::Convolution {
                        taps: 1,
                        k: vec![0.0; n * n],
                        parts: std::sync::Arc::new(Partitions::new(&[], 1, n, block_for(1))),
                    },
                    DMatrix::zeros(n, n),
                )
            }
            RadiationMethod::Convolution => convolution_kernel(&irf_all, &hyd, n, dt),
            RadiationMethod::StateSpace => state_space_kernel(sys, &a_inf_all, &tail, &opts, n, &mut damping)?,
        };
        let (s_inv, mass_inv) = step_inverses(&mass, &(&damping + &d_inst), &stiffness, &opts)?;
        // the convolution's IRF for the implied frequency response (active DOFs, unweighted)
        let irf = matches!(opts.radiation, RadiationMethod::Convolution).then(|| active_irf(&irf_all, &hyd, n, dt));
        let external = sys.spec.external.has_nonlinear().then(|| sys.spec.external.clone());
        let stiffness_linearized = &stiffness + sub(&sys.spec.external.nonlinear_tangent(sys.n_states()));
        let drift_modes = super::drift::drift_modes(&mass, &stiffness_linearized);
        let mut nl_offset = vec![0.0; sys.n_states()];
        if let Some(e) = &external {
            let z = vec![0.0; sys.n_states()];
            e.nonlinear_force(&z, &z, &mut nl_offset);
        }
        let labels = active.iter().map(|&i| crate::hydro::mode_label(sys, i)).collect();
        let mut bdc = DMatrix::zeros(n, 2 * n);
        bdc.view_mut((0, 0), (n, n)).copy_from(&(&damping + &d_inst));
        bdc.view_mut((0, n), (n, n)).copy_from(&stiffness);
        let model = TimeModel {
            n_pad: super::dense::pad(n),
            cols_bdc: super::dense::columns(&bdc),
            cols_s_inv: super::dense::columns(&s_inv),
            n_modes: sys.n_states(),
            n_hydro: nh,
            external,
            nl_offset,
            active,
            labels,
            opts,
            mass,
            mass_inv,
            damping,
            stiffness,
            stiffness_linearized,
            drift_modes,
            quadratic,
            kernel,
            db: sys.db.clone(),
            g_m_s2: sys.spec.g_m_s2,
            water_depth_m: sys.spec.water_depth_m,
            irf,
        };
        Ok(model)
    }

    /// K(i w) = B(w) + i w (A(w) - A_inf) of the model's own radiation memory (active DOFs): the
    /// transform of the sampled K (linear between samples), or the state-space model's kernel.
    pub fn kernel_at(&self, omega_rad_s: f64) -> DMatrix<num_complex::Complex64> {
        self.kernels_at(&[omega_rad_s])
            .pop()
            .unwrap_or_else(|| DMatrix::zeros(self.n(), self.n()))
    }

    /// [`TimeModel::kernel_at`] at each of `omegas_rad_s`: the sampled K's transform made for all of
    /// them at once (one pass over the memory's samples).
    pub fn kernels_at(&self, omegas_rad_s: &[f64]) -> Vec<DMatrix<num_complex::Complex64>> {
        use num_complex::Complex64;
        let n = self.n();
        match (&self.kernel, &self.irf) {
            (Kernel::StateSpace { model, .. }, _) => {
                let nh = self.n_hydro;
                omegas_rad_s
                    .iter()
                    .map(|&w| {
                        let k = model.kernel(w);
                        DMatrix::from_fn(n, n, |i, j| {
                            if i < nh && j < nh {
                                k[(i, j)]
                            } else {
                                Complex64::default()
                            }
                        })
                    })
                    .collect()
            }
            (_, Some(irf)) => {
                let c = irf::transform_irf(irf, omegas_rad_s, false);
                let s = irf::transform_irf(irf, omegas_rad_s, true);
                c.iter()
                    .zip(&s)
                    .map(|(c, s)| DMatrix::from_fn(n, n, |i, j| Complex64::new(c[(i, j)], -s[(i, j)])))
                    .collect()
            }
            _ => vec![DMatrix::zeros(n, n); omegas_rad_s.len()],
        }
    }

    /// The frequency-domain response of this time-domain model itself (the A and B implied by its
    /// radiation memory, its A_inf, B_lin, C, the nonlinear connections linearized at equilibrium as the
    /// frequency-domain solver has them): the floor a linear time-domain run converges to as dt -> 0.
    /// Every mode, inactive ones zero, per metre of wave amplitude, zero speed.
    pub fn implied_rao(&self, omega_rad_s: f64, heading_rad: f64) -> Result<Vec<num_complex::Complex64>> {
        self.implied_rao_with(&self.kernel_at(omega_rad_s), omega_rad_s, heading_rad)
    }

    /// [`TimeModel::implied_rao`] with the kernel at `omega_rad_s` already computed (`kernel_at`): one
    /// kernel serves every heading.
    pub fn implied_rao_with(
        &self,
        k: &DMatrix<num_complex::Complex64>,
        omega_rad_s: f64,
        heading_rad: f64,
    ) -> Result<Vec<num_complex::Complex64>> {
        use num_complex::Complex64;
        let n = self.n();
        let mut x = vec![Complex64::default(); self.n_modes];
        let nm = self.db.n_modes;
        self.db.excitation_into(omega_rad_s, heading_rad, &mut x[..nm])?;
        let w = omega_rad_s;
        let z = DMatrix::from_fn(n, n, |i, j| {
            Complex64::new(
                -w * w * self.mass[(i, j)] + self.stiffness_linearized[(i, j)],
                w * self.damping[(i, j)],
            ) + Complex64::new(0.0, w) * k[(i, j)]
        });
        let rhs = nalgebra::DVector::from_fn(n, |r, _| x[self.active[r]]);
        let sol = z
            .lu()
            .solve(&rhs)
            .ok_or_else(|| Error::Input(format!("singular equations at {w} rad/s")))?;
        let mut out = vec![Complex64::default(); self.n_modes];
        for (r, &i) in self.active.iter().enumerate() {
            out[i] = sol[r];
        }
        Ok(out)
    }

    /// True when the equations have nonlinear terms (quadratic damping, lines, fenders).
    pub fn is_nonlinear(&self) -> bool {
        self.quadratic.is_some() || self.external.is_some()
    }

    /// The nonlinear forces at the active states x, v (B_Q |v| v plus the connections' force relative
    /// to equilibrium, as a load on the left-hand side: the negative of the connection force), into
    /// `out`; `ws` is scratch.
    pub fn nonlinear_force(&self, x: &[f64], v: &[f64], out: &mut [f64], ws: &mut NlScratch) {
        let n = out.len();
        match &self.quadratic {
            Some(q) => {
                for i in 0..n {
                    out[i] = (0..n).map(|j| q[(i, j)] * v[j].abs() * v[j]).sum();
                }
            }
            None => out.iter_mut().for_each(|f| *f = 0.0),
        }
        if let Some(e) = &self.external {
            let nm = self.n_modes;
            for b in [&mut ws.x, &mut ws.v, &mut ws.f] {
                b.clear();
                b.resize(nm, 0.0);
            }
            for (r, &i) in self.active.iter().enumerate() {
                ws.x[i] = x[r];
                ws.v[i] = v[r];
            }
            e.nonlinear_force(&ws.x, &ws.v, &mut ws.f);
            for (r, &i) in self.active.iter().enumerate() {
                out[r] -= ws.f[i] - self.nl_offset[i];
            }
        }
    }

    /// Number of active states.
    pub fn n(&self) -> usize {
        self.active.len()
    }

    /// Memory length in steps (convolution taps), or the number of state-space states.
    pub fn memory_size(&self) -> usize {
        match &self.kernel {
            Kernel::Convolution { taps, .. } => *taps,
            Kernel::StateSpace { model, .. } => model.real_order(),
        }
    }
}
