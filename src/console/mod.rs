//! The operator console's core (pure): what the watch officer sees, decided from values (the latest
//! forecast, the measured motion, the daemon's status, the wall time now, the operator's settings) and
//! drawn into a ratatui frame. No terminal, no IPC and no clock here: `shipcast console`
//! (`src/cli/console.rs`) owns the terminal, the subscriptions and the clock and calls [`Console`]'s
//! methods; tests draw into ratatui's `TestBackend`.
//!
//! Conventions: channel values in display units (m, deg; [`crate::operation`]); chart time axes in
//! seconds relative to the forecast's issue time on the data clock (0 = "now" of the forecast, negative
//! = measured past); wall times are UNIX seconds, given by the shell.

mod view;

pub use view::draw;

use crate::hydro::external::External;
use crate::operation::{self, Channel, Source, Verdict, Window};
use ratatui::style::Color;
use std::collections::VecDeque;

/// Display colours (from `[console.colours]` in the config file).
#[derive(Debug, Clone, PartialEq)]
pub struct Colours {
    pub measured: Color,
    pub forecast: Color,
    pub beyond_horizon: Color,
    pub limit: Color,
    pub go: Color,
    pub no_go: Color,
    pub caution: Color,
}

impl Default for Colours {
    fn default() -> Self {
        Colours {
            measured: Color::White,
            forecast: Color::Cyan,
            beyond_horizon: Color::DarkGray,
            limit: Color::Red,
            go: Color::Green,
            no_go: Color::Red,
            caution: Color::Yellow,
        }
    }
}

impl Colours {
    /// A dim palette for the bridge at night (keeps night vision: dark reds and ambers, no white).
    pub fn night() -> Colours {
        Colours {
            measured: Color::Indexed(131),
            forecast: Color::Indexed(166),
            beyond_horizon: Color::Indexed(238),
            limit: Color::Indexed(88),
            go: Color::Indexed(94),
            no_go: Color::Indexed(160),
            caution: Color::Indexed(130),
        }
    }
}

/// The operator's settings: channels with limits, the operation's duration, how much past to show.
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    pub channels: Vec<Channel>,
    pub duration_s: f64,
    pub history_s: f64,
    /// The daemon's forecast period (its config), for staleness.
    pub period_s: f64,
    /// The measured history the daemon's forecasts want behind them, s ([`crate::engine::history_wanted_s`]):
    /// how long the console says the warm-up lasts.
    pub history_wanted_s: f64,
    /// The confidence of a go (`operation.confidence`): the band drawn holds this probability.
    pub confidence: f64,
    pub colours: Colours,
}

/// A forecast as received: `x[s][k]` is series s (6 per vessel, m or rad) at issue + k dt.
#[derive(Debug, Clone, PartialEq)]
pub struct Forecast {
    pub issue_time_s: f64,
    pub dt_s: f64,
    /// End of each vessel's trusted span, s of lead.
    pub horizon_s: Vec<f64>,
    /// Start of each vessel's trusted span, s of lead.
    pub trusted_from_s: Vec<f64>,
    /// Each series' own trusted span [from, to], s of lead (6 per vessel; empty: the vessel's).
    pub series_span_s: Vec<[f64; 2]>,
    pub flags: Vec<&'static str>,
    pub compute_ms: f64,
    pub x: Vec<Vec<f64>>,
    /// The band: standard deviation of each series at each step (as `x`; empty: none sent).
    pub sigma: Vec<Vec<f64>>,
    /// When it arrived (wall clock).
    pub received_wall_s: f64,
}

impl Forecast {
    /// Series `i`'s trusted span (from, to), s of lead: its own, or its vessel's when none was sent.
    pub fn series_span(&self, i: usize) -> (f64, f64) {
        match self.series_span_s.get(i) {
            Some([f, t]) => (*f, *t),
            None => (
                self.trusted_from_s.get(i / 6).copied().unwrap_or(0.0),
                self.horizon_s.get(i / 6).copied().unwrap_or(0.0),
            ),
        }
    }
}

