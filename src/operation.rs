//! Operations (pure): the channels an operator watches, their limits, and the quiescent windows when
//! every chosen channel stays inside its limit for at least the operation's duration. Used by the
//! console (the next windows, go / no-go now) and by replay's skill report (windows forecast against
//! windows that happened).
//!
//! Conventions (DESIGN.md section 1): DOF order surge, sway, heave, roll, pitch, yaw per vessel; a
//! channel's value is in display units: m for translations and point motions, degrees for rotations.
//! A limit is symmetric: the channel is inside while |value| <= limit. Times are seconds on the data
//! clock; a series is sampled at t0 + k dt.
//!
//! Channel names: `<vessel>.<dof>` (`carrier.heave`, `lighter.roll`), `<point>.<x|y|z>` for a point of
//! interest (`crane_tip.z`), `<relative_motion>.<x|y|z>` for a relative motion (`hook_over_hatch.z`),
//! components in the point's body frame for a point and in the first point's body frame for a
//! relative motion (small rotations: all frames coincide to first order).

use crate::hydro::Dof;
use crate::hydro::external::External;

/// What a channel reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Source {
    Dof { vessel: usize, dof: usize },
    Point { point: usize, axis: usize },
    Relative { relative: usize, axis: usize },
}

/// A named channel with its operator limit.
#[derive(Debug, Clone, PartialEq)]
pub struct Channel {
    pub name: String,
    pub source: Source,
    /// |value| <= limit is inside; display units (m or deg).
    pub limit: f64,
}

impl Channel {
    /// The unit of the channel's values.
    pub fn unit(&self) -> &'static str {
        match self.source {
            Source::Dof { dof, .. } if dof >= 3 => "deg",
            _ => "m",
        }
    }

    /// The channel's value for the displacements `x` (6 per vessel, SI: m and rad).
    pub fn value(&self, ext: &External, x: &[f64]) -> f64 {
        match self.source {
            Source::Dof { vessel, dof } => {
                let v = x.get(6 * vessel + dof).copied().unwrap_or(f64::NAN);
                if dof >= 3 { v.to_degrees() } else { v }
            }
            Source::Point { point, axis } => match ext.points.get(point) {
                Some(p) if x.len() >= 6 * (p.body + 1) => ext.point_motion(p, x)[axis],
                _ => f64::NAN,
            },
            Source::Relative { relative, axis } => match ext.relative_motions.get(relative) {
                Some(r) => {
                    let (pa, pb) = (&ext.points[r.a], &ext.points[r.b]);
                    if x.len() < 6 * (pa.body.max(pb.body) + 1) {
                        return f64::NAN;
                    }
                    (ext.point_motion(pa, x) - ext.point_motion(pb, x))[axis]
                }
                None => f64::NAN,
            },
        }
    }
}

impl Channel {
    /// The channel's standard deviation along a forecast from each series' (`sigma[s][k]`, as
    /// `series`): sum_i |d value / d x_i| sigma_i, the bound for series that move together (heave and
    /// pitch of a point are not independent); display units. Empty when `sigma` is.
    pub fn sigma_along<S: AsRef<[f64]>>(&self, ext: &External, sigma: &[S]) -> Vec<f64> {
        let n = sigma.iter().map(|s| s.as_ref().len()).min().unwrap_or(0);
        let gradient = self.gradient(ext, sigma.len());
        (0..n)
            .map(|k| {
                gradient
                    .iter()
                    .zip(sigma)
                    .filter(|(g, _)| **g > 0.0)
                    .map(|(g, s)| g * s.as_ref()[k])
                    .sum()
            })
            .collect()
    }

    /// |d value / d x_i| for each of `n_series` series: the channel is linear in the displacements
    /// (small rotations), so one unit step of each from rest.
    fn gradient(&self, ext: &External, n_series: usize) -> Vec<f64> {
        let zero = vec![0.0; n_series];
        let base = self.value(ext, &zero);
        (0..n_series)
            .map(|i| {
                let mut x = zero.clone();
                x[i] = 1.0;
                (self.value(ext, &x) - base).abs()
            })
            .collect()
    }

