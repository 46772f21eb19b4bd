//! `shipcast forecast`: a scenario's forecast as CSV or JSON, optionally timed.

use super::Radiation;
use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};
use serde::Serialize;
use shipcast::hydro::VesselSystem;
use shipcast::rom::outputs::Derived;
use shipcast::rom::{Forecast, Forecaster, RadiationMethod, TimeModel};
use shipcast::shell::files;
use shipcast::shell::scenario::{Scenario, past_options, prepare};
use std::io::Write;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct ForecastArgs {
    /// The scenario file (e.g. config/scenarios/two-ship.toml).
    pub scenario: PathBuf,
    /// Forecast length, s, in (0, 3600] (default: the scenario's).
    #[arg(long = "horizon", visible_alias = "length", value_name = "SECONDS", allow_negative_numbers = true, value_parser = forecast_length)]
    pub length_s: Option<f64>,
    /// Run the forecast N times and print the median and p95 wall time of one, as the last line.
    #[arg(long, allow_negative_numbers = true, default_value_t = 1)]
    pub repeat: usize,
    /// Radiation memory (default: the scenario's).
    #[arg(long, value_enum)]
    pub radiation: Option<Radiation>,
    /// Output format.
    #[arg(long, value_enum, default_value = "csv")]
    pub format: Format,
    /// Write the forecast here instead of stdout.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// `--horizon` (the forecast's length): checked as it is read, before any work.
pub fn forecast_length(s: &str) -> Result<f64, String> {
    let max = shipcast::rom::forecast::MAX_FORECAST_LENGTH_S;
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 && v <= max => Ok(v),
        Ok(v) => Err(format!("{v} s: a forecast's length must be in (0, {max}] s")),
        Err(_) => Err(format!("`{s}` is not a number of seconds")),
    }
}

#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Csv,
    Json,
}

pub fn run(args: &ForecastArgs) -> Result<()> {
    let mut sc = Scenario::load(&args.scenario)?;
    if let Some(l) = args.length_s {
        sc.length_s = l;
    }
    if let Some(r) = args.radiation {
        sc.opts.radiation = r.into();
    }
    if args.repeat == 0 {
        bail!("--repeat must be at least 1");
    }
    let loaded = files::load_system(&sc.system)?;
    let sys = &loaded.system;
    let t_build = std::time::Instant::now();
    let model = TimeModel::new(sys, sc.opts).with_context(|| sc.system.display().to_string())?;
    let build_s = t_build.elapsed().as_secs_f64();
    // the simulated measured past is the convolution's, whatever method forecasts
    let past_opts = past_options(sc.opts);
    let past = if past_opts == sc.opts {
        None
    } else {
        Some(TimeModel::new(sys, past_opts).with_context(|| sc.system.display().to_string())?)
    };
    let prep =
        prepare(past.as_ref().unwrap_or(&model), &model, &sc.waves, sc.history_s).context("spin-up of the history")?;
    let mut fc = Forecaster::new();
    let req = prep.request(sc.length_s);
    let mut times_ms = vec![];
    for _ in 0..args.repeat {
        let t = std::time::Instant::now();
        fc.forecast(&model, &req)?;
        times_ms.push(t.elapsed().as_secs_f64() * 1e3);
    }
    let f = fc.forecast(&model, &req)?;
    let extra = shipcast::rom::outputs::derived(&sys.spec.external, f);
    let horizons = scenario_horizons(sys, &sc, &prep.waves);
    let text = match args.format {
        Format::Csv => csv_text(sys, f, &extra),
        Format::Json => json_text(sys, f, &extra, &horizons, sc.opts.radiation)?,
    };
    let mut out = std::io::stdout().lock();
    match &args.out {
        Some(p) => std::fs::write(p, &text).with_context(|| format!("writing {}", p.display()))?,
        None => out.write_all(text.as_bytes())?,
    }
    eprintln!(
        "shipcast forecast: {} ({} active DOFs, {} wave components, {:?} radiation, memory {}), length {} s at dt {} s; model built in {:.2} s",
        args.scenario.display(),
        model.n(),
        prep.waves.len(),
        sc.opts.radiation,
        model.memory_size(),
        sc.length_s,
        sc.opts.dt_s,
        build_s
    );
    eprintln!(
        "predictable horizon ({}): {}",
        match sc.radar_radius_m {
            Some(r) => format!("radar disc of {r} m around the origin"),
            None => "the sea is known everywhere".into(),
        },
        horizons
            .iter()
            .map(|(n, h)| format!("{n} {h:.1} s"))
            .collect::<Vec<_>>()
            .join(", ")
    );
    if args.repeat > 1 {
        times_ms.sort_by(f64::total_cmp);
        let median = times_ms[times_ms.len() / 2];
        let p95 = times_ms[((times_ms.len() as f64 * 0.95).ceil() as usize).clamp(1, times_ms.len()) - 1];
        writeln!(out, "forecast_ms_median={median:.3} forecast_ms_p95={p95:.3}")?;
    }
    Ok(())
}