/// The daemon's health as its status service reports it.
#[derive(Debug, Clone, PartialEq)]
pub struct Health {
    pub flags: Vec<&'static str>,
    /// Age of the newest wave field, s (negative: none yet).
    pub wave_age_s: f64,
    /// Per vessel: age of the newest motion sample, s (negative: none yet), and its rate, Hz.
    pub motion_age_s: Vec<f64>,
    pub motion_rate_hz: Vec<f64>,
    pub last_compute_ms: f64,
    /// The median and the 99th percentile of a forecast's time from its newest motion sample's stamp
    /// to its hand-over for publishing, over the daemon's newest forecasts, ms (negative: none yet).
    pub latency_p50_ms: f64,
    pub latency_p99_ms: f64,
    pub overruns: u64,
    /// False in the last status of a clean shutdown.
    pub running: bool,
    pub received_wall_s: f64,
    /// The ship-to-ship link, when one runs.
    pub link: Option<LinkHealth>,
}

/// The ship-to-ship link's health as the status reports it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinkHealth {
    pub up: bool,
    /// Median latency, ms (negative: none measured).
    pub latency_ms: f64,
    /// Share of messages lost, 0..1 (negative: none heard of).
    pub loss: f64,
    /// Age of the newest message from the other ship, s (negative: none yet).
    pub age_s: f64,
}

/// Keys the console understands (the shell maps the terminal's events to these).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Key {
    Char(char),
    Up,
    Down,
    Esc,
}

/// What a key asks of the shell.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Action {
    None,
    Quit,
}

/// Whether the daemon is talking to us.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Link {
    /// Nothing received yet.
    Waiting,
    /// A status or forecast within the last [`STALE_PERIODS`] periods.
    Live,
    /// Silent for `silent_s` (daemon stopped, crashed or unreachable).
    Silent { silent_s: f64 },
    /// The daemon said it was stopping.
    Stopped,
}

/// Silence (in forecast periods) after which the console says the daemon is not responding and
/// stops presenting the forecast as current: below 2 so it is said within two periods even when the
/// redraw comes a little late.
pub const STALE_PERIODS: f64 = 1.5;

/// The console's state.
#[derive(Debug, Clone)]
pub struct Console {
    pub settings: Settings,
    pub vessels: Vec<String>,
    pub external: External,
    pub forecast: Option<Forecast>,
    pub health: Option<Health>,
    /// Combined measured displacements (6 per vessel, the newest of each) after every sample.
    measured: VecDeque<(f64, Vec<f64>)>,
    /// The first measured time (every vessel seen), s: the start of the history the daemon has.
    first_measured_s: Option<f64>,
    latest_x: Vec<f64>,
    seen: Vec<bool>,
    pub selected: usize,
    pub help: bool,
    /// A message to the operator about the last key (e.g. why a channel could not be added).
    pub note: Option<String>,
    /// The other palette (the config's or the night one), swapped in by `n`.
    other_colours: Colours,
}

/// What the forecast says for the operation, with the channel that decides it.
#[derive(Debug, Clone, PartialEq)]
pub struct Outlook {
    pub verdict: Verdict,
    /// The trusted span's end (min of the channels' horizons), s.
    pub trusted_s: f64,
    /// ... and its start (max of the channels' starts), s.
    pub trusted_from_s: f64,
    /// Quiescent windows within the trusted span (times relative to the forecast's issue).
    pub windows: Vec<Window>,
    /// For a no-go: the first channel to leave its limit and when (relative s).
    pub first_exceedance: Option<(String, f64)>,
}

impl Console {
    pub fn new(settings: Settings, vessels: Vec<String>, external: External) -> Console {
        let n = vessels.len();
        Console {
            settings,
            vessels,
            external,
            forecast: None,
            health: None,
            measured: VecDeque::new(),
            first_measured_s: None,
            latest_x: vec![0.0; 6 * n],
            seen: vec![false; n],
            selected: 0,
            help: false,
            note: None,
            other_colours: Colours::night(),
        }
    }

