//! What a finished job publishes and teaches, and the status.

use super::message::{ForecastHeader, Output, Status, flags, link_state};
use super::*;

impl Engine {
    /// A finished job, handed back at `clock_s`: the forecast to publish, if it succeeded.
    pub fn done(&mut self, d: Done, clock_s: f64) -> Option<Output> {
        self.busy = false;
        self.last_compute_ms = d.compute_ms;
        if let Some(start) = self.job_start.take() {
            let stages = self.latency.record(start, d.times, clock_s);
            tracing::debug!(
                t0_s = start.stamp_s,
                ?stages,
                "forecast's latency, ms: {}",
                latency::STAGE_NAMES
                    .iter()
                    .zip(stages)
                    .map(|(n, v)| format!("{n} {v:.1}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            );
        }
        if let Some(r) = &d.tuning {
            self.tuned(r);
        }
        match (d.values, d.error) {
            (Some(values), _) => {
                let mut header = d.header;
                self.dropped_wave_share = d.dropped_wave_share;
                if d.dropped_wave_share > 0.0 {
                    header.flags |= flags::WAVES_DROPPED;
                }
                if d.dropped_wave_share > self.cfg.max_dropped_wave_share {
                    header.untrust_all();
                }
                self.counters.forecasts += 1;
                self.last_forecast_time = header.issue_time_s;
                // only forecasts whose waves the daemon trusts teach it the model's error (an
                // untrusted field's error is its waves'), with or without a trusted span
                let n = (header.steps as usize + 1) * header.n_series as usize;
                let unknown = self.job_unknown.iter().any(|u| *u);
                // a start settling after a restart (and all it is coupled to) teaches nothing and is
                // trusted nowhere: it may be off by the jump
                let withdrawn = self.job_withdrawn.iter().any(|w| *w);
                for (b, _) in self.job_withdrawn.iter().enumerate().filter(|(_, w)| **w) {
                    header.set_span(b, 0.0, 0.0);
                }
                let trusted =
                    d.teaches && d.dropped_wave_share <= self.cfg.max_dropped_wave_share && !unknown && !withdrawn;
                let mut values = values;
                if unknown {
                    self.unknown_start(&mut header, &mut values, &d.motion_sigma, &d.model_error);
                }
                if values.len() == 2 * n {
                    if !withdrawn {
                        self.learn_model_mean(&header, &values[..n]);
                    }
                    self.shift_to_measured_mean(&header, &mut values[..n]);
                }
                if values.len() == 2 * n && trusted {
                    self.model_error.record(
                        header.issue_time_s,
                        header.dt_s,
                        (&values[..n], &values[n..]),
                        &d.motion_sigma,
                        &d.model_error,
                        (&d.start_var, &d.check_var),
                    );
                }
                self.last_horizon = header.horizon_s;
                Some(Output::Forecast(header, values))
            }
            (None, e) => {
                self.state_flags |= flags::NUMERICAL;
                tracing::warn!("forecast abandoned: {}", e.unwrap_or_default());
                None
            }
        }
    }

    /// The model's own mean displacement in waves (heave, roll, pitch), from a forecast's settled leads
    /// (at least [`SETTLED_LEAD_S`]): averaged over [`crate::settings::EstimatorConfig`]'s
    /// `bias_time_s`, as the estimator averages the measured motion. Lines and fenders give a moored
    /// vessel a mean heel in waves; the model starts from its own, and its forecast of roll and pitch
    /// is shifted to the measured one ([`MEASURED_MEAN_DOFS`]).
    fn learn_model_mean(&mut self, header: &ForecastHeader, values: &[f64]) {
        let steps = header.steps as usize;
        let first = (SETTLED_LEAD_S / header.dt_s).ceil() as usize;
        if first > steps || values.len() != (steps + 1) * 6 * self.n_bodies {
            return;
        }
        let dt = match self.model_mean_time_s {
            Some(t) => (header.issue_time_s - t).max(0.0),
            None => 0.0,
        };
        self.model_mean_time_s = Some(header.issue_time_s);
        for (b, m) in self.model_mean.iter_mut().enumerate() {
            // heave, roll and pitch (the DOFs with a bias); the others stay 0
            let mut mean = [f64::NAN; 6];
            for d in 2..5 {
                let series = &values[(6 * b + d) * (steps + 1) + first..(6 * b + d + 1) * (steps + 1)];
                mean[d] = series.iter().sum::<f64>() / series.len() as f64;
            }
            m.add(dt, &mean, self.bias_time_s);
        }
    }

    /// A forecast that started vessels from rest for want of their motion: nothing of theirs is trusted
    /// (horizon 0), and their band is at least the error of a guess unrelated to the motion, twice
    /// its variance (the motion as the checks measured it, at least `motion_sigma`, the model's
    /// response to the whole sea), as for unknown waves.
    fn unknown_start(
        &self,
        header: &mut ForecastHeader,
        values: &mut [f64],
        motion_sigma: &[f64],
        learnt: &crate::band::ModelErrorCurve,
    ) {
        let per = header.steps as usize + 1;
        let n = per * header.n_series as usize;
        for (b, _) in self.job_unknown.iter().enumerate().filter(|(_, u)| **u) {
            header.set_span(b, 0.0, 0.0);
            if values.len() != 2 * n {
                continue;
            }
            for i in 6 * b..(6 * b + 6).min(header.n_series as usize) {
                // the motion as measured where the checks have seen it, and at least the model's
                let model = motion_sigma.get(i).copied().unwrap_or(f64::NAN);
                let floor = std::f64::consts::SQRT_2 * learnt.motion_sigma(i, model).max(model);
                for s in &mut values[n + i * per..n + (i + 1) * per] {
                    // NaN (no band known) stays NaN
                    if floor.is_finite() && *s < floor {
                        *s = floor;
                    }
                }
            }
        }
    }

    /// Shifts a forecast's values (the model's motion about its own mean) by the job's offsets: the
    /// measured mean less the model's, per vessel and DOF.
    fn shift_to_measured_mean(&self, header: &ForecastHeader, values: &mut [f64]) {
        let per = header.steps as usize + 1;
        if values.len() != per * 6 * self.n_bodies {
            return;
        }
        for (b, o) in self.job_offset.iter().enumerate().take(self.n_bodies) {
            for (d, od) in o.iter().enumerate() {
                if *od != 0.0 && od.is_finite() {
                    let i = 6 * b + d;
                    values[i * per..(i + 1) * per].iter_mut().for_each(|v| *v += od);
                }
            }
        }
    }

    /// The status at `clock_s` (`wall_s`: the wall clock to stamp it with); clears the one-shot flags.
    pub fn status(&mut self, clock_s: f64, wall_s: f64, running: bool) -> Status {
        let now_data = self.newest_motion_s().1;
        let c = &self.counters;
        let waves_dropped = if self.dropped_wave_share > 0.0 {
            flags::WAVES_DROPPED
        } else {
            0
        };
        let mut s = Status {
            schema_version: message::STATUS_SCHEMA_VERSION,
            flags: self.state_flags | waves_dropped,
            time_s: if now_data.is_finite() { now_data } else { -1.0 },
            wall_time_s: wall_s,
            wave_age_s: match &self.field {
                Some(f) if now_data.is_finite() => (now_data - f.time_s).max(0.0),
                _ => -1.0,
            },
            last_forecast_time_s: self.last_forecast_time,
            last_compute_ms: self.last_compute_ms,
            latency_ms: self.latency.last(),
            latency_p50_ms: self.latency.total_quantile_ms(0.5),
            latency_p99_ms: self.latency.total_quantile_ms(0.99),
            horizon_s: self.last_horizon,
            forecasts: c.forecasts,
            overruns: c.overruns,
            samples: c.samples,
            wave_fields: c.wave_fields,
            dropped_nonfinite: c.nonfinite,
            dropped_late: c.late,
            dropped_duplicate: c.duplicate,
            dropped_future: c.future,
            dropped_past: c.past,
            dropped_rejected: c.rejected,
            clock_steps: c.clock_steps,
            dropped_wave_share: self.dropped_wave_share,
            dropped_implausible: c.implausible,
            motion_restarts: c.motion_restarts,
            running: running as u32,
            roll_tuning: self.roll_tuning,
            roll_tuning_converged: self.roll_tuning_converged as u32,
            ..Status::default()
        };
        (s.link_state, s.link_latency_ms, s.link_loss, s.link_age_s) = match self.link {
            None => (link_state::NONE, -1.0, -1.0, -1.0),
            Some((l, at)) => {
                let since = (clock_s - at).max(0.0);
                let up = l.up == 1 && since <= LINK_SILENT_S;
                (
                    if up { link_state::UP } else { link_state::DOWN },
                    l.latency_ms,
                    l.loss,
                    if l.last_message_age_s >= 0.0 {
                        l.last_message_age_s + since
                    } else {
                        -1.0
                    },
                )
            }
        };
        for (b, h) in self.hist.iter().enumerate() {
            s.motion_age_s[b] = self.arrival[b].map(|a| clock_s - a).unwrap_or(-1.0);
            s.motion_rate_hz[b] = h.rate_hz();
            let bias = h.bias();
            s.motion_bias[b] = [bias[2], bias[3], bias[4]];
        }
        self.state_flags &= !ONE_SHOT_FLAGS;
        s
    }
}
