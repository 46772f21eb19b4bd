//! The two-ship demo as the daemon runs it (issue 27, free drift): a 10-minute simulated log of the
//! demo's config (`config/shipcast.toml`: the pair moored to each other by lines and fenders) replayed
//! through the daemon's engine at its defaults. Consecutive forecasts must agree in surge and sway far
//! ahead, and no forecast may move one hull into the other. On the main before `rom::drift`, the same
//! replay's consecutive forecasts at 119 s lead differed by up to 26.9 m in sway (the sensors' velocity
//! noise integrated over the forecast by the modes without restoring), and the free pair's forecasts
//! closed the 5 m gap by 22 m.

use crate::util::{SimLog, TWIN_SEA, simulated_with};
use shipcast::shell::ipc::Output;
use shipcast::shell::ipc::wire::ForecastHeader;
use shipcast::shell::replay::{self, Record};
use std::collections::BTreeMap;
use std::sync::OnceLock;

/// Simulated seconds in the log.
const LOG_S: f64 = 600.0;
/// The lead the forecasts are compared at, s: the demo's 120 s forecast less the 1 s between them.
const LEAD_S: f64 = 119.0;
/// Surge and sway of two forecasts 1 s apart at 119 s lead differ by at most this, m: a fifth of the
/// 5 m gap between the hulls (measured on this log: largest 1.24 m, the lighter's surge, whose lines
/// give it a 440 s period: too soft to restore within a forecast, too stiff to be drift).
const CONSECUTIVE_MAX_M: f64 = 1.5;
/// ... and by at most this in 95 % of the pairs, m (measured: 0.66 m, the same).
const CONSECUTIVE_P95_M: f64 = 0.8;
/// Gap between the hull sides at rest, m (the carrier's beam 30 m, the lighter's 20 m, 30 m apart).
const GAP_M: f64 = 5.0;
/// The drift estimate must at least halve the RMS error of surge and sway at 119 s lead against the
/// simulation's truth (measured: by 4 to 15 times).
const DRIFT_GAIN: f64 = 2.0;

#[derive(Clone)]
struct Forecast {
    header: ForecastHeader,
    values: Vec<f64>,
}

impl Forecast {
    fn at(&self, vessel: usize, dof: usize, t_s: f64) -> Option<f64> {
        let h = &self.header;
        let k = ((t_s - h.issue_time_s) / h.dt_s).round();
        if k < 0.0 || k > h.steps as f64 {
            return None;
        }
        let s = 6 * vessel + dof;
        Some(self.values[s * (h.steps as usize + 1) + k as usize])
    }

    /// The band's standard deviation at lead 0 of (vessel, dof).
    fn sigma_at_start(&self, vessel: usize, dof: usize) -> f64 {
        let h = &self.header;
        let n = (h.steps as usize + 1) * h.n_series as usize;
        self.values[n + (6 * vessel + dof) * (h.steps as usize + 1)]
    }
}

/// The demo's log: its config's system must be the moored pair.
fn log() -> &'static SimLog {
    static LOG: OnceLock<SimLog> = OnceLock::new();
    // the drift estimate under test, in the twin sea: with the shipped radar (shadowing, blind zone)
    // consecutive forecasts of the lighter's surge at 119 s differ by up to 2.4 m (issue 28's notes)
    LOG.get_or_init(|| {
        simulated_with(
            "two-ship-demo",
            "shipcast.toml",
            "vessels/pair/moored.toml",
            LOG_S,
            &TWIN_SEA,
        )
    })
}

/// The demo's log in the shipped sea (its truth another model of the hulls, the sensors as shipped),
/// 7 minutes.
pub(crate) fn sea_log() -> &'static SimLog {
    static LOG: OnceLock<SimLog> = OnceLock::new();
    LOG.get_or_init(|| {
        simulated_with(
            "two-ship-demo-sea",
            "shipcast.toml",
            "vessels/pair/moored.toml",
            SEA_LOG_S,
            &[],
        )
    })
}