    /// A motion sample of one vessel (m, rad) at data time `t_s`. Samples out of order are ignored.
    pub fn on_motion(&mut self, vessel: usize, t_s: f64, x: &[f64; 6]) {
        if vessel >= self.seen.len() || !t_s.is_finite() || x.iter().any(|v| !v.is_finite()) {
            return;
        }
        if let Some((last, _)) = self.measured.back()
            && t_s < *last
        {
            return;
        }
        self.latest_x[6 * vessel..6 * vessel + 6].copy_from_slice(x);
        self.seen[vessel] = true;
        if self.seen.iter().all(|s| *s) {
            self.measured.push_back((t_s, self.latest_x.clone()));
            self.first_measured_s.get_or_insert(t_s);
        }
        let keep_s = self.settings.history_s + self.forecast_span_s() + 10.0;
        while self.measured.front().is_some_and(|(t, _)| *t < t_s - keep_s) {
            self.measured.pop_front();
        }
    }

    /// While the daemon's history is shorter than it wants: how much measured motion there is and how
    /// many seconds are still to come (from the motion this console has seen; None once it is full or
    /// before any motion).
    pub fn warmup(&self) -> Option<(f64, f64)> {
        let have = self.latest_measured_s()? - self.first_measured_s?;
        let left = self.settings.history_wanted_s - have;
        (left > 0.0).then_some((have, left))
    }

    pub fn on_forecast(&mut self, f: Forecast) {
        self.forecast = Some(f);
    }

    pub fn on_health(&mut self, h: Health) {
        self.health = Some(h);
    }

    fn forecast_span_s(&self) -> f64 {
        self.forecast.as_ref().map_or(0.0, |f| {
            f.x.first().map_or(0, |s| s.len().saturating_sub(1)) as f64 * f.dt_s
        })
    }

    /// The daemon link at wall time `now_wall_s`.
    pub fn link(&self, now_wall_s: f64) -> Link {
        if self.health.as_ref().is_some_and(|h| !h.running) {
            let later = self.forecast.as_ref().zip(self.health.as_ref());
            if !later.is_some_and(|(f, h)| f.received_wall_s > h.received_wall_s) {
                return Link::Stopped;
            }
        }
        let last = [
            self.forecast.as_ref().map(|f| f.received_wall_s),
            self.health.as_ref().map(|h| h.received_wall_s),
        ]
        .into_iter()
        .flatten()
        .fold(None, |m: Option<f64>, t| Some(m.map_or(t, |m| m.max(t))));
        match last {
            None => Link::Waiting,
            Some(t) if now_wall_s - t > STALE_PERIODS * self.settings.period_s => Link::Silent {
                silent_s: now_wall_s - t,
            },
            Some(_) => Link::Live,
        }
    }

    /// Whether the forecast on screen is current: the daemon is live and the forecast is no older
    /// than [`STALE_PERIODS`] periods.
    pub fn forecast_is_current(&self, now_wall_s: f64) -> bool {
        self.link(now_wall_s) == Link::Live
            && self
                .forecast
                .as_ref()
                .is_some_and(|f| now_wall_s - f.received_wall_s <= STALE_PERIODS * self.settings.period_s)
    }

    /// Channel `c` of the forecast, sample by sample.
    pub fn forecast_channel(&self, c: &Channel) -> Vec<f64> {
        self.forecast
            .as_ref()
            .map_or_else(Vec::new, |f| c.along(&self.external, &f.x))
    }

    /// Channel `c` as measured: (time relative to `t0_s`, value) from `from_s` on.
    pub fn measured_channel(&self, c: &Channel, t0_s: f64, from_s: f64) -> Vec<(f64, f64)> {
        self.measured
            .iter()
            .filter(|(t, _)| *t - t0_s >= from_s)
            .map(|(t, x)| (t - t0_s, c.value(&self.external, x)))
            .collect()
    }

    /// Newest measured data time, s.
    pub fn latest_measured_s(&self) -> Option<f64> {
        self.measured.back().map(|(t, _)| *t)
    }

    /// Trusted horizon of channel `c` for the current forecast, s.
    pub fn horizon_of(&self, c: &Channel) -> f64 {
        self.span_of(c).1
    }

    /// Start of channel `c`'s trusted span for the current forecast, s.
    pub fn trusted_from_of(&self, c: &Channel) -> f64 {
        self.span_of(c).0
    }

    /// Channel `c`'s trusted span (from, to) for the current forecast, s: where every series it reads
    /// is trusted ([`Channel::span_s`]; (0, 0) without a forecast).
    pub fn span_of(&self, c: &Channel) -> (f64, f64) {
        self.forecast.as_ref().map_or((0.0, 0.0), |f| {
            c.span_s(&self.external, f.x.len(), |i| f.series_span(i))
        })
    }

