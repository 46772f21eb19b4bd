//! A forecast job and the computer that runs it: the model (rebuilt for the forward speed when the
//! system has speed terms), the forecaster and the band.

use super::message::{ForecastHeader, MAX_VESSELS, flags};
use super::*;
use crate::band::{ResponseTable, SpreadOptions};
use crate::radiation::history::Memory;
use crate::rom::{ForecastRequest, Forecaster, RomOptions, Track};

/// One forecast job.
#[derive(Debug, Clone)]
pub struct Job {
    pub(super) t0_s: f64,
    pub(super) x0: Vec<f64>,
    pub(super) v0: Vec<f64>,
    pub(super) velocities: Vec<Vec<f64>>,
    /// How many of `velocities` (the newest) were measured, fewest over the vessels.
    pub(super) known: usize,
    pub(super) waves: Vec<crate::waves::WaveComponent>,
    /// Per vessel, per component of `waves`, the leads (s from t0) over which it is known
    /// (`horizon::known_leads`; none when the field cannot be trusted).
    pub(super) known_leads: Vec<Vec<[f64; 2]>>,
    /// Whether the field can be trusted at all (located, navigation fresh).
    pub(super) trustworthy: bool,
    /// The model error of each series against lead, as a fraction of its motion
    /// ([`band::ModelError`]).
    pub(super) model_error: band::ModelErrorCurve,
    /// Per series, the variance of the start's random error and its expected error
    /// ([`band::SpreadOptions`]; the estimator's `start_var` and, for roll and pitch,
    /// [`band::heel_split`]).
    pub(super) start_var: Vec<f64>,
    pub(super) start_offset: Vec<f64>,
    /// Per series, the estimate's own error variance (`estimator::Estimator::estimate_var`).
    pub(super) check_var: Vec<f64>,
    /// The frame's track from t0 (speed and turn from navigation; None: keeping station).
    pub(super) track: Option<Track>,
    pub(super) header: ForecastHeader,
    /// What the in-situ tuning takes from this tick (None: tuning is off).
    pub(super) tune: Option<super::tune::TuneInput>,
    /// Per vessel, whether it is started from rest for want of its motion: the vessels coupled to it
    /// have its unknown start in their band ([`band::coupled_var`]).
    pub(super) unknown: Vec<bool>,
}

/// A job's result.
#[derive(Debug, Clone)]
pub struct Done {
    pub header: ForecastHeader,
    pub values: Option<Vec<f64>>,
    pub compute_ms: f64,
    /// The compute thread's stages ([`super::latency`]); `build_ms` and `queued_ms` are the shell's to set.
    pub times: super::latency::ComputeTimes,
    pub error: Option<String>,
    /// Share of the wave variance the forecast left out (outside the database), 0..1.
    pub dropped_wave_share: f64,
    /// Each series' motion standard deviation by the band's model, and the model error the band took.
    pub motion_sigma: Vec<f64>,
    pub model_error: band::ModelErrorCurve,
    /// Per series, the variance of the start's random error (the band's floor) and of the estimate's
    /// own error (the filter's: what a check against a later estimate differs by beside the motion;
    /// the sensor's drift, slow, the two share).
    pub start_var: Vec<f64>,
    pub check_var: Vec<f64>,
    /// The forecast may teach the model error: its waves were trusted and its band known (a forecast
    /// with no trusted span teaches all the same: its error is the model's).
    pub teaches: bool,
    /// A round of the in-situ roll tuning finished since the last job ([`crate::tuning`]).
    pub tuning: Option<crate::tuning::TunerReport>,
}