/// Simulated seconds of [`sea_log`].
const SEA_LOG_S: f64 = 420.0;

/// [`sea_log`]'s forecasts at the daemon's defaults (replayed once for the tests that read them).
fn sea_forecasts() -> &'static [Forecast] {
    static FS: OnceLock<Vec<Forecast>> = OnceLock::new();
    FS.get_or_init(|| forecasts_of(sea_log(), shipcast::rom::drift::DRIFT_WINDOW_S))
}

fn forecasts(drift_window_s: f64) -> Vec<Forecast> {
    forecasts_of(log(), drift_window_s)
}

/// [`log`]'s forecasts at the daemon's defaults (replayed once for the tests that read them).
fn log_forecasts() -> &'static [Forecast] {
    static FS: OnceLock<Vec<Forecast>> = OnceLock::new();
    FS.get_or_init(|| forecasts(shipcast::rom::drift::DRIFT_WINDOW_S))
}

/// Forecasts per second of log, at least: the demo issues one a second, the rest a margin for the start.
const MIN_FORECASTS_PER_S: f64 = 0.9;

fn forecasts_of(l: &SimLog, drift_window_s: f64) -> Vec<Forecast> {
    let mut cfg = l.cfg.clone();
    cfg.forecast.drift_window_s = drift_window_s;
    let mut out = vec![];
    replay::drive(
        &cfg,
        &l.sys,
        &l.records,
        |_| {},
        |o| {
            if let Output::Forecast(header, values) = o {
                out.push(Forecast { header, values })
            }
        },
    )
    .unwrap();
    let log_s = l.records.last().unwrap().0 - l.records.first().unwrap().0;
    assert!(
        out.len() as f64 > MIN_FORECASTS_PER_S * log_s,
        "{} forecasts",
        out.len()
    );
    out
}

/// RMS error at `LEAD_S` against the log's truth of (vessel, dof).
fn rms_error(fs: &[Forecast], vessel: usize, dof: usize) -> f64 {
    rms_error_at(fs, vessel, dof, LEAD_S)
}

/// RMS error at `lead_s` against the log's truth of (vessel, dof).
fn rms_error_at(fs: &[Forecast], vessel: usize, dof: usize, lead_s: f64) -> f64 {
    rms_error_of(log(), fs, vessel, dof, lead_s)
}

/// A time as the key of [`truth_of`]: whole ms.
fn ms(t_s: f64) -> i64 {
    (t_s * 1000.0).round() as i64
}

/// The truth of (vessel, dof) in log `l`, by time ([`ms`]).
fn truth_of(l: &SimLog, vessel: usize, dof: usize) -> BTreeMap<i64, f64> {
    l.records
        .iter()
        .filter_map(|(_, r)| match r {
            Record::Truth(m) if m.vessel as usize == vessel => Some((ms(m.time_s), m.x[dof])),
            _ => None,
        })
        .collect()
}

/// RMS error at `lead_s` against the truth of (vessel, dof) in log `l`.
fn rms_error_of(l: &SimLog, fs: &[Forecast], vessel: usize, dof: usize, lead_s: f64) -> f64 {
    let truth = truth_of(l, vessel, dof);
    let (mut se, mut n) = (0.0, 0usize);
    for f in fs {
        let t = f.header.issue_time_s + lead_s;
        if let (Some(x), Some(tr)) = (f.at(vessel, dof, t), truth.get(&ms(t))) {
            se += (x - tr).powi(2);
            n += 1;
        }
    }
    assert!(n > 100, "{n} forecasts met the truth");
    (se / n as f64).sqrt()
}

/// The moored lighter's roll at lead 0 and 5 s, RMS error over the truth's standard deviation, in the
/// second half of the log (the estimator's bias and the model's mean averaged), at most: the lines
/// and fenders give it a mean heel in waves, which the estimator takes off as a sensor's bias; the
/// model's own mean in waves goes back on (measured 0.03 and 0.06; over the whole log 0.56 and 0.32
/// without it).
const HEELED_START_NRMSE: f64 = 0.2;

