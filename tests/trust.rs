//! Faulty but plausible inputs fed through the daemon's own engine (`replay::drive`, as `shipcast
//! replay` does) (issue 26): each test pins a fault found on an earlier main and says what it did.
//! The log: three simulated minutes of the one-ship demo (`config/one-ship.toml`) in the twin sea
//! (`util::ONE_SHIP_TWIN_SEA`: faults against a clean baseline, whose forecasts are trusted), made once.

use crate::util::{ONE_SHIP_TWIN_SEA, SimLog, simulated_with};
use shipcast::shell::ipc::Output;
use shipcast::shell::ipc::wire::{ForecastHeader, Status, flags};
use shipcast::shell::replay::{self, Record};
use std::sync::OnceLock;

/// Simulated seconds in the log.
const LOG_S: f64 = 180.0;
/// Where in the log the faults are put, s after its start: after the 60 s memory has filled.
const FAULT_AT_S: f64 = 90.0;

fn log() -> &'static SimLog {
    static LOG: OnceLock<SimLog> = OnceLock::new();
    LOG.get_or_init(|| {
        simulated_with(
            "trust",
            "one-ship.toml",
            "vessels/ship/system.toml",
            LOG_S,
            &ONE_SHIP_TWIN_SEA,
        )
    })
}

/// The log's first time, s.
fn start(records: &[(f64, Record)]) -> f64 {
    records[0].0
}

struct Run {
    forecasts: Vec<(ForecastHeader, Vec<f64>)>,
    statuses: Vec<Status>,
}

fn drive(records: &[(f64, Record)]) -> Run {
    let l = log();
    let mut run = Run {
        forecasts: vec![],
        statuses: vec![],
    };
    replay::drive(
        &l.cfg,
        &l.sys,
        records,
        |_| {},
        |o| match o {
            Output::Forecast(h, v) => run.forecasts.push((h, v)),
            Output::Status(s) => run.statuses.push(s),
        },
    )
    .unwrap();
    run
}

/// Forecasts issued after `after_s` (seconds after the log's start).
fn after(run: &Run, t0: f64, after_s: f64) -> Vec<&ForecastHeader> {
    run.forecasts
        .iter()
        .map(|(h, _)| h)
        .filter(|h| h.issue_time_s - t0 > after_s)
        .collect()
}

/// A horizon is a step's lead, steps * dt: what the product may round beyond the forecast's length, s.
const HORIZON_ROUNDING_S: f64 = 1e-9;

/// The invariants every output keeps, whatever the input: finite values and horizons, a horizon
/// no longer than the forecast, ages never negative.
fn invariants(run: &Run) {
    for (h, v) in &run.forecasts {
        assert!(v.iter().all(|x| x.is_finite()), "a non-finite forecast value");
        let len = h.steps as f64 * h.dt_s;
        for hz in &h.horizon_s[..h.n_vessels as usize] {
            assert!(hz.is_finite() && *hz >= 0.0, "horizon {hz}");
            assert!(
                *hz <= len + HORIZON_ROUNDING_S,
                "horizon {hz} s beyond the forecast's {len} s"
            );
        }
        for i in 0..h.n_series as usize {
            let (from, to) = h.series_span(i);
            assert!(
                from.is_finite() && to.is_finite() && from >= 0.0 && (to == 0.0 || from <= to),
                "series {i}'s span {from} to {to} s"
            );
            assert!(
                to <= len + HORIZON_ROUNDING_S,
                "series {i}'s span ends at {to} s, beyond the forecast's {len} s"
            );
        }
    }
    for s in &run.statuses {
        assert!(
            s.wave_age_s == -1.0 || (s.wave_age_s.is_finite() && s.wave_age_s >= 0.0),
            "wave age {}",
            s.wave_age_s
        );
        assert!(s.horizon_s.iter().all(|h| h.is_finite()), "{:?}", s.horizon_s);
    }
}

#[test]
#[should_panic(expected = "series 2's span ends at 10.5 s")]
fn the_invariants_fail_on_a_series_span_longer_than_the_forecast() {
    let mut h = ForecastHeader {
        n_vessels: 1,
        n_series: 6,
        steps: 100,
        dt_s: 0.1,
        ..ForecastHeader::default()
    };
    h.set_series_span(2, 0.0, 10.5);
    invariants(&Run {
        forecasts: vec![(h, vec![0.0; 12])],
        statuses: vec![],
    });
}

#[test]
#[should_panic(expected = "beyond the forecast")]
fn the_invariants_fail_on_a_horizon_longer_than_the_forecast() {
    let h = ForecastHeader {
        n_vessels: 1,
        steps: 100,
        dt_s: 0.1,
        horizon_s: [10.5, 0.0, 0.0, 0.0],
        ..ForecastHeader::default()
    };
    invariants(&Run {
        forecasts: vec![(h, vec![0.0; 12])],
        statuses: vec![],
    });
}