    /// The series (6 per vessel, of `n_series`) the channel's value changes with.
    pub fn series(&self, ext: &External, n_series: usize) -> Vec<usize> {
        let gradient = self.gradient(ext, n_series);
        (0..n_series)
            .filter(|&i| gradient[i].is_finite() && gradient[i] > 0.0)
            .collect()
    }

    /// The channel's trusted span (from, to), s of lead, from each series' (`span(i)`, as the
    /// forecast sends them): where every series it reads is trusted (a relative motion: both
    /// vessels'). (0, 0): not trusted, or it reads no series.
    pub fn span_s(&self, ext: &External, n_series: usize, span: impl Fn(usize) -> (f64, f64)) -> (f64, f64) {
        let read = self.series(ext, n_series);
        if read.is_empty() {
            return (0.0, 0.0);
        }
        let (from, to) = read.iter().fold((0.0f64, f64::INFINITY), |(f, t), &i| {
            let (a, b) = span(i);
            (f.max(a), t.min(b))
        });
        if to > 0.0 && to >= from { (from, to) } else { (0.0, 0.0) }
    }
}

impl Channel {
    /// The channel along a forecast: `series[s][k]` is series s (6 per vessel, m or rad) at sample k;
    /// as many values as the shortest series.
    pub fn along<S: AsRef<[f64]>>(&self, ext: &External, series: &[S]) -> Vec<f64> {
        let n = series.iter().map(|s| s.as_ref().len()).min().unwrap_or(0);
        let mut x = vec![0.0; series.len()];
        (0..n)
            .map(|k| {
                for (xi, s) in x.iter_mut().zip(series) {
                    *xi = s.as_ref()[k];
                }
                self.value(ext, &x)
            })
            .collect()
    }
}

/// The span a set of channels is trusted over (from, to), s of lead: where each of them is
/// ([`Channel::span_s`]); (0, infinity) for none.
pub fn trusted_span_s(
    channels: &[Channel],
    ext: &External,
    n_series: usize,
    span: impl Fn(usize) -> (f64, f64),
) -> (f64, f64) {
    let (from, to) = channels
        .iter()
        .map(|c| c.span_s(ext, n_series, &span))
        .fold((0.0f64, f64::INFINITY), |(f, t), (a, b)| (f.max(a), t.min(b)));
    if to > 0.0 && to >= from { (from, to) } else { (0.0, 0.0) }
}

/// Resolves a channel name against the vessels' names and the system's points and relative motions.
/// The error names what would have been accepted.
pub fn resolve(name: &str, vessels: &[String], ext: &External) -> Result<Source, String> {
    let (head, tail) = name
        .rsplit_once('.')
        .ok_or_else(|| format!("channel \"{name}\": expected <vessel>.<dof> or <point>.<x|y|z>"))?;
    if let Some(vessel) = vessels.iter().position(|v| v == head) {
        return Dof::NAMES
            .iter()
            .position(|d| *d == tail)
            .map(|dof| Source::Dof { vessel, dof })
            .ok_or_else(|| {
                format!(
                    "channel \"{name}\": unknown DOF \"{tail}\" (one of {})",
                    Dof::NAMES.join(", ")
                )
            });
    }
    let axis = match tail {
        "x" => 0,
        "y" => 1,
        "z" => 2,
        _ => {
            return Err(format!(
                "channel \"{name}\": \"{head}\" is not a vessel, and a point's component is x, y or z"
            ));
        }
    };
    if let Some(point) = ext.points.iter().position(|p| p.name == head) {
        return Ok(Source::Point { point, axis });
    }
    if let Some(relative) = ext.relative_motions.iter().position(|r| r.name == head) {
        return Ok(Source::Relative { relative, axis });
    }
    let mut known: Vec<&str> = vessels.iter().map(|v| v.as_str()).collect();
    known.extend(ext.points.iter().map(|p| p.name.as_str()));
    known.extend(ext.relative_motions.iter().map(|r| r.name.as_str()));
    Err(format!(
        "channel \"{name}\": no vessel, point or relative motion \"{head}\" (known: {})",
        known.join(", ")
    ))
}

