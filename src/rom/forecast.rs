//! The forecaster: state and history in, motion out (pure; no clock, no IO). A repeated forecast of
//! the same size allocates nothing: the workspace is kept between calls (rapier's habit).

use super::known::KnownPart;
use super::model::TimeModel;
use super::sinusoids::Sinusoids;
use super::stepper::Stepper;
use super::{Error, Result};
use crate::radiation::history::Memory;
use crate::waves::{WaveComponent, encounter_frequency, wave_number};
use num_complex::Complex64;

/// The longest forecast, s: the daemon's `forecast.horizon_s`, a scenario's `horizon_s` and the CLI's
/// `--horizon` (alias `--length`) are all bounded by it. No radar-observed sea is predictable for more than minutes; the
/// bound keeps the forecast's buffers (steps x states) sized by input within reason.
pub const MAX_FORECAST_LENGTH_S: f64 = 3600.0;

/// Most steps of one forecast (length / dt): an hour at 0.01 s; the forecast of a 24-state system
/// that long is 70 MB.
pub const MAX_FORECAST_STEPS: usize = 360_000;

/// The steps of a forecast `length_s` long on `model`'s step (the nearest whole number).
pub fn steps_of(model: &TimeModel, length_s: f64) -> usize {
    (length_s / model.opts.dt_s).round() as usize
}

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
    /// The vessels' track over the forecast (forward speed, turn). None: straight ahead at the model's
    /// speed (`RomOptions::speed_m_s`).
    pub track: Option<Track>,
}

/// The track of the seakeeping frame over a forecast, relative to its pose at t0 (x along the heading
/// at t0, y to port): the frame advances at `speed_m_s` along its own heading, which is constant until
/// `turn_start_s` and then turns at `turn_rate_rad_s` (counterclockwise seen from above, i.e. to port,
/// positive). The motions are small oscillations about this frame; the frame's own turn adds no force
/// (the centripetal and Coriolis terms of order U r are left out: 0.01 m/s^2 at 3 m/s and 0.2 deg/s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Track {
    /// Forward speed through the water, m/s.
    pub speed_m_s: f64,
    /// Rate of turn, rad/s, counterclockwise positive (to port).
    pub turn_rate_rad_s: f64,
    /// Time after t0 the turn starts, s (0: turning from t0).
    pub turn_start_s: f64,
    /// The largest heading change over one piece of the wave force, rad (default [`TURN_PIECE_RAD`];
    /// the simulator's truth takes finer pieces).
    pub piece_rad: f64,
}

/// A turning track's wave force is computed in pieces over which the heading changes by at most this
/// much, rad (2 deg). Over a piece the frame moves along the chord of its arc, and each component's
/// excitation goes linearly from its value at the piece's start heading to that at its end: the
/// heading's error is then second order, and the chord departs from the arc by U r T^2 / 8 (0.13 m
/// over the 10 s piece of a 0.2 deg/s turn at 3 m/s: 0.013 rad of a 6 s wave's phase). Each piece costs
/// two sums of sinusoids over every component (a straight forecast's wave force costs one).
pub const TURN_PIECE_RAD: f64 = 2.0 * std::f64::consts::PI / 180.0;

impl Track {
    /// A straight track at `speed_m_s`.
    pub fn straight(speed_m_s: f64) -> Track {
        Track {
            speed_m_s,
            turn_rate_rad_s: 0.0,
            turn_start_s: 0.0,
            piece_rad: TURN_PIECE_RAD,
        }
    }

