//! Forecast scenarios (`shipcast forecast SCENARIO`): a system, a sea, speed, history and length. The
//! measured past is simulated: a model runs from rest in the same sea for `history_s` (a spin-up whose
//! velocities become the memory and whose end state is the state at t0), then the forecasting model
//! forecasts for the scenario's length (key `horizon_s`, or `length_s`: the forecast's length, not a
//! predictable horizon). The past is simulated by the reference (direct convolution) whatever method
//! forecasts, as a measured past would not depend on it: the methods then differ only by their forecasts.

use crate::radiation::history::Memory;
use crate::rom::{self, ForecastRequest, Forecaster, RadiationMethod, RomOptions, TimeModel};
use crate::shell::files;
use crate::waves::WaveComponent;
use crate::waves::sea::{self, SeaState, Spreading};
use num_complex::Complex64;
use serde::Deserialize;
use std::path::{Path, PathBuf};

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct ScenarioFile {
    system: String,
    /// The forecast's length, s (key `horizon_s`, or `length_s`).
    #[serde(rename = "horizon_s", alias = "length_s")]
    length_s: f64,
    history_s: f64,
    #[serde(default = "default_dt")]
    dt_s: f64,
    #[serde(default)]
    speed_m_s: f64,
    radiation: Option<String>,
    /// The radar's view: a disc of this radius around the origin at t0 (default: the sea is known
    /// everywhere and the horizon is unlimited).
    radar_radius_m: Option<f64>,
    sea: Option<SeaFile>,
    /// A second sea state superposed (swell); same keys as `[sea]`.
    swell: Option<SeaFile>,
    /// Explicit components instead of a sea state: amplitude and phase at the origin at the start of
    /// the history (t = -history_s).
    #[serde(default)]
    component: Vec<ComponentFile>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct ComponentFile {
    omega_rad_s: f64,
    heading_deg: f64,
    amplitude_m: f64,
    #[serde(default)]
    phase_deg: f64,
}

fn default_dt() -> f64 {
    0.1
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct SeaFile {
    hs_m: f64,
    tp_s: f64,
    #[serde(default = "one")]
    gamma: f64,
    heading_deg: f64,
    /// cos-2s spreading exponent (omit, and no `spreading`, for long-crested waves).
    spreading_s: Option<f64>,
    /// "cos2" for cos^2 spreading instead.
    spreading: Option<String>,
    components: usize,
    #[serde(default = "wmin")]
    omega_min_rad_s: f64,
    #[serde(default = "wmax")]
    omega_max_rad_s: f64,
    #[serde(default)]
    seed: u64,
}

fn one() -> f64 {
    1.0
}
fn wmin() -> f64 {
    0.2
}
fn wmax() -> f64 {
    1.6
}

/// Errors reading a scenario: the file, or a key and what is wrong with it.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    #[error(transparent)]
    File(#[from] files::Error),
    #[error("{file}: {msg}")]
    Invalid { file: String, msg: String },
}

/// The waves of a scenario: a sea state to realize, or components as given.
#[derive(Debug, Clone)]
pub enum Waves {
    /// One sea state, or several superposed (wind sea + swell).
    Sea(Vec<SeaState>),
    Components(Vec<WaveComponent>),
}

/// A validated scenario.
#[derive(Debug, Clone)]
pub struct Scenario {
    pub system: PathBuf,
    /// The forecast's length, s (the file's `horizon_s`).
    pub length_s: f64,
    pub history_s: f64,
    pub opts: RomOptions,
    pub waves: Waves,
    /// Radius of the observed disc around the origin, m (None: known everywhere).
    pub radar_radius_m: Option<f64>,
}

impl Scenario {
    pub fn load(path: &Path) -> Result<Scenario, Error> {
        let text = files::read_text(path)?;
        let file = path.display().to_string();
        let raw: ScenarioFile = toml::from_str(&text).map_err(|e| Error::Invalid {
            file: file.clone(),
            msg: e.to_string(),
        })?;
        let bad = |k: &str, m: String| Error::Invalid {
            file: file.clone(),
            msg: format!("{k}: {m}"),
        };
        for (k, v) in [
            ("horizon_s", raw.length_s),
            ("history_s", raw.history_s),
            ("dt_s", raw.dt_s),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(bad(k, format!("must be positive, found {v}")));
            }
        }
        // both are runs of the model, sized steps x states
        for (k, v) in [("horizon_s", raw.length_s), ("history_s", raw.history_s)] {
            if v > crate::rom::forecast::MAX_FORECAST_LENGTH_S {
                return Err(bad(
                    k,
                    format!("at most {} s, found {v}", crate::rom::forecast::MAX_FORECAST_LENGTH_S),
                ));
            }
        }
        if let Some(r) = raw.radar_radius_m
            && !(r.is_finite() && r > 0.0)
        {
            return Err(bad("radar_radius_m", format!("must be positive, found {r}")));
        }
        let radiation = match raw.radiation.as_deref() {
            None | Some("state-space") => RadiationMethod::StateSpace,
            Some("convolution") => RadiationMethod::Convolution,
            Some(o) => {
                return Err(bad(
                    "radiation",
                    format!("expected \"convolution\" or \"state-space\", found \"{o}\""),
                ));
            }
        };
        let sea_of = |sf: &SeaFile, key: &str| sea_state(sf, key).map_err(|(k, m)| bad(&k, m));
        let waves = match (raw.sea, raw.component.is_empty()) {
            (Some(s), true) => {
                let mut seas = vec![sea_of(&s, "sea")?];
                if let Some(sw) = &raw.swell {
                    seas.push(sea_of(sw, "swell")?);
                }
                Waves::Sea(seas)
            }
            (None, false) => Waves::Components(components(&raw.component).map_err(|(k, m)| bad(&k, m))?),
            _ => {
                return Err(bad(
                    "sea",
                    "give either a [sea] table or [[component]] entries, not both, not neither".into(),
                ));
            }
        };
        let opts = RomOptions {
            dt_s: raw.dt_s,
            radiation,
            speed_m_s: raw.speed_m_s,
            ..RomOptions::default()
        };
        opts.validate().map_err(|e| bad(e.field, e.msg))?;
        Ok(Scenario {
            system: path.parent().unwrap_or(Path::new(".")).join(raw.system),
            length_s: raw.length_s,
            history_s: raw.history_s,
            opts,
            waves,
            radar_radius_m: raw.radar_radius_m,
        })
    }
}

/// The sea state of table `key` (`sea`, `swell`); an error is (key, message).
fn sea_state(s: &SeaFile, key: &str) -> Result<SeaState, (String, String)> {
    let spreading = match (s.spreading.as_deref(), s.spreading_s) {
        (None, None) => Spreading::LongCrested,
        (None, Some(e)) => Spreading::Cos2s(e),
        (Some("cos2"), None) => Spreading::Cos2,
        (Some(o), _) => {
            return Err((
                format!("{key}.spreading"),
                format!("expected \"cos2\" (or spreading_s = <s> alone), found \"{o}\""),
            ));
        }
    };
    let sea = SeaState {
        hs_m: s.hs_m,
        tp_s: s.tp_s,
        gamma: s.gamma,
        heading_rad: s.heading_deg.to_radians(),
        spreading,
        components: s.components,
        omega_min_rad_s: s.omega_min_rad_s,
        omega_max_rad_s: s.omega_max_rad_s,
        seed: s.seed,
    };
    sea::validate(&sea).map_err(|m| (key.to_string(), m))?;
    Ok(sea)
}

/// The explicit `[[component]]` entries (amplitude and phase at the origin at the start of the history);
/// an error is (key, message).
fn components(component: &[ComponentFile]) -> Result<Vec<WaveComponent>, (String, String)> {
    let mut out = vec![];
    for (k, c) in component.iter().enumerate() {
        let ok = c.omega_rad_s.is_finite()
            && c.omega_rad_s > 0.0
            && c.heading_deg.is_finite()
            && c.amplitude_m.is_finite()
            && c.amplitude_m >= 0.0
            && c.phase_deg.is_finite();
        if !ok {
            return Err((
                format!("component[{k}]"),
                "needs omega_rad_s > 0, amplitude_m >= 0 and finite heading_deg, phase_deg".into(),
            ));
        }
        out.push(WaveComponent {
            omega_rad_s: c.omega_rad_s,
            heading_rad: c.heading_deg.to_radians(),
            amplitude_m: Complex64::from_polar(c.amplitude_m, c.phase_deg.to_radians()),
        });
    }
    Ok(out)
}

/// The inputs of the forecast at t0, prepared by a spin-up from rest over the history.
pub struct Prepared {
    pub x0: Vec<f64>,
    pub v0: Vec<f64>,
    pub memory: Memory,
    /// Components referred to t0.
    pub waves: Vec<WaveComponent>,
}

impl Prepared {
    /// The forecast request from this state, `length_s` long.
    pub fn request(&self, length_s: f64) -> ForecastRequest<'_> {
        ForecastRequest {
            x0: &self.x0,
            v0: &self.v0,
            memory: &self.memory,
            waves: &self.waves,
            length_s,
            ramp_s: 0.0,
            drift_velocity: None,
            track: None,
        }
    }
}

