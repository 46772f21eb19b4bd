//! The time stamps of each input source judged against the engine's clock (pure: values in, verdicts
//! out).
//!
//! Every source (one vessel's motion stream, the radar) stamps its samples with its own clock (the data
//! clock: UNIX seconds for live sensors). The engine's clock is the daemon's monotonic clock (in replay,
//! the recorded one). A source is tracked by its offset, stamp - engine clock. The reference offset is
//! the first sample's, then follows the least-delayed accepted samples (it rises with any accepted
//! offset, and may fall by at most [`DRIFT_S_PER_S`] per second, for a sensor clock running slow).
//!
//! Rules ([`ClockRules`], from `[forecast]` in the config):
//! - a stamp that is not finite is refused;
//! - a stamp more than `max_clock_skew_s` ahead of the reference is refused as from the future (a clock
//!   glitch must not make every later genuine sample look late); a source whose clock may run faster
//!   than the engine's (a simulator at `simulate.speed`) is allowed `max_rate - 1` more seconds ahead
//!   per second since its last accepted sample (a sample of such a source that arrives more than the skew
//!   behind where its clock may have run is accepted and leaves the reference alone: it waited);
//! - a stamp more than `max_clock_lag_s` behind it is refused as from the past;
//! - `clock_resync_samples` consecutive refused samples that agree with each other (within the skew) are
//!   a step of the source's clock: the source re-synchronizes to them ([`Stamp::Stepped`]), and the
//!   caller drops what it kept from that source in the old time base.

/// How far a source's stamps may stray from its reference offset, and when a step is believed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClockRules {
    /// Largest lead of a stamp over the reference, s.
    pub max_skew_s: f64,
    /// Largest lag of a stamp behind the reference, s.
    pub max_lag_s: f64,
    /// Consecutive consistent refused samples that re-synchronize the source.
    pub resync_samples: u32,
    /// The fastest a source's clock may run against the engine's (source seconds per second, >= 1).
    pub max_rate: f64,
}

/// How fast the reference offset may fall without a step, s per s: 1000 ppm, far beyond a drifting
/// crystal (tens of ppm) and far below any step a clock makes.
pub const DRIFT_S_PER_S: f64 = 1e-3;

/// The verdict on one stamp.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Stamp {
    Accepted,
    /// Not finite (or the engine's clock is not): refused.
    NonFinite,
    /// Refused: this far ahead of the source's reference, s.
    Future {
        ahead_s: f64,
    },
    /// Refused: this far behind the source's reference, s.
    Past {
        behind_s: f64,
    },
    /// Accepted after a step of the source's clock by `step_s`: what was kept in the old time base
    /// must go.
    Stepped {
        step_s: f64,
    },
}

/// One source's clock.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SourceClock {
    /// Reference offset (stamp - engine clock) and the engine time it was last moved, s.
    reference: Option<(f64, f64)>,
    /// Refused samples in a row that agree: the last one's offset and engine time, and their count.
    candidate: Option<(f64, f64, u32)>,
}

impl SourceClock {
    /// Judges a stamp `stamp_s` (source clock) that arrived at `clock_s` (engine clock).
    pub fn judge(&mut self, stamp_s: f64, clock_s: f64, rules: &ClockRules) -> Stamp {
        if !(stamp_s.is_finite() && clock_s.is_finite()) {
            return Stamp::NonFinite;
        }
        let offset = stamp_s - clock_s;
        let Some((reference, since)) = self.reference else {
            self.reference = Some((offset, clock_s));
            return Stamp::Accepted;
        };
        let elapsed_s = (clock_s - since).max(0.0);
        let floor = reference - DRIFT_S_PER_S * elapsed_s;
        let fast_s = (rules.max_rate - 1.0).max(0.0);
        let verdict = if offset > reference + rules.max_skew_s + fast_s * elapsed_s {
            Stamp::Future {
                ahead_s: offset - reference,
            }
        } else if offset < floor - rules.max_lag_s {
            Stamp::Past {
                behind_s: floor - offset,
            }
        } else {
            self.candidate = None;
            // a faster source's sample that waited (in a service's history, say) is accepted but
            // leaves the reference where the clock may have run to: moved to it, the next fresh
            // sample would look ahead by the wait times the rate
            let waited = fast_s > 0.0 && offset < reference + fast_s * elapsed_s - rules.max_skew_s;
            if !waited {
                self.reference = Some((offset.max(floor), clock_s));
            }
            return Stamp::Accepted;
        };
        let count = match self.candidate {
            Some((c, at, n)) if (offset - c).abs() <= rules.max_skew_s + fast_s * (clock_s - at).max(0.0) => n + 1,
            _ => 1,
        };
        if count >= rules.resync_samples.max(1) {
            self.reference = Some((offset, clock_s));
            self.candidate = None;
            return Stamp::Stepped {
                step_s: offset - reference,
            };
        }
        self.candidate = Some((offset, clock_s, count));
        verdict
    }