    /// Checks the numbers: finite, |speed| within the model's bound, |rate| at most 10 deg/s (a ship's
    /// turn; beyond it the frame's own accelerations are not small).
    pub fn validate(&self) -> Result<()> {
        if !(self.speed_m_s.is_finite() && self.speed_m_s.abs() <= super::model::MAX_SPEED_M_S) {
            return Err(Error::Input(format!(
                "track speed {} m/s: must be finite and at most {} m/s",
                self.speed_m_s,
                super::model::MAX_SPEED_M_S
            )));
        }
        if !(self.turn_rate_rad_s.is_finite() && self.turn_rate_rad_s.abs() <= MAX_TURN_RATE_RAD_S) {
            return Err(Error::Input(format!(
                "track rate of turn {} deg/s: must be finite and at most {} deg/s",
                self.turn_rate_rad_s.to_degrees(),
                MAX_TURN_RATE_RAD_S.to_degrees()
            )));
        }
        if !(self.piece_rad.is_finite() && self.piece_rad >= MIN_PIECE_RAD) {
            return Err(Error::Input(format!(
                "track piece {} deg: must be at least {} deg",
                self.piece_rad.to_degrees(),
                MIN_PIECE_RAD.to_degrees()
            )));
        }
        if !self.turn_start_s.is_finite() {
            return Err(Error::Input(format!(
                "track turn start {} s: must be finite",
                self.turn_start_s
            )));
        }
        Ok(())
    }

    /// The frame's heading change (rad) and position (m, in the t0 frame) at `t_s` after t0.
    pub fn pose(&self, t_s: f64) -> (f64, [f64; 2]) {
        let u = self.speed_m_s;
        let ts = self.turn_start_s.max(0.0);
        if t_s <= ts || self.turn_rate_rad_s == 0.0 {
            return (0.0, [u * t_s, 0.0]);
        }
        let r = self.turn_rate_rad_s;
        let tau = t_s - ts;
        let psi = r * tau;
        // the arc: U/r (sin psi, 1 - cos psi), written so that small r loses no digits
        let (s, c) = (psi.sin(), psi.cos());
        let (along, across) = if psi.abs() < 1e-6 {
            (u * tau, 0.5 * u * r * tau * tau)
        } else {
            (u * s / r, u * (1.0 - c) / r)
        };
        (psi, [u * ts + along, across])
    }
}

/// The finest piece a [`Track`] may ask for, rad (0.01 deg: pieces cost a sum each).
pub const MIN_PIECE_RAD: f64 = 0.01 * std::f64::consts::PI / 180.0;

