//! Per-vessel motion history (pure): samples in, the state and velocity history at the solver's step
//! out.
//!
//! Rules (time stamps are the samples', never arrival times):
//! - a sample with a non-finite value is dropped (counted);
//! - a sample older than the newest kept is dropped as late; one with the same time as duplicate;
//! - resampling to the solver step is linear between samples; walking back from t0, a gap up to
//!   `max_gap_s` is bridged (and flagged), a longer one ends the history: what is before it counts as
//!   at rest (flagged as short history, like a history shorter than the radiation memory).

use std::collections::VecDeque;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    pub time_s: f64,
    pub x: [f64; 6],
    pub v: [f64; 6],
}

/// Why a sample was dropped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Drop {
    NonFinite,
    Late,
    Duplicate,
}

/// What resampling found.
#[derive(Debug, Clone, PartialEq)]
pub struct Resampled {
    pub x0: [f64; 6],
    pub v0: [f64; 6],
    /// Velocities at t0 - n dt .. t0 - dt (oldest first).
    pub velocities: Vec<[f64; 6]>,
    /// Part of the requested history was not there (taken as at rest).
    pub short: bool,
    /// A gap was bridged.
    pub gap: bool,
}

#[derive(Debug, Clone)]
pub struct History {
    samples: VecDeque<Sample>,
    keep_s: f64,
}

impl History {
    /// Keeps samples spanning `keep_s` seconds behind the newest.
    pub fn new(keep_s: f64) -> History {
        History {
            samples: VecDeque::new(),
            keep_s,
        }
    }

    pub fn push(&mut self, s: Sample) -> Result<(), Drop> {
        if !(s.time_s.is_finite() && s.x.iter().chain(&s.v).all(|v| v.is_finite())) {
            return Err(Drop::NonFinite);
        }
        if let Some(last) = self.samples.back() {
            if s.time_s == last.time_s {
                return Err(Drop::Duplicate);
            }
            if s.time_s < last.time_s {
                return Err(Drop::Late);
            }
        }
        self.samples.push_back(s);
        while let Some(f) = self.samples.front() {
            if s.time_s - f.time_s > self.keep_s && self.samples.len() > 2 {
                self.samples.pop_front();
            } else {
                break;
            }
        }
        Ok(())
    }

    pub fn newest_time_s(&self) -> Option<f64> {
        self.samples.back().map(|s| s.time_s)
    }

    pub fn len(&self) -> usize {
        self.samples.len()
    }

    pub fn is_empty(&self) -> bool {
        self.samples.is_empty()
    }

    /// Sample rate over the kept samples, Hz.
    pub fn rate_hz(&self) -> f64 {
        match (self.samples.front(), self.samples.back()) {
            (Some(a), Some(b)) if b.time_s > a.time_s => (self.samples.len() - 1) as f64 / (b.time_s - a.time_s),
            _ => 0.0,
        }
    }

    /// The state at t0 and the `n` velocities before it at step `dt_s`.
    pub fn resample(&self, t0_s: f64, dt_s: f64, n: usize, max_gap_s: f64) -> Option<Resampled> {
        let last = self.samples.back()?;
        if t0_s > last.time_s + 1e-9 || self.samples.len() < 2 {
            return None;
        }
        let mut out = Resampled {
            x0: [0.0; 6],
            v0: [0.0; 6],
            velocities: vec![[0.0; 6]; n],
            short: false,
            gap: false,
        };
        // index j of the newest sample at or before t
        let mut j = self.samples.len() - 1;
        let mut ended = false;
        let mut at = |t: f64, x: Option<&mut [f64; 6]>, v: &mut [f64; 6], out_short: &mut bool, out_gap: &mut bool| {
            if ended {
                *out_short = true;
                return;
            }
            while j > 0 && self.samples[j].time_s > t {
                j -= 1;
            }
            let a = self.samples[j];
            if a.time_s > t {
                // before the first sample
                ended = true;
                *out_short = true;
                return;
            }
            let b = if j + 1 < self.samples.len() {
                self.samples[j + 1]
            } else {
                a
            };
            let span = b.time_s - a.time_s;
            if span > max_gap_s {
                ended = true;
                *out_short = true;
                return;
            }
            let w = if span > 0.0 { (t - a.time_s) / span } else { 0.0 };
            if span > 2.5 * self.nominal_interval() {
                *out_gap = true;
            }
            for d in 0..6 {
                v[d] = a.v[d] + w * (b.v[d] - a.v[d]);
            }
            if let Some(x) = x {
                for d in 0..6 {
                    x[d] = a.x[d] + w * (b.x[d] - a.x[d]);
                }
            }
        };
        let (mut short, mut gap) = (false, false);
        at(t0_s, Some(&mut out.x0), &mut out.v0, &mut short, &mut gap);
        for m in 1..=n {
            let mut v = [0.0; 6];
            at(t0_s - m as f64 * dt_s, None, &mut v, &mut short, &mut gap);
            out.velocities[n - m] = v;
        }
        out.short = short;
        out.gap = gap;
        Some(out)
    }

    fn nominal_interval(&self) -> f64 {
        let r = self.rate_hz();
        if r > 0.0 { 1.0 / r } else { f64::INFINITY }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn s(t: f64, v: f64) -> Sample {
        Sample {
            time_s: t,
            x: [v; 6],
            v: [v; 6],
        }
    }

    #[test]
    fn drops_are_counted_by_kind() {
        let mut h = History::new(100.0);
        assert!(h.push(s(1.0, 0.0)).is_ok());
        assert_eq!(h.push(s(1.0, 0.0)), Err(Drop::Duplicate));
        assert_eq!(h.push(s(0.5, 0.0)), Err(Drop::Late));
        assert_eq!(h.push(s(2.0, f64::NAN)), Err(Drop::NonFinite));
        assert_eq!(h.len(), 1);
    }

    #[test]
    fn resampling_is_linear_and_gaps_follow_the_rule() {
        let mut h = History::new(100.0);
        for k in 0..=100 {
            let t = k as f64 * 0.1;
            if (40..60).contains(&k) {
                continue; // a 2 s gap from 3.9 to 6.0
            }
            h.push(s(t, t)).unwrap();
        }
        let r = h.resample(10.0, 0.25, 8, 3.0).unwrap();
        assert!((r.x0[2] - 10.0).abs() < 1e-12 && (r.velocities[7][0] - 9.75).abs() < 1e-12);
        assert!(!r.short && !r.gap);
        // back across the gap: bridged with max_gap 3 s, ends the history with 1 s
        let r = h.resample(10.0, 0.5, 16, 3.0).unwrap();
        assert!(r.gap && !r.short);
        assert!((r.velocities[0][0] - 2.0).abs() < 1e-12);
        let r = h.resample(10.0, 0.5, 16, 1.0).unwrap();
        assert!(r.short);
        assert_eq!(r.velocities[0], [0.0; 6]);
        // history longer than what is kept: short
        let r = h.resample(10.0, 1.0, 20, 3.0).unwrap();
        assert!(r.short);
        // t0 after the newest sample: nothing
        assert!(h.resample(10.5, 0.1, 5, 1.0).is_none());
    }
}
