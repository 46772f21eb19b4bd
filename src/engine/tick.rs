//! The engine's cadence tick: the flags of the moment and, when the inputs allow, the forecast job
//! (start states, bias and heel, the model error's checks, the pose, the wave field's known leads).

use super::message::{ForecastHeader, flags};
use super::*;
use crate::rom::Track;
use crate::waves::horizon;

/// The inputs of the moment, judged: the flags, which vessels' motion is fresh, the start time t0
/// (the oldest of the fresh vessels' newest motion) and whether a forecast can run.
struct Moment {
    flags: u32,
    motion_fresh: Vec<bool>,
    t0_s: f64,
    can: bool,
}

/// The measured state a job starts from, per active row, and each series' start error.
struct Start {
    x0: Vec<f64>,
    v0: Vec<f64>,
    velocities: Vec<Vec<f64>>,
    known_history: usize,
    offset: Vec<[f64; 6]>,
    start_var: Vec<f64>,
    start_offset: Vec<f64>,
    check_var: Vec<f64>,
}

/// The system frame at t0: heading (rad), origin (m, earth), the vessel's velocity over ground (m/s),
/// its track, and whether the pose is an old one (stale navigation: not trusted).
struct Pose {
    heading_rad: f64,
    origin_m: [f64; 2],
    velocity_m_s: [f64; 2],
    track: Option<Track>,
    untrusted: bool,
}

impl Engine {
    /// One cadence tick at `clock_s`: the flags of the moment and, when the inputs allow and no
    /// forecast is running, the job to run (a tick while one runs is an overrun).
    pub fn tick(&mut self, clock_s: f64) -> Option<Job> {
        let Moment {
            flags: mut fl,
            motion_fresh,
            t0_s: t0,
            can,
        } = self.moment(clock_s);
        let mut job = None;
        if can && self.busy {
            self.counters.overruns += 1;
        } else if can && let Some(wave_time_s) = self.field.as_ref().map(|f| f.time_s) {
            let start = self.start_states(t0, &motion_fresh, &mut fl);
            if let Some(start) = start {
                self.learn_model_error(t0);
                let mut header = ForecastHeader {
                    schema_version: message::FORECAST_SCHEMA_VERSION,
                    n_vessels: self.n_bodies as u32,
                    dt_s: self.dt_s,
                    n_series: (6 * self.n_bodies) as u32,
                    flags: fl,
                    wave_time_s,
                    motion_time_s: t0,
                    ..ForecastHeader::default()
                };
                let pose = self.pose(t0, &mut header);
                let (waves, known_leads, trustworthy) = self.wave_trust(t0, &pose, &mut header);
                let model_error = self.model_error.curve();
                if model_error.checked_to_s <= 0.0 {
                    header.flags |= flags::MODEL_ERROR_UNCHECKED;
                }
                fl = header.flags;
                self.busy = true;
                self.job_start = Some(latency::JobStart {
                    stamp_s: t0,
                    arrival_s: (0..self.n_bodies)
                        .filter(|b| motion_fresh[*b])
                        .filter_map(|b| self.arrival[b])
                        .fold(f64::NEG_INFINITY, f64::max),
                    tick_s: clock_s,
                });
                self.job_offset = start.offset;
                self.job_unknown = motion_fresh.iter().map(|f| !f).collect();
                self.job_withdrawn = self.withdrawn();
                job = Some(Job {
                    t0_s: t0,
                    x0: start.x0,
                    v0: start.v0,
                    velocities: start.velocities,
                    known: start.known_history,
                    waves,
                    known_leads,
                    trustworthy,
                    model_error,
                    start_var: start.start_var,
                    start_offset: start.start_offset,
                    check_var: start.check_var,
                    track: pose.track,
                    unknown: motion_fresh.iter().map(|f| !f).collect(),
                    tune: self.tune_input(
                        t0,
                        trustworthy && motion_fresh.iter().all(|f| *f) && fl & flags::MOTION_SETTLING == 0,
                        fl,
                    ),
                    header,
                });
            }
        }
        self.state_flags = fl | (self.state_flags & ONE_SHOT_FLAGS);
        job
    }

