//! The daemon's learnt state kept across a restart (issue 53, item 2), through the engine as the
//! daemon runs it (`replay::drive_from`): the shipped two-ship demo's sea, the daemon killed after 11
//! minutes (its 600 s motion memory full, the model error learnt) and back 6 s later (its start: the
//! model built, the ports opened), from the state it kept then or cold; and states refused (the demo's
//! 7-minute log, `two_ship_demo::sea_log`).

use crate::two_ship_demo::sea_log;
use crate::util::{SimLog, simulated_with};
use shipcast::shell::ipc::Output;
use shipcast::shell::ipc::wire::{ForecastHeader, Status, flags};
use shipcast::shell::replay::{self, Record};
use std::sync::OnceLock;
use std::time::Instant;

/// When the daemon is killed, s after the log's start, and how long it is away, s.
const KILLED_AT_S: f64 = 660.0;
const AWAY_S: f64 = 6.0;
/// How long the log runs on after the daemon is back, s: the span's minute and some.
const BACK_FOR_S: f64 = 84.0;

/// The demo in its shipped sea, long enough to kill the daemon after 11 minutes.
fn long_log() -> &'static SimLog {
    static LOG: OnceLock<SimLog> = OnceLock::new();
    LOG.get_or_init(|| {
        simulated_with(
            "warm-start-sea",
            "shipcast.toml",
            "vessels/pair/moored.toml",
            KILLED_AT_S + AWAY_S + BACK_FOR_S,
            &[],
        )
    })
}
/// A warm start trusts a forecast this soon after it is back, s (the Show's bound).
const TRUSTED_WITHIN_S: f64 = 15.0;
/// Over the first minute back, the warm start's median heave span is at least this share of its median
/// over the minute before the kill (the history's 6 s gap aside, the same state; the sea the same).
const SPAN_SHARE: f64 = 0.8;

struct Run {
    forecasts: Vec<ForecastHeader>,
    statuses: Vec<Status>,
}

fn run(
    records: &[(f64, Record)],
    state: Option<shipcast::engine::state::EngineState>,
) -> (Run, shipcast::engine::state::EngineState) {
    let l = long_log();
    let mut r = Run {
        forecasts: vec![],
        statuses: vec![],
    };
    let (_, kept) = replay::drive_from(
        &l.cfg,
        &l.sys,
        records,
        state,
        |_| {},
        |o| match o {
            Output::Forecast(h, _) => r.forecasts.push(h),
            Output::Status(s) => r.statuses.push(s),
        },
    )
    .unwrap();
    (r, kept)
}

/// The first forecast that trusts the carrier, s after `from_s` (None: none).
fn first_trusted(r: &Run, from_s: f64) -> Option<f64> {
    r.forecasts
        .iter()
        .find(|h| h.horizon_s[0] > 0.0)
        .map(|h| h.issue_time_s - from_s)
}

/// The median end of the carrier's heave span over forecasts issued in `[a, b)`, s.
fn median_heave_span(r: &Run, a: f64, b: f64) -> f64 {
    let mut s: Vec<f64> = r
        .forecasts
        .iter()
        .filter(|h| (a..b).contains(&h.issue_time_s))
        .map(|h| h.series_span(2).1)
        .collect();
    s.sort_by(f64::total_cmp);
    s.get(s.len() / 2).copied().unwrap_or(0.0)
}

