//! Reach: how far ahead each channel is trusted in the realistic sea (`config/one-ship.toml` as
//! shipped: a truth that is not the forecaster's model, the radar's blind zone and shadowing, the
//! IMU's drift), through the daemon's own engine (`replay::drive`). The radar's window of scans fills
//! its blind zone with what earlier scans saw (`waves::window`), so heave is trusted from lead 0 far
//! ahead; where the waves come from a sector the radar never sees, no channel that moves is trusted
//! past what the measured state carries.

use crate::util::{SimLog, median, simulated_with};
use shipcast::shell::ipc::Output;
use shipcast::shell::ipc::wire::ForecastHeader;
use shipcast::shell::replay;

/// Simulated seconds per log: the 60 s memory, then model-error checks out to the longest leads.
const LOG_S: f64 = 300.0;
/// Forecasts from this long after the start are judged, s: their model error checked to 120 s.
const JUDGED_AFTER_S: f64 = 200.0;
/// The median heave span end with the whole disc seen at least this, s: the radar's reach (1 km at
/// the sea's group speeds, 7-8 m/s, is two minutes; a third of it is a forecast that remembers its
/// scans, against the 2-5 s of one that forgets them).
const MIN_SEEN_HEAVE_SPAN_S: f64 = 40.0;
/// The longest any series is trusted when the up-wave side is masked, s: what the measured state
/// carries (the response to the waves before the start rings on for its group delay, a few seconds
/// for the heave and pitch of a 180 m ship); a longer span would trust waves nobody saw.
const MAX_UNSEEN_SPAN_S: f64 = 10.0;

fn spans(log: &SimLog) -> Vec<ForecastHeader> {
    let mut out = vec![];
    let t0 = log.records[0].0;
    replay::drive(
        &log.cfg,
        &log.sys,
        &log.records,
        |_| {},
        |o| {
            if let Output::Forecast(h, _) = o
                && h.issue_time_s - t0 > JUDGED_AFTER_S
            {
                out.push(h);
            }
        },
    )
    .unwrap();
    out
}

#[test]
fn heave_is_trusted_from_the_start_far_ahead_and_never_where_the_waves_were_not_seen() {
    let seen = spans(&simulated_with(
        "reach-seen",
        "one-ship.toml",
        "vessels/ship/system.toml",
        LOG_S,
        &[],
    ));
    let masked = spans(&simulated_with(
        "reach-masked",
        "one-ship.toml",
        "vessels/ship/system.toml",
        LOG_S,
        // head seas: the waves come from the bow
        &[(
            "[simulate.radar]\n",
            "[simulate.radar]\nmasked_sector_deg = [-60.0, 60.0]\n",
        )],
    ));
    assert!(
        seen.len() > 50 && masked.len() > 50,
        "{} / {}",
        seen.len(),
        masked.len()
    );
    // heave (series 2) with the whole disc seen: from lead 0, far ahead
    let to = median(seen.iter().map(|h| h.series_span(2).1).collect());
    let from = median(seen.iter().map(|h| h.series_span(2).0).collect());
    eprintln!("whole disc: heave trusted {from:.1}-{to:.1} s (median)");
    assert!(from == 0.0 && to >= MIN_SEEN_HEAVE_SPAN_S, "{from}-{to} s");
    // the up-wave side masked: no series that moves (surge, heave and pitch in head seas) trusted
    // past what the state carries in any forecast; roll, sway and yaw, which head seas barely move,
    // are trusted where their expected error is below what a motion sensor resolves
    // (`band::SIGNIFICANT_DOF`), as they are with the whole disc seen
    for (i, name) in [(0, "surge"), (2, "heave"), (4, "pitch")] {
        let longest = masked.iter().map(|h| h.series_span(i).1).fold(0.0, f64::max);
        eprintln!("up-wave side masked: {name}'s longest span {longest:.1} s");
        assert!(longest <= MAX_UNSEEN_SPAN_S, "{name}: {longest} s");
    }
}