fn baseline() -> &'static Run {
    static RUN: OnceLock<Run> = OnceLock::new();
    RUN.get_or_init(|| drive(&log().records))
}

/// The faulted run issues as many forecasts after the fault as the unfaulted one (two fewer at most).
fn forecasts_go_on(records: &[(f64, Record)], run: &Run, fault: &str) {
    let t0 = start(records);
    let (base, got) = (
        after(baseline(), t0, FAULT_AT_S).len(),
        after(run, t0, FAULT_AT_S).len(),
    );
    assert!(
        got + 2 >= base,
        "{got} forecasts after {fault} against {base} without it"
    );
}

/// The index of the first record of `kind` at or after `at_s` seconds into the log.
fn first_after(records: &[(f64, Record)], at_s: f64, waves: bool) -> usize {
    let t0 = start(records);
    records
        .iter()
        .position(|(t, r)| {
            *t - t0 >= at_s
                && matches!(r, Record::Waves(_)) == waves
                && matches!(r, Record::Waves(_) | Record::Motion(_))
        })
        .unwrap()
}

#[test]
fn the_unfaulted_log_forecasts_with_finite_trusted_horizons() {
    let run = baseline();
    invariants(run);
    let t0 = start(&log().records);
    let late = after(run, t0, FAULT_AT_S);
    assert!(late.len() > 50, "{} forecasts", late.len());
    assert!(
        late.iter()
            .all(|h| h.horizon_s[0] > 10.0 && h.flags & flags::HISTORY_SHORT == 0)
    );
}

/// The log with one edit at the first motion sample (or wave field) after the fault time, driven.
fn one_fault(waves: bool, edit: impl FnOnce(&mut Record)) -> (Vec<(f64, Record)>, Run) {
    let mut records = log().records.clone();
    let i = first_after(&records, FAULT_AT_S, waves);
    edit(&mut records[i].1);
    let run = drive(&records);
    invariants(&run);
    (records, run)
}

/// Was: one wave field stamped an hour ahead made every later forecast trusted for its whole length,
/// and every genuine field after it was ignored as older.
#[test]
fn one_wave_field_stamped_an_hour_ahead_is_refused() {
    let (records, run) = one_fault(true, |r| {
        if let Record::Waves(w) = r {
            w.time_s += 3600.0;
        }
    });
    let late = after(&run, start(&records), FAULT_AT_S + 10.0);
    assert!(late.len() > 50);
    for h in &late {
        assert!(h.wave_time_s < h.issue_time_s + 1.0, "a forecast used the future field");
        assert!(h.horizon_s[0] < h.steps as f64 * h.dt_s, "trusted for its whole length");
    }
    assert_eq!(run.statuses.last().unwrap().dropped_future, 1);
}

/// Was: one IMU sample stamped an hour ahead dropped every later genuine sample as late: that vessel
/// never forecast again until restart.
#[test]
fn one_motion_sample_stamped_an_hour_ahead_is_refused_and_forecasts_go_on() {
    let (records, run) = one_fault(false, |r| {
        if let Record::Motion(m) = r {
            m.time_s += 3600.0;
        }
    });
    forecasts_go_on(&records, &run, "the fault");
    assert_eq!(run.statuses.last().unwrap().dropped_future, 1);
}

/// Was: a wave field stamped +inf stopped forecasting until restart, with `wave_age_s = -inf`.
#[test]
fn a_wave_field_stamped_infinite_is_refused() {
    let (records, run) = one_fault(true, |r| {
        if let Record::Waves(w) = r {
            w.time_s = f64::INFINITY;
        }
    });
    assert!(after(&run, start(&records), FAULT_AT_S + 10.0).len() > 50);
}

/// Was: a field with radius 0 ("unknown region") or no components was published with an infinite
/// trusted horizon over a wave-free forecast.
#[test]
fn a_field_that_says_nothing_of_where_it_was_observed_is_not_trusted() {
    for (flag, edit) in [
        (
            flags::WAVE_REGION_UNKNOWN,
            (|w: &mut replay::WavesRecord| w.radius_m = 0.0) as fn(&mut replay::WavesRecord),
        ),
        (flags::NO_WAVE_COMPONENTS, |w: &mut replay::WavesRecord| {
            w.components.clear()
        }),
    ] {
        let mut records = log().records.clone();
        for (_, r) in records.iter_mut() {
            if let Record::Waves(w) = r {
                edit(w);
            }
        }
        let run = drive(&records);
        invariants(&run);
        let t0 = start(&records);
        let late = after(&run, t0, FAULT_AT_S);
        assert!(!late.is_empty());
        for h in late {
            assert!(h.flags & flag != 0, "flags {:?}", flags::names(h.flags));
            assert_eq!(h.horizon_s[0], 0.0);
        }
    }
}