/// The fastest turn a [`Track`] may have, rad/s (10 deg/s).
pub const MAX_TURN_RATE_RAD_S: f64 = 10.0 * std::f64::consts::PI / 180.0;

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
    /// Components met at an encounter frequency below one cycle over the forecast (following seas at
    /// speed: w_e = w - k U cos(beta) passes through zero), in any piece of the track. They are kept:
    /// their force is quasi-static (Re{X a exp(i w_e t)} with w_e near or at 0 is finite), and counted
    /// here so that the caller can say so.
    pub quasi_static_components: usize,
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
    /// The radiation force the start owes at each step ([`KnownPart`]).
    known: KnownPart,
    // the wave force as a sum of sinusoids: radians per step and complex amplitudes, output-major
    sums: Sinusoids,
    x_rad: Vec<f64>,
    q: Vec<Complex64>,
    xbuf: Vec<Complex64>,
    kept_we: Vec<f64>,
    kept_x: Vec<Complex64>,
    /// Wave number of each component, rad/m.
    k_rad_m: Vec<f64>,
    /// Per component: left out, quasi-static, the sign of its last encounter frequency.
    marks: Vec<(bool, bool, i8)>,
    /// A turning track's pieces: each component's excitation at the current piece's end (every mode),
    /// whether it is known, the kept components' change of X a over the piece, and its sum.
    x_ends: Vec<Complex64>,
    x_ends_known: Vec<bool>,
    kept_dx: Vec<Complex64>,
    ramp: Vec<f64>,
    f0: Vec<f64>,
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
            known: KnownPart::default(),
            sums: Sinusoids::new(),
            x_rad: vec![],
            q: vec![],
            xbuf: vec![],
            kept_we: vec![],
            kept_x: vec![],
            k_rad_m: vec![],
            marks: vec![],
            x_ends: vec![],
            x_ends_known: vec![],
            kept_dx: vec![],
            ramp: vec![],
            f0: vec![],
        }
    }

    /// Runs one forecast. Errors: inputs that do not fit the model; a state that diverges (which DOF,
    /// when): never NaN to the caller.
    pub fn forecast(&mut self, model: &TimeModel, req: &ForecastRequest) -> Result<&Forecast> {
        let dt = model.opts.dt_s;
        let length_s = req.length_s;
        if !(length_s.is_finite() && length_s > 0.0 && length_s <= MAX_FORECAST_LENGTH_S) {
            return Err(Error::Input(format!(
                "forecast length {length_s} s: must be in (0, {MAX_FORECAST_LENGTH_S}] s"
            )));
        }
        let steps = steps_of(model, length_s);
        if steps > MAX_FORECAST_STEPS {
            return Err(Error::Input(format!(
                "forecast length {length_s} s at a {dt} s step is {steps} steps, more than {MAX_FORECAST_STEPS}"
            )));
        }
        // the wave force and the radiation force the start owes need nothing of each other: with a
        // history to convolve, they are computed side by side (on two cores when there are)
        let mut known = std::mem::take(&mut self.known);
        let (waves, owed) = if KnownPart::needed(model, req.v0, req.memory) {
            rayon::join(
                || self.spanned_wave_force(model, req, steps),
                || known.compute(model, req.v0, req.memory, steps),
            )
        } else {
            let waves = self.spanned_wave_force(model, req, steps);
            (waves, known.compute(model, req.v0, req.memory, steps))
        };
        self.known = known;
        waves?;
        owed?;
        let _span = tracing::trace_span!("steps", steps).entered();
        self.run(model, req, steps)
    }

    fn spanned_wave_force(&mut self, model: &TimeModel, req: &ForecastRequest, steps: usize) -> Result<()> {
        let _span = tracing::trace_span!("wave_force", components = req.waves.len()).entered();
        self.wave_force(model, req.waves, steps, req.ramp_s, req.track)
    }

    /// [`Self::forecast`] with the wave force given (`force_for` of the same request on a model with
    /// the same excitation): a model re-run from one start with other damping or stiffness (in-situ
    /// tuning) need not sum the waves again.
    pub fn forecast_forced(&mut self, model: &TimeModel, req: &ForecastRequest, force: &[f64]) -> Result<&Forecast> {
        let n = model.n();
        let steps = steps_of(model, req.length_s);
        if force.len() != (steps + 1) * n {
            return Err(Error::Input(format!(
                "a given wave force of {} values for {} steps of {n} states",
                force.len(),
                steps + 1
            )));
        }
        self.force.clear();
        self.force.extend_from_slice(force);
        self.known.compute(model, req.v0, req.memory, steps)?;
        self.run(model, req, steps)
    }

    /// The forecast over `steps` from the request's start with the wave force in `self.force` and
    /// the radiation force the start owes in `self.known` (the convolution's only: the modal states
    /// carry their own past).
    fn run(&mut self, model: &TimeModel, req: &ForecastRequest, steps: usize) -> Result<&Forecast> {
        let n = model.n();
        let dt = model.opts.dt_s;
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
            let kn = self.known.values.get(k * n..(k + 1) * n).unwrap_or(&[]);
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
        self.from_rest_on(model, waves, length_s, ramp_s, None)
    }

    /// A run from rest along a track (None: straight at the model's speed).
    pub fn from_rest_on(
        &mut self,
        model: &TimeModel,
        waves: &[WaveComponent],
        length_s: f64,
        ramp_s: f64,
        track: Option<Track>,
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
            track,
        };
        self.forecast(model, &req)
    }

    /// The wave force a request implies at t0 + k dt, k = 0..steps (k-major, active DOFs), through the
    /// same code as a forecast.
    pub fn force_for(&mut self, model: &TimeModel, req: &ForecastRequest) -> Result<Vec<f64>> {
        let steps = steps_of(model, req.length_s);
        self.wave_force(model, req.waves, steps, req.ramp_s, req.track)?;
        Ok(self.force.clone())
    }

    /// Components of the last request left out (outside the database).
    pub fn skipped(&self) -> usize {
        self.out.skipped_components
    }

    /// F_wave at t0 + k dt for k = 0..steps: sum over components of Re{X a exp(i w_e t)}, in pieces of
    /// the track over which the heading changes by at most `track.piece_rad` (one piece when it does
    /// not turn).
    fn wave_force(
        &mut self,
        model: &TimeModel,
        waves: &[WaveComponent],
        steps: usize,
        ramp_s: f64,
        track: Option<Track>,
    ) -> Result<()> {
        let n = model.n();
        let dt = model.opts.dt_s;
        let track = track.unwrap_or_else(|| Track::straight(model.opts.speed_m_s));
        track.validate()?;
        let total = self.wave_numbers(model, waves)?;
        self.xbuf.resize(model.n_modes, Complex64::default());
        // per component: left out somewhere (outside the database), quasi-static somewhere, the sign of
        // its encounter frequency in the piece before
        self.marks.clear();
        self.marks.resize(waves.len(), (false, false, 0));
        self.force.clear();
        self.force.resize((steps + 1) * n, 0.0);
        // below one cycle over the forecast
        let slow_rad_s = std::f64::consts::TAU / (steps.max(1) as f64 * dt);
        let turning = track.turn_rate_rad_s != 0.0 && track.turn_start_s < steps as f64 * dt;
        let piece_steps = if turning {
            ((track.piece_rad / track.turn_rate_rad_s.abs() / dt)
                .min((steps + 1) as f64)
                .floor() as usize)
                .max(1)
        } else {
            steps + 1
        };
        let turn_k = (track.turn_start_s.max(0.0) / dt).ceil() as usize;
        self.x_ends.clear();
        self.x_ends.resize(waves.len() * model.n_modes, Complex64::default());
        self.x_ends_known.clear();
        self.x_ends_known.resize(waves.len(), false);
        let mut k0 = 0;
        while k0 <= steps {
            let k1 = if !turning {
                steps + 1
            } else if k0 < turn_k {
                turn_k.min(steps + 1)
            } else {
                k0.saturating_add(piece_steps).min(steps + 1)
            };
            let t_s = k0 as f64 * dt;
            let (psi, p) = track.pose(t_s);
            // a turning piece: the frame moves along the chord of its arc, and the excitation goes
            // linearly from its value at the piece's start heading to that at its end heading
            let piece_turns = turning && k0 >= turn_k;
            let (psi_e, v) = if piece_turns {
                let t_e = k1 as f64 * dt;
                let (psi_e, p_e) = track.pose(t_e);
                (psi_e, [(p_e[0] - p[0]) / (t_e - t_s), (p_e[1] - p[1]) / (t_e - t_s)])
            } else {
                (psi, [track.speed_m_s, 0.0])
            };
            let piece = Piece {
                t_s,
                psi,
                psi_e,
                p,
                v,
                turns: piece_turns,
                speed_m_s: track.speed_m_s,
                slow_rad_s,
            };
            self.piece_components(model, waves, &piece);
            self.piece_sum(n, dt, k0, k1, piece_turns);
            k0 = k1;
        }
        self.left_out(waves, total);
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

    /// Checks every component and keeps its wavenumber; the waves' total variance, m^2.
    fn wave_numbers(&mut self, model: &TimeModel, waves: &[WaveComponent]) -> Result<f64> {
        let mut total = 0.0;
        self.k_rad_m.clear();
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
            total += 0.5 * w.amplitude_m.norm_sqr();
            self.k_rad_m
                .push(wave_number(w.omega_rad_s, model.g_m_s2, model.water_depth_m));
        }
        Ok(total)
    }

    /// One piece's kept components: each one's encounter frequency, its excitation times its amplitude
    /// at the frame's origin at the piece's start (and, turning, the change of that to the piece's end);
    /// marks what is left out or quasi-static.
    fn piece_components(&mut self, model: &TimeModel, waves: &[WaveComponent], piece: &Piece) {
        self.kept_we.clear();
        self.kept_x.clear();
        self.kept_dx.clear();
        let nm = model.n_modes;
        let (p, v) = (piece.p, piece.v);
        for (c, w) in waves.iter().enumerate() {
            let beta = w.heading_rad - piece.psi;
            // the start's excitation: the previous piece's end, when it had one
            let start_known = piece.turns && self.x_ends_known[c];
            if start_known {
                self.xbuf.copy_from_slice(&self.x_ends[c * nm..(c + 1) * nm]);
            } else if model.db.excitation_into(w.omega_rad_s, beta, &mut self.xbuf).is_err() {
                self.marks[c].0 = true;
                continue;
            }
            if piece.turns {
                let end = &mut self.x_ends[c * nm..(c + 1) * nm];
                // an end outside the database's headings keeps the start's value over this piece,
                // and the next piece looks its start up again (and is left out there)
                let known = model
                    .db
                    .excitation_into(w.omega_rad_s, w.heading_rad - piece.psi_e, end)
                    .is_ok();
                if !known {
                    end.copy_from_slice(&self.xbuf);
                }
                self.x_ends_known[c] = known;
            }
            let k = self.k_rad_m[c];
            let we = if piece.turns {
                w.omega_rad_s - k * (v[0] * w.heading_rad.cos() + v[1] * w.heading_rad.sin())
            } else {
                encounter_frequency(w.omega_rad_s, k, piece.speed_m_s, beta)
            };
            let sign = if we > 0.0 {
                1
            } else if we < 0.0 {
                -1
            } else {
                0
            };
            let mark = &mut self.marks[c];
            if we.abs() < piece.slow_rad_s || (mark.2 != 0 && sign != mark.2) {
                mark.1 = true;
            }
            mark.2 = sign;
            // the amplitude at the frame's origin at the piece's start
            let (sd, cd) = w.heading_rad.sin_cos();
            let a = w.amplitude_m * Complex64::from_polar(1.0, w.omega_rad_s * piece.t_s - k * (p[0] * cd + p[1] * sd));
            self.kept_we.push(we);
            for &i in &model.active {
                self.kept_x.push(self.xbuf[i] * a);
                if piece.turns {
                    self.kept_dx.push((self.x_ends[c * nm + i] - self.xbuf[i]) * a);
                }
            }
        }
    }

    /// The kept components' force over steps k0..k1 (and, turning, the linear change of the
    /// excitation over the piece: + (tau / T) Re{sum dX a exp(i w_e tau)}).
    fn piece_sum(&mut self, n: usize, dt: f64, k0: usize, k1: usize, turns: bool) {
        let nc = self.kept_we.len();
        self.x_rad.clear();
        self.x_rad.extend(self.kept_we.iter().map(|we| we * dt));
        transpose_into(&self.kept_x, n, nc, &mut self.q);
        self.sums
            .real_sum(&self.x_rad, &self.q, n, k1 - k0, &mut self.force[k0 * n..k1 * n]);
        if turns {
            transpose_into(&self.kept_dx, n, nc, &mut self.q);
            self.ramp.clear();
            self.ramp.resize((k1 - k0) * n, 0.0);
            self.sums.real_sum(&self.x_rad, &self.q, n, k1 - k0, &mut self.ramp);
            let len = (k1 - k0) as f64;
            for (j, row) in self.ramp.chunks(n).enumerate() {
                let f = &mut self.force[(k0 + j) * n..(k0 + j + 1) * n];
                for (fi, ri) in f.iter_mut().zip(row) {
                    *fi += j as f64 / len * ri;
                }
            }
        }
    }

    /// What the marks say of the request: the components left out, the quasi-static ones, and the
    /// share of the waves' variance (`total`) left out.
    fn left_out(&mut self, waves: &[WaveComponent], total: f64) {
        let skipped: f64 = waves
            .iter()
            .zip(&self.marks)
            .filter(|(_, m)| m.0)
            .map(|(w, _)| 0.5 * w.amplitude_m.norm_sqr())
            .sum();
        self.out.skipped_components = self.marks.iter().filter(|m| m.0).count();
        self.out.quasi_static_components = self.marks.iter().filter(|m| m.1 && !m.0).count();
        self.out.skipped_variance_fraction = if total > 0.0 { skipped / total } else { 0.0 };
    }
}

