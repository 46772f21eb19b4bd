//! The link's health (pure): messages from the other ship in, latency, loss and age out.
//!
//! Each stream (one per kind of message the other ship sends) numbers its messages from 0; a gap in
//! the numbers is that many lost, a number at or below the last one is a late or repeated message
//! (counted as received, no loss), and a 0 after more is the sender restarted. Latency is the
//! receipt's wall clock less the sender's stamp (both hosts' clocks: GNSS-disciplined on a ship,
//! exact on one host). Times in s.

use crate::shell::ipc::wire::{LINK_SCHEMA_VERSION, LinkStatus};
use std::collections::{BTreeMap, VecDeque};

/// What happened to one message, over the window.
#[derive(Debug, Clone, Copy)]
struct Event {
    at_s: f64,
    latency_s: f64,
    /// Messages found lost just before this one.
    lost: u64,
}

/// Health of the messages received from the other ship.
#[derive(Debug, Clone)]
pub struct Health {
    window_s: f64,
    stale_s: f64,
    last_seq: BTreeMap<String, u64>,
    events: VecDeque<Event>,
    newest_s: Option<f64>,
    received: u64,
    lost: u64,
}

impl Health {
    /// Latency and loss over the last `window_s`; down when nothing arrived for `stale_s`.
    pub fn new(window_s: f64, stale_s: f64) -> Health {
        Health {
            window_s,
            stale_s,
            last_seq: BTreeMap::new(),
            events: VecDeque::new(),
            newest_s: None,
            received: 0,
            lost: 0,
        }
    }

    /// A message of `stream`, number `seq`, stamped `sent_s` by its sender, received at `now_s`.
    pub fn received(&mut self, stream: &str, seq: u64, sent_s: f64, now_s: f64) {
        let lost = match self.last_seq.get(stream) {
            Some(&last) if seq > last => seq - last - 1,
            _ => 0,
        };
        let newer = self.last_seq.get(stream).is_none_or(|&last| seq > last || seq == 0);
        if newer {
            self.last_seq.insert(stream.to_string(), seq);
        }
        self.received += 1;
        self.lost += lost;
        self.newest_s = Some(self.newest_s.map_or(now_s, |t| t.max(now_s)));
        self.events.push_back(Event {
            at_s: now_s,
            latency_s: if sent_s.is_finite() { now_s - sent_s } else { f64::NAN },
            lost,
        });
        self.forget(now_s);
    }

    fn forget(&mut self, now_s: f64) {
        while self.events.front().is_some_and(|e| now_s - e.at_s > self.window_s) {
            self.events.pop_front();
        }
    }

    /// The health at `now_s`, `sent` messages sent so far.
    pub fn status(&mut self, now_s: f64, sent: u64) -> LinkStatus {
        self.forget(now_s);
        let mut lat: Vec<f64> = self
            .events
            .iter()
            .map(|e| e.latency_s)
            .filter(|l| l.is_finite())
            .collect();
        let latency_ms = if lat.is_empty() {
            -1.0
        } else {
            let m = lat.len() / 2;
            let (_, mid, _) = lat.select_nth_unstable_by(m, f64::total_cmp);
            *mid * 1000.0
        };
        let got = self.events.len() as u64;
        let lost: u64 = self.events.iter().map(|e| e.lost).sum();
        let age = self.newest_s.map(|t| (now_s - t).max(0.0));
        LinkStatus {
            schema_version: LINK_SCHEMA_VERSION,
            up: age.is_some_and(|a| a <= self.stale_s) as u32,
            wall_time_s: now_s,
            latency_ms,
            loss: if got + lost == 0 {
                -1.0
            } else {
                lost as f64 / (got + lost) as f64
            },
            last_message_age_s: age.unwrap_or(-1.0),
            received: self.received,
            lost: self.lost,
            sent,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gaps_are_lost_late_ones_are_not_and_silence_is_down() {
        let mut h = Health::new(30.0, 2.0);
        let s = h.status(0.0, 0);
        assert_eq!(
            (s.up, s.latency_ms, s.loss, s.last_message_age_s),
            (0, -1.0, -1.0, -1.0)
        );
        for (seq, t) in [(0, 1.0), (1, 1.1), (4, 1.4), (3, 1.45), (5, 1.5)] {
            h.received("motion", seq, t - 0.005, t);
        }
        h.received("forecast", 0, 1.49, 1.5);
        let s = h.status(1.6, 7);
        // 6 received, 2 lost (2 and 3 missing at 4; 3 came late but was counted lost when 4 came)
        assert_eq!((s.received, s.lost, s.sent, s.up), (6, 2, 7, 1));
        assert!((s.loss - 2.0 / 8.0).abs() < 1e-12, "{}", s.loss);
        assert!((s.latency_ms - 5.0).abs() < 1e-6, "{}", s.latency_ms);
        assert!((s.last_message_age_s - 0.1).abs() < 1e-9);
        // silence: down, and the window forgets
        let s = h.status(40.0, 7);
        assert_eq!((s.up, s.latency_ms, s.loss), (0, -1.0, -1.0));
        // a restarted sender numbers from 0 again: no loss
        h.received("motion", 0, 40.0, 40.01);
        h.received("motion", 1, 40.1, 40.11);
        let s = h.status(40.2, 7);
        assert_eq!((s.up, s.lost), (1, 2));
        assert_eq!(s.loss, 0.0);
    }
}