/// Was: a step of an IMU's clock (GNSS/NTP) left that vessel without forecasts until restart. Now the
/// source re-synchronizes after `clock_resync_samples` consistent samples; while the motion's clock and
/// the radar's disagree nothing is forecast; when the host's clock stepped for both, forecasts resume
/// at once, with the motion history restarting (flagged short).
#[test]
fn a_step_of_the_clocks_is_recovered_from_and_a_disagreement_never_forecast() {
    const STEP_S: f64 = -3600.0;
    let cfg = &log().cfg;
    // forecasts resume this soon after a step of every clock, s: the radar's resync samples, one per
    // scan, then a tick
    let resume_s = cfg.forecast.clock_resync_samples as f64 * cfg.simulate.radar.period_s + cfg.forecast.period_s;
    for both in [false, true] {
        let mut records = log().records.clone();
        let t0 = start(&records);
        for (t, r) in records.iter_mut() {
            match r {
                Record::Motion(m) if *t - t0 >= FAULT_AT_S => m.time_s += STEP_S,
                Record::Waves(w) if both && *t - t0 >= FAULT_AT_S => w.time_s += STEP_S,
                _ => {}
            }
        }
        let run = drive(&records);
        invariants(&run);
        let last = run.statuses.last().unwrap();
        assert_eq!(last.clock_steps, if both { 2 } else { 1 }, "{last:?}");
        assert!(run.statuses.iter().any(|s| s.flags & flags::CLOCK_STEP != 0));
        // forecasts after the step are issued on the new clock
        let later: Vec<&ForecastHeader> = run
            .forecasts
            .iter()
            .map(|(h, _)| h)
            .filter(|h| h.issue_time_s < t0 + FAULT_AT_S + STEP_S / 2.0)
            .collect();
        if both {
            let first = later.first().expect("no forecast after the step");
            let resumed_s = first.issue_time_s - (t0 + FAULT_AT_S + STEP_S);
            eprintln!("forecasts resumed {resumed_s:.1} s after a step of every clock (bound {resume_s:.1} s)");
            assert!(resumed_s <= resume_s, "{resumed_s}");
            assert!(first.flags & flags::HISTORY_SHORT != 0);
            assert!(later.len() > 50);
        } else {
            assert!(later.is_empty(), "{} forecasts while the clocks disagree", later.len());
            assert!(
                last.flags & flags::CLOCKS_DISAGREE != 0,
                "{:?}",
                flags::names(last.flags)
            );
        }
    }
}

/// Was: samples with a vessel index out of range or an unknown schema version were dropped with no
/// counter, flag or log line.
#[test]
fn refused_samples_are_counted_in_the_status() {
    let (_, run) = one_fault(false, |r| {
        if let Record::Motion(m) = r {
            m.vessel = 7;
        }
    });
    assert_eq!(run.statuses.last().unwrap().dropped_rejected, 1);
}

/// The true displacement of vessel 0's DOF `dof` at stamp `t_s` (linear between the log's `/truth`
/// samples).
fn truth_at(records: &[(f64, Record)], t_s: f64, dof: usize) -> f64 {
    let truth: Vec<(f64, f64)> = records
        .iter()
        .filter_map(|(_, r)| match r {
            Record::Truth(m) if m.vessel == 0 => Some((m.time_s, m.x[dof])),
            _ => None,
        })
        .collect();
    let k = truth.partition_point(|(t, _)| *t <= t_s).clamp(1, truth.len() - 1);
    let ((ta, a), (tb, b)) = (truth[k - 1], truth[k]);
    a + (b - a) * (t_s - ta) / (tb - ta)
}

/// A forecast's first value of DOF `dof` of vessel 0.
fn initial(h: &ForecastHeader, v: &[f64], dof: usize) -> f64 {
    v[dof * (h.steps as usize + 1)]
}

/// A forecast's initial heave and pitch may differ from the true ones by this much (m, rad): five
/// times the IMU's noise (0.01 m and 0.0005 rad in `config/one-ship.toml`).
const INITIAL_STATE_TOL: [(usize, f64); 2] = [(2, 0.05), (4, 0.0025)];