#[test]
fn a_moored_vessel_s_forecast_starts_from_its_mean_heel() {
    let fs = log_forecasts();
    let start = log().records.first().map(|r| r.0).unwrap();
    let late: Vec<Forecast> = fs
        .iter()
        .filter(|f| f.header.issue_time_s - start >= LOG_S / 2.0)
        .cloned()
        .collect();
    let truth: Vec<f64> = log()
        .records
        .iter()
        .filter_map(|(t, r)| match r {
            Record::Truth(m) if m.vessel == 1 && *t - start >= LOG_S / 2.0 => Some(m.x[3]),
            _ => None,
        })
        .collect();
    let mean = truth.iter().sum::<f64>() / truth.len() as f64;
    let std = (truth.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / truth.len() as f64).sqrt();
    for lead_s in [0.0, 5.0] {
        let e = rms_error_at(&late, 1, 3, lead_s) / std;
        eprintln!(
            "lighter roll at {lead_s} s lead: NRMSE {e:.3} (the truth's mean heel {:.2} deg)",
            mean.to_degrees()
        );
        assert!(e <= HEELED_START_NRMSE, "{lead_s} s: {e}");
    }
}

/// Roll and pitch of both vessels at lead 0 in the shipped sea (where they move enough to matter,
/// `band::SIGNIFICANT`), RMS error over the truth's standard deviation in the log's second half, at
/// most: the truth (another model of the hulls) heels the
/// moored lighter by about 0.5 deg more than the model does, and the forecast keeps the measured
/// heel (measured at most 0.05; the lighter's roll 0.35 when the forecast took the model's own mean).
const MEASURED_HEEL_NRMSE: f64 = 0.1;
/// ... and the truth inside the published 90 % band at lead 0 in at least this share of them. Not the
/// Show's 0.85: the 210 s judged are a third of the sensor's drift's correlation time, so they see one
/// draw of it, and a band right over many draws (`band::tests::the_band_at_the_start_covers_nine_
/// in_ten_when_heel_and_bias_are_as_likely_as_said`) covers less where that draw is large; here the
/// carrier's IMU reads 0.0002 rad low throughout (0.8 of the drift's standard deviation the bias
/// average holds). Measured 0.68 (carrier; 0.74 before the radar's window of scans changed the
/// forecasts whose settled mean the heel is learnt from) and 0.92 (lighter, its 3.3 deg heel kept);
/// 0.56-0.66 for roll when the checks at lead 0 took the sensor's noise for what explains their error.
const START_COVERAGE: f64 = 0.65;

#[test]
fn a_heel_the_model_does_not_know_is_kept() {
    let l = sea_log();
    let start = l.records.first().map(|r| r.0).unwrap();
    let late: Vec<Forecast> = sea_forecasts()
        .iter()
        .filter(|f| f.header.issue_time_s - start >= SEA_LOG_S / 2.0)
        .cloned()
        .collect();
    for (v, name) in [(0, "carrier"), (1, "lighter")] {
        for (d, dof) in [(3, "roll"), (4, "pitch")] {
            let truth: Vec<f64> = l
                .records
                .iter()
                .filter_map(|(t, r)| match r {
                    Record::Truth(m) if m.vessel == v as u32 && *t - start >= SEA_LOG_S / 2.0 => Some(m.x[d]),
                    _ => None,
                })
                .collect();
            let mean = truth.iter().sum::<f64>() / truth.len() as f64;
            let std = (truth.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / truth.len() as f64).sqrt();
            if std < shipcast::band::SIGNIFICANT[d - 2] {
                // a DOF the sea barely moves (the carrier's pitch in beam seas): its error is the
                // sensor's noise, not a measure of the heel kept
                eprintln!(
                    "{name} {dof}: standard deviation {:.4} deg, not judged",
                    std.to_degrees()
                );
                continue;
            }
            let e = rms_error_of(l, &late, v, d, 0.0) / std;
            let truth_at = truth_of(l, v, d);
            let inside: Vec<bool> = late
                .iter()
                .filter_map(|f| {
                    let t = f.header.issue_time_s;
                    let tr = truth_at.get(&ms(t))?;
                    Some((f.at(v, d, t)? - tr).abs() <= 1.645 * f.sigma_at_start(v, d))
                })
                .collect();
            let coverage = inside.iter().filter(|b| **b).count() as f64 / inside.len() as f64;
            eprintln!(
                "{name} {dof} at lead 0: NRMSE {e:.3}, coverage_90 {coverage:.2} (the truth's mean {:.3} deg, \
                 standard deviation {:.3} deg)",
                mean.to_degrees(),
                std.to_degrees()
            );
            assert!(e <= MEASURED_HEEL_NRMSE, "{name} {dof}: {e}");
            assert!(
                inside.len() > 100 && coverage >= START_COVERAGE,
                "{name} {dof}: coverage {coverage}"
            );
        }
    }
}

