//! The forecaster: state and history in, motion out (pure; no clock, no IO). A repeated forecast of
//! the same size allocates nothing: the workspace is kept between calls (rapier's habit).

use super::memory::Memory;
use super::model::{Kernel, TimeModel};
use super::sinusoids::Sinusoids;
use super::stepper::Stepper;
use super::{Error, Result};
use crate::waves::{WaveComponent, encounter_frequency, wave_number};
use num_complex::Complex64;
use rustfft::{Fft, FftPlanner};
use std::sync::Arc;

/// The longest forecast, s: the daemon's `forecast.horizon_s`, a scenario's `horizon_s` and the CLI's
/// `--horizon` (alias `--length`) are all bounded by it. No radar-observed sea is predictable for more than minutes; the
/// bound keeps the forecast's buffers (steps x states) sized by input within reason.
pub const MAX_FORECAST_LENGTH_S: f64 = 3600.0;

/// Most steps of one forecast (length / dt): an hour at 0.01 s; the forecast of a 24-state system
/// that long is 70 MB.
pub const MAX_FORECAST_STEPS: usize = 360_000;

/// What a forecast needs, for the active DOFs of the model (in `model.active` order).
#[derive(Debug, Clone, Copy)]
pub struct ForecastRequest<'a> {
    /// Displacements at t0, m or rad.
    pub x0: &'a [f64],
    /// Velocities at t0, m/s or rad/s.
    pub v0: &'a [f64],
    /// The velocities before t0 (see [`Memory`]).
    pub memory: &'a Memory,
    /// Wave components in the seakeeping frame, amplitudes at the origin at t0.
    pub waves: &'a [WaveComponent],
    /// Forecast length, s (not the predictable horizon).
    pub length_s: f64,
    /// Optional ramp of the wave force over its first seconds (regular-wave runs), s; 0 = none.
    pub ramp_s: f64,
    /// The slow drift velocity measured before t0 ([`super::drift::slow_velocity`]): the mean velocity
    /// of the modes without restoring over the forecast is set to it ([`super::drift::apply`]). None:
    /// the forecast runs from `v0` as it is.
    pub drift_velocity: Option<&'a [f64]>,
}

/// A forecast: every state (6N body modes then the tanks; inactive ones zero) on t = t0 + k dt,
/// k = 0..steps. Points, relative motions and connection forces: [`super::outputs`].
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Forecast {
    pub dt_s: f64,
    pub n_modes: usize,
    pub steps: usize,
    /// x[k * n_modes + i], m or rad.
    pub x: Vec<f64>,
    /// v[k * n_modes + i], m/s or rad/s.
    pub v: Vec<f64>,
    /// a[k * n_modes + i], m/s^2 or rad/s^2.
    pub a: Vec<f64>,
    /// Components outside the database (frequency or heading) and left out.
    pub skipped_components: usize,
    /// Their share of the field's variance, sum |a|^2 / 2.
    pub skipped_variance_fraction: f64,
}

impl Forecast {
    pub fn at(&self, k: usize, mode: usize) -> f64 {
        self.x[k * self.n_modes + mode]
    }
}

/// Reusable forecasting workspace for one model.
pub struct Forecaster {
    stepper: Stepper,
    out: Forecast,
    force: Vec<f64>,
    known: Vec<f64>,
    // the wave force as a sum of sinusoids: radians per step and complex amplitudes, output-major
    sums: Sinusoids,
    x_rad: Vec<f64>,
    q: Vec<Complex64>,
    xbuf: Vec<Complex64>,
    kept_we: Vec<f64>,
    kept_x: Vec<Complex64>,
    f0: Vec<f64>,
    // FFT of the kernel (convolution with a history), built on first use; the forecast's own
    // velocities are the stepper's ([`super::partitioned`])
    fft: Option<HistoryFft>,
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

impl Default for Forecaster {
    fn default() -> Self {
        Self::new()
    }
}

impl Forecaster {
    pub fn new() -> Self {
        Forecaster {
            stepper: Stepper::new(),
            out: Forecast::default(),
            force: vec![],
            known: vec![],
            sums: Sinusoids::new(),
            x_rad: vec![],
            q: vec![],
            xbuf: vec![],
            kept_we: vec![],
            kept_x: vec![],
            f0: vec![],
            fft: None,
        }
    }