/// Was: an IMU stall of 1.9 s around a forecast's start gave that vessel an initial state of exactly
/// zero (heave 0.000 m where it was 0.69 m), published with only `history_short`. A stalled sensor
/// either stops sending or sends zeros (an empty field read as 0); both are bridged now.
#[test]
fn an_imu_stall_is_bridged_and_the_initial_state_follows_the_motion() {
    const STALL_S: f64 = 1.9;
    for zeros in [true, false] {
        let mut records = log().records.clone();
        let t0 = start(&records);
        // the stall is centred on the largest pitch in the ten seconds after the fault time (the ship
        // heads into the waves: pitch is its largest motion)
        let centre_s = (0..100)
            .map(|k| t0 + FAULT_AT_S + 0.1 * k as f64)
            .max_by(|a, b| {
                truth_at(&records, *a, 4)
                    .abs()
                    .total_cmp(&truth_at(&records, *b, 4).abs())
            })
            .unwrap();
        let (a_s, b_s) = (centre_s - STALL_S / 2.0, centre_s + STALL_S / 2.0);
        let stalled = |r: &Record| matches!(r, Record::Motion(m) if m.time_s > a_s && m.time_s < b_s);
        if zeros {
            for (_, r) in records.iter_mut() {
                if stalled(r)
                    && let Record::Motion(m) = r
                {
                    m.x = [0.0; 6];
                    m.v = [0.0; 6];
                }
            }
        } else {
            records.retain(|(_, r)| !stalled(r));
        }
        let run = drive(&records);
        invariants(&run);
        let near: Vec<&(ForecastHeader, Vec<f64>)> = run
            .forecasts
            .iter()
            .filter(|(h, _)| (h.issue_time_s - centre_s).abs() < 10.0)
            .collect();
        assert!(near.len() > 10, "{} forecasts near the stall", near.len());
        for (h, v) in near {
            let what = if zeros { "zeros" } else { "no samples" };
            for (dof, tol) in INITIAL_STATE_TOL {
                let (got, truth) = (initial(h, v, dof), truth_at(&records, h.issue_time_s, dof));
                assert!(
                    (got - truth).abs() < tol,
                    "{what} for {STALL_S} s: forecast at {:.1} s: initial DOF {dof} {got:.4}, true {truth:.4} ({:?})",
                    h.issue_time_s - t0,
                    flags::names(h.flags)
                );
            }
            assert!(
                h.flags & flags::HISTORY_SHORT == 0,
                "{what} for {STALL_S} s: forecast at {:.1} s: the gap ended the history",
                h.issue_time_s - t0
            );
        }
    }
}

/// Was: one finite but absurd IMU sample (heave 1e6 m, 1e6 m/s) stopped forecasts for 2 minutes, then
/// 173 forecasts with values up to 9.8 km were published, flagged only `history_short` (the spike sat in
/// the radiation history for its whole memory).
#[test]
fn an_absurd_motion_sample_is_refused_and_never_enters_the_history() {
    let (records, run) = one_fault(false, |r| {
        if let Record::Motion(m) = r {
            m.x = [1e6; 6];
            m.v = [1e6; 6];
        }
    });
    forecasts_go_on(&records, &run, "the spike");
    let t0 = start(&records);
    // the forecasts after the spike are those without it: the spike is not in their state or history
    let largest = |run: &Run| {
        run.forecasts
            .iter()
            .filter(|(h, _)| h.issue_time_s - t0 > FAULT_AT_S)
            .flat_map(|(_, v)| v.iter())
            .fold(0.0f64, |m, x| m.max(x.abs()))
    };
    let (base_max, got_max) = (largest(baseline()), largest(&run));
    assert!(
        got_max <= 1.01 * base_max,
        "largest value {got_max} after the spike, {base_max} without it"
    );
    assert_eq!(run.statuses.last().unwrap().dropped_implausible, 1);
    assert!(run.statuses.iter().any(|s| s.flags & flags::MOTION_IMPLAUSIBLE != 0));
}

/// Was: one 1M-component wave field took 1.1-1.6 s per forecast and left 640 MB that was never
/// released.
#[test]
fn a_wave_field_of_a_million_components_is_refused_and_forecasts_go_on() {
    let (records, run) = one_fault(true, |r| {
        if let Record::Waves(w) = r {
            let one = w.components.clone();
            w.components = one.iter().cycle().take(1_000_000).copied().collect();
        }
    });
    assert_eq!(run.statuses.last().unwrap().dropped_rejected, 1);
    forecasts_go_on(&records, &run, "the field");
}

/// Was: a replay of a system with more than 4 bodies (more than the payloads carry) panicked.
#[test]
fn a_replay_of_more_vessels_than_the_payloads_carry_is_refused() {
    let l = log();
    let mut sys = l.sys.clone();
    let body = sys.spec.bodies[0].clone();
    sys.spec.bodies.extend(std::iter::repeat_n(body, 4));
    let err = replay::drive(&l.cfg, &sys, &l.records, |_| {}, |_| {}).unwrap_err();
    assert!(
        err.to_string().contains("5 vessels") && err.to_string().contains("at most 4"),
        "{err}"
    );
}

/// The share of the variance the added component holds: as much as all the others.
const HALF_THE_SEA: f64 = 0.5;
/// What the share may differ from that by: the field's own weakest components pruned
/// (`forecast.wave_variance_kept`) and any at the database's edges.
const SHARE_TOL: f64 = 0.05;