#[test]
fn consecutive_forecasts_agree_and_keep_the_hulls_apart() {
    let fs = log_forecasts();
    let raw = forecasts(0.0);
    for (v, name) in [(0, "carrier"), (1, "lighter")] {
        for (d, dof) in [(0, "surge"), (1, "sway")] {
            let mut diffs: Vec<f64> = fs
                .windows(2)
                .filter_map(|p| {
                    let t = p[1].header.issue_time_s + LEAD_S;
                    Some((p[0].at(v, d, t)? - p[1].at(v, d, t)?).abs())
                })
                .collect();
            diffs.sort_by(f64::total_cmp);
            let n = diffs.len();
            let (p95, max) = (diffs[n * 95 / 100], diffs[n - 1]);
            let (with, without) = (rms_error(fs, v, d), rms_error(&raw, v, d));
            eprintln!(
                "{name} {dof}: forecasts 1 s apart at {LEAD_S} s lead differ by median {:.3}, p95 {p95:.3}, \
                 max {max:.3} m; RMS error against the truth {with:.3} m ({without:.3} m with the last \
                 sample's velocity)",
                diffs[n / 2]
            );
            assert!(max <= CONSECUTIVE_MAX_M, "{name} {dof}: {max} m");
            assert!(p95 <= CONSECUTIVE_P95_M, "{name} {dof}: {p95} m");
            assert!(with * DRIFT_GAIN <= without, "{name} {dof}: {with} against {without}");
        }
    }
    // the gap at the lighter's ends (x = -60, 60 m), at the waterline, over every step of every forecast
    let mut min_gap = f64::INFINITY;
    for f in fs {
        for k in 0..=f.header.steps {
            let t = f.header.issue_time_s + k as f64 * f.header.dt_s;
            for x in [-60.0, 60.0] {
                let side = |v: usize| f.at(v, 1, t).unwrap() + x * f.at(v, 5, t).unwrap();
                min_gap = min_gap.min(GAP_M + side(1) - side(0));
            }
        }
    }
    eprintln!("smallest gap between the hulls in any forecast: {min_gap:.3} m");
    assert!(
        min_gap > 0.0,
        "a forecast moved the lighter into the carrier: gap {min_gap} m"
    );
}

/// The lighter's motion is missing from this to [`OUTAGE_END_S`] after the start of [`sea_log`] (the
/// link between the ships down), s.
const OUTAGE_START_S: f64 = 240.0;
const OUTAGE_END_S: f64 = 300.0;
/// During the outage the truth of the lighter (started from rest: its state unknown) is inside its
/// published 90 % band at lead 0 to 60 s at least this often: the Show's lower bound for coverage
/// (measured 0.95: the band is at least the motion's own, twice its variance).
const UNKNOWN_START_COVERAGE: f64 = 0.85;
/// The variance the carrier's band gains when the lighter's motion is missing, as a share of the
/// variance its error gains: the model's free response to the lighter's unknown motion, within a factor
/// of 2 of what the truth shows (measured 0.72 and 0.88 at 30 and 60 s; 0 before the coupled band).
const COUPLED_BAND_SHARE: std::ops::RangeInclusive<f64> = 0.5..=2.0;