    /// Channel `c`'s band along the current forecast: its standard deviation at each step (empty
    /// when the forecast has none).
    pub fn forecast_sigma(&self, c: &Channel) -> Vec<f64> {
        self.forecast
            .as_ref()
            .filter(|f| !f.sigma.is_empty())
            .map_or_else(Vec::new, |f| c.sigma_along(&self.external, &f.sigma))
    }

    /// The operation's outlook from the current forecast (None without a forecast or channels).
    pub fn outlook(&self) -> Option<Outlook> {
        let f = self.forecast.as_ref()?;
        let chans = &self.settings.channels;
        if chans.is_empty() {
            return None;
        }
        let series: Vec<Vec<f64>> = chans.iter().map(|c| self.forecast_channel(c)).collect();
        let sigmas: Vec<Vec<f64>> = chans.iter().map(|c| self.forecast_sigma(c)).collect();
        let (trusted_from_s, trusted_s) =
            operation::trusted_span_s(chans, &self.external, f.x.len(), |i| f.series_span(i));
        let n = series.iter().map(|s| s.len()).min().unwrap_or(0);
        let m = operation::trusted_samples(n, f.dt_s, trusted_s);
        // the trusted span's samples: from its start (a whole step) to its end
        let first = ((trusted_from_s / f.dt_s - 1e-9).ceil().max(0.0) as usize).min(m);
        let views: Vec<&[f64]> = series.iter().map(|s| &s[first..m]).collect();
        let bands: Vec<&[f64]> = sigmas
            .iter()
            .map(|s| if s.len() >= m { &s[first..m] } else { &[][..] })
            .collect();
        let limits: Vec<f64> = chans.iter().map(|c| c.limit).collect();
        let ok = operation::inside_with_confidence(&views, &bands, &limits, self.settings.confidence);
        let d = self.settings.duration_s;
        let windows = operation::windows(first as f64 * f.dt_s, f.dt_s, &ok, d);
        // a span that starts later cannot say whether to start now
        let verdict = if m <= first || first > 0 {
            Verdict::Unknown
        } else {
            operation::verdict(&windows, 0.0, d)
        };
        // the first step at which a channel is likelier than the confidence allows to be outside
        let first_exceedance = chans
            .iter()
            .zip(views.iter().zip(&bands))
            .filter_map(|(c, (s, b))| {
                let k = operation::inside_with_confidence(&[s], &[b], &[c.limit], self.settings.confidence)
                    .iter()
                    .position(|ok| !ok)?;
                Some((c.name.clone(), (first + k) as f64 * f.dt_s))
            })
            .min_by(|a, b| a.1.total_cmp(&b.1));
        Some(Outlook {
            verdict,
            trusted_s: trusted_s.min((n.max(1) - 1) as f64 * f.dt_s),
            trusted_from_s: first as f64 * f.dt_s,
            windows,
            first_exceedance,
        })
    }

    /// The names of every channel the system offers.
    pub fn available_channels(&self) -> Vec<String> {
        operation::available(&self.vessels, &self.external)
    }

    /// Handles a key; returns what the shell must do.
    pub fn key(&mut self, k: Key) -> Action {
        self.note = None;
        let n = self.settings.channels.len();
        match k {
            Key::Char('q') | Key::Esc => {
                if self.help {
                    self.help = false;
                } else {
                    return Action::Quit;
                }
            }
            Key::Char('?') | Key::Char('h') => self.help = !self.help,
            Key::Up | Key::Char('k') if n > 0 => self.selected = (self.selected + n - 1) % n,
            Key::Down | Key::Char('j') if n > 0 => self.selected = (self.selected + 1) % n,
            Key::Char('+') | Key::Char('=') if n > 0 => {
                let c = &mut self.settings.channels[self.selected];
                c.limit = round_step(c.limit * 1.1);
            }
            Key::Char('-') if n > 0 => {
                let c = &mut self.settings.channels[self.selected];
                c.limit = round_step(c.limit / 1.1).max(1e-3);
            }
            Key::Char(']') => self.settings.duration_s += 10.0,
            Key::Char('[') => self.settings.duration_s = (self.settings.duration_s - 10.0).max(10.0),
            Key::Char('a') => self.add_channel(),
            Key::Char('n') => {
                std::mem::swap(&mut self.settings.colours, &mut self.other_colours);
                self.note = Some("colours swapped (n again to swap back)".into());
            }
            Key::Char('x') | Key::Char('d') if n > 1 => {
                let c = self.settings.channels.remove(self.selected);
                self.note = Some(format!("removed {}", c.name));
                self.selected = self.selected.min(n - 2);
            }
            Key::Char('x') | Key::Char('d') => self.note = Some("the last channel stays".into()),
            _ => {}
        }
        Action::None
    }