/// `q[i * nc + c] = rows[c * n + i]`: component-major values to the output-major layout of
/// [`Sinusoids::real_sum`].
fn transpose_into(rows: &[Complex64], n: usize, nc: usize, q: &mut Vec<Complex64>) {
    q.clear();
    q.resize(n * nc, Complex64::default());
    for c in 0..nc {
        for i in 0..n {
            q[i * nc + c] = rows[c * n + i];
        }
    }
}

/// One piece of the track over which the wave force is summed: its start time (s from t0), the
/// frame's heading at its start and end (rad), its position at the start (m) and its velocity (m/s,
/// earth), whether it turns, the speed along the track (m/s) and the encounter frequency below which a
/// component is quasi-static (rad/s).
struct Piece {
    t_s: f64,
    psi: f64,
    psi_e: f64,
    p: [f64; 2],
    v: [f64; 2],
    turns: bool,
    speed_m_s: f64,
    slow_rad_s: f64,
}

#[cfg(test)]
mod tests {

    use super::*;

    #[test]
    fn a_track_is_straight_then_an_arc_of_radius_u_over_r() {
        let tr = Track {
            speed_m_s: 3.0,
            turn_rate_rad_s: 0.2f64.to_radians(),
            turn_start_s: 100.0,
            piece_rad: TURN_PIECE_RAD,
        };
        let (psi, p) = tr.pose(50.0);
        assert_eq!((psi, p), (0.0, [150.0, 0.0]));
        let radius = 3.0 / tr.turn_rate_rad_s;
        for t in [100.0, 150.0, 400.0, 1900.0] {
            let (psi, p) = tr.pose(t);
            assert!((psi - tr.turn_rate_rad_s * (t - 100.0)).abs() < 1e-12);
            // the arc's centre is radius to port of where the turn starts
            let d = (p[0] - 300.0).hypot(p[1] - radius);
            assert!((d - radius).abs() < 1e-9 * radius, "{t}: {d} vs {radius}");
        }
        // the arc's length is the distance run
        let (n, t1) = (10_000, 400.0);
        let mut len = 0.0;
        for k in 0..n {
            let a = tr.pose(100.0 + (t1 - 100.0) * k as f64 / n as f64).1;
            let b = tr.pose(100.0 + (t1 - 100.0) * (k + 1) as f64 / n as f64).1;
            len += (b[0] - a[0]).hypot(b[1] - a[1]);
        }
        assert!((len - 3.0 * 300.0).abs() < 1e-6, "{len}");
    }

    #[test]
    fn tracks_beyond_a_ship_s_are_refused() {
        assert!(Track::straight(3.0).validate().is_ok());
        assert!(Track::straight(f64::NAN).validate().is_err());
        assert!(Track::straight(30.0).validate().is_err());
        let fast = Track {
            turn_rate_rad_s: 0.5,
            ..Track::straight(3.0)
        };
        assert!(fast.validate().is_err());
    }
}