/// Runs jobs: the model and a reusable forecaster (the compute thread live, inline in replay).
pub struct Computer {
    /// The model forecasts run with: `base` with the in-situ tuning applied.
    model: TimeModel,
    /// The model as built (at its speed), before the tuning.
    base: TimeModel,
    /// The in-situ roll tuning (idle when off, or when no vessel's roll can be tuned) and its work
    /// between jobs ([`Computer::tune`]).
    tuning: super::tune::Tuning,
    /// The model's response for the band (None: it could not be made; nothing is trusted then).
    table: Option<ResponseTable>,
    /// The model as built's kernels for the table, which its tuned models share.
    kernels: band::TableKernels,
    trusted_nrmse: f64,
    /// The system and options to rebuild the model at another speed, when the system file has speed
    /// terms (`speed_damping` B_U, `speed_restoring` C_UQ) or databases at several speeds (interpolated:
    /// `VesselSystem::at_speed`); None: one model serves every speed (the speed then enters through the
    /// encounter frequency only).
    rebuild: Option<(Box<VesselSystem>, RomOptions)>,
    /// The speed step a rebuild failed at (not tried again until the speed moves).
    failed_speed: Option<f64>,
    fc: Forecaster,
    n_bodies: usize,
    /// Forecast length, s.
    length_s: f64,
    /// `forecast.drift_window_s` (0: no drift estimate).
    drift_window_s: f64,
    /// Per vessel, the model's free response to its start's error, made when first wanted (a vessel
    /// without motion) and forgotten when the model changes.
    coupling: Vec<Option<band::CouplingResponse>>,
}

impl Computer {
    pub fn new(model: TimeModel, sys: &VesselSystem, cfg: &ShipcastConfig) -> Computer {
        let speed_terms = !sys.speed_dbs.is_empty()
            || sys.spec.bodies.iter().any(|b| {
                b.speed_damping
                    .iter()
                    .chain(b.speed_restoring.iter())
                    .any(|v| *v != 0.0)
            });
        let n_bodies = sys.spec.bodies.len();
        let kernels = band::TableKernels::of(&model);
        Computer {
            tuning: super::tune::Tuning::new(&model, cfg),
            base: model.clone(),
            rebuild: speed_terms.then(|| (Box::new(sys.clone()), model.opts)),
            failed_speed: None,
            table: response_table(&model, &kernels),
            kernels,
            trusted_nrmse: cfg.forecast.trusted_nrmse,
            model,
            fc: Forecaster::new(),
            n_bodies,
            length_s: cfg.forecast.horizon_s,
            drift_window_s: cfg.forecast.drift_window_s,
            coupling: vec![None; n_bodies],
        }
    }

    /// The model at the speed a job's track asks for, rebuilt when the system has speed terms and the
    /// speed moved to another step of [`MODEL_SPEED_STEP_M_S`]. An error (a speed beyond the databases')
    /// keeps the model it had, and is reported once per speed step; [`Self::speed_mismatch`] says so
    /// while the speed stays there.
    pub fn at_speed(&mut self, track: Option<Track>) -> Result<(), String> {
        let Some((sys, opts)) = &self.rebuild else {
            return Ok(());
        };
        let Some(want) = self.wanted_speed(track) else {
            return Ok(());
        };
        if self.failed_speed == Some(want) {
            return Ok(());
        }
        // tried once per speed step: an error is logged once, the model kept
        self.failed_speed = Some(want);
        let at = sys
            .at_speed(want)
            .map_err(|e| format!("the database at {want} m/s: {e}"))?;
        let model = TimeModel::new(
            &at,
            RomOptions {
                speed_m_s: want,
                ..*opts
            },
        )
        .map_err(|e| format!("the model at {want} m/s: {e}"))?;
        tracing::info!(
            speed_m_s = want,
            "model rebuilt for the forward speed (its speed terms)"
        );
        self.kernels = band::TableKernels::of(&model);
        self.table = response_table(&model, &self.kernels);
        self.coupling = vec![None; self.n_bodies];
        self.tuning.reset(&model);
        self.base = model.clone();
        self.model = model;
        self.failed_speed = None;
        // its workspace holds the old model's kernel spectra
        self.fc = Forecaster::new();
        Ok(())
    }