    /// The flags of the moment at `clock_s`, and whether a forecast can run (logged when that changes).
    fn moment(&mut self, clock_s: f64) -> Moment {
        let cfg = &self.cfg;
        let mut fl = 0u32;
        let motion_ok: Vec<bool> = (0..self.n_bodies)
            .map(|b| self.arrival[b].is_some_and(|a| clock_s - a <= cfg.max_motion_age_s))
            .collect();
        if self.arrival.iter().any(|a| a.is_none()) {
            fl |= flags::NO_MOTION;
        }
        if motion_ok.iter().any(|ok| !ok) {
            fl |= flags::STALE_MOTION;
        }
        // a vessel whose motion is stale or missing (the other ship's, when the link between them is
        // down) does not stop the others' forecasts: the model starts it from rest at its mean in
        // waves, it is trusted nowhere and its band is the motion's own, and its error reaches the
        // fresh vessels through the coupling (lines, fenders, the water between them)
        let mut motion_fresh: Vec<bool> = (0..self.n_bodies)
            .map(|b| motion_ok[b] && self.hist[b].newest_time_s().is_some())
            .collect();
        if self.drop_clocks_apart(&mut motion_fresh) {
            fl |= flags::MOTION_CLOCK_APART;
        }
        let (t0, newest) = self.newest_motion_of(&motion_fresh);
        // the sources' clocks must agree: vessels' newest motion within the staleness and the skew of
        // each other, and no wave field from after the motion beyond the skew
        let mut disagree = newest - t0 > cfg.max_motion_age_s + cfg.max_clock_skew_s;
        if let Some(f) = &self.field
            && f.time_s - t0 > cfg.max_clock_skew_s
        {
            disagree = true;
        }
        if disagree {
            fl |= flags::CLOCKS_DISAGREE;
        }
        if self.waves_frozen {
            fl |= flags::WAVES_FROZEN;
        }
        if self.hist.iter().any(|h| h.settling()) {
            fl |= flags::MOTION_SETTLING;
        }
        // ages are never negative: a field stamped a little after the newest motion (within the
        // clocks' skew) is taken as current. With no vessel's motion fresh, the waves' age is taken
        // against the newest motion there is (as the status's is): stale motion is not stale waves
        // (with no motion at all it reads 0, and `no_motion` says why nothing is forecast)
        let wave_ref_s = if t0.is_finite() { t0 } else { self.newest_motion_s().1 };
        match self.field.as_ref().map(|f| (wave_ref_s - f.time_s).max(0.0)) {
            None => fl |= flags::NO_WAVES,
            Some(a) if a.is_nan() || a > cfg.suppress_wave_age_s => fl |= flags::NO_WAVES | flags::STALE_WAVES,
            Some(a) if a > cfg.max_wave_age_s => fl |= flags::STALE_WAVES,
            _ => {}
        }
        let can =
            fl & (flags::NO_WAVES | flags::CLOCKS_DISAGREE) == 0 && motion_fresh.iter().any(|f| *f) && t0.is_finite();
        if self.forecasting != Some(can) {
            let why = flags::names(fl).join(", ");
            match (self.forecasting, can) {
                (_, true) => tracing::info!("forecasting"),
                (Some(true), false) => tracing::warn!(flags = %why, "forecasting stopped: status only"),
                (None, false) => tracing::info!(flags = %why, "waiting for inputs: status only"),
                _ => {}
            }
            self.forecasting = Some(can);
        }
        Moment {
            flags: fl,
            motion_fresh,
            t0_s: t0,
            can,
        }
    }

    /// Each vessel's motion clock judged alone against the radar's (the other ship's, over the link,
    /// may be wrong while this ship's is right): a fresh vessel whose newest motion is behind the newest
    /// field beyond the clocks' skew, or ahead of it beyond `suppress_wave_age_s` and the skew, is
    /// taken as stale, if another fresh vessel's agrees. Whether any was.
    fn drop_clocks_apart(&self, motion_fresh: &mut [bool]) -> bool {
        let Some(field_s) = self.field.as_ref().map(|f| f.time_s) else {
            return false;
        };
        let skew = self.cfg.max_clock_skew_s;
        let apart: Vec<bool> = (0..self.n_bodies)
            .map(|b| {
                motion_fresh[b]
                    && self.hist[b]
                        .newest_time_s()
                        .is_some_and(|t| field_s - t > skew || t - field_s > self.cfg.suppress_wave_age_s + skew)
            })
            .collect();
        let agree = (0..self.n_bodies).any(|b| motion_fresh[b] && !apart[b]);
        if !agree || !apart.iter().any(|a| *a) {
            return false;
        }
        for (b, a) in apart.iter().enumerate() {
            if *a {
                motion_fresh[b] = false;
                tracing::debug!(vessel = b, "motion clock apart from the radar's: forecast from rest");
            }
        }
        true
    }