    /// Adds the first channel on offer that is not shown, with a default limit (1 m or 2 deg).
    fn add_channel(&mut self) {
        let shown: Vec<&str> = self.settings.channels.iter().map(|c| c.name.as_str()).collect();
        let next = self
            .available_channels()
            .into_iter()
            .find(|a| !shown.contains(&a.as_str()));
        let Some(name) = next else {
            self.note = Some("every channel is shown".into());
            return;
        };
        match operation::resolve(&name, &self.vessels, &self.external) {
            Ok(source) => {
                let limit = match source {
                    Source::Dof { dof, .. } if dof >= 3 => 2.0,
                    _ => 1.0,
                };
                self.note = Some(format!("added {name} (limit {limit}; +/- to change)"));
                self.settings.channels.push(Channel { name, source, limit });
                self.selected = self.settings.channels.len() - 1;
            }
            Err(e) => self.note = Some(e),
        }
    }
}

/// Rounds a limit to 2 significant digits (what an operator types).
fn round_step(x: f64) -> f64 {
    if !(x.is_finite() && x > 0.0) {
        return x;
    }
    let p = 10f64.powf(x.log10().floor() - 1.0);
    (x / p).round() * p
}

#[cfg(test)]
mod tests {
    use super::*;

    pub(super) fn two_vessels() -> Console {
        let chans = vec![
            Channel {
                name: "a.heave".into(),
                source: Source::Dof { vessel: 0, dof: 2 },
                limit: 1.0,
            },
            Channel {
                name: "b.roll".into(),
                source: Source::Dof { vessel: 1, dof: 3 },
                limit: 2.0,
            },
        ];
        let s = Settings {
            channels: chans,
            duration_s: 30.0,
            history_s: 60.0,
            period_s: 1.0,
            history_wanted_s: 600.0,
            confidence: 0.9,
            colours: Colours::default(),
        };
        Console::new(s, vec!["a".into(), "b".into()], External::default())
    }

    /// A forecast of `len_s` at dt 1 s: vessel a heaves `heave(t)`, vessel b rolls `roll_deg(t)`.
    pub(super) fn forecast(
        len_s: usize,
        horizon_s: f64,
        heave: impl Fn(f64) -> f64,
        roll_deg: impl Fn(f64) -> f64,
    ) -> Forecast {
        let mut x = vec![vec![0.0; len_s + 1]; 12];
        for k in 0..=len_s {
            x[2][k] = heave(k as f64);
            x[9][k] = roll_deg(k as f64).to_radians();
        }
        Forecast {
            issue_time_s: 1000.0,
            dt_s: 1.0,
            horizon_s: vec![horizon_s, horizon_s],
            trusted_from_s: vec![0.0, 0.0],
            series_span_s: vec![],
            flags: vec![],
            compute_ms: 12.0,
            x,
            sigma: vec![],
            received_wall_s: 5000.0,
        }
    }

    #[test]
    fn go_when_quiet_for_the_duration_within_the_horizon() {
        let mut c = two_vessels();
        c.on_forecast(forecast(120, 100.0, |_| 0.5, |t| if t > 70.0 { 3.0 } else { 1.0 }));
        let o = c.outlook().unwrap();
        assert_eq!(o.verdict, Verdict::Go { window_s: 70.0 });
        assert_eq!(o.first_exceedance, Some(("b.roll".into(), 71.0)));
        assert_eq!(o.trusted_s, 100.0);
    }

