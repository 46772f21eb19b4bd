//! One time step of the Cummins equations, Newmark (gamma = 1/2, beta from the options), with the
//! radiation force split into a known part and an implicit instantaneous part (see [`super`]).
//! The stepper owns only reusable workspace; what it reads comes in as arguments.

use super::dense;
use super::model::{Kernel, NlScratch, TimeModel};
use super::{Error, Result};
use crate::radiation::history::Memory;
use crate::radiation::partitioned::{PartitionedRun, Partitions, block_for_run};
use multiversion::multiversion;
use std::sync::{Arc, Weak};

/// Displacement beyond which a state counts as unbounded (m or rad).
pub const UNBOUNDED: f64 = 1.0e4;

/// Workspace and current state of a run.
#[derive(Debug, Clone, Default)]
pub struct Stepper {
    n: usize,
    /// Steps the buffers are sized for.
    capacity: usize,
    pub x: Vec<f64>,
    pub v: Vec<f64>,
    pub a: Vec<f64>,
    /// Index of the current step (0 at the start).
    pub k: usize,
    /// Convolution: velocities in reverse time order; v_k at (capacity - k) n, history after v_0.
    buf: Vec<f64>,
    /// Convolution: the run's velocities (v_1 on) against the taps beyond one block.
    run: PartitionedRun,
    /// Convolution: the partitions this run uses: the model's, or a set blocked for the run's length.
    active: Option<Arc<Partitions>>,
    /// Convolution: the sets blocked for shorter runs, built for the model whose partitions these are.
    sized: Vec<Arc<Partitions>>,
    sized_for: Weak<Partitions>,
    /// State space: the modes' states (r real parts, then r imaginary parts), held one half-update
    /// ahead during a run (see [`crate::radiation::modal`]), and their input b . v at the start, laid out alike.
    states: Vec<f64>,
    beta: Vec<f64>,
    /// State space: the radiation force the states give at the next step (all but the new velocity's).
    rad_next: Vec<f64>,
    // scratch; `zt` is the predictor, velocities then displacements (one product with [B + D | C])
    zt: Vec<f64>,
    lin: Vec<f64>,
    rhs: Vec<f64>,
    a_try: Vec<f64>,
    p: Vec<f64>,
    fnl: Vec<f64>,
    a_new: Vec<f64>,
    v_new: Vec<f64>,
    v_pred: Vec<f64>,
    x_pred: Vec<f64>,
    nl: NlScratch,
    /// Fixed-point passes of the nonlinear forces taken by the last step.
    pub passes: usize,
}

/// Nonlinear forces (quadratic damping, lines, fenders) are iterated at each step until the new
/// acceleration changes by less than this fraction of its largest entry...
pub const NL_TOLERANCE: f64 = 1e-10;
/// ... or for at most this many passes (each pass is one force evaluation and one n x n product).
pub const NL_MAX_PASSES: usize = 12;

/// Partition sets blocked for shorter runs a stepper keeps (its forecasts' length and the estimator's
/// runs; each a few MB).
const SIZED_KEPT: usize = 4;

impl Stepper {
    pub fn new() -> Self {
        Self::default()
    }

    /// Sizes the workspace for `steps` steps (reallocates only when it grows).
    fn reserve(&mut self, model: &TimeModel, steps: usize) {
        let n = model.n();
        let taps = match &model.kernel {
            Kernel::Convolution { taps, .. } => *taps,
            Kernel::StateSpace { .. } => 0,
        };
        if self.n != n || self.capacity < steps {
            self.n = n;
            self.capacity = steps;
            for v in [
                &mut self.x,
                &mut self.v,
                &mut self.a,
                &mut self.rad_next,
                &mut self.lin,
                &mut self.rhs,
                &mut self.a_try,
                &mut self.p,
                &mut self.fnl,
                &mut self.a_new,
                &mut self.v_new,
                &mut self.v_pred,
                &mut self.x_pred,
            ] {
                v.resize(n, 0.0);
            }
            self.zt.resize(2 * n, 0.0);
            self.buf = vec![0.0; if taps > 0 { (steps + taps) * n } else { 0 }];
        }
        if let Kernel::StateSpace { step, .. } = &model.kernel {
            self.states.resize(2 * step.r, 0.0);
            self.beta.resize(2 * step.r, 0.0);
        }
    }