    /// Per vessel, whether its start or that of a vessel coupled to it is settling after a restart
    /// (`Estimator::settling`): the start may be off by the jump, and the coupling carries it.
    fn withdrawn(&self) -> Vec<bool> {
        (0..self.n_bodies)
            .map(|b| (0..self.n_bodies).any(|o| self.coupled[b][o] && self.hist[o].settling()))
            .collect()
    }

    /// The measured state at `t0` of every vessel, its start error and (roll, pitch) its heel; None when
    /// a fresh vessel's history cannot be resampled. Sets `history_short` and `history_gap` in `fl`.
    fn start_states(&mut self, t0: f64, motion_fresh: &[bool], fl: &mut u32) -> Option<Start> {
        let n_bodies = self.n_bodies;
        let n_hist = self.taps.saturating_sub(1);
        let mut s = Start {
            x0: vec![0.0; self.n_active],
            v0: vec![0.0; self.n_active],
            velocities: vec![vec![0.0; self.n_active]; n_hist],
            known_history: n_hist,
            offset: vec![[0.0; 6]; n_bodies],
            // the start's error per series: a vessel without fresh motion is bounded apart
            // (`unknown_start`), so its share here is the sensor's noise
            start_var: self.model_error.noise_var().to_vec(),
            start_offset: vec![0.0; 6 * n_bodies],
            check_var: self.model_error.noise_var().to_vec(),
        };
        let heel_dt = match self.heel_time_s {
            Some(t) => (t0 - t).max(0.0),
            None => 0.0,
        };
        self.heel_time_s = Some(t0);
        for b in 0..n_bodies {
            if !motion_fresh[b] {
                // at rest at the model's own mean in waves, no history
                for (row, &i) in self.active.iter().enumerate() {
                    if i / 6 == b && i < 6 * n_bodies {
                        s.x0[row] = self.model_mean[b].value[i % 6];
                    }
                }
                continue;
            }
            let r = self.hist[b].resample(t0, self.dt_s, n_hist, self.cfg.max_gap_s)?;
            if r.short {
                *fl |= flags::HISTORY_SHORT;
            }
            if r.gap {
                *fl |= flags::HISTORY_GAP;
            }
            s.known_history = s.known_history.min(r.known);
            // the estimator takes its bias off (the sensor's and a mean heel alike); the model
            // starts from its own mean in waves, and the forecast of roll and pitch is shifted
            // toward the measured mean when done: beyond what the sensor's bias can be, a heel or
            // trim the model does not know (angles are gravity-referenced; heave is integrated
            // acceleration, whose mean is drift: heave keeps the model's)
            let bias = self.hist[b].bias();
            for (row, &i) in self.active.iter().enumerate() {
                if i / 6 == b && i < 6 * n_bodies {
                    let d = i % 6;
                    if bias[d] != 0.0 && MEASURED_MEAN_DOFS.contains(&d) {
                        s.offset[b][d] = beyond(bias[d] - self.model_mean[b].value[d], self.angle_bias_rad);
                    }
                    s.x0[row] = r.x0[d]
                        + if bias[d] != 0.0 {
                            self.model_mean[b].value[d]
                        } else {
                            0.0
                        };
                    s.v0[row] = r.v0[i % 6];
                    for (m, v) in r.velocities.iter().enumerate() {
                        s.velocities[m][row] = v[i % 6];
                    }
                }
            }
            if let Some(v) = self.hist[b].start_var(t0) {
                s.start_var[6 * b..6 * b + 6].copy_from_slice(&v);
            }
            if let Some(v) = self.hist[b].estimate_var(t0) {
                s.check_var[6 * b..6 * b + 6].copy_from_slice(&v);
            }
            self.heel(b, &bias, heel_dt, &mut s);
        }
        Some(s)
    }