/// Every channel name a system offers: each vessel's DOFs, each point's and relative motion's z, x, y.
pub fn available(vessels: &[String], ext: &External) -> Vec<String> {
    let mut out = vec![];
    for v in vessels {
        out.extend(Dof::NAMES.iter().map(|d| format!("{v}.{d}")));
    }
    for n in ext
        .points
        .iter()
        .map(|p| &p.name)
        .chain(ext.relative_motions.iter().map(|r| &r.name))
    {
        out.extend(["z", "x", "y"].iter().map(|a| format!("{n}.{a}")));
    }
    out
}

/// A quiescent window: every channel inside its limit from `start_s` to `end_s` (sample times).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Window {
    pub start_s: f64,
    pub end_s: f64,
    /// The window reaches the end of the span looked at (the trusted horizon): it may last longer.
    pub open_end: bool,
}

impl Window {
    pub fn length_s(&self) -> f64 {
        self.end_s - self.start_s
    }
}

/// Whether every channel is inside its limit, sample by sample. `values[c][k]` is channel `c` at
/// sample `k`; a non-finite value is outside (an unknown motion is never quiet).
pub fn inside(values: &[&[f64]], limits: &[f64]) -> Vec<bool> {
    let n = values.iter().map(|v| v.len()).min().unwrap_or(0);
    (0..n)
        .map(|k| {
            values
                .iter()
                .zip(limits)
                .all(|(v, l)| v[k].is_finite() && v[k].abs() <= *l)
        })
        .collect()
}

/// Whether every channel is inside its limit with at least `confidence` probability, sample by
/// sample, each channel normal with mean `values[c][k]` and standard deviation `sigmas[c][k]` (an
/// empty `sigmas[c]`: none). The probability that some channel is outside is at most the sum of
/// each one's ([`crate::band::exceedance`]; no assumption on how they move together).
pub fn inside_with_confidence(values: &[&[f64]], sigmas: &[&[f64]], limits: &[f64], confidence: f64) -> Vec<bool> {
    let n = values.iter().map(|v| v.len()).min().unwrap_or(0);
    (0..n)
        .map(|k| {
            let mut p = 0.0;
            for ((v, s), l) in values.iter().zip(sigmas).zip(limits) {
                if !v[k].is_finite() {
                    return false;
                }
                let sd = s.get(k).copied().unwrap_or(0.0);
                if !sd.is_finite() {
                    return false;
                }
                p += crate::band::exceedance(v[k], sd, *l);
            }
            p <= 1.0 - confidence
        })
        .collect()
}

/// The maximal runs of inside samples lasting at least `min_length_s`, for samples at t0 + k dt.
/// A run touching the last sample is `open_end` and is kept whatever its length (it may go on).
pub fn windows(t0_s: f64, dt_s: f64, ok: &[bool], min_length_s: f64) -> Vec<Window> {
    let mut out = vec![];
    let mut k = 0;
    while k < ok.len() {
        if !ok[k] {
            k += 1;
            continue;
        }
        let start = k;
        while k < ok.len() && ok[k] {
            k += 1;
        }
        let w = Window {
            start_s: t0_s + start as f64 * dt_s,
            end_s: t0_s + (k - 1) as f64 * dt_s,
            open_end: k == ok.len(),
        };
        if w.open_end || w.length_s() >= min_length_s - 1e-9 {
            out.push(w);
        }
    }
    out
}

/// Number of samples at t0 + k dt inside the trusted horizon (t - t0 <= horizon), of `n`.
pub fn trusted_samples(n: usize, dt_s: f64, horizon_s: f64) -> usize {
    if !(horizon_s >= 0.0 && dt_s > 0.0) {
        return 0;
    }
    let k = (horizon_s / dt_s + 1e-9).floor();
    if k >= n as f64 { n } else { k as usize + 1 }
}