/// Was: wave components outside the database's frequencies were dropped with nothing in the flags.
#[test]
fn wave_variance_outside_the_database_is_flagged_and_beyond_the_share_not_trusted() {
    let mut records = log().records.clone();
    for (_, r) in records.iter_mut() {
        if let Record::Waves(w) = r {
            // a component above the database's 1.6 rad/s holding as much variance as all the others
            let var: f64 = w.components.iter().map(|c| 0.5 * (c[2] * c[2] + c[3] * c[3])).sum();
            let a = (2.0 * var).sqrt();
            w.components.push([2.0, 0.0, a, 0.0]);
        }
    }
    let run = drive(&records);
    invariants(&run);
    let t0 = start(&records);
    let late = after(&run, t0, FAULT_AT_S);
    assert!(!late.is_empty());
    for h in late {
        assert!(h.flags & flags::WAVES_DROPPED != 0);
        assert_eq!(h.horizon_s[0], 0.0, "half the sea left out, yet trusted");
    }
    let share = run.statuses.last().unwrap().dropped_wave_share;
    assert!((share - HALF_THE_SEA).abs() < SHARE_TOL, "{share}");
}

/// A wave processor that froze: from the fault on, every field repeats the first one after it, value
/// for value, stamped later. The repeats are refused and flagged (`waves_frozen`), and the forecasts
/// take the last field that differed, at its own age, until it is too old to forecast from. Fails
/// before the flag: every repeat was taken as a new field (`wave_time_s` advancing), never flagged,
/// and its forecasts trusted.
#[test]
fn a_frozen_wave_processor_is_flagged_and_its_repeats_refused() {
    let mut records = log().records.clone();
    let t0 = start(&records);
    let frozen_at = records
        .iter()
        .position(|(t, r)| matches!(r, Record::Waves(_)) && t - t0 > FAULT_AT_S)
        .expect("a wave field after the fault time");
    let Record::Waves(frozen) = records[frozen_at].1.clone() else {
        unreachable!()
    };
    for (_, r) in records[frozen_at + 1..].iter_mut() {
        if let Record::Waves(w) = r {
            *w = shipcast::shell::record::WavesRecord {
                time_s: w.time_s,
                ..frozen.clone()
            };
        }
    }
    let run = drive(&records);
    invariants(&run);
    // the refused repeats: every forecast after the freeze takes the frozen field at its own time
    let late: Vec<&ForecastHeader> = after(&run, t0, records[frozen_at].0 - t0 + FROZEN_NOTICED_S);
    assert!(!late.is_empty(), "forecasts after the freeze");
    for h in &late {
        assert!(h.flags & flags::WAVES_FROZEN != 0, "{:?}", flags::names(h.flags));
        assert_eq!(h.wave_time_s, frozen.time_s, "a repeat taken as a new field");
    }
    assert!(
        run.statuses.iter().any(|s| s.flags & flags::WAVES_FROZEN != 0),
        "the status says so"
    );
    // the field grows old: stale, then no forecast at all
    let last = run.statuses.last().unwrap();
    assert!(last.flags & flags::STALE_WAVES != 0, "{:?}", flags::names(last.flags));
}

/// A wave field with one component no sea has (1,000 m, 10 m: more than the highest seas; 5 m in a
/// sea of 2.5 m: a jump over the last fields no sea makes) is refused and flagged
/// (`waves_implausible`): no forecast takes it, they go on from the last field taken, and none moves
/// the hull more than the sea does. Fails before the check: the field was taken, and its forecasts
/// trusted with a heave of tens of metres.
#[test]
fn a_wave_field_that_is_not_a_sea_is_refused_and_flagged() {
    let base_heave = max_heave(baseline(), start(&log().records));
    for amplitude_m in [1000.0, 10.0, 5.0] {
        let mut records = log().records.clone();
        let t0 = start(&records);
        let at = records
            .iter()
            .position(|(t, r)| matches!(r, Record::Waves(_)) && t - t0 > FAULT_AT_S)
            .expect("a wave field after the fault time");
        let Record::Waves(w) = &mut records[at].1 else {
            unreachable!()
        };
        w.components.push([0.6, 0.0, amplitude_m, 0.0]);
        let bad_time_s = w.time_s;
        let run = drive(&records);
        invariants(&run);
        forecasts_go_on(&records, &run, "a field that is not a sea");
        assert!(
            run.statuses.iter().any(|s| s.flags & flags::WAVES_IMPLAUSIBLE != 0),
            "{amplitude_m} m: not flagged"
        );
        assert!(
            run.forecasts.iter().all(|(h, _)| h.wave_time_s != bad_time_s),
            "{amplitude_m} m: a forecast took the field"
        );
        let heave = max_heave(&run, t0);
        assert!(
            heave <= HEAVE_GROWTH * base_heave,
            "{amplitude_m} m: heave {heave} m against {base_heave} m"
        );
    }
}

/// The largest heave any forecast issued after the fault time carries, m (vessel 0).
fn max_heave(run: &Run, t0: f64) -> f64 {
    run.forecasts
        .iter()
        .filter(|(h, _)| h.issue_time_s - t0 > FAULT_AT_S)
        .flat_map(|(h, v)| {
            let per = h.steps as usize + 1;
            v[2 * per..3 * per].iter().map(|x| x.abs())
        })
        .fold(0.0, f64::max)
}