    #[test]
    fn no_go_names_the_channel_and_the_next_window() {
        let mut c = two_vessels();
        c.on_forecast(forecast(120, 100.0, |t| if t < 20.0 { 1.5 } else { 0.2 }, |_| 0.0));
        let o = c.outlook().unwrap();
        assert_eq!(
            o.verdict,
            Verdict::NoGo {
                next_window_in_s: Some(20.0)
            }
        );
        assert_eq!(o.first_exceedance, Some(("a.heave".into(), 0.0)));
        assert_eq!(o.windows.len(), 1);
        assert!(o.windows[0].open_end);
    }

    #[test]
    fn a_short_horizon_cannot_say() {
        let mut c = two_vessels();
        c.on_forecast(forecast(120, 20.0, |_| 0.1, |_| 0.1));
        assert_eq!(c.outlook().unwrap().verdict, Verdict::Unknown);
        // a quiet sea beyond the horizon does not count: the trace there is not trusted
        assert_eq!(c.outlook().unwrap().trusted_s, 20.0);
    }

    #[test]
    fn the_link_goes_silent_within_two_periods_and_says_a_clean_stop() {
        let mut c = two_vessels();
        assert_eq!(c.link(0.0), Link::Waiting);
        c.on_forecast(forecast(10, 10.0, |_| 0.0, |_| 0.0)); // received at 5000
        assert_eq!(c.link(5001.0), Link::Live);
        assert!(c.forecast_is_current(5001.0));
        assert!(matches!(c.link(5001.6), Link::Silent { .. }));
        assert!(!c.forecast_is_current(5001.6));
        // a status keeps the link live, but an old forecast is still not current (suspended)
        c.on_health(Health {
            flags: vec!["no_waves"],
            wave_age_s: 40.0,
            motion_age_s: vec![0.1, 0.1],
            motion_rate_hz: vec![10.0, 10.0],
            last_compute_ms: 10.0,
            latency_p50_ms: -1.0,
            latency_p99_ms: -1.0,
            overruns: 0,
            running: true,
            link: None,
            received_wall_s: 5010.0,
        });
        assert_eq!(c.link(5010.5), Link::Live);
        assert!(!c.forecast_is_current(5010.5));
        c.health.as_mut().unwrap().running = false;
        assert_eq!(c.link(5010.5), Link::Stopped);
    }

    #[test]
    fn keys_change_limits_duration_and_channels() {
        let mut c = two_vessels();
        c.key(Key::Down);
        assert_eq!(c.selected, 1);
        c.key(Key::Char('+'));
        assert_eq!(c.settings.channels[1].limit, 2.2);
        c.key(Key::Char('-'));
        assert_eq!(c.settings.channels[1].limit, 2.0);
        c.key(Key::Char(']'));
        assert_eq!(c.settings.duration_s, 40.0);
        c.key(Key::Char('a'));
        assert_eq!(c.settings.channels[2].name, "a.surge");
        c.key(Key::Char('x'));
        assert_eq!(c.settings.channels.len(), 2);
        c.key(Key::Char('n'));
        assert_eq!(c.settings.colours, Colours::night());
        c.key(Key::Char('n'));
        assert_eq!(c.settings.colours, Colours::default());
        assert_eq!(c.key(Key::Char('?')), Action::None);
        assert!(c.help);
        assert_eq!(c.key(Key::Esc), Action::None);
        assert_eq!(c.key(Key::Char('q')), Action::Quit);
    }

    #[test]
    fn measured_motion_needs_every_vessel_and_keeps_order() {
        let mut c = two_vessels();
        c.on_motion(0, 10.0, &[0.0, 0.0, 0.3, 0.0, 0.0, 0.0]);
        assert_eq!(c.latest_measured_s(), None);
        c.on_motion(1, 10.1, &[0.0, 0.0, 0.0, 0.01, 0.0, 0.0]);
        c.on_motion(0, 9.0, &[0.0; 6]); // late: ignored
        c.on_motion(0, 10.2, &[0.0, 0.0, f64::NAN, 0.0, 0.0, 0.0]); // garbage: ignored
        let m = c.measured_channel(&c.settings.channels[0].clone(), 10.0, -5.0);
        assert_eq!(m.len(), 1);
        assert!((m[0].0 - 0.1).abs() < 1e-12 && m[0].1 == 0.3);
    }
}