    fn pos(&self, k: isize) -> usize {
        ((self.capacity as isize - k) as usize) * self.n
    }

    /// Starts a run of up to `steps` steps from (x0, v0) at t0 with the memory of the velocities before
    /// t0; `f0` is the wave force at t0.
    pub fn start(
        &mut self,
        model: &TimeModel,
        x0: &[f64],
        v0: &[f64],
        memory: &Memory,
        steps: usize,
        f0: &[f64],
    ) -> Result<()> {
        let n = model.n();
        if x0.len() != n || v0.len() != n {
            return Err(Error::Input(format!(
                "initial state has {} / {} values, the model {n} active DOFs",
                x0.len(),
                v0.len()
            )));
        }
        if let Some(i) = x0.iter().chain(v0).position(|x| !x.is_finite()) {
            return Err(Error::Input(format!(
                "initial state of {} is not finite",
                model.labels[i % n]
            )));
        }
        self.reserve(model, steps);
        self.k = 0;
        self.x.copy_from_slice(x0);
        self.v.copy_from_slice(v0);
        // radiation force at t0
        let mut frad = std::mem::take(&mut self.p);
        frad.iter_mut().for_each(|f| *f = 0.0);
        match (&model.kernel, memory) {
            (Kernel::Convolution { taps, k, parts }, Memory::Convolution { .. }) => {
                let parts = self.partitions_for(parts, k, *taps, n, steps);
                // the run's input s_0 is zero: v_0 and the history are the caller's known part
                self.run.reset(&parts);
                self.v_new.iter_mut().for_each(|v| *v = 0.0);
                self.run.push(&parts, &self.v_new);
                self.active = Some(parts);
                let p0 = self.pos(0);
                self.buf[p0..p0 + n].copy_from_slice(v0);
                for m in 1..*taps {
                    let at = p0 + m * n;
                    memory.velocity_ago(m - 1, n, &mut self.buf[at..at + n]);
                }
                for (i, f) in frad.iter_mut().enumerate() {
                    let row = &k[i * taps * n..(i + 1) * taps * n];
                    *f = dot(row, &self.buf[p0..p0 + taps * n]);
                }
            }
            (
                Kernel::StateSpace { step, .. },
                Memory::StateSpace {
                    states, beta, started, ..
                },
            ) => {
                self.states.copy_from_slice(states);
                self.beta.copy_from_slice(beta);
                step.feed(&mut self.states, &mut self.beta, v0, *started);
                step.output(&self.states, &mut frad);
                // one half-update ahead for the first step: E xi_0 + g0 beta_0, and its force
                let (xr, xi) = self.states.split_at_mut(step.r);
                let (br, bi) = self.beta.split_at_mut(step.r);
                step.propagate(xr, xi, br, bi);
                self.rad_next.iter_mut().for_each(|f| *f = 0.0);
                step.output(&self.states, &mut self.rad_next);
            }
            _ => return Err(Error::Input("memory and model use different radiation methods".into())),
        }
        model.nonlinear_force(&self.x, &self.v, &mut self.fnl, &mut self.nl);
        // M a0 = F - B v - C x - F_nl - F_rad
        for i in 0..n {
            let mut r = f0[i] - frad[i] - self.fnl[i];
            for j in 0..n {
                r -= model.damping[(i, j)] * v0[j] + model.stiffness[(i, j)] * x0[j];
            }
            self.rhs[i] = r;
        }
        for i in 0..n {
            self.a[i] = (0..n).map(|j| model.mass_inv[(i, j)] * self.rhs[j]).sum();
        }
        self.p = frad;
        Ok(())
    }

    /// Advances one step with the wave force `f1` at the new time and the known radiation part `known`:
    /// the convolution over the start's velocity and the history before it (empty: none). The run's own
    /// velocities are convolved here: the last block's taps directly, the rest by partitioned FFTs.
    pub fn step(&mut self, model: &TimeModel, f1: &[f64], known: &[f64]) -> Result<()> {
        step_dispatched(self, model, f1, known)
    }
}