    /// Runs one forecast. Errors: inputs that do not fit the model; a state that diverges (which DOF,
    /// when): never NaN to the caller.
    pub fn forecast(&mut self, model: &TimeModel, req: &ForecastRequest) -> Result<&Forecast> {
        let n = model.n();
        let dt = model.opts.dt_s;
        let length_s = req.length_s;
        if !(length_s.is_finite() && length_s > 0.0 && length_s <= MAX_FORECAST_LENGTH_S) {
            return Err(Error::Input(format!(
                "forecast length {length_s} s: must be in (0, {MAX_FORECAST_LENGTH_S}] s"
            )));
        }
        let steps = (length_s / dt).round() as usize;
        if steps > MAX_FORECAST_STEPS {
            return Err(Error::Input(format!(
                "forecast length {length_s} s at a {dt} s step is {steps} steps, more than {MAX_FORECAST_STEPS}"
            )));
        }
        self.wave_force(model, req.waves, steps, req.ramp_s)?;
        // the known radiation part: the convolution's only (the modal states carry their own past)
        self.known.clear();
        if matches!(model.kernel, Kernel::Convolution { .. }) {
            self.known.resize((steps + 1) * n, 0.0);
        }
        if let (Kernel::Convolution { .. }, Memory::Convolution { len, .. }) = (&model.kernel, req.memory)
            && (*len > 0 || req.v0.iter().any(|v| *v != 0.0))
        {
            self.history_part(model, req.v0, req.memory, steps)?;
        }
        self.f0.clear();
        self.f0.extend_from_slice(&self.force[..n]);
        self.stepper.start(model, req.x0, req.v0, req.memory, steps, &self.f0)?;
        let nm = model.n_modes;
        self.out.dt_s = dt;
        self.out.n_modes = nm;
        self.out.steps = steps;
        // every entry is written below when every state is active: zeroed only otherwise
        let all_active = n == nm;
        for out in [&mut self.out.x, &mut self.out.v, &mut self.out.a] {
            if !all_active {
                out.clear();
            }
            out.resize((steps + 1) * nm, 0.0);
        }
        for (r, &i) in model.active.iter().enumerate() {
            self.out.x[i] = req.x0[r];
            self.out.v[i] = req.v0[r];
            self.out.a[i] = self.stepper.a[r];
        }
        for k in 1..=steps {
            let f = &self.force[k * n..(k + 1) * n];
            let kn = self.known.get(k * n..(k + 1) * n).unwrap_or(&[]);
            self.stepper.step(model, f, kn)?;
            for (r, &i) in model.active.iter().enumerate() {
                self.out.x[k * nm + i] = self.stepper.x[r];
                self.out.v[k * nm + i] = self.stepper.v[r];
                self.out.a[k * nm + i] = self.stepper.a[r];
            }
        }
        if let Some(vd) = req.drift_velocity {
            if vd.len() != n {
                return Err(Error::Input(format!(
                    "drift velocity has {} values, the model {n} active states",
                    vd.len()
                )));
            }
            super::drift::apply(
                &model.drift_modes,
                vd,
                &model.active,
                nm,
                dt,
                &mut self.out.x,
                &mut self.out.v,
            );
        }
        Ok(&self.out)
    }

    /// A run from rest with no past (simulations, regular-wave runs, tests).
    pub fn from_rest(
        &mut self,
        model: &TimeModel,
        waves: &[WaveComponent],
        length_s: f64,
        ramp_s: f64,
    ) -> Result<&Forecast> {
        let z = vec![0.0; model.n()];
        let memory = Memory::new(model);
        let req = ForecastRequest {
            x0: &z,
            v0: &z,
            memory: &memory,
            waves,
            length_s,
            ramp_s,
            drift_velocity: None,
        };
        self.forecast(model, &req)
    }

    /// The wave force a request implies at t0 + k dt, k = 0..steps (k-major, active DOFs), through the
    /// same code as a forecast.
    pub fn force_for(&mut self, model: &TimeModel, req: &ForecastRequest) -> Result<Vec<f64>> {
        let steps = (req.length_s / model.opts.dt_s).round() as usize;
        self.wave_force(model, req.waves, steps, req.ramp_s)?;
        Ok(self.force.clone())
    }