    /// The speed step a track asks the model to be rebuilt at (None: the model it has serves: no speed
    /// terms, or a speed within [`MODEL_SPEED_HYSTERESIS`] steps of the model's).
    fn wanted_speed(&self, track: Option<Track>) -> Option<f64> {
        self.rebuild.as_ref()?;
        let speed = track.map_or(0.0, |t| t.speed_m_s);
        let want = (speed / MODEL_SPEED_STEP_M_S).round() * MODEL_SPEED_STEP_M_S;
        // a speed between two steps keeps the model it has (no rebuild per forecast on noise)
        let near = (speed - self.model.opts.speed_m_s).abs() <= MODEL_SPEED_HYSTERESIS * MODEL_SPEED_STEP_M_S;
        (!near && (want - self.model.opts.speed_m_s).abs() >= 1e-9).then_some(want)
    }

    /// Whether the model is not the one a track's speed asks for: its rebuild at that speed failed
    /// ([`Self::at_speed`]), and forecasts at that speed are the old model's.
    pub fn speed_mismatch(&self, track: Option<Track>) -> bool {
        self.wanted_speed(track)
            .is_some_and(|want| self.failed_speed == Some(want))
    }

    /// Runs one job; `elapsed_ms` measures its compute time (the shell passes a clock).
    pub fn run(&mut self, job: Job, elapsed_ms: impl Fn() -> f64) -> Done {
        if let Err(e) = self.at_speed(job.track) {
            tracing::warn!("{e}: forecasts keep the model they have, trusted nowhere");
        }
        let mismatch = self.speed_mismatch(job.track);
        let tuning = self.tuning.take(job.t0_s, job.tune.as_ref(), || crate::tuning::Case {
            t0_s: job.t0_s,
            x0: job.x0.clone(),
            v0: job.v0.clone(),
            velocities: job.velocities.clone(),
            waves: job.waves.clone(),
            track: job.track,
        });
        // the band's start, when the forecast succeeds (else the band is nothing)
        let mut t_forecast_ms = elapsed_ms();
        let (result, early) = self.forecast_beside_band(&job);
        let result = result.map(|(values, steps, dropped, quasi_static)| {
            t_forecast_ms = elapsed_ms();
            let _span = tracing::debug_span!("band", t0_s = job.t0_s).entered();
            let spread = early.unwrap_or_else(|| self.band(&job, steps));
            (values, steps, dropped, quasi_static, spread)
        });
        let compute_ms = elapsed_ms();
        let times = super::latency::ComputeTimes {
            build_ms: 0.0,
            queued_ms: 0.0,
            forecast_ms: t_forecast_ms,
            band_ms: compute_ms - t_forecast_ms,
        };
        let mut header = job.header;
        header.compute_ms = compute_ms;
        header.issue_time_s = job.t0_s;
        let n_bodies = self.n_bodies;
        match result {
            Ok((mut values, steps, dropped_wave_share, quasi_static, spread)) => {
                header.steps = steps as u32;
                let mut motion_sigma = vec![];
                match spread {
                    Some(s) => {
                        values.extend_from_slice(&s.sigma);
                        for b in 0..n_bodies.min(MAX_VESSELS) {
                            if !job.trustworthy {
                                header.set_span(b, 0.0, 0.0);
                                continue;
                            }
                            // the vessel's span, then each series' own (a vessel whose pitch errs
                            // everywhere may still have its heave trusted)
                            header.set_span(b, s.from_s[b], s.to_s[b]);
                            for i in 6 * b..6 * b + 6 {
                                header.set_series_span(i, s.series_from_s[i], s.series_to_s[i]);
                            }
                        }
                        motion_sigma = s.motion_sigma;
                    }
                    None => {
                        // no band known: not a band of zero
                        values.extend(std::iter::repeat_n(f64::NAN, 6 * n_bodies * (steps + 1)));
                        header.untrust_all();
                    }
                }
                if quasi_static > 0 {
                    header.flags |= flags::QUASI_STATIC_WAVES;
                }
                if mismatch {
                    header.flags |= flags::MODEL_SPEED_MISMATCH;
                    header.untrust_all();
                }
                Done {
                    header,
                    values: Some(values),
                    compute_ms,
                    times,
                    error: None,
                    dropped_wave_share,
                    teaches: job.trustworthy && !motion_sigma.is_empty() && !mismatch,
                    tuning,
                    motion_sigma,
                    model_error: job.model_error,
                    start_var: job.start_var,
                    check_var: job.check_var,
                }
            }
            Err(e) => Done {
                header,
                values: None,
                compute_ms,
                times,
                error: Some(e.to_string()),
                dropped_wave_share: 0.0,
                motion_sigma: vec![],
                model_error: job.model_error,
                start_var: job.start_var,
                check_var: job.check_var,
                teaches: false,
                tuning,
            },
        }
    }

