//! Replay (shell): a recorded log ([`crate::shell::record`]) fed through the daemon's own engine on the log's
//! clock ([`drive`]), and external CSV recordings turned into records ([`import`]).
//!
//! The log's records and reader are [`crate::shell::record`]'s; the ones replay's callers use with [`drive`] are
//! re-exported here.

pub use crate::shell::record::{
    Error, ForecastRecord, MotionRecord, NavigationRecord, Read, Record, WavesRecord, read,
};

pub mod import;

/// Feeds a log's inputs through the daemon's engine and computer on the log's clock, forecasts computed
/// inline (no overruns: replay is not real time). A log recorded by the daemon carries its ticks
/// (`/tick`, log time = the engine's clock): replay ticks exactly there and so takes every decision the
/// live daemon took; a log without ticks (the simulator's) is ticked every `period_s` of log time.
/// `on_output` sees every forecast and every tick's status; `pace` is called with each tick's log time
/// (the shell sleeps there for `--speed`, and publishes the inputs up to it).
pub fn drive(
    cfg: &crate::shell::config::ShipcastConfig,
    sys: &crate::hydro::VesselSystem,
    records: &[(f64, Record)],
    pace: impl FnMut(f64),
    on_output: impl FnMut(crate::shell::ipc::Output),
) -> Result<crate::engine::Counters, Error> {
    drive_from(cfg, sys, records, None, pace, on_output).map(|(c, _)| c)
}

/// [`drive`] from a kept learnt state (as the daemon takes it at start, at the first record's time;
/// refused: an error), returning the state at the end too (at the last record's time).
pub fn drive_from(
    cfg: &crate::shell::config::ShipcastConfig,
    sys: &crate::hydro::VesselSystem,
    records: &[(f64, Record)],
    state: Option<crate::engine::state::EngineState>,
    mut pace: impl FnMut(f64),
    mut on_output: impl FnMut(crate::shell::ipc::Output),
) -> Result<(crate::engine::Counters, crate::engine::state::EngineState), Error> {
    use crate::engine::{Computer, Engine, rom_options};
    use crate::shell::ipc::{Input, Output};
    crate::engine::fits_the_wire(sys)?;
    let model = crate::rom::TimeModel::new(sys, rom_options(cfg, sys))?;
    let mut engine = Engine::new(cfg, sys, &model);
    let mut computer = Computer::new(model, sys, cfg);
    if let (Some(s), Some((t, _))) = (state, records.first()) {
        engine.restore(s, *t).map_err(|why| Error::from(why.to_string()))?;
        computer.resume_tuning(engine.roll_tuning());
    }
    let period = cfg.forecast.period_s;
    // ticks on the grid t0 + k period; past this long after the last input no tick can issue a forecast
    // (the motion is stale), so a gap in the log is crossed in one step, not a tick per period
    let quiet_after_s = cfg.forecast.max_motion_age_s + period;
    let mut grid: Option<(f64, f64)> = None; // (t0, next k)
    let mut last_input_s = f64::NEG_INFINITY;
    let mut tick = |at: f64, engine: &mut Engine, computer: &mut Computer| {
        pace(at);
        if let Some(job) = engine.tick(at) {
            let d = computer.run(job, || 0.0);
            if let Some(o @ Output::Forecast(..)) = engine.done(d, at) {
                on_output(o);
            }
            computer.tune();
        }
        on_output(Output::Status(engine.status(at, at, true)));
    };
    let recorded_ticks = records.iter().any(|(_, r)| matches!(r, Record::Tick(_)));
    for (t, r) in records {
        if recorded_ticks {
            if let Record::Tick(k) = r {
                tick(k.clock_s, &mut engine, &mut computer);
            }
        } else {
            let (t0, mut k) = grid.unwrap_or((*t, 0.0));
            let mut jumped = false;
            while t0 + k * period <= *t {
                if !jumped && t0 + k * period > last_input_s + quiet_after_s {
                    // the gap's ticks would all be stale: on to the grid's last point before `t`
                    k = k.max(((*t - t0) / period).floor());
                    if t0 + k * period > *t {
                        k -= 1.0;
                    }
                    jumped = true;
                    continue;
                }
                tick(t0 + k * period, &mut engine, &mut computer);
                k += 1.0;
            }
            grid = Some((t0, k));
        }
        if matches!(
            r,
            Record::Motion(_) | Record::Waves(_) | Record::Navigation(_) | Record::Elevation(_)
        ) {
            last_input_s = *t;
        }
        match r {
            Record::Motion(m) => engine.input(Input::Motion(m.to_wire()), *t),
            Record::Navigation(n) => engine.input(Input::Navigation(n.to_wire()), *t),
            Record::Elevation(g) => match g.scan() {
                Ok(scan) => engine.input(Input::Elevation(Box::new(scan)), *t),
                Err(e) => engine.input(Input::Rejected(e), *t),
            },
            Record::Waves(w) => match w.field() {
                Ok(f) => engine.input(Input::Waves(f), *t),
                Err(e) => engine.input(Input::Rejected(e), *t),
            },
            Record::Truth(_) | Record::Forecast(_) | Record::Tick(_) => {}
        }
    }
    let end_s = records.last().map_or(0.0, |(t, _)| *t);
    Ok((engine.counters.clone(), engine.state(end_s)))
}