/// Times where a series crosses its limit (|x| goes from inside to outside or back), linearly
/// interpolated between samples.
pub fn limit_crossings(t0_s: f64, dt_s: f64, x: &[f64], limit: f64) -> Vec<f64> {
    let mut out = vec![];
    for k in 1..x.len() {
        let (a, b) = (x[k - 1], x[k]);
        if !(a.is_finite() && b.is_finite()) || (a.abs() <= limit) == (b.abs() <= limit) {
            continue;
        }
        // the bound crossed is the one on the outside sample's side
        let outside = if a.abs() > limit { a } else { b };
        let bound = limit.copysign(outside);
        let f = if b != a {
            ((bound - a) / (b - a)).clamp(0.0, 1.0)
        } else {
            0.0
        };
        out.push(t0_s + (k as f64 - 1.0 + f) * dt_s);
    }
    out
}

/// The operator's verdict for starting the operation now.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Verdict {
    /// A window opens now and lasts at least the duration within the trusted horizon.
    Go { window_s: f64 },
    /// A channel is outside its limit now, or will be before the duration has passed.
    NoGo { next_window_in_s: Option<f64> },
    /// The trusted horizon is shorter than the duration: the forecast cannot say.
    Unknown,
}

/// The verdict for an operation of `duration_s` starting at `now_s`, from the windows of the trusted
/// span (as [`windows`] returns them with `min_length_s` = the duration).
pub fn verdict(windows: &[Window], now_s: f64, duration_s: f64) -> Verdict {
    let current = windows.iter().find(|w| w.start_s <= now_s + 1e-9 && w.end_s >= now_s);
    match current {
        Some(w) if w.end_s - now_s >= duration_s - 1e-9 => Verdict::Go {
            window_s: w.end_s - now_s,
        },
        Some(w) if w.open_end => Verdict::Unknown,
        _ => Verdict::NoGo {
            next_window_in_s: windows
                .iter()
                .find(|w| w.start_s > now_s && (w.length_s() >= duration_s - 1e-9 || w.open_end))
                .map(|w| w.start_s - now_s),
        },
    }
}

/// Forecast windows matched against the windows that happened.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct WindowScore {
    /// Windows that happened and were forecast (overlapping a forecast window).
    pub hits: usize,
    /// Windows that happened and were not forecast.
    pub misses: usize,
    /// Forecast windows during which the operation would have met a limit (no window that happened
    /// covers its first `duration_s`).
    pub false_alarms: usize,
    /// Forecast windows that held for their first `duration_s`.
    pub good_calls: usize,
    /// Start of the forecast window minus start of the matched window, per hit, s.
    pub timing_errors_s: Vec<f64>,
}

impl WindowScore {
    /// hits / (hits + misses); None without windows that happened.
    pub fn detection_rate(&self) -> Option<f64> {
        let n = self.hits + self.misses;
        (n > 0).then(|| self.hits as f64 / n as f64)
    }

    /// false alarms / forecast windows; None without forecast windows.
    pub fn false_alarm_ratio(&self) -> Option<f64> {
        let n = self.false_alarms + self.good_calls;
        (n > 0).then(|| self.false_alarms as f64 / n as f64)
    }

    pub fn add(&mut self, o: &WindowScore) {
        self.hits += o.hits;
        self.misses += o.misses;
        self.false_alarms += o.false_alarms;
        self.good_calls += o.good_calls;
        self.timing_errors_s.extend(&o.timing_errors_s);
    }
}

/// Scores forecast windows against the windows that happened over the same span; only windows of at
/// least `duration_s` count (an open-ended forecast window shorter than that is not a call).
pub fn score_windows(forecast: &[Window], actual: &[Window], duration_s: f64) -> WindowScore {
    let long = |w: &&Window| w.length_s() >= duration_s - 1e-9;
    let mut s = WindowScore::default();
    let forecast: Vec<&Window> = forecast.iter().filter(long).collect();
    for a in actual.iter().filter(long) {
        let hit = forecast.iter().find(|f| f.start_s <= a.end_s && f.end_s >= a.start_s);
        match hit {
            Some(f) => {
                s.hits += 1;
                s.timing_errors_s.push(f.start_s - a.start_s);
            }
            None => s.misses += 1,
        }
    }
    for f in forecast {
        let held = actual
            .iter()
            .any(|a| a.start_s <= f.start_s + 1e-9 && a.end_s >= f.start_s + duration_s - 1e-9);
        if held {
            s.good_calls += 1;
        } else {
            s.false_alarms += 1;
        }
    }
    s
}