    /// The job's forecast ([`Self::forecast`]) and, when every vessel's motion is known, its band
    /// computed beside it, on two cores when there are (it needs the forecast's length, not its values; with a
    /// vessel's motion unknown the band needs the forecaster for the free responses, after it): the
    /// band, or None when it is made after the forecast.
    #[allow(clippy::type_complexity)]
    fn forecast_beside_band(
        &mut self,
        job: &Job,
    ) -> (
        crate::rom::Result<(Vec<f64>, usize, f64, usize)>,
        Option<Option<band::Spread>>,
    ) {
        let mut fc = std::mem::take(&mut self.fc);
        let this = &*self;
        let steps = crate::rom::forecast::steps_of(&this.model, this.length_s);
        let alone = !job.unknown.iter().any(|u| *u) && this.table.is_some();
        let forecast = |fc: &mut Forecaster| {
            let _span = tracing::debug_span!("forecast", t0_s = job.t0_s).entered();
            this.forecast(fc, job)
        };
        let out = if alone {
            let (result, spread) = rayon::join(
                || forecast(&mut fc),
                || {
                    let _span = tracing::debug_span!("band", t0_s = job.t0_s).entered();
                    this.spread_with(job, steps, &this.spread_options(job))
                },
            );
            (result, Some(spread))
        } else {
            (forecast(&mut fc), None)
        };
        self.fc = fc;
        out
    }

    /// The job's forecast: its displacements series-major, the steps, the wave variance left out and
    /// the quasi-static components.
    #[allow(clippy::type_complexity)]
    fn forecast(&self, fc: &mut Forecaster, job: &Job) -> crate::rom::Result<(Vec<f64>, usize, f64, usize)> {
        let (model, n_bodies) = (&self.model, self.n_bodies);
        let drift = (self.drift_window_s > 0.0)
            .then(|| {
                crate::rom::drift::slow_velocity(
                    &job.velocities,
                    job.known,
                    &job.v0,
                    model.opts.dt_s,
                    self.drift_window_s,
                )
            })
            .flatten();
        Memory::from_history(model, &job.velocities).and_then(|memory| {
            let req = ForecastRequest {
                x0: &job.x0,
                v0: &job.v0,
                memory: &memory,
                waves: &job.waves,
                length_s: self.length_s,
                ramp_s: 0.0,
                drift_velocity: drift.as_deref(),
                track: job.track,
            };
            fc.forecast(model, &req).map(|f| {
                let mut values = Vec::with_capacity(6 * n_bodies * (f.steps + 1));
                for i in 0..6 * n_bodies {
                    values.extend((0..=f.steps).map(|k| f.at(k, i)));
                }
                (values, f.steps, f.skipped_variance_fraction, f.quasi_static_components)
            })
        })
    }