#[test]
fn a_restarted_daemon_trusts_again_within_seconds_from_the_state_it_kept() {
    let l = long_log();
    let start = l.records[0].0;
    let (killed, back) = (start + KILLED_AT_S, start + KILLED_AT_S + AWAY_S);
    let before: Vec<(f64, Record)> = l.records.iter().filter(|(t, _)| *t < killed).cloned().collect();
    let after: Vec<(f64, Record)> = l.records.iter().filter(|(t, _)| *t >= back).cloned().collect();
    let (first, kept) = run(&before, None);
    // through the state file as the daemon writes it (a full memory's samples) and reads it back
    let file = crate::util::scratch_dir("warm-start-file").join(shipcast::shell::state::FILE_NAME);
    let written = Instant::now();
    shipcast::shell::state::write(&file, &kept).unwrap();
    let write_s = written.elapsed().as_secs_f64();
    let bytes = std::fs::metadata(&file).unwrap().len();
    let kept = shipcast::shell::state::read(&file).unwrap().expect("the state written");
    eprintln!("the state kept after {KILLED_AT_S} s: {bytes} bytes, written in {write_s:.3} s");
    let (warm, _) = run(&after, Some(kept));
    let (cold, _) = run(&after, None);
    let (w, c) = (first_trusted(&warm, back), first_trusted(&cold, back));
    let spans = [
        median_heave_span(&first, killed - 60.0, killed),
        median_heave_span(&warm, back, back + 60.0),
        median_heave_span(&cold, back, back + 60.0),
    ];
    eprintln!(
        "back {AWAY_S} s after a kill at {KILLED_AT_S} s: the carrier trusted {w:?} s later from the kept state, {c:?} s cold; median heave span over the minute before the kill {:.1} s, over the first minute back warm {:.1} s, cold {:.1} s",
        spans[0], spans[1], spans[2]
    );
    assert!(w.is_some_and(|w| w <= TRUSTED_WITHIN_S), "warm: {w:?}");
    assert!(
        c.is_none_or(|c| c > TRUSTED_WITHIN_S),
        "a cold start trusts as soon ({c:?}): the test shows nothing"
    );
    assert!(spans[1] >= SPAN_SHARE * spans[0], "{spans:?}");
    for s in &warm.statuses {
        assert_eq!(s.flags & flags::CLOCK_STEP, 0, "a clock step raised by the restart");
        assert_eq!(
            s.dropped_future + s.dropped_past,
            0,
            "samples refused by the restored clocks"
        );
    }
}

#[test]
fn a_kept_state_that_is_stale_foreign_or_corrupt_is_refused() {
    let l = sea_log();
    let start = l.records[0].0;
    let first: Vec<(f64, Record)> = l.records.iter().filter(|(t, _)| *t < start + 120.0).cloned().collect();
    let (_, kept) = run(&first, None);
    // stale: back after more than the radiation memory
    let memory_s = shipcast::engine::Engine::new(
        &l.cfg,
        &l.sys,
        &shipcast::rom::TimeModel::new(&l.sys, shipcast::engine::rom_options(&l.cfg, &l.sys)).unwrap(),
    )
    .memory_s();
    let late: Vec<(f64, Record)> = l
        .records
        .iter()
        .filter(|(t, _)| *t >= start + 120.0)
        .map(|(t, r)| (t + memory_s, r.clone()))
        .collect();
    let err = replay::drive_from(&l.cfg, &l.sys, &late[..10], Some(kept.clone()), |_| {}, |_| {}).unwrap_err();
    assert!(err.to_string().contains("older than"), "{err}");
    // foreign: kept for another system
    let mut foreign = kept.clone();
    foreign.fingerprint = "another system".into();
    let err = replay::drive_from(&l.cfg, &l.sys, &first[..10], Some(foreign), |_| {}, |_| {}).unwrap_err();
    assert!(err.to_string().contains("another system"), "{err}");
    // corrupt: the file cut short, or not a state at all; each named
    let dir = crate::util::scratch_dir("warm-start-refused");
    let path = dir.join(shipcast::shell::state::FILE_NAME);
    shipcast::shell::state::write(&path, &kept).unwrap();
    assert!(shipcast::shell::state::read(&path).unwrap().is_some());
    let bytes = std::fs::read(&path).unwrap();
    std::fs::write(&path, &bytes[..bytes.len() / 2]).unwrap();
    let err = shipcast::shell::state::read(&path).unwrap_err();
    assert!(
        err.contains("corrupt") && err.contains(&path.display().to_string()),
        "{err}"
    );
    std::fs::write(&path, b"{\"not\": \"a state\"}").unwrap();
    let err = shipcast::shell::state::read(&path).unwrap_err();
    assert!(err.contains("not a shipcast state"), "{err}");
}