/// [`Stepper::step`], compiled for AVX2 + FMA as well as the baseline and chosen at run time (its
/// short loops over the DOFs; the products are [`dense`]'s, the modal update [`crate::radiation::modal`]'s).
#[multiversion(targets("x86_64+avx2+fma", "x86_64+avx"))]
fn step_dispatched(st: &mut Stepper, model: &TimeModel, f1: &[f64], known: &[f64]) -> Result<()> {
    st.step_body(model, f1, known)
}

impl Stepper {
    #[inline(always)]
    fn step_body(&mut self, model: &TimeModel, f1: &[f64], known: &[f64]) -> Result<()> {
        let n = self.n;
        let dt = model.opts.dt_s;
        let beta = model.opts.beta;
        let k1 = self.k + 1;
        if k1 > self.capacity {
            return Err(Error::Input("stepper capacity exceeded".into()));
        }
        // radiation: known part P
        self.known_radiation(model, k1, known);
        // predictor (the short loops over the DOFs take slices of length n first: no bounds checks, no
        // reloads of the vectors through `self`, and they vectorize)
        {
            let (vt, xt) = self.zt[..2 * n].split_at_mut(n);
            let (x, v, a) = (&self.x[..n], &self.v[..n], &self.a[..n]);
            for i in 0..n {
                xt[i] = x[i] + dt * v[i] + dt * dt * (0.5 - beta) * a[i];
                vt[i] = v[i] + 0.5 * dt * a[i];
            }
        }
        let np = model.n_pad;
        // (B + D) vt + C xt: it does not change between the passes
        dense::gemv(np, &model.cols_bdc, &self.zt, &mut self.lin);
        // nonlinear forces at the state the new acceleration implies: fixed-point passes starting from
        // a_{k+1} = a_k (they contract fast: the step matrix S is dominated by the mass)
        let nonlinear = model.is_nonlinear();
        if !nonlinear {
            self.fnl.iter_mut().for_each(|f| *f = 0.0);
        }
        self.a_new.copy_from_slice(&self.a);
        self.passes = 0;
        loop {
            if nonlinear {
                for i in 0..n {
                    self.v_pred[i] = self.zt[i] + 0.5 * dt * self.a_new[i];
                    self.x_pred[i] = self.zt[n + i] + beta * dt * dt * self.a_new[i];
                }
                model.nonlinear_force(&self.x_pred, &self.v_pred, &mut self.fnl, &mut self.nl);
            }
            {
                let (rhs, f1, p, fnl, lin) = (
                    &mut self.rhs[..n],
                    &f1[..n],
                    &self.p[..n],
                    &self.fnl[..n],
                    &self.lin[..n],
                );
                for i in 0..n {
                    rhs[i] = f1[i] - p[i] - fnl[i] - lin[i];
                }
            }
            dense::gemv(np, &model.cols_s_inv, &self.rhs, &mut self.a_try);
            let (mut change, mut size) = (0.0f64, 0.0f64);
            if nonlinear {
                for (a_new, a) in self.a_new[..n].iter().zip(&self.a_try[..n]) {
                    change = change.max((a - a_new).abs());
                    size = size.max(a.abs());
                }
            }
            self.a_new[..n].copy_from_slice(&self.a_try[..n]);
            self.passes += 1;
            if !nonlinear || change <= NL_TOLERANCE * size || self.passes >= NL_MAX_PASSES {
                break;
            }
        }
        {
            let (vt, xt) = self.zt[..2 * n].split_at(n);
            let (x, v_new, a_new) = (&mut self.x[..n], &mut self.v_new[..n], &self.a_new[..n]);
            for i in 0..n {
                x[i] = xt[i] + beta * dt * dt * a_new[i];
                v_new[i] = vt[i] + 0.5 * dt * a_new[i];
            }
            self.a[..n].copy_from_slice(a_new);
        }
        // memory
        match &model.kernel {
            Kernel::Convolution { parts, .. } => {
                let p = self.pos(k1 as isize);
                self.buf[p..p + n].copy_from_slice(&self.v_new);
                self.run.push(self.active.as_deref().unwrap_or(parts), &self.v_new);
            }
            Kernel::StateSpace { step, .. } => step.advance(&self.v_new, &mut self.states, &mut self.rad_next),
        }
        std::mem::swap(&mut self.v, &mut self.v_new);
        self.k = k1;
        // one pass without branches (NaN fails both comparisons); the DOF is looked for only on failure
        let bounded = self.x[..n].iter().zip(&self.v[..n]).fold(true, |ok, (x, v)| {
            ok & (x.abs() <= UNBOUNDED) & (v.abs() < f64::INFINITY)
        });
        if bounded {
            return Ok(());
        }
        self.divergence(model, k1)
    }