/// The options of the model that simulates the measured past of a forecast made with `opts`: the
/// reference, direct convolution, at the same step and speed.
pub fn past_options(opts: RomOptions) -> RomOptions {
    RomOptions {
        radiation: RadiationMethod::Convolution,
        ..opts
    }
}

/// Runs the spin-up with `past` (the model that simulates the measured past) and returns the state,
/// `model`'s memory of that past and the waves at t0. Both models must share the step and active DOFs.
pub fn prepare(past: &TimeModel, model: &TimeModel, waves: &Waves, history_s: f64) -> rom::Result<Prepared> {
    if past.opts.dt_s != model.opts.dt_s || past.active != model.active {
        return Err(rom::Error::Input(format!(
            "the past's model (dt {} s, {} active states) and the forecasting model (dt {} s, {} active states) differ",
            past.opts.dt_s,
            past.active.len(),
            model.opts.dt_s,
            model.active.len()
        )));
    }
    let waves = match waves {
        Waves::Sea(seas) => sea::realize_all(seas),
        Waves::Components(c) => c.clone(),
    };
    let n = model.n();
    let zeros = vec![0.0; n];
    let rest = Memory::new(past);
    let mut fc = Forecaster::new();
    let spin = fc.forecast(
        past,
        &ForecastRequest {
            x0: &zeros,
            v0: &zeros,
            memory: &rest,
            waves: &waves,
            length_s: history_s,
            ramp_s: 30.0_f64.min(history_s / 2.0),
            drift_velocity: None,
            track: None,
        },
    )?;
    let mut memory = Memory::new(model);
    let nm = spin.n_modes;
    let act = |k: usize, arr: &[f64]| -> Vec<f64> { model.active.iter().map(|&i| arr[k * nm + i]).collect() };
    for k in 0..spin.steps {
        memory.push(model, &act(k, &spin.v))?;
    }
    let t0 = spin.steps as f64 * model.opts.dt_s;
    let x0 = act(spin.steps, &spin.x);
    let v0 = act(spin.steps, &spin.v);
    let u = model.opts.speed_m_s;
    let waves = waves
        .into_iter()
        .map(|w| {
            let k = crate::waves::wave_number(w.omega_rad_s, model.g_m_s2, model.water_depth_m);
            let we = crate::waves::encounter_frequency(w.omega_rad_s, k, u, w.heading_rad);
            WaveComponent {
                amplitude_m: w.amplitude_m * Complex64::from_polar(1.0, we * t0),
                ..w
            }
        })
        .collect();
    Ok(Prepared { x0, v0, memory, waves })
}