/// How far past the clean run's largest forecast heave a run's may go, as a factor: forecasts from
/// other fields of the same sea differ, but not by a sea's worth.
const HEAVE_GROWTH: f64 = 1.5;

/// The freeze is seen at the first repeat, one radar period after the frozen field, s (a margin of a
/// second for the tick).
const FROZEN_NOTICED_S: f64 = 6.0;

/// A fault put into one record of the log.
#[derive(Debug, Clone, Copy)]
enum Fault {
    NanValue,
    NanStamp,
    InfStamp,
    /// The stamp moved by this many seconds (ahead or behind).
    Stamp(f64),
    /// A finite but absurd displacement and velocity (m, m/s).
    Spike(f64),
    /// The sensor stalled: this and the next records of the vessel repeat zeros.
    Zeros,
    /// This and the next 29 motion records lost (3 s at 10 Hz).
    Gap,
    /// The record sent twice.
    Duplicate,
    /// The record swapped with the next one (out of order).
    Swap,
    /// The wave field emptied, or its region forgotten.
    EmptyField,
    UnknownRegion,
}

fn apply(records: &mut Vec<(f64, Record)>, at: usize, fault: Fault) {
    let at = at.min(records.len() - 2);
    match (&mut records[at].1, fault) {
        (Record::Motion(m), Fault::NanValue) => m.x[2] = f64::NAN,
        (Record::Motion(m), Fault::NanStamp) => m.time_s = f64::NAN,
        (Record::Motion(m), Fault::InfStamp) => m.time_s = f64::INFINITY,
        (Record::Motion(m), Fault::Stamp(d)) => m.time_s += d,
        (Record::Motion(m), Fault::Spike(v)) => {
            m.x = [v; 6];
            m.v = [v; 6];
        }
        (Record::Motion(_), Fault::Zeros) => {
            for (_, r) in records[at..].iter_mut().take(20) {
                if let Record::Motion(m) = r {
                    m.x = [0.0; 6];
                    m.v = [0.0; 6];
                }
            }
        }
        (Record::Motion(_), Fault::Gap) => {
            let end = (at + 30).min(records.len() - 2);
            let kept: Vec<(f64, Record)> = records
                .drain(at..end)
                .filter(|(_, r)| !matches!(r, Record::Motion(_)))
                .collect();
            records.splice(at..at, kept);
        }
        (Record::Waves(w), Fault::NanValue) => w.components.iter_mut().for_each(|c| c[2] = f64::NAN),
        (Record::Waves(w), Fault::NanStamp) => w.time_s = f64::NAN,
        (Record::Waves(w), Fault::InfStamp) => w.time_s = f64::INFINITY,
        (Record::Waves(w), Fault::Stamp(d)) => w.time_s += d,
        (Record::Waves(w), Fault::EmptyField) => w.components.clear(),
        (Record::Waves(w), Fault::UnknownRegion) => w.radius_m = 0.0,
        (_, Fault::Duplicate) => {
            let r = records[at].clone();
            records.insert(at, r);
        }
        (_, Fault::Swap) => records.swap(at, at + 1),
        _ => {}
    }
}

fn fault() -> impl proptest::strategy::Strategy<Value = Fault> {
    use proptest::prelude::*;
    prop_oneof![
        Just(Fault::NanValue),
        Just(Fault::NanStamp),
        Just(Fault::InfStamp),
        prop_oneof![-1e9..-1.0f64, 1.0..1e9f64].prop_map(Fault::Stamp),
        prop_oneof![Just(1e6), Just(-1e6), Just(1e300)].prop_map(Fault::Spike),
        Just(Fault::Zeros),
        Just(Fault::Gap),
        Just(Fault::Duplicate),
        Just(Fault::Swap),
        Just(Fault::EmptyField),
        Just(Fault::UnknownRegion),
    ]
}

/// Forecasts are back this long after the last fault, s: the 60 s radiation memory (a step of a
/// clock restarts the history) and ten periods.
const RECOVERY_S: f64 = 70.0;

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(12))]
    /// Any mix of faults in the first half of the log: every output keeps the invariants (finite
    /// values and horizons, ages never negative, no horizon from a field that says nothing), and once
    /// the inputs are good again forecasts come back within RECOVERY_S.
    #[test]
    fn random_faults_never_break_the_invariants_and_forecasts_recover(
        faults in proptest::collection::vec((0.0..0.5f64, fault()), 1..25)
    ) {
        let mut records = log().records.clone();
        let n = records.len();
        for (at, f) in &faults {
            apply(&mut records, (at * n as f64) as usize, *f);
        }
        let run = drive(&records);
        invariants(&run);
        let t0 = start(&log().records);
        let last_fault_s = LOG_S * 0.5;
        let back = after(&run, t0, last_fault_s + RECOVERY_S);
        proptest::prop_assert!(!back.is_empty(), "no forecast after {} s: {faults:?}", last_fault_s + RECOVERY_S);
        for h in back {
            proptest::prop_assert!(h.horizon_s[0] > 0.0, "{:?}", flags::names(h.flags));
        }
    }
}