    /// Roll and pitch of vessel `b`: what the forecast leaves out of the measured mean's offset from
    /// the model's (within `angle_bias_rad`) is the sensor's bias or a heel, which no sample tells
    /// apart; the band holds either, as likely as the sensor's drift and the offsets seen so far make
    /// them ([`band::heel_split`]). Takes the offset's square into the heel's memory.
    fn heel(&mut self, b: usize, bias: &[f64; 6], heel_dt: f64, s: &mut Start) {
        let held = self.hist[b].drift_in_bias_var();
        let heel_memory_s = HEEL_MEMORY_BIAS_TIMES * self.bias_time_s;
        let mut square = [f64::NAN; 6];
        for d in MEASURED_MEAN_DOFS {
            if bias[d] != 0.0 {
                let m = bias[d] - self.model_mean[b].value[d];
                square[d] = m * m;
                let heel_var = band::heel_var(
                    self.heel_square[b].value[d],
                    held[d],
                    self.drift_time_s,
                    self.heel_square[b].span_s.min(heel_memory_s),
                );
                let (mean, var) = band::heel_split(m, m - s.offset[b][d], held[d], heel_var);
                s.start_offset[6 * b + d] = mean;
                s.start_var[6 * b + d] += var;
            }
        }
        self.heel_square[b].add(heel_dt, &square, heel_memory_s);
    }

    /// Past forecasts against the motion that followed them, as measured, with the sensor's bias off
    /// as the forecast takes it: about the model's own mean where the measured mean is taken for the
    /// sensor's (heave's drift; roll and pitch within the bias the sensor may have: how much of that
    /// may be heel is in the band at the start, [`band::heel_split`]), with the measured mean where
    /// roll or pitch keeps a heel (gravity-referenced: part of what the forecast leaves out of it as
    /// bias may be heel, and a forecast settles to the model's equilibrium whatever its start).
    /// While an estimate settles after a restart its measured motion is off by the jump: the
    /// checks wait (the pending forecasts are checked once it has settled, against the motion as
    /// then known).
    fn learn_model_error(&mut self, t0: f64) {
        if self.hist.iter().any(|h| h.settling()) {
            return;
        }
        let (dt, max_gap_s) = (self.dt_s, self.cfg.max_gap_s);
        let (hist, model_mean, angle_bias_rad) = (&self.hist, &self.model_mean, self.angle_bias_rad);
        self.model_error.observe(t0, |t| {
            measured_series(hist, model_mean, angle_bias_rad, t, dt, max_gap_s)
        });
        self.log_model_error();
    }

    /// Every series' measured value at `t` as past forecasts are checked against it
    /// ([`Self::learn_model_error`]); None where a vessel's history does not reach.
    pub(super) fn measured_at(&self, t: f64) -> Option<Vec<f64>> {
        measured_series(
            &self.hist,
            &self.model_mean,
            self.angle_bias_rad,
            t,
            self.dt_s,
            self.cfg.max_gap_s,
        )
    }

    /// The learnt model error in the log: when first learnt, then every 600 checks at 30 s.
    fn log_model_error(&mut self) {
        let c30 = self.model_error.checks()[4];
        if c30 != self.model_error_logged && (c30 == 60 || c30.is_multiple_of(600)) && c30 > 0 {
            self.model_error_logged = c30;
            let curve = self.model_error.curve();
            let at = |i: usize| {
                let m = curve.motion_var[i];
                format!("{:.3}", (curve.at(i, 30.0, m) / m).sqrt())
            };
            tracing::info!(
                checks = c30,
                "model error at 30 s lead (fraction of each measured motion; heave, roll, pitch per vessel): {}",
                (0..self.n_bodies)
                    .map(|b| format!("[{} {} {}]", at(6 * b + 2), at(6 * b + 3), at(6 * b + 4)))
                    .collect::<Vec<_>>()
                    .join(" ")
            );
        }
    }