    /// Components of the last request left out (outside the database).
    pub fn skipped(&self) -> usize {
        self.out.skipped_components
    }

    /// F_wave at t0 + k dt for k = 0..steps: sum over components of Re{X a exp(i w_e t)}.
    fn wave_force(&mut self, model: &TimeModel, waves: &[WaveComponent], steps: usize, ramp_s: f64) -> Result<()> {
        let n = model.n();
        let dt = model.opts.dt_s;
        let u = model.opts.speed_m_s;
        self.xbuf.resize(model.n_modes, Complex64::default());
        self.kept_we.clear();
        self.kept_x.clear();
        let (mut total, mut skipped) = (0.0, 0.0);
        self.out.skipped_components = 0;
        for w in waves {
            if !(w.omega_rad_s.is_finite()
                && w.omega_rad_s > 0.0
                && w.heading_rad.is_finite()
                && w.amplitude_m.re.is_finite()
                && w.amplitude_m.im.is_finite())
            {
                return Err(Error::Input(format!(
                    "wave component {w:?}: frequency must be positive and every value finite"
                )));
            }
            let var = 0.5 * w.amplitude_m.norm_sqr();
            total += var;
            if model
                .db
                .excitation_into(w.omega_rad_s, w.heading_rad, &mut self.xbuf)
                .is_err()
            {
                skipped += var;
                self.out.skipped_components += 1;
                continue;
            }
            let k = wave_number(w.omega_rad_s, model.g_m_s2, model.water_depth_m);
            let we = encounter_frequency(w.omega_rad_s, k, u, w.heading_rad);
            self.kept_we.push(we);
            for &i in &model.active {
                self.kept_x.push(self.xbuf[i] * w.amplitude_m);
            }
        }
        self.out.skipped_variance_fraction = if total > 0.0 { skipped / total } else { 0.0 };
        let nc = self.kept_we.len();
        self.x_rad.clear();
        self.x_rad.extend(self.kept_we.iter().map(|we| we * dt));
        self.q.clear();
        self.q.resize(n * nc, Complex64::default());
        for c in 0..nc {
            for i in 0..n {
                self.q[i * nc + c] = self.kept_x[c * n + i];
            }
        }
        self.force.clear();
        self.force.resize((steps + 1) * n, 0.0);
        self.sums.real_sum(&self.x_rad, &self.q, n, steps + 1, &mut self.force);
        if ramp_s > 0.0 {
            for k in 0..=steps {
                let t = k as f64 * dt;
                if t >= ramp_s {
                    break;
                }
                let ramp = 0.5 * (1.0 - (std::f64::consts::PI * t / ramp_s).cos());
                self.force[k * n..(k + 1) * n].iter_mut().for_each(|f| *f *= ramp);
            }
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
        let len = (2 * taps).next_power_of_two();
        if self.fft.as_ref().is_none_or(|f| f.len != len || f.n != n) {
            self.fft = Some(HistoryFft::new(k, taps, n, len));
        }
        let Some(f) = self.fft.as_mut() else { return Ok(()) };
        // u_j[p]: p = taps-1 is v0, p = taps-1-m is the velocity m steps before t0
        let mut tmp = std::mem::take(&mut self.f0);
        tmp.resize(n, 0.0);
        f.u.iter_mut().for_each(|c| *c = Complex64::default());
        for m in 0..taps {
            if m == 0 {
                tmp.copy_from_slice(v0);
            } else {
                memory.velocity_ago(m - 1, n, &mut tmp);
            }
            for j in 0..n {
                f.u[j * len + taps - 1 - m] = Complex64::new(tmp[j], 0.0);
            }
        }
        self.f0 = tmp;
        f.transform_inputs(n);
        let scale = 1.0 / len as f64;
        for p in 0..n.div_ceil(2) {
            f.output(p, n);
            let (i, i2) = (2 * p, 2 * p + 1);
            for kk in 1..=steps.min(taps - 1) {
                let y = f.acc[kk + taps - 1] * scale;
                self.known[kk * n + i] = y.re;
                if i2 < n {
                    self.known[kk * n + i2] = y.im;
                }
            }
        }
        Ok(())
    }
}