/// The forecast as CSV: `t_s`, then every state's column (units in the names), then the points',
/// relative motions' and connections' columns, 7 significant digits.
fn csv_text(sys: &VesselSystem, f: &Forecast, extra: &Derived) -> String {
    let labels: Vec<String> = (0..sys.n_states())
        .map(|i| shipcast::hydro::output_label(sys, i))
        .collect();
    let value = |k: usize, i: usize| shipcast::hydro::output_value(sys, i, f.at(k, i));
    let mut text = String::new();
    text.push_str("t_s");
    for l in labels.iter().chain(&extra.names) {
        text.push(',');
        text.push_str(l);
    }
    text.push('\n');
    for k in 0..=f.steps {
        text.push_str(&format!("{:.3}", k as f64 * f.dt_s));
        for i in 0..f.n_modes {
            text.push_str(&format!(",{:.6e}", value(k, i)));
        }
        for c in 0..extra.names.len() {
            text.push_str(&format!(",{:.6e}", extra.at(k, c)));
        }
        text.push('\n');
    }
    text
}

/// The forecast as one JSON object ([`ForecastJson`]).
fn json_text(
    sys: &VesselSystem,
    f: &Forecast,
    extra: &Derived,
    horizons: &[(String, f64)],
    radiation: RadiationMethod,
) -> Result<String> {
    let labels: Vec<String> = (0..sys.n_states())
        .map(|i| shipcast::hydro::output_label(sys, i))
        .collect();
    let value = |k: usize, i: usize| shipcast::hydro::output_value(sys, i, f.at(k, i));
    let motion: Vec<(String, Vec<Option<f64>>)> = (0..f.n_modes)
        .map(|i| {
            (
                labels[i].clone(),
                (0..=f.steps).map(|k| seven_digits(value(k, i))).collect(),
            )
        })
        .collect();
    let points: Vec<(String, Vec<Option<f64>>)> = (0..extra.names.len())
        .map(|c| {
            let v = (0..=f.steps).map(|k| seven_digits(extra.at(k, c))).collect();
            (extra.names[c].clone(), v)
        })
        .collect();
    let predictable: Vec<(String, Option<f64>)> = horizons
        .iter()
        .map(|(n, h)| {
            (
                n.clone(),
                format!("{h:.1}").parse().ok().filter(|h: &f64| h.is_finite()),
            )
        })
        .collect();
    let doc = ForecastJson {
        dt_s: f.dt_s,
        horizon_s: f.steps as f64 * f.dt_s,
        predictable_horizon_s: InOrder(&predictable),
        radiation: format!("{:?}", radiation),
        skipped_components: f.skipped_components,
        motion: InOrder(&motion),
        points: InOrder(&points),
    };
    let mut text = serde_json::to_string(&doc)?;
    text.push('\n');
    Ok(text)
}

/// The predictable horizon of each vessel in a scenario: the sea at t0 seen over the scenario's radar
/// disc around the origin (infinite without one), each vessel at its reference point.
pub fn scenario_horizons(
    sys: &shipcast::hydro::VesselSystem,
    sc: &Scenario,
    waves: &[shipcast::waves::WaveComponent],
) -> Vec<(String, f64)> {
    use shipcast::waves::field::{Region, WaveField};
    let region = match sc.radar_radius_m {
        Some(r) => Region::Disc {
            centre_m: [0.0, 0.0],
            radius_m: r,
        },
        None => Region::Everywhere,
    };
    let field = WaveField::from_components(waves, sys.spec.g_m_s2, sys.spec.water_depth_m, region);
    sys.spec
        .bodies
        .iter()
        .map(|b| {
            let h = shipcast::waves::horizon::of_field(
                &field,
                [b.position_m.x, b.position_m.y],
                [sc.opts.speed_m_s, 0.0],
                0.0,
            );
            (b.name.clone(), h.horizon_s)
        })
        .collect()
}

/// `--format json`: one object; series in the CSV's order and precision (7 significant digits), a
/// non-finite number written as null.
#[derive(Serialize)]
struct ForecastJson<'a> {
    dt_s: f64,
    /// The forecast's length, s (the name users read).
    horizon_s: f64,
    /// Each vessel's predictable horizon, s (null: unlimited).
    predictable_horizon_s: InOrder<'a, Option<f64>>,
    radiation: String,
    skipped_components: usize,
    motion: InOrder<'a, Vec<Option<f64>>>,
    points: InOrder<'a, Vec<Option<f64>>>,
}

/// (name, value) pairs written as a JSON object in their order.
struct InOrder<'a, T>(&'a [(String, T)]);

impl<T: Serialize> Serialize for InOrder<'_, T> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_map(self.0.iter().map(|(k, v)| (k, v)))
    }
}

/// `v` to the 7 significant digits the CSV writes (`{:.6e}`), None when not finite.
fn seven_digits(v: f64) -> Option<f64> {
    if v.is_finite() {
        format!("{v:.6e}").parse().ok()
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::{InOrder, seven_digits};

    #[test]
    fn json_keeps_the_order_escapes_names_and_writes_non_finite_numbers_as_null() {
        let pairs = vec![
            ("b \"quoted\"".to_string(), seven_digits(f64::NAN)),
            ("a".to_string(), seven_digits(-0.605463444)),
        ];
        assert_eq!(
            serde_json::to_string(&InOrder(&pairs)).unwrap(),
            r#"{"b \"quoted\"":null,"a":-0.6054634}"#
        );
        assert_eq!(seven_digits(f64::NEG_INFINITY), None);
    }
}