    /// The system frame at t0: from the first vessel with fresh navigation, else the last pose
    /// navigation gave (stale: not trusted), else `[site]` (keeping station; `navigation_fallback`).
    fn pose(&mut self, t0: f64, header: &mut ForecastHeader) -> Pose {
        let cfg = &self.cfg;
        let fresh = (0..self.n_bodies).find_map(|b| {
            let newest = self.nav[b].newest_time_s()?;
            if t0 - newest > cfg.max_navigation_age_s {
                return None;
            }
            self.nav[b].pose_at(t0, cfg.navigation_window_s).map(|p| (b, p))
        });
        let Some((b, p)) = fresh else {
            header.flags |= flags::NAVIGATION_FALLBACK;
            let (heading_rad, origin_m, untrusted) = match self.last_frame {
                Some((h, o, _)) => (h, o, true),
                None => (self.heading, self.origin_m, false),
            };
            return Pose {
                heading_rad,
                origin_m,
                velocity_m_s: [0.0, 0.0],
                track: None,
                untrusted,
            };
        };
        let (s, c) = p.heading_rad.sin_cos();
        let r = self.body_xy_m[b];
        let origin = [
            p.position_m[0] - (c * r[0] - s * r[1]),
            p.position_m[1] - (s * r[0] + c * r[1]),
        ];
        self.last_frame = Some((p.heading_rad, origin, p.velocity_m_s));
        let track = Track {
            speed_m_s: p
                .speed_m_s
                .clamp(-crate::rom::model::MAX_SPEED_M_S, crate::rom::model::MAX_SPEED_M_S),
            turn_rate_rad_s: p.turn_rate_rad_s.clamp(
                -crate::rom::forecast::MAX_TURN_RATE_RAD_S,
                crate::rom::forecast::MAX_TURN_RATE_RAD_S,
            ),
            turn_start_s: 0.0,
            piece_rad: crate::rom::forecast::TURN_PIECE_RAD,
        };
        Pose {
            heading_rad: p.heading_rad,
            origin_m: origin,
            velocity_m_s: p.velocity_m_s,
            track: Some(track),
            untrusted: false,
        }
    }

    /// The field's components in the system frame at t0, each one's known leads at each vessel (from
    /// t0: the field is that much older), and whether the field can be trusted at all: what the field
    /// says about where it was observed decides how far it is trusted (no region or stale navigation:
    /// no known leads).
    fn wave_trust(
        &self,
        t0: f64,
        pose: &Pose,
        header: &mut ForecastHeader,
    ) -> (Vec<crate::waves::WaveComponent>, Vec<Vec<[f64; 2]>>, bool) {
        let Some(f) = &self.field else {
            return (vec![], vec![vec![]; self.n_bodies], false);
        };
        let waves = f.for_vessel(pose.origin_m, pose.heading_rad, t0);
        let located = match f.region {
            _ if f.components.is_empty() => {
                header.flags |= flags::NO_WAVE_COMPONENTS;
                false
            }
            crate::waves::field::Region::Everywhere => {
                header.flags |= flags::WAVE_REGION_UNKNOWN;
                false
            }
            _ => true,
        };
        let trustworthy = located && !pose.untrusted;
        let (s, c) = pose.heading_rad.sin_cos();
        let age_s = (t0 - f.time_s).max(0.0);
        let origin = pose.origin_m;
        let known_leads = self
            .body_xy_m
            .iter()
            .map(|r| {
                if !trustworthy {
                    return vec![[0.0, 0.0]; f.components.len()];
                }
                let p = [origin[0] + c * r[0] - s * r[1], origin[1] + s * r[0] + c * r[1]];
                horizon::known_leads(f, p, pose.velocity_m_s)
                    .into_iter()
                    .map(|[a, b]| [a - age_s, b - age_s])
                    .collect()
            })
            .collect();
        (waves, known_leads, trustworthy)
    }
}

/// Every series' measured value at `t`, with the sensor's bias off as a forecast takes it (see
/// [`Engine::learn_model_error`]).
fn measured_series(
    hist: &[Estimator],
    model_mean: &[estimator::RunningMean],
    angle_bias_rad: f64,
    t: f64,
    dt: f64,
    max_gap_s: f64,
) -> Option<Vec<f64>> {
    let mut x = vec![0.0; 6 * hist.len()];
    for (b, h) in hist.iter().enumerate() {
        let r = h.resample(t, dt, 0, max_gap_s)?;
        let bias = h.bias();
        for d in 0..6 {
            let mean = model_mean[b].value[d];
            let heel = MEASURED_MEAN_DOFS.contains(&d) && beyond(bias[d] - mean, angle_bias_rad) != 0.0;
            x[6 * b + d] = r.x0[d]
                + match (bias[d] != 0.0, heel) {
                    (false, _) => 0.0,
                    (true, true) => bias[d],
                    (true, false) => mean,
                };
        }
    }
    Some(x)
}
