//! What the engine keeps across a restart of the daemon (pure): each vessel's motion history and what
//! its estimator learnt (bias, drift, the hindsight checks), the sources' clocks, the navigation
//! fixes, the model error learnt from past forecasts (and the forecasts still to be checked), the
//! model's own mean in waves, the heel, and the in-situ roll tuning in force (the computer takes it
//! back: `Computer::resume_tuning`). Kept
//! with a fingerprint of the system and settings they were learnt on, and the engine clock then:
//! [`Engine::restore`] refuses a state of another version, another system or settings, or older than
//! the radiation memory the engine keeps (its history would say nothing of the motion now).
//!
//! Times are the engine's clock (the daemon's: monotonic, anchored to UNIX time at its start, so
//! comparable across restarts) and the sources' stamps, s.

use super::clock::SourceClock;
use super::estimator::{EstimatorState, RunningMean};
use super::navigation::NavTrack;
use super::*;

/// The state's layout; a state of another version is refused.
pub const STATE_VERSION: u32 = 2;

/// The engine's learnt state ([`Engine::state`], [`Engine::restore`]).
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct EngineState {
    pub version: u32,
    /// The system and settings it was learnt on ([`Engine::fingerprint`]).
    pub fingerprint: String,
    /// The engine clock when it was kept, s.
    pub clock_s: f64,
    estimators: Vec<EstimatorState>,
    motion_clock: Vec<SourceClock>,
    wave_clock: SourceClock,
    nav: Vec<NavTrack>,
    nav_clock: Vec<SourceClock>,
    model_error: band::ModelError,
    model_mean: Vec<RunningMean>,
    model_mean_time_s: Option<f64>,
    heel_square: Vec<RunningMean>,
    heel_time_s: Option<f64>,
    roll_tuning: [[f64; 3]; MAX_VESSELS],
}

/// Why a kept state was not taken.
#[derive(Debug, Clone, PartialEq)]
pub enum Refused {
    Version(u32),
    OtherSystem {
        kept: String,
        now: String,
    },
    /// Kept this long before now, s, beyond the memory, s.
    Stale {
        age_s: f64,
        memory_s: f64,
    },
}

impl std::fmt::Display for Refused {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Refused::Version(v) => write!(f, "state of version {v} (this shipcast keeps version {STATE_VERSION})"),
            Refused::OtherSystem { kept, now } => {
                write!(
                    f,
                    "state of another system or settings (kept for \"{kept}\", now \"{now}\")"
                )
            }
            Refused::Stale { age_s, memory_s } => write!(
                f,
                "state kept {age_s:.0} s ago, older than the {memory_s:.0} s radiation memory (or from the future)"
            ),
        }
    }
}

impl Engine {
    /// The system and settings the learnt state depends on: the vessels, the step and the memory, the
    /// model's rows and inertia, the estimator's noise and bias time.
    pub fn fingerprint(&self) -> String {
        format!(
            "{} vessels at {:?} m; step {} s, {} taps; rows {:?}; inertia {}; noise {} m {} rad, bias {} s",
            self.n_bodies,
            self.body_xy_m,
            self.dt_s,
            self.taps,
            self.active,
            self.inertia_digest,
            self.model_error.noise_var().first().copied().unwrap_or(0.0).sqrt(),
            self.model_error.noise_var().get(3).copied().unwrap_or(0.0).sqrt(),
            self.bias_time_s
        )
    }

    /// The learnt state at engine clock `clock_s`, to keep across a restart.
    pub fn state(&self, clock_s: f64) -> EngineState {
        EngineState {
            version: STATE_VERSION,
            fingerprint: self.fingerprint(),
            clock_s,
            estimators: self.hist.iter().map(|h| h.state()).collect(),
            motion_clock: self.motion_clock.clone(),
            wave_clock: self.wave_clock.clone(),
            nav: self.nav.clone(),
            nav_clock: self.nav_clock.clone(),
            model_error: self.model_error.clone(),
            model_mean: self.model_mean.clone(),
            model_mean_time_s: self.model_mean_time_s,
            heel_square: self.heel_square.clone(),
            heel_time_s: self.heel_time_s,
            roll_tuning: self.roll_tuning,
        }
    }

    /// Takes a kept state at engine clock `clock_s`, or says why not (nothing is changed then).
    pub fn restore(&mut self, s: EngineState, clock_s: f64) -> Result<(), Refused> {
        if s.version != STATE_VERSION {
            return Err(Refused::Version(s.version));
        }
        let now = self.fingerprint();
        let fits = s.estimators.len() == self.n_bodies
            && s.motion_clock.len() == self.n_bodies
            && s.nav.len() == self.n_bodies
            && s.nav_clock.len() == self.n_bodies
            && s.model_mean.len() == self.n_bodies
            && s.heel_square.len() == self.n_bodies;
        if s.fingerprint != now || !fits {
            return Err(Refused::OtherSystem {
                kept: s.fingerprint,
                now,
            });
        }
        let age_s = clock_s - s.clock_s;
        let memory_s = self.memory_s();
        if !(age_s.is_finite() && (0.0..=memory_s).contains(&age_s)) {
            return Err(Refused::Stale { age_s, memory_s });
        }
        for (h, e) in self.hist.iter_mut().zip(s.estimators) {
            h.restore(e);
        }
        self.motion_clock = s.motion_clock;
        self.wave_clock = s.wave_clock;
        self.nav = s.nav;
        self.nav_clock = s.nav_clock;
        self.model_error = s.model_error;
        self.model_mean = s.model_mean;
        self.model_mean_time_s = s.model_mean_time_s;
        self.heel_square = s.heel_square;
        self.heel_time_s = s.heel_time_s;
        self.roll_tuning = s.roll_tuning;
        Ok(())
    }
}
