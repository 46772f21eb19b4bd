//! Where a forecast's time goes, from the newest motion sample it starts from to its hand-over to the
//! output thread: the stages of each forecast and their running quantiles, for the status.
//!
//! Times in ms. The stages ([`STAGE_NAMES`]): `received` the newest sample's arrival at the daemon less
//! its stamp (the sensor's and the transport's lateness: the engine's clock is the wall clock's, the
//! stamp the data clock's, which agree on one host and on a GNSS-disciplined ship); `waited` the tick
//! that took it less its arrival (the cadence's wait for every vessel's sample); `built` the job's
//! making (the start states, the wave field's trust, on the daemon's loop); `queued` the job's
//! wait for the compute thread (busy with the in-situ tuning's work); `forecast` the model's run;
//! `band` the band and spans; `handed` the finished forecast's way back to the loop and its checks.
//! What is left to a subscriber (the output thread, iceoryx2, its own poll) it measures itself
//! (`shipcast watch --json`: `received_wall_s` less `issue_time_s`).

use std::collections::VecDeque;

/// The stages, in their order on the path.
pub const STAGE_NAMES: [&str; 7] = ["received", "waited", "built", "queued", "forecast", "band", "handed"];

/// The running quantiles are over this many of the newest forecasts (10 minutes at the 1 s cadence).
pub const LATENCY_WINDOW: usize = 600;

/// A forecast's stages, ms ([`STAGE_NAMES`] order).
pub type Stages = [f64; 7];

/// What the shell measured of a job, ms: its making, its wait for the compute thread, the model's
/// run, the band.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ComputeTimes {
    pub build_ms: f64,
    pub queued_ms: f64,
    pub forecast_ms: f64,
    pub band_ms: f64,
}

/// Where the running job's time started: its newest sample's stamp and arrival, and its tick (engine
/// clock, s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JobStart {
    pub stamp_s: f64,
    pub arrival_s: f64,
    pub tick_s: f64,
}

/// The last forecast's stages and the totals (stamp to hand-over) of the newest [`LATENCY_WINDOW`].
#[derive(Debug, Clone, Default)]
pub struct Latency {
    last: Stages,
    totals_ms: VecDeque<f64>,
}

impl Latency {
    /// A finished job, handed over at `done_s` (engine clock): its stages, recorded and returned.
    pub fn record(&mut self, start: JobStart, c: ComputeTimes, done_s: f64) -> Stages {
        let ms = |a: f64, b: f64| {
            if a.is_finite() && b.is_finite() {
                1e3 * (b - a)
            } else {
                0.0
            }
        };
        let received = ms(start.stamp_s, start.arrival_s).max(0.0);
        let waited = ms(start.arrival_s, start.tick_s).max(0.0);
        let computed = c.build_ms + c.queued_ms + c.forecast_ms + c.band_ms;
        // what is left of the tick-to-hand-over time after the job's making and the compute thread's
        let handed = (ms(start.tick_s, done_s) - computed).max(0.0);
        let stages = [
            received,
            waited,
            c.build_ms,
            c.queued_ms,
            c.forecast_ms,
            c.band_ms,
            handed,
        ];
        if stages.iter().all(|s| s.is_finite()) {
            self.last = stages;
            if self.totals_ms.len() == LATENCY_WINDOW {
                self.totals_ms.pop_front();
            }
            self.totals_ms.push_back(stages.iter().sum());
        }
        stages
    }

    /// The last forecast's stages (zeros before the first).
    pub fn last(&self) -> Stages {
        self.last
    }

    /// The `q` quantile (0..1, nearest rank) of the window's totals, ms; -1 before any forecast.
    pub fn total_quantile_ms(&self, q: f64) -> f64 {
        if self.totals_ms.is_empty() {
            return -1.0;
        }
        let mut v: Vec<f64> = self.totals_ms.iter().copied().collect();
        v.sort_by(f64::total_cmp);
        let i = (q.clamp(0.0, 1.0) * (v.len() - 1) as f64).round() as usize;
        v[i]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn start(stamp_s: f64) -> JobStart {
        JobStart {
            stamp_s,
            arrival_s: stamp_s + 0.004,
            tick_s: stamp_s + 0.005,
        }
    }

    #[test]
    fn stages_add_up_to_the_stamp_to_hand_over_time() {
        let mut l = Latency::default();
        let c = ComputeTimes {
            build_ms: 1.5,
            queued_ms: 2.0,
            forecast_ms: 20.0,
            band_ms: 8.0,
        };
        let s = l.record(start(100.0), c, 100.040);
        let want = [4.0, 1.0, 1.5, 2.0, 20.0, 8.0, 3.5];
        for (got, want) in s.iter().zip(want) {
            assert!((got - want).abs() < 1e-6, "{s:?}");
        }
        assert!((l.total_quantile_ms(0.5) - 40.0).abs() < 1e-6);
    }

    #[test]
    fn quantiles_are_over_the_newest_window_only() {
        let mut l = Latency::default();
        assert_eq!(l.total_quantile_ms(0.99), -1.0);
        // a slow first forecast, then a window of fast ones: it has left the window
        l.record(
            start(0.0),
            ComputeTimes {
                forecast_ms: 900.0,
                ..Default::default()
            },
            1.0,
        );
        for k in 1..=LATENCY_WINDOW {
            let t = k as f64;
            l.record(start(t), ComputeTimes::default(), t + 0.010);
        }
        assert!((l.total_quantile_ms(0.99) - 10.0).abs() < 1e-6);
        assert!((l.total_quantile_ms(1.0) - 10.0).abs() < 1e-6);
    }

    #[test]
    fn a_clock_that_runs_backwards_gives_no_negative_stage() {
        let mut l = Latency::default();
        let s = l.record(
            JobStart {
                stamp_s: 10.0,
                arrival_s: 9.0,
                tick_s: 9.5,
            },
            ComputeTimes::default(),
            9.4,
        );
        assert!(s.iter().all(|v| *v >= 0.0), "{s:?}");
    }
}