    /// The known part P of the radiation force at step `k1`: the convolution's taps 1..B-1 over the
    /// run's velocities directly and the partitions' rest, or the modal states' force.
    #[inline(always)]
    fn known_radiation(&mut self, model: &TimeModel, k1: usize, known: &[f64]) {
        let n = self.n;
        match &model.kernel {
            Kernel::Convolution { taps, k, parts } => {
                let parts = self.active.as_deref().unwrap_or(parts);
                // taps 1..B-1 over v_k1-1 back to v_1 directly; the partitions have the rest
                let mcount = (k1 - 1).min(parts.block - 1).min(taps - 1);
                let start = self.pos(k1 as isize - 1);
                let tail = self.run.tail(parts, k1);
                for i in 0..n {
                    let row = &k[(i * taps + 1) * n..(i * taps + 1 + mcount) * n];
                    let known_i = known.get(i).copied().unwrap_or(0.0);
                    self.p[i] = known_i + tail[i] + dot(row, &self.buf[start..start + mcount * n]);
                }
            }
            // the states hold everything but the new input (E xi + g0 beta_k): their force, computed
            // when they were
            Kernel::StateSpace { .. } => self.p.copy_from_slice(&self.rad_next),
        }
    }

    /// The partitions a run of `steps` steps uses: the model's (`model_parts`, blocked for runs past the
    /// kernel's length), or a set of the same kernel (`k`, `taps` taps, `n` states) blocked for the
    /// run's length ([`block_for_run`]), built once per model and block and kept.
    fn partitions_for(
        &mut self,
        model_parts: &Arc<Partitions>,
        k: &[f64],
        taps: usize,
        n: usize,
        steps: usize,
    ) -> Arc<Partitions> {
        let block = block_for_run(taps, steps);
        if block == model_parts.block {
            return model_parts.clone();
        }
        if !std::ptr::eq(self.sized_for.as_ptr(), Arc::as_ptr(model_parts)) {
            self.sized.clear();
            self.sized_for = Arc::downgrade(model_parts);
        }
        if let Some(p) = self.sized.iter().find(|p| p.block == block && p.steps >= steps) {
            return p.clone();
        }
        // room for runs up to twice as long, so a run a little longer does not build again
        let p = Arc::new(Partitions::reaching(k, taps, n, block, steps.next_power_of_two()));
        if self.sized.len() >= SIZED_KEPT {
            self.sized.remove(0);
        }
        self.sized.push(p.clone());
        p
    }

    /// The error of a step `k1` that left the bounds: the first DOF non-finite or beyond 1e4 m or rad.
    fn divergence(&self, model: &TimeModel, k1: usize) -> Result<()> {
        let (n, dt) = (self.n, model.opts.dt_s);
        for i in 0..n {
            let (x, v) = (self.x[i], self.v[i]);
            if !(x.is_finite() && v.is_finite()) {
                return Err(Error::Diverged {
                    dof: model.labels[i].clone(),
                    time_s: k1 as f64 * dt,
                    what: "non-finite",
                });
            }
            if x.abs() > UNBOUNDED {
                return Err(Error::Diverged {
                    dof: model.labels[i].clone(),
                    time_s: k1 as f64 * dt,
                    what: "unbounded (beyond 1e4 m or rad)",
                });
            }
        }
        Ok(())
    }
}

/// Dot product with eight independent accumulators over exact chunks (no bounds checks, no dependency
/// chain): the compiler turns it into packed multiply-adds.
#[inline]
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let mut acc = [0.0f64; 8];
    let (ca, cb) = (a.chunks_exact(8), b.chunks_exact(8));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for l in 0..8 {
            acc[l] += x[l] * y[l];
        }
    }
    let mut s = ((acc[0] + acc[4]) + (acc[1] + acc[5])) + ((acc[2] + acc[6]) + (acc[3] + acc[7]));
    for (x, y) in ra.iter().zip(rb) {
        s += x * y;
    }
    s
}