#[test]
fn a_vessel_whose_motion_stops_is_forecast_from_rest_and_trusted_nowhere() {
    let l = sea_log();
    let start = l.records.first().map(|r| r.0).unwrap();
    let cut = crate::util::SimLog {
        cfg: l.cfg.clone(),
        sys: l.sys.clone(),
        records: l
            .records
            .iter()
            // the log up to the outage's end (the replay need not go further)
            .filter(|(t, r)| {
                let gone = (OUTAGE_START_S..OUTAGE_END_S).contains(&(t - start));
                t - start <= OUTAGE_END_S && !(gone && matches!(r, Record::Motion(m) if m.vessel == 1))
            })
            .cloned()
            .collect(),
    };
    // forecasts issued once the lighter's motion is stale (2 s) until it returns
    let window = |fs: &[Forecast]| -> Vec<Forecast> {
        fs.iter()
            .filter(|f| (OUTAGE_START_S + 3.0..OUTAGE_END_S).contains(&(f.header.issue_time_s - start)))
            .cloned()
            .collect()
    };
    let whole = window(sea_forecasts());
    let cut_fs = forecasts_of(&cut, shipcast::rom::drift::DRIFT_WINDOW_S);
    let out = window(&cut_fs);
    // the ten seconds before the outage, in the same run (the same learnt model error)
    let before: Vec<Forecast> = cut_fs
        .iter()
        .filter(|f| (OUTAGE_START_S - 10.0..OUTAGE_START_S).contains(&(f.header.issue_time_s - start)))
        .cloned()
        .collect();
    let first_out: Vec<Forecast> = out.iter().take(before.len()).cloned().collect();
    assert!(out.len() >= 50, "{} forecasts during the outage", out.len());
    for f in &out {
        let h = &f.header;
        assert!(
            h.flags & shipcast::shell::ipc::wire::flags::STALE_MOTION != 0,
            "{:?}",
            h.flags
        );
        assert_eq!(h.horizon_s[1], 0.0);
    }
    let rms = |fs: &[Forecast], v: usize, d: usize, lead_s: f64| -> f64 {
        let truth = truth_of(l, v, d);
        let e: Vec<f64> = fs
            .iter()
            .filter_map(|f| {
                let t = f.header.issue_time_s + lead_s;
                Some(f.at(v, d, t)? - truth.get(&ms(t))?)
            })
            .collect();
        (e.iter().map(|x| x * x).sum::<f64>() / e.len().max(1) as f64).sqrt()
    };
    for (v, d, name) in [
        (0, 2, "carrier heave (m)"),
        (0, 3, "carrier roll (rad)"),
        (1, 3, "lighter roll (rad)"),
    ] {
        let leads = [0.0, 10.0, 30.0, 60.0];
        let with: Vec<String> = leads.iter().map(|&k| format!("{:.4}", rms(&whole, v, d, k))).collect();
        let without: Vec<String> = leads.iter().map(|&k| format!("{:.4}", rms(&out, v, d, k))).collect();
        eprintln!("{name}: RMS error at leads {leads:?} s with the lighter's motion {with:?}, without it {without:?}");
    }
    // the share of the truth of (v, d) inside the published 90 % band at leads 0-60 s
    let coverage = |fs: &[Forecast], v: usize, d: usize| -> (f64, usize) {
        let truth = truth_of(l, v, d);
        let (mut inside, mut n) = (0, 0);
        for f in fs {
            let h = &f.header;
            let per = h.steps as usize + 1;
            let s = (6 * v + d) * per;
            let base = h.n_series as usize * per;
            for k in (0..per).step_by(10).take_while(|k| *k as f64 * h.dt_s <= 60.0) {
                let t = h.issue_time_s + k as f64 * h.dt_s;
                if let Some(tr) = truth.get(&ms(t)) {
                    n += 1;
                    if (f.values[s + k] - tr).abs() <= 1.645 * f.values[base + s + k] {
                        inside += 1;
                    }
                }
            }
        }
        (inside as f64 / n.max(1) as f64, n)
    };
    for (v, d, name) in [(0, 2, "carrier heave"), (0, 3, "carrier roll")] {
        eprintln!(
            "{name} inside its 90 % band at leads 0-60 s: {:.2} with the lighter's motion, {:.2} without it",
            coverage(&whole, v, d).0,
            coverage(&out, v, d).0
        );
    }
    // the carrier's band holds what the lighter's unknown start does to it through the lines, the
    // fenders and the water (was: the band of the lighter's motion known, 0.93 coverage of an error
    // 2.7 times larger at 30 s)
    let band_square = |fs: &[Forecast], v: usize, d: usize, lead_s: f64| -> f64 {
        let squares: Vec<f64> = fs
            .iter()
            .map(|f| {
                let h = &f.header;
                let per = h.steps as usize + 1;
                f.values[h.n_series as usize * per + (6 * v + d) * per + (lead_s / h.dt_s).round() as usize].powi(2)
            })
            .collect();
        squares.iter().sum::<f64>() / squares.len().max(1) as f64
    };
    for lead_s in [30.0, 60.0] {
        let added = band_square(&first_out, 0, 3, lead_s) - band_square(&before, 0, 3, lead_s);
        let erred = rms(&out, 0, 3, lead_s).powi(2) - rms(&whole, 0, 3, lead_s).powi(2);
        let share = added / erred;
        eprintln!(
            "the carrier's roll at {lead_s} s: band {:.4} rad before the outage, {:.4} rad after; error {:.4} -> {:.4} rad with and without the lighter's motion: the band's added variance is {share:.2} of the error's",
            band_square(&before, 0, 3, lead_s).sqrt(),
            band_square(&first_out, 0, 3, lead_s).sqrt(),
            rms(&whole, 0, 3, lead_s),
            rms(&out, 0, 3, lead_s)
        );
        assert!(COUPLED_BAND_SHARE.contains(&share), "{share:.2} at {lead_s} s");
    }
    let (c, n) = coverage(&out, 0, 3);
    assert!(c >= UNKNOWN_START_COVERAGE, "the carrier's roll: {c} of {n}");
    let spans = |fs: &[Forecast]| -> f64 {
        let mut s: Vec<f64> = fs.iter().map(|f| f.header.series_span(3).1).collect();
        s.sort_by(f64::total_cmp);
        s[s.len() / 2]
    };
    eprintln!(
        "the carrier's roll span: median to {:.1} s with the lighter's motion, {:.1} s without it",
        spans(&whole),
        spans(&out)
    );
    // the lighter's band holds its unknown start
    let (c, n) = coverage(&out, 1, 3);
    eprintln!("the lighter's roll inside its 90 % band at leads 0-60 s during the outage: {c:.2} of {n}");
    assert!(n > 100 && c >= UNKNOWN_START_COVERAGE, "{c} of {n}");
}