    /// The job's band and trusted span over `steps` (None without the response table: nothing trusted).
    /// With a vessel started from rest for want of its motion, the others' band holds what its
    /// unknown start does to them through the coupling ([`band::coupled_var`]).
    fn band(&mut self, job: &Job, steps: usize) -> Option<band::Spread> {
        let mut opts = self.spread_options(job);
        let alone = self.spread_with(job, steps, &opts)?;
        if !job.unknown.iter().any(|u| *u) {
            return Some(alone);
        }
        let omega_rad_s = band::mean_omega_rad_s(&job.waves);
        for (b, _) in job.unknown.iter().enumerate().filter(|(_, u)| **u) {
            let probe = band::significant(&alone.motion_sigma, b);
            let kept = self.coupling.get(b).and_then(|c| c.as_ref());
            if kept.is_some_and(|c| c.serves(&probe, omega_rad_s, steps)) || b >= self.coupling.len() {
                continue;
            }
            let history = job.velocities.len();
            let made = band::free_responses(
                &self.model,
                &mut self.fc,
                b,
                self.n_bodies,
                self.length_s,
                history,
                probe,
                omega_rad_s,
            );
            match made {
                Ok(r) => self.coupling[b] = Some(r),
                Err(e) => {
                    tracing::warn!(
                        vessel = b,
                        "no free response for the coupled band ({e}): nothing trusted"
                    );
                    return Some(untrusted(alone));
                }
            }
        }
        let responses: Vec<&band::CouplingResponse> = job
            .unknown
            .iter()
            .zip(&self.coupling)
            .filter_map(|(u, c)| c.as_ref().filter(|_| *u))
            .collect();
        opts.coupled_var = band::coupled_var(&responses, self.n_bodies, steps);
        self.spread_with(job, steps, &opts)
    }

    /// The band's options for a job, the coupled variance none.
    fn spread_options(&self, job: &Job) -> SpreadOptions {
        SpreadOptions {
            model_error: job.model_error.clone(),
            trusted_nrmse: self.trusted_nrmse,
            start_var: job.start_var.clone(),
            start_offset: job.start_offset.clone(),
            coupled_var: vec![],
        }
    }

    /// [`band::spread`] of a job with `opts`.
    fn spread_with(&self, job: &Job, steps: usize, opts: &SpreadOptions) -> Option<band::Spread> {
        let model = &self.model;
        self.table.as_ref().map(|table| {
            band::spread(
                table,
                &job.waves,
                &job.known_leads,
                self.n_bodies,
                job.track.map_or(0.0, |t| t.speed_m_s),
                model.g_m_s2,
                model.water_depth_m,
                steps,
                model.opts.dt_s,
                opts,
            )
        })
    }
}

/// A spread with no span trusted.
fn untrusted(mut s: band::Spread) -> band::Spread {
    s.from_s.iter_mut().chain(&mut s.to_s).for_each(|x| *x = 0.0);
    s.series_from_s
        .iter_mut()
        .chain(&mut s.series_to_s)
        .for_each(|x| *x = 0.0);
    s
}

impl Computer {
    /// Starts the in-situ roll tuning from the tuning kept across a restart (per vessel: damping,
    /// quadratic, frequency; `Engine::roll_tuning` after `Engine::restore`).
    pub fn resume_tuning(&mut self, kept: &[[f64; 3]]) {
        if let Some(model) = self.tuning.resume(&self.base, kept) {
            self.table = response_table(&model, &self.kernels);
            self.coupling = vec![None; self.n_bodies];
            self.model = model;
        }
    }

    /// One step of the in-situ roll tuning (a round's next candidate), run between jobs so that it
    /// does not delay a forecast; a finished round's tuning becomes the model forecasts run with.
    pub fn tune(&mut self) {
        if let Some(model) = self.tuning.work(&self.base) {
            self.table = response_table(&model, &self.kernels);
            self.coupling = vec![None; self.n_bodies];
            self.model = model;
        }
    }
}

/// The model's response table for the band, or None (logged) where its equations are singular.
fn response_table(model: &TimeModel, kernels: &band::TableKernels) -> Option<ResponseTable> {
    ResponseTable::with_kernels(model, kernels)
        .map_err(|e| tracing::warn!("no band for the forecasts (nothing will be trusted): {e}"))
        .ok()
}