/// Was: while every vessel's motion was stale (a stalled stream) the status said `no_waves` and
/// `stale_waves` with a wave age of 1.6 s: the waves' age was judged against no motion at all (an
/// infinite start time). Now it is judged against the newest motion there is.
#[test]
fn a_motion_stall_does_not_call_fresh_waves_stale() {
    let l = log();
    let t0 = start(&l.records);
    let stall = (t0 + FAULT_AT_S, t0 + FAULT_AT_S + 10.0);
    let records: Vec<(f64, Record)> = l
        .records
        .iter()
        .filter(|(t, r)| !(matches!(r, Record::Motion(_)) && *t > stall.0 && *t < stall.1))
        .cloned()
        .collect();
    let run = drive(&records);
    let stalled: Vec<&Status> = run
        .statuses
        .iter()
        .filter(|s| s.flags & flags::STALE_MOTION != 0 && s.time_s > stall.0 - 1.0)
        .collect();
    assert!(stalled.len() >= 3, "the stall is seen: {}", stalled.len());
    for s in stalled {
        if (0.0..5.0).contains(&s.wave_age_s) {
            assert_eq!(
                s.flags & (flags::NO_WAVES | flags::STALE_WAVES),
                0,
                "{:?} with waves {:.1} s old",
                flags::names(s.flags),
                s.wave_age_s
            );
        }
    }
}

/// A trusted forecast's initial heave may be this far from the truth, m: ten times the IMU's noise
/// (0.01 m), far below the faults below (2 m, 50 m).
const TRUSTED_START_TOL_M: f64 = 0.1;

/// Forecasts of `run` issued after `from_s` (s after the log's start) that trust vessel 0 while its
/// initial heave is more than [`TRUSTED_START_TOL_M`] from the truth, described.
fn trusted_off_the_truth(run: &Run, records: &[(f64, Record)], from_s: f64) -> Vec<String> {
    let t0 = start(records);
    run.forecasts
        .iter()
        .filter(|(h, _)| h.issue_time_s - t0 > from_s && h.horizon_s[0] > 0.0)
        .filter_map(|(h, v)| {
            let (got, truth) = (initial(h, v, 2), truth_at(records, h.motion_time_s, 2));
            ((got - truth).abs() > TRUSTED_START_TOL_M).then(|| {
                format!(
                    "at {:.1} s: heave {got:.3} m (true {truth:.3} m), trusted to {:.1} s, {:?}",
                    h.issue_time_s - t0,
                    h.horizon_s[0],
                    flags::names(h.flags)
                )
            })
        })
        .collect()
}

/// The band (standard deviation) of vessel 0's heave at `lead_s` in a forecast, m.
fn heave_sigma_at(h: &ForecastHeader, v: &[f64], lead_s: f64) -> f64 {
    let per = h.steps as usize + 1;
    let n = per * h.n_series as usize;
    v[n + 2 * per + (lead_s / h.dt_s).round() as usize]
}

/// The largest ratio of the heave band at 30 s in `run`'s forecasts issued after `from_s` to the
/// clean run's issued at the same time: what the faults taught the model error (forecasts from an
/// estimate still settling after a restart hold the jump in their band, and are left out).
fn heave_band_growth(run: &Run, t0: f64, from_s: f64) -> f64 {
    let base: std::collections::HashMap<i64, f64> = baseline()
        .forecasts
        .iter()
        .map(|(h, v)| ((h.issue_time_s * 1e3).round() as i64, heave_sigma_at(h, v, 30.0)))
        .collect();
    run.forecasts
        .iter()
        .filter(|(h, _)| h.issue_time_s - t0 > from_s && h.flags & flags::MOTION_SETTLING == 0)
        .filter_map(|(h, v)| {
            let b = base.get(&((h.issue_time_s * 1e3).round() as i64))?;
            Some(heave_sigma_at(h, v, 30.0) / b)
        })
        .fold(0.0, f64::max)
}

/// How far the band at 30 s may grow over the clean run's after a fault the daemon refused: the
/// checks it missed while refusing and their noise, not the fault's size.
const BAND_GROWTH_AFTER_FAULT: f64 = 1.25;

/// `records` (a motion fault from [`FAULT_AT_S`]) driven: forecasts go on, none trusted with a start
/// off the truth, and the band learnt no more than [`BAND_GROWTH_AFTER_FAULT`] of the fault.
fn never_trusted_off_nor_learnt(records: &[(f64, Record)], fault: &str) -> Run {
    let run = drive(records);
    invariants(&run);
    forecasts_go_on(records, &run, fault);
    let wrong = trusted_off_the_truth(&run, records, FAULT_AT_S - 1.0);
    assert!(wrong.is_empty(), "{fault}: {}", wrong.join("\n"));
    let growth = heave_band_growth(&run, start(records), FAULT_AT_S);
    assert!(
        growth < BAND_GROWTH_AFTER_FAULT,
        "{fault}: the heave band at 30 s grew {growth:.2} times"
    );
    run
}