/// Where in [`sea_log`] the spike burst is put, s after its start (the model error checked by then).
const BURST_AT_S: f64 = 200.0;
/// No trusted forecast of the lighter rolls beyond this, rad (30 deg: far beyond the demo's sea,
/// whose roll stays under 5 deg).
const LIGHTER_ROLL_MAX_RAD: f64 = 0.52;

/// Was: five +50 m heave spikes of the carrier in 0.5 s, the fifth just before a forecast, restarted
/// the carrier's estimate from them; the forecast started the carrier 50 m up, and the lighter moored
/// to it, judged alone, was published trusted with a roll of 7.4 rad. Now a vessel whose estimate is
/// restarted withdraws trust from every vessel coupled to it.
#[test]
fn a_partner_s_bad_start_withdraws_trust_from_the_hull_moored_to_it() {
    let l = sea_log();
    let start = l.records.first().map(|r| r.0).unwrap();
    let burst_tick = sea_forecasts()
        .iter()
        .find(|f| f.header.issue_time_s - start > BURST_AT_S)
        .expect("a forecast after the burst time")
        .header;
    let mut records = l.records.clone();
    let burst: Vec<usize> = records
        .iter()
        .enumerate()
        .filter(|(_, (_, r))| matches!(r, Record::Motion(m) if m.vessel == 0 && m.time_s <= burst_tick.motion_time_s))
        .map(|(i, _)| i)
        .collect();
    for &i in &burst[burst.len() - 5..] {
        if let Record::Motion(m) = &mut records[i].1 {
            m.x[2] += 50.0;
        }
    }
    let faulted = crate::util::SimLog {
        cfg: l.cfg.clone(),
        sys: l.sys.clone(),
        records,
    };
    let fs = forecasts_of(&faulted, shipcast::rom::drift::DRIFT_WINDOW_S);
    let at_burst = fs
        .iter()
        .find(|f| f.header.issue_time_s == burst_tick.issue_time_s)
        .expect("the burst's forecast is published");
    assert_eq!(
        &at_burst.header.horizon_s[..2],
        &[0.0, 0.0],
        "the forecast from the burst trusts a vessel"
    );
    for f in &fs {
        let h = &f.header;
        if h.horizon_s[1] <= 0.0 {
            continue;
        }
        let steps = (h.horizon_s[1] / h.dt_s).floor() as usize;
        let roll = (0..=steps)
            .map(|k| f.values[(6 + 3) * (h.steps as usize + 1) + k].abs())
            .fold(0.0, f64::max);
        assert!(
            roll < LIGHTER_ROLL_MAX_RAD,
            "the lighter trusted with a roll of {roll:.2} rad at {:.1} s",
            h.issue_time_s - start
        );
    }
}