/// A forecast as [`score_forecast_windows`] takes it: series s (6 per vessel) at t0 + k dt, each
/// value's standard deviation (`sigma`, same layout; empty: none), and the trusted span (lead s).
#[derive(Debug, Clone, Copy)]
pub struct SpanForecast<'a> {
    pub t0_s: f64,
    pub dt_s: f64,
    pub values: &'a [&'a [f64]],
    pub sigma: &'a [&'a [f64]],
    pub trusted_from_s: f64,
    pub trusted_s: f64,
}

/// One forecast's operator windows against the motion measured over its trusted span, as the console
/// judges them (a step is quiet when every channel is inside its limit with `confidence` by the band):
/// channel values of the forecast and of the measurement (`measured[s]`: sorted (t, value) of series
/// s), windows of each, matched by [`score_windows`]. None when the measurement does not cover the
/// span.
pub fn score_forecast_windows(
    channels: &[Channel],
    ext: &External,
    f: &SpanForecast,
    measured: &[Vec<(f64, f64)>],
    duration_s: f64,
    confidence: f64,
) -> Option<WindowScore> {
    let (t0_s, dt_s, forecast) = (f.t0_s, f.dt_s, f.values);
    let n = forecast.iter().map(|s| s.len()).min()?;
    let m = trusted_samples(n, dt_s, f.trusted_s);
    let first = ((f.trusted_from_s / dt_s - 1e-9).ceil().max(0.0) as usize).min(m);
    if m < first + 2 || measured.len() < forecast.len() {
        return None;
    }
    let span: Vec<&[f64]> = forecast.iter().map(|s| &s[first..m]).collect();
    let vf: Vec<Vec<f64>> = channels.iter().map(|ch| ch.along(ext, &span)).collect();
    let bands: Vec<Vec<f64>> = if f.sigma.len() == forecast.len() && f.sigma.iter().all(|s| s.len() >= m) {
        let span: Vec<&[f64]> = f.sigma.iter().map(|s| &s[first..m]).collect();
        channels.iter().map(|ch| ch.sigma_along(ext, &span)).collect()
    } else {
        vec![vec![]; channels.len()]
    };
    let mut xm = vec![0.0; forecast.len()];
    let mut vm = vec![Vec::with_capacity(m - first); channels.len()];
    for k in first..m {
        let t = t0_s + k as f64 * dt_s;
        for s in 0..forecast.len() {
            xm[s] = crate::skill::interpolate(&measured[s], t)?;
        }
        for (c, ch) in channels.iter().enumerate() {
            vm[c].push(ch.value(ext, &xm));
        }
    }
    let limits: Vec<f64> = channels.iter().map(|c| c.limit).collect();
    let fv: Vec<&[f64]> = vf.iter().map(|x| x.as_slice()).collect();
    let fb: Vec<&[f64]> = bands.iter().map(|x| x.as_slice()).collect();
    let mv: Vec<&[f64]> = vm.iter().map(|x| x.as_slice()).collect();
    let start = t0_s + first as f64 * dt_s;
    let wf = windows(
        start,
        dt_s,
        &inside_with_confidence(&fv, &fb, &limits, confidence),
        duration_s,
    );
    let wm = windows(start, dt_s, &inside(&mv, &limits), duration_s);
    Some(score_windows(&wf, &wm, duration_s))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn windows_are_the_long_enough_runs_and_the_last_one_is_open() {
        //          0    1    2     3    4    5    6    7     8    9
        let ok = [true, true, false, true, true, true, true, false, true, true];
        let w = windows(10.0, 1.0, &ok, 3.0);
        assert_eq!(
            w,
            vec![
                Window {
                    start_s: 13.0,
                    end_s: 16.0,
                    open_end: false
                },
                Window {
                    start_s: 18.0,
                    end_s: 19.0,
                    open_end: true
                },
            ]
        );
        assert!(windows(0.0, 1.0, &[false; 4], 0.0).is_empty());
    }

    #[test]
    fn inside_with_confidence_needs_the_band_inside_the_limit() {
        // 0.5 with sigma 0.25 against a limit of 1: P(outside) = P(z > 2) ~ 0.023: inside at 0.9
        let v = [0.5, 0.5, 0.5, f64::NAN];
        let s = [0.25, 0.4, f64::NAN, 0.1];
        let ok = inside_with_confidence(&[&v], &[&s], &[1.0], 0.9);
        // sigma 0.4: P(z > 1.25) ~ 0.106 > 0.1: outside; a non-finite value or band: outside
        assert_eq!(ok, vec![true, false, false, false]);
        // two channels each at 0.06: together 0.12 > 0.1
        let v1 = [0.0];
        let s1 = [1.0 / 1.880_794];
        assert_eq!(inside_with_confidence(&[&v1], &[&s1], &[1.0], 0.9), vec![true]);
        assert_eq!(
            inside_with_confidence(&[&v1, &v1], &[&s1, &s1], &[1.0, 1.0], 0.9),
            vec![false]
        );
        // no band: the value alone
        assert_eq!(inside_with_confidence(&[&v1], &[&[][..]], &[1.0], 0.9), vec![true]);
    }

    #[test]
    fn inside_needs_every_channel_and_finite_values() {
        let a = [0.5, 1.5, 0.2, f64::NAN];
        let b = [-0.9, 0.0, -1.1, 0.0];
        assert_eq!(inside(&[&a, &b], &[1.0, 1.0]), vec![true, false, false, false]);
    }

    #[test]
    fn crossings_are_interpolated_on_either_bound() {
        let x = [0.0, 2.0, 0.0, -2.0, 0.0];
        let c = limit_crossings(0.0, 1.0, &x, 1.0);
        assert_eq!(c, vec![0.5, 1.5, 2.5, 3.5]);
        assert!(limit_crossings(0.0, 1.0, &[0.0, 0.5], 1.0).is_empty());
    }

    #[test]
    fn trusted_samples_stop_at_the_horizon() {
        assert_eq!(trusted_samples(1201, 0.1, 45.0), 451);
        assert_eq!(trusted_samples(1201, 0.1, 500.0), 1201);
        assert_eq!(trusted_samples(1201, 0.1, -1.0), 0);
        assert_eq!(trusted_samples(1201, 0.1, f64::INFINITY), 1201);
        assert_eq!(trusted_samples(1201, 0.1, f64::NAN), 0);
    }

    #[test]
    fn verdicts() {
        let w = |s: f64, e: f64, open: bool| Window {
            start_s: s,
            end_s: e,
            open_end: open,
        };
        assert_eq!(
            verdict(&[w(0.0, 90.0, false)], 0.0, 60.0),
            Verdict::Go { window_s: 90.0 }
        );
        assert_eq!(verdict(&[w(0.0, 30.0, true)], 0.0, 60.0), Verdict::Unknown);
        assert_eq!(
            verdict(&[w(0.0, 30.0, false), w(50.0, 120.0, false)], 0.0, 60.0),
            Verdict::NoGo {
                next_window_in_s: Some(50.0)
            }
        );
        assert_eq!(verdict(&[], 0.0, 60.0), Verdict::NoGo { next_window_in_s: None });
    }

    #[test]
    fn window_scores_count_hits_misses_and_false_alarms() {
        let w = |s: f64, e: f64| Window {
            start_s: s,
            end_s: e,
            open_end: false,
        };
        let actual = [w(0.0, 100.0), w(200.0, 300.0), w(400.0, 420.0)];
        let forecast = [w(10.0, 90.0), w(150.0, 260.0), w(500.0, 600.0)];
        let s = score_windows(&forecast, &actual, 60.0);
        assert_eq!((s.hits, s.misses), (2, 0)); // the 20 s window is too short to count
        assert_eq!(s.timing_errors_s, vec![10.0, -50.0]);
        // 10..70 held; 150.. did not (the sea was rough until 200); 500.. did not
        assert_eq!((s.good_calls, s.false_alarms), (1, 2));
        assert_eq!(s.detection_rate(), Some(1.0));
        assert!((s.false_alarm_ratio().unwrap() - 2.0 / 3.0).abs() < 1e-12);
    }

    #[test]
    fn a_perfect_forecast_scores_hits_only_and_a_calm_one_false_alarms() {
        let ch = [Channel {
            name: "a.heave".into(),
            source: Source::Dof { vessel: 0, dof: 2 },
            limit: 1.0,
        }];
        let ext = External::default();
        // heave bursts above 1 m between 40 and 60 s, quiet otherwise
        let heave = |t: f64| if (40.0..60.0).contains(&t) { 1.5 } else { 0.3 };
        let n = 121;
        let series: Vec<Vec<f64>> = (0..6)
            .map(|s| (0..n).map(|k| if s == 2 { heave(k as f64) } else { 0.0 }).collect())
            .collect();
        let measured: Vec<Vec<(f64, f64)>> = (0..6)
            .map(|s| {
                (0..=130)
                    .map(|k| (k as f64, if s == 2 { heave(k as f64) } else { 0.0 }))
                    .collect()
            })
            .collect();
        fn at<'a>(values: &'a [&'a [f64]], sigma: &'a [&'a [f64]], t0_s: f64, from: f64, to: f64) -> SpanForecast<'a> {
            SpanForecast {
                t0_s,
                dt_s: 1.0,
                values,
                sigma,
                trusted_from_s: from,
                trusted_s: to,
            }
        }
        let f: Vec<&[f64]> = series.iter().map(|s| s.as_slice()).collect();
        let s = score_forecast_windows(&ch, &ext, &at(&f, &[], 0.0, 0.0, 120.0), &measured, 30.0, 0.9).unwrap();
        assert_eq!((s.hits, s.misses, s.false_alarms, s.good_calls), (2, 0, 0, 2));
        assert_eq!(s.timing_errors_s, vec![0.0, 0.0]);
        let calm_owned: Vec<Vec<f64>> = (0..6).map(|_| vec![0.0; n]).collect();
        let calm: Vec<&[f64]> = calm_owned.iter().map(|s| s.as_slice()).collect();
        let s = score_forecast_windows(&ch, &ext, &at(&calm, &[], 0.0, 0.0, 120.0), &measured, 30.0, 0.9).unwrap();
        // one long forecast window over the whole span: it overlaps both real ones, and it held for
        // its first 30 s (the burst comes at 40 s)
        assert_eq!((s.hits, s.misses, s.false_alarms, s.good_calls), (2, 0, 0, 1));
        // starting at 20 s the same calm call fails: the burst is inside its first 30 s
        let s = score_forecast_windows(&ch, &ext, &at(&calm, &[], 20.0, 0.0, 100.0), &measured, 30.0, 0.9).unwrap();
        assert_eq!((s.false_alarms, s.good_calls), (1, 0));
        // the calm call with a band of 0.7 m on heave: 0 +- 0.7 is likelier than 10 % to leave 1 m, so
        // no quiet window is forecast: both real ones are missed, and no false alarm
        let wide_owned: Vec<Vec<f64>> = (0..6).map(|s| vec![if s == 2 { 0.7 } else { 0.0 }; n]).collect();
        let wide: Vec<&[f64]> = wide_owned.iter().map(|s| s.as_slice()).collect();
        let s = score_forecast_windows(&ch, &ext, &at(&calm, &wide, 0.0, 0.0, 120.0), &measured, 30.0, 0.9).unwrap();
        assert_eq!((s.hits, s.misses, s.false_alarms), (0, 2, 0));
        // a span from 70 s: only the real window after the burst is scored, from its start
        let s = score_forecast_windows(&ch, &ext, &at(&f, &[], 0.0, 70.0, 120.0), &measured, 30.0, 0.9).unwrap();
        assert_eq!((s.hits, s.misses, s.timing_errors_s.clone()), (1, 0, vec![0.0]));
        // no measurement beyond 130 s: a forecast reaching past it is not scored
        assert!(score_forecast_windows(&ch, &ext, &at(&calm, &[], 20.0, 0.0, 120.0), &measured, 30.0, 0.9).is_none());
    }
}