    /// The source's clock minus the engine's, s (None before its first sample).
    pub fn offset_s(&self) -> Option<f64> {
        self.reference.map(|(r, _)| r)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const RULES: ClockRules = ClockRules {
        max_skew_s: 1.0,
        max_lag_s: 30.0,
        resync_samples: 5,
        max_rate: 1.0,
    };

    /// A source at 10 Hz whose clock reads 1.7e9 s at engine time 0, with `f` applied to each stamp.
    fn run(n: usize, f: impl Fn(usize, f64) -> f64) -> Vec<Stamp> {
        let mut c = SourceClock::default();
        (0..n)
            .map(|k| {
                let t = k as f64 * 0.1;
                c.judge(f(k, 1.7e9 + t), t, &RULES)
            })
            .collect()
    }

    #[test]
    fn a_steady_source_with_jitter_is_accepted() {
        let v = run(1000, |k, s| s - 0.05 * ((k * 7919) % 13) as f64 / 13.0);
        assert!(v.iter().all(|s| *s == Stamp::Accepted));
    }

    #[test]
    fn one_stamp_an_hour_ahead_is_refused_and_the_next_genuine_one_accepted() {
        let v = run(20, |k, s| if k == 10 { s + 3600.0 } else { s });
        assert!(matches!(v[10], Stamp::Future { ahead_s } if (ahead_s - 3600.0).abs() < 1e-6));
        assert!(v.iter().enumerate().all(|(k, s)| k == 10 || *s == Stamp::Accepted));
    }

    #[test]
    fn a_step_is_believed_after_the_consistent_samples_and_in_either_direction() {
        for step in [3600.0, -3600.0] {
            let v = run(30, |k, s| if k >= 10 { s + step } else { s });
            for (k, s) in v.iter().enumerate() {
                match k {
                    0..=9 => assert_eq!(*s, Stamp::Accepted),
                    10..=13 => assert!(matches!(s, Stamp::Future { .. } | Stamp::Past { .. }), "{k}: {s:?}"),
                    14 => assert!(matches!(s, Stamp::Stepped { step_s } if (step_s - step).abs() < 1e-6)),
                    _ => assert_eq!(*s, Stamp::Accepted, "{k}"),
                }
            }
        }
    }

    #[test]
    fn glitches_that_disagree_never_resynchronize() {
        let v = run(100, |k, s| if k % 2 == 1 { s + 100.0 * k as f64 } else { s });
        assert!(v.iter().all(|s| !matches!(s, Stamp::Stepped { .. })));
    }

    #[test]
    fn non_finite_stamps_are_refused_and_leave_the_reference_alone() {
        let mut c = SourceClock::default();
        assert_eq!(c.judge(f64::INFINITY, 0.0, &RULES), Stamp::NonFinite);
        assert_eq!(c.judge(f64::NAN, 0.0, &RULES), Stamp::NonFinite);
        assert_eq!(c.offset_s(), None);
        assert_eq!(c.judge(10.0, 0.0, &RULES), Stamp::Accepted);
        assert_eq!(c.offset_s(), Some(10.0));
    }

    /// A simulator at 4x: its fields every 2 s of its clock arrive every 0.5 s, each 1.5 s further
    /// ahead of the engine's clock than the last (more than the skew).
    #[test]
    fn a_source_running_faster_within_max_rate_is_accepted_and_its_glitch_refused() {
        let fast = ClockRules { max_rate: 4.0, ..RULES };
        let mut c = SourceClock::default();
        for k in 0..100 {
            let t = k as f64 * 0.5;
            assert_eq!(c.judge(1.7e9 + 4.0 * t, t, &fast), Stamp::Accepted, "{k}");
        }
        assert!(matches!(
            c.judge(1.7e9 + 4.0 * 50.0 + 3600.0, 50.0, &fast),
            Stamp::Future { .. }
        ));
        let mut slow = SourceClock::default();
        assert_eq!(slow.judge(1.7e9, 0.0, &RULES), Stamp::Accepted);
        assert!(matches!(slow.judge(1.7e9 + 2.0, 0.5, &RULES), Stamp::Future { .. }));
    }

    /// Was: a sample that waited 0.4 s (the waves service's history, read by a daemon just started)
    /// moved the reference back with the engine's clock, and every fresh field after it was refused as
    /// ahead until the clock was re-synchronized and the wave history thrown away.
    #[test]
    fn a_faster_source_s_sample_that_waited_does_not_make_the_next_fresh_one_look_ahead() {
        let fast = ClockRules { max_rate: 4.0, ..RULES };
        let mut c = SourceClock::default();
        for k in 0..40 {
            let t = k as f64 * 0.5;
            let arrived = if k == 20 { t + 0.4 } else { t };
            assert_eq!(c.judge(1.7e9 + 4.0 * t, arrived, &fast), Stamp::Accepted, "{k}");
        }
    }

    #[test]
    fn a_slow_drift_is_followed() {
        // the sensor clock loses 100 ppm: over an hour 0.36 s, never refused
        let v = run(36_000, |k, s| s - 1e-4 * k as f64 * 0.1);
        assert!(v.iter().all(|s| *s == Stamp::Accepted));
    }
}