/// When the lighter's clock steps an hour ahead in [`sea_log`], s after its start.
const PEER_CLOCK_AT_S: f64 = 200.0;

/// Was: the other ship's motion stamped an hour ahead (its clock, over the link) raised
/// `clocks_disagree` and stopped every forecast, the own hull's included. Now each vessel's clock is
/// judged alone against the radar's: the lighter is forecast from rest and trusted nowhere, the
/// carrier's forecasts go on.
#[test]
fn a_peer_an_hour_ahead_does_not_stop_the_own_hull_s_forecasts() {
    use shipcast::shell::ipc::wire::flags;
    let l = sea_log();
    let start = l.records.first().map(|r| r.0).unwrap();
    let mut records = l.records.clone();
    for (t, r) in records.iter_mut() {
        if let Record::Motion(m) = r
            && m.vessel == 1
            && *t - start >= PEER_CLOCK_AT_S
        {
            m.time_s += 3600.0;
        }
    }
    let faulted = crate::util::SimLog {
        cfg: l.cfg.clone(),
        sys: l.sys.clone(),
        records,
    };
    // from a minute after the step (the resync, the model error's checks) to the end of the log
    let late = |fs: &[Forecast]| -> Vec<ForecastHeader> {
        fs.iter()
            .map(|f| f.header)
            .filter(|h| h.issue_time_s - start > PEER_CLOCK_AT_S + 60.0)
            .collect()
    };
    let (base, got) = (
        late(sea_forecasts()),
        late(&forecasts_of(&faulted, shipcast::rom::drift::DRIFT_WINDOW_S)),
    );
    assert!(
        got.len() + 2 >= base.len(),
        "{} forecasts with the lighter's clock an hour ahead, {} without",
        got.len(),
        base.len()
    );
    for h in &got {
        assert!(h.flags & flags::MOTION_CLOCK_APART != 0, "{:?}", flags::names(h.flags));
        assert_eq!(h.horizon_s[1], 0.0, "the lighter trusted on a clock an hour ahead");
    }
    let trusted = got.iter().filter(|h| h.horizon_s[0] > 0.0).count();
    assert!(
        trusted * 2 > got.len(),
        "the carrier trusted in {trusted} of {} forecasts",
        got.len()
    );
}