/// Was: five +50 m heave spikes in 0.5 s, the fifth just before a forecast, restarted the estimate
/// from them: that forecast was published starting at 50 m with only `history_short`, the next good
/// samples restarted it again, and the model error learnt from both (the band at 30 s grew many
/// times for the rest of the run). A burst that the motion then leaves is taken back; while an
/// estimate is restarted its vessel is trusted nowhere and nothing is learnt from it.
#[test]
fn a_burst_of_spikes_is_never_published_trusted_nor_learnt_from() {
    const SPIKES: usize = 5;
    const SPIKE_M: f64 = 50.0;
    let t0 = start(&log().records);
    let (h, _) = baseline()
        .forecasts
        .iter()
        .find(|(h, _)| h.issue_time_s - t0 > FAULT_AT_S)
        .expect("a forecast after the fault time");
    let mut records = log().records.clone();
    let burst: Vec<usize> = records
        .iter()
        .enumerate()
        .filter(|(_, (_, r))| matches!(r, Record::Motion(m) if m.vessel == 0 && m.time_s <= h.motion_time_s))
        .map(|(i, _)| i)
        .collect();
    for &i in &burst[burst.len() - SPIKES..] {
        if let Record::Motion(m) = &mut records[i].1 {
            m.x[2] += SPIKE_M;
        }
    }
    let run = never_trusted_off_nor_learnt(&records, "the burst");
    // the burst is gone as soon as the motion leaves it: forecasts are trusted again within seconds
    let back = after(&run, t0, FAULT_AT_S + 10.0);
    assert!(
        back.iter().all(|h| h.horizon_s[0] > 0.0),
        "not trusted again after the burst"
    );
}

/// Was: a heave sensor re-zeroed by +2 m restarted the estimate and its forecasts were trusted at
/// once, starting 2 m off with the band of the sensor's drift (0.06 m), until the new offset had
/// been averaged. Now a restarted estimate is trusted nowhere until its offset is known again, and
/// then its forecasts start from the motion.
#[test]
fn a_sensor_re_zeroed_is_not_trusted_until_its_new_offset_is_known() {
    const OFFSET_M: f64 = 2.0;
    let mut records = log().records.clone();
    let t0 = start(&records);
    for (_, r) in records.iter_mut() {
        if let Record::Motion(m) = r
            && m.vessel == 0
            && m.time_s - t0 > FAULT_AT_S
        {
            m.x[2] += OFFSET_M;
        }
    }
    let run = never_trusted_off_nor_learnt(&records, "the offset");
    assert!(
        run.statuses.iter().any(|s| s.flags & flags::MOTION_SETTLING != 0),
        "the status says the estimate is settling"
    );
}

/// How long the motion is away in [`a_motion_outage_keeps_the_history_before_it`], s: longer than
/// `forecast.max_gap_s` (the other ship's link down, a sensor restarted).
const OUTAGE_S: f64 = 10.0;

/// Was: motion back after an outage longer than `forecast.max_gap_s` restarted the history there, and
/// every forecast said `history_short` until the radiation memory had refilled (60 s here, 600 s for
/// the moored pair). Now the history before the outage is kept, the outage itself at rest
/// (`history_gap` while it is inside the memory), and the forecasts start as before.
#[test]
fn a_motion_outage_keeps_the_history_before_it() {
    let l = log();
    let t0 = start(&l.records);
    let gone = (t0 + FAULT_AT_S, t0 + FAULT_AT_S + OUTAGE_S);
    let records: Vec<(f64, Record)> = l
        .records
        .iter()
        .filter(|(t, r)| !(matches!(r, Record::Motion(_)) && *t > gone.0 && *t < gone.1))
        .cloned()
        .collect();
    let run = drive(&records);
    invariants(&run);
    let back: Vec<&(ForecastHeader, Vec<f64>)> = run
        .forecasts
        .iter()
        .filter(|(h, _)| {
            h.issue_time_s > gone.1 + 1.0 && h.issue_time_s < gone.0 + l.cfg.forecast.memory_s.unwrap_or(60.0)
        })
        .collect();
    assert!(back.len() > 20, "{} forecasts after the outage", back.len());
    for (h, v) in &back {
        assert_eq!(
            h.flags & flags::HISTORY_SHORT,
            0,
            "at {:.1} s: {:?}",
            h.issue_time_s - t0,
            flags::names(h.flags)
        );
        assert!(h.flags & flags::HISTORY_GAP != 0, "{:?}", flags::names(h.flags));
        for (dof, tol) in INITIAL_STATE_TOL {
            let (got, truth) = (initial(h, v, dof), truth_at(&records, h.motion_time_s, dof));
            assert!(
                (got - truth).abs() < tol,
                "DOF {dof} at {:.1} s: {got} against {truth}",
                h.issue_time_s - t0
            );
        }
    }
}
