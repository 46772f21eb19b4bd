//! Drawing the console (pure: into a ratatui frame). The words an operator reads are decided by
//! [`banner`] and [`health_lines`] (tested on their own); [`draw`] lays them out with the charts.

use super::{Console, Forecast, Health, Link, LinkHealth, Outlook};
use crate::operation::{Channel, Verdict};
use ratatui::Frame;
use ratatui::layout::{Alignment, Constraint, Layout, Rect};
use ratatui::style::{Color, Modifier, Style};
use ratatui::symbols::Marker;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Axis, Block, Borders, Chart, Clear, Dataset, GraphType, Paragraph, Wrap};

/// How loud a line is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Severity {
    Ok,
    Caution,
    Alarm,
}

/// Below this size the console shows text only.
const MIN_CHART_WIDTH: u16 = 60;
const MIN_CHART_HEIGHT: u16 = 16;

fn colour(c: &Console, s: Severity) -> Color {
    match s {
        Severity::Ok => c.settings.colours.go,
        Severity::Caution => c.settings.colours.caution,
        Severity::Alarm => c.settings.colours.no_go,
    }
}

/// The one line that matters: can the operation start now, or why the console cannot say.
pub fn banner(c: &Console, now_wall_s: f64) -> (Severity, String) {
    if let Some(b) = link_banner(c.link(now_wall_s)) {
        return b;
    }
    if !c.forecast_is_current(now_wall_s) {
        let why = suspended_reason(c, now_wall_s);
        return (
            Severity::Alarm,
            format!("Forecast suspended: {why}. NO-GO until it returns."),
        );
    }
    let Some(o) = c.outlook() else {
        return (Severity::Caution, "No channels chosen: press a to add one".into());
    };
    verdict_banner(c, &o)
}

/// The banner when the daemon is not live (waiting, stopped or silent); `None` when it is.
fn link_banner(link: Link) -> Option<(Severity, String)> {
    match link {
        Link::Waiting => Some((
            Severity::Caution,
            "Waiting for shipcast: no forecast or status yet (is `shipcast run` running?)".into(),
        )),
        Link::Stopped => Some((
            Severity::Alarm,
            "shipcast has STOPPED: no forecast. Do not use the traces below.".into(),
        )),
        Link::Silent { silent_s } => Some((
            Severity::Alarm,
            format!("shipcast NOT RESPONDING for {silent_s:.0} s: the forecast below is STALE, do not use it"),
        )),
        Link::Live => None,
    }
}

/// Why the forecast is not current, in an operator's words: the radar, the IMUs, the model, or its age.
fn suspended_reason(c: &Console, now_wall_s: f64) -> String {
    let h = c.health.as_ref();
    let has = |f: &str| h.is_some_and(|h| h.flags.contains(&f));
    if has("no_waves") {
        match h.map(|h| h.wave_age_s) {
            Some(a) if a >= 0.0 => format!("radar data {a:.0} s old"),
            _ => "no radar data yet".into(),
        }
    } else if has("no_motion") {
        stale_motion_reason(c, h)
    } else if has("numerical_trouble") {
        "the model diverged".into()
    } else {
        match &c.forecast {
            Some(f) => format!("last forecast {:.0} s ago", now_wall_s - f.received_wall_s),
            None => "no forecast yet".into(),
        }
    }
}

/// The vessels whose IMU data is missing or older than 2 s, or "no motion data" when none is.
fn stale_motion_reason(c: &Console, h: Option<&Health>) -> String {
    let stale: Vec<String> = h
        .map(|h| {
            h.motion_age_s
                .iter()
                .zip(&c.vessels)
                .filter(|(a, _)| **a < 0.0 || **a > 2.0)
                .map(|(a, n)| {
                    if *a < 0.0 {
                        format!("no IMU data from {n}")
                    } else {
                        format!("{n} IMU data {a:.0} s old")
                    }
                })
                .collect()
        })
        .unwrap_or_default();
    if stale.is_empty() {
        "no motion data".into()
    } else {
        stale.join(", ")
    }
}

/// The banner for a current forecast: go, no-go or can't tell, from the outlook `o`.
fn verdict_banner(c: &Console, o: &Outlook) -> (Severity, String) {
    let d = c.settings.duration_s;
    match o.verdict {
        Verdict::Go { window_s } => (
            Severity::Ok,
            format!(
                "GO ({:.0} % confidence): every channel inside its limits for the next {window_s:.0} s ({d:.0} s operation)",
                100.0 * c.settings.confidence
            ),
        ),
        Verdict::Unknown if o.trusted_from_s > 0.0 && o.trusted_from_s < o.trusted_s => (
            Severity::Caution,
            format!(
                "CAN'T TELL: the forecast is trusted from {:.0} s to {:.0} s ahead: not the next {:.0} s",
                o.trusted_from_s, o.trusted_s, o.trusted_from_s
            ),
        ),
        Verdict::Unknown if o.trusted_from_s > 0.0 => (
            Severity::Caution,
            "CAN'T TELL: the channels' trusted spans do not overlap".into(),
        ),
        Verdict::Unknown => (
            Severity::Caution,
            format!(
                "CAN'T TELL: the forecast is trusted {:.0} s ahead, less than the {d:.0} s operation",
                o.trusted_s
            ),
        ),
        Verdict::NoGo { next_window_in_s } => no_go_banner(c, o, next_window_in_s),
    }
}

/// The no-go banner: which channel leaves its limit and when, and when the next window opens.
fn no_go_banner(c: &Console, o: &Outlook, next_window_in_s: Option<f64>) -> (Severity, String) {
    let d = c.settings.duration_s;
    let who = match &o.first_exceedance {
        Some((n, t)) if *t <= 0.0 => format!("{n} outside its limit now"),
        Some((n, t)) => format!("{n} leaves its limit in {}", fmt_in(*t)),
        None => "a channel leaves its limit".into(),
    };
    let next = match next_window_in_s {
        Some(t) => format!("next window in {}", fmt_in(t)),
        None => format!("no {d:.0} s window within the trusted {:.0} s", o.trusted_s),
    };
    (
        Severity::Alarm,
        format!(
            "NO-GO ({:.0} % confidence): {who}; {next}",
            100.0 * c.settings.confidence
        ),
    )
}

/// The inputs' health in an operator's words.
pub fn health_lines(c: &Console, now_wall_s: f64) -> Vec<(Severity, String)> {
    let mut out = vec![];
    let link = c.link(now_wall_s);
    out.push(daemon_line(c, link));
    if let Some(f) = &c.forecast {
        forecast_lines(c, f, now_wall_s, &mut out);
    }
    if let Some(h) = &c.health {
        sensor_lines(c, h, &mut out);
        if let Some(l) = &h.link {
            out.push(ship_link_line(l));
        }
        flag_lines(c, h, &mut out);
    }
    out
}

/// The daemon's state: waiting, live (with its forecast period), silent or stopped.
fn daemon_line(c: &Console, link: Link) -> (Severity, String) {
    match link {
        Link::Waiting => (Severity::Caution, "shipcast: waiting".to_string()),
        Link::Live => (
            Severity::Ok,
            format!("shipcast: live (forecast every {:.1} s)", c.settings.period_s),
        ),
        Link::Silent { silent_s } => (Severity::Alarm, format!("shipcast: silent for {silent_s:.0} s")),
        Link::Stopped => (Severity::Alarm, "shipcast: stopped".into()),
    }
}

/// Pushes the forecast's age and compute time, then each vessel's trusted span, onto `out`.
fn forecast_lines(c: &Console, f: &Forecast, now_wall_s: f64, out: &mut Vec<(Severity, String)>) {
    let age = now_wall_s - f.received_wall_s;
    let s = if c.forecast_is_current(now_wall_s) {
        Severity::Ok
    } else {
        Severity::Alarm
    };
    // the daemon's own figure for the whole path, from the sensor's stamp to the hand-over
    let path = match &c.health {
        Some(h) if h.latency_p50_ms >= 0.0 => format!(
            " (sensor to publish {:.0} ms, p99 {:.0} ms)",
            h.latency_p50_ms, h.latency_p99_ms
        ),
        _ => String::new(),
    };
    out.push((
        s,
        format!("Forecast: {age:.0} s old, computed in {:.0} ms{path}", f.compute_ms),
    ));
    for (b, (n, h)) in c.vessels.iter().zip(&f.horizon_s).enumerate() {
        // each of heave, roll and pitch's own span, when the daemon sent them
        let dofs: String = if f.series_span_s.len() >= 6 * (b + 1) {
            let span = |d: usize, name: &str| {
                let [from, to] = f.series_span_s[6 * b + d];
                format!("{name} {from:.0}-{to:.0}")
            };
            format!(" ({}, {}, {} s)", span(2, "heave"), span(3, "roll"), span(4, "pitch"))
        } else {
            String::new()
        };
        match f.trusted_from_s.get(b).copied().filter(|x| *x > 0.0) {
            Some(from) => out.push((
                Severity::Caution,
                format!("Trusted ahead: {n} {from:.0}-{h:.0} s{dofs}"),
            )),
            None => out.push((Severity::Ok, format!("Trusted ahead: {n} {h:.0} s{dofs}"))),
        }
    }
}

/// Pushes the radar's data age, then each vessel's IMU age and rate, onto `out`.
fn sensor_lines(c: &Console, h: &Health, out: &mut Vec<(Severity, String)>) {
    out.push(match h.wave_age_s {
        a if a < 0.0 => (Severity::Alarm, "Radar: no data yet".into()),
        a if h.flags.contains(&"no_waves") => {
            (Severity::Alarm, format!("Radar: data {a:.0} s old, forecast suspended"))
        }
        a if h.flags.contains(&"stale_waves") => (
            Severity::Caution,
            format!("Radar: data {a:.0} s old, forecast less sure"),
        ),
        a => (Severity::Ok, format!("Radar: data {a:.1} s old")),
    });
    for ((n, a), r) in c.vessels.iter().zip(&h.motion_age_s).zip(&h.motion_rate_hz) {
        out.push(if *a < 0.0 {
            (Severity::Alarm, format!("{n} IMU: no data yet"))
        } else if *a > 2.0 {
            (Severity::Alarm, format!("{n} IMU: no data for {a:.0} s"))
        } else {
            (Severity::Ok, format!("{n} IMU: {a:.1} s old, {r:.0} Hz"))
        });
    }
}

/// The ship-to-ship link: up with its latency and loss, or down and for how long.
fn ship_link_line(l: &LinkHealth) -> (Severity, String) {
    let lat = if l.latency_ms >= 0.0 {
        format!("{:.0} ms", l.latency_ms)
    } else {
        "-".into()
    };
    let loss = if l.loss >= 0.0 {
        format!("{:.0} %", 100.0 * l.loss)
    } else {
        "-".into()
    };
    match (l.up, l.age_s) {
        (true, a) => (
            Severity::Ok,
            format!("Link to the other ship: up, latency {lat}, loss {loss}, last {a:.1} s ago"),
        ),
        (false, a) if a < 0.0 => (Severity::Alarm, "Link to the other ship: nothing heard yet".into()),
        (false, a) => (
            Severity::Alarm,
            format!("Link to the other ship: down, nothing for {a:.0} s (loss {loss})"),
        ),
    }
}

/// Pushes the lines of the health's flags (warm-up, clocks, radar, gaps, divergence) and the
/// overruns onto `out`.
fn flag_lines(c: &Console, h: &Health, out: &mut Vec<(Severity, String)>) {
    if h.flags.contains(&"history_short") {
        out.push((
            Severity::Caution,
            match c.warmup() {
                Some((_, left)) => format!(
                    "Warming up: {left:.0} s more until the {:.0} s motion memory is full; less sure until then",
                    c.settings.history_wanted_s
                ),
                None => "Motion history short (a gap or a restart): less sure".into(),
            },
        ));
    }
    for (flag, words) in [
        ("clocks_disagree", "Sensor clocks disagree: no forecast"),
        ("clock_step", "A sensor clock stepped: re-synchronized"),
        ("wave_region_unknown", "Radar: field without its region: not trusted"),
        ("no_wave_components", "Radar: an empty field: not trusted"),
        ("waves_dropped", "Part of the sea is outside the vessel database"),
        (
            "waves_frozen",
            "Radar: the wave processor repeats itself (frozen): its last field ages",
        ),
        ("waves_implausible", "Radar: a field that is not a sea was refused"),
        (
            "model_speed_mismatch",
            "Model not rebuilt for this speed (beyond its databases): not trusted",
        ),
        (
            "motion_clock_apart",
            "A vessel's clock disagrees with the radar's: it is not trusted",
        ),
        (
            "motion_settling",
            "Motion sensor re-zeroed: not trusted until its new offset is learnt",
        ),
        (
            "model_error_unchecked",
            "Learning the model's error: no lead trusted until forecasts are checked",
        ),
    ] {
        if h.flags.contains(&flag) {
            out.push((Severity::Caution, words.into()));
        }
    }
    if h.flags.contains(&"history_gap") {
        out.push((
            Severity::Caution,
            "A gap in the motion history (bridged, or at rest where long)".into(),
        ));
    }
    if h.flags.contains(&"numerical_trouble") {
        out.push((Severity::Alarm, "The model diverged: no forecast".into()));
    }
    if h.overruns > 0 {
        out.push((Severity::Caution, format!("{} forecasts ran late", h.overruns)));
    }
}

/// Four evenly spaced time labels (ratatui spreads labels evenly), "now" at 0.
fn time_labels(from_s: f64, to_s: f64) -> Vec<String> {
    (0..4)
        .map(|i| {
            let t = from_s + (to_s - from_s) * i as f64 / 3.0;
            if t.abs() < 0.05 * (to_s - from_s) {
                "now".to_string()
            } else {
                format!("{t:+.0} s")
            }
        })
        .collect()
}

/// A lead time as an operator reads it.
fn fmt_in(t: f64) -> String {
    if t < 10.0 {
        format!("{t:.1} s")
    } else {
        format!("{t:.0} s")
    }
}

fn fmt_window(w: &crate::operation::Window) -> String {
    let start = if w.start_s <= 0.0 {
        "now".to_string()
    } else {
        format!("in {:.0} s", w.start_s)
    };
    if w.open_end {
        format!("{start:>8}, at least {:.0} s", w.length_s())
    } else {
        format!("{start:>8}, {:.0} s long", w.length_s())
    }
}

/// Draws the whole console for wall time `now_wall_s`.
pub fn draw(frame: &mut Frame, c: &Console, now_wall_s: f64) {
    let area = frame.area();
    if area.width < MIN_CHART_WIDTH || area.height < MIN_CHART_HEIGHT {
        draw_text(frame, area, c, now_wall_s);
        return;
    }
    let [top, middle, bottom] =
        Layout::vertical([Constraint::Length(3), Constraint::Min(8), Constraint::Length(1)]).areas(area);
    let (sev, text) = banner(c, now_wall_s);
    frame.render_widget(
        Paragraph::new(Line::from(Span::styled(
            text,
            Style::default().fg(colour(c, sev)).add_modifier(Modifier::BOLD),
        )))
        .block(Block::default().borders(Borders::ALL).title(" shipcast console ")),
        top,
    );
    let [charts, side] = Layout::horizontal([Constraint::Min(40), Constraint::Length(40)]).areas(middle);
    let n = c.settings.channels.len().max(1);
    let rows = Layout::vertical(vec![Constraint::Ratio(1, n as u32); n]).split(charts);
    for (i, ch) in c.settings.channels.iter().enumerate() {
        draw_chart(frame, rows[i], c, ch, i == c.selected, now_wall_s);
    }
    draw_side(frame, side, c, now_wall_s);
    let hint = c
        .note
        .clone()
        .unwrap_or_else(|| "? help  ↑↓ channel  +/- limit  [/] duration  a add  x remove  n night  q quit".into());
    frame.render_widget(Paragraph::new(hint).style(Style::default().fg(Color::Gray)), bottom);
    if c.help {
        draw_help(frame, area);
    }
}

/// Draws one channel's chart: the measured motion, the forecast with its band and trusted span, the
/// limits and now.
fn draw_chart(frame: &mut Frame, area: Rect, c: &Console, ch: &Channel, selected: bool, now_wall_s: f64) {
    let current = c.forecast_is_current(now_wall_s);
    let hist = c.settings.history_s;
    let s = chart_series(c, ch);
    let x_max = s.span_s.max(10.0);
    let y = chart_peak(&s, ch.limit) * 1.05;
    let marks = ChartMarks {
        limit_hi: [(-hist, ch.limit), (x_max, ch.limit)],
        limit_lo: [(-hist, -ch.limit), (x_max, -ch.limit)],
        horizon: [(s.horizon_s, -y), (s.horizon_s, y)],
        from: [(s.from_s, -y), (s.from_s, y)],
        now: [(0.0, -y), (0.0, y)],
    };
    let sets = chart_datasets(c, &s, &marks, current);
    let title = chart_title(c, ch, &s, selected, current);
    let chart = Chart::new(sets)
        .block(Block::default().borders(Borders::ALL).title(title))
        .x_axis(
            Axis::default()
                .bounds([-hist, x_max])
                .labels(time_labels(-hist, x_max))
                .style(Style::default().fg(Color::Gray)),
        )
        .y_axis(
            Axis::default()
                .bounds([-y, y])
                .labels([format!("{:.1}", -y), "0".into(), format!("{y:.1}")])
                .style(Style::default().fg(Color::Gray)),
        );
    frame.render_widget(chart, area);
}

/// One channel's traces on a chart, in (s from the forecast's issue, channel units).
struct ChartSeries {
    /// The forecast's length, s.
    span_s: f64,
    /// The end of the trusted span, s.
    horizon_s: f64,
    /// The start of the trusted span, s.
    from_s: f64,
    /// The first sample of the trusted span.
    k_f: usize,
    /// The forecast within the trusted span.
    trusted: Vec<(f64, f64)>,
    /// The forecast before the trusted span.
    before: Vec<(f64, f64)>,
    /// The forecast beyond the trusted span.
    beyond: Vec<(f64, f64)>,
    /// The band's upper edge: forecast + z sigma.
    band_hi: Vec<(f64, f64)>,
    /// The band's lower edge: forecast - z sigma.
    band_lo: Vec<(f64, f64)>,
    /// The measured motion over the history shown.
    measured: Vec<(f64, f64)>,
}

/// The straight lines of a chart: the limits, the trusted span's ends and now.
struct ChartMarks {
    limit_hi: [(f64, f64); 2],
    limit_lo: [(f64, f64); 2],
    horizon: [(f64, f64); 2],
    from: [(f64, f64); 2],
    now: [(f64, f64); 2],
}

/// The forecast of `ch` split at its trusted span, its band, and the measured motion before it.
fn chart_series(c: &Console, ch: &Channel) -> ChartSeries {
    let hist = c.settings.history_s;
    let (t0, dt) = c.forecast.as_ref().map_or_else(
        || (c.latest_measured_s().unwrap_or(0.0), 1.0),
        |f| (f.issue_time_s, f.dt_s),
    );
    let fc = c.forecast_channel(ch);
    let span_s = (fc.len().max(1) - 1) as f64 * dt;
    let horizon = c.horizon_of(ch).min(span_s);
    let k_h = crate::operation::trusted_samples(fc.len(), dt, horizon);
    let pts = |r: std::ops::Range<usize>| -> Vec<(f64, f64)> {
        r.filter(|k| fc[*k].is_finite())
            .map(|k| (k as f64 * dt, fc[k]))
            .collect()
    };
    let from = c.trusted_from_of(ch).min(horizon);
    let k_f = ((from / dt - 1e-9).ceil().max(0.0) as usize).min(k_h);
    let trusted = pts(k_f..k_h);
    let before = pts(0..(k_f + 1).min(fc.len()));
    let beyond = pts(k_h.saturating_sub(1)..fc.len());
    // the band holding the go's confidence: forecast +- z sigma
    let sigma = c.forecast_sigma(ch);
    let z = crate::band::band_z(c.settings.confidence);
    let band = |sign: f64| -> Vec<(f64, f64)> {
        (0..fc.len().min(sigma.len()))
            .filter(|k| fc[*k].is_finite() && sigma[*k].is_finite())
            .map(|k| (k as f64 * dt, fc[k] + sign * z * sigma[k]))
            .collect()
    };
    let (band_hi, band_lo) = (band(1.0), band(-1.0));
    let measured = c.measured_channel(ch, t0, -hist);
    ChartSeries {
        span_s,
        horizon_s: horizon,
        from_s: from,
        k_f,
        trusted,
        before,
        beyond,
        band_hi,
        band_lo,
        measured,
    }
}

/// The largest magnitude the chart shows (at least 1.2 times `limit`): of the traces and of the band
/// within the trusted span (beyond it, it may grow without bound).
fn chart_peak(s: &ChartSeries, limit: f64) -> f64 {
    let band_trusted = s
        .band_hi
        .iter()
        .chain(&s.band_lo)
        .filter(|p| p.0 >= s.from_s - 1e-9 && p.0 <= s.horizon_s + 1e-9);
    s.trusted
        .iter()
        .chain(&s.beyond)
        .chain(&s.before)
        .chain(&s.measured)
        .chain(band_trusted)
        .map(|p| p.1.abs())
        .filter(|v| v.is_finite())
        .fold(limit * 1.2, f64::max)
}

/// The chart's lines in drawing order: limits and now, then (with a forecast) the span's marks, the
/// band and the forecast, then the measured motion on top.
fn chart_datasets<'a>(c: &Console, s: &'a ChartSeries, m: &'a ChartMarks, current: bool) -> Vec<Dataset<'a>> {
    let colours = &c.settings.colours;
    let fc_colour = if current {
        colours.forecast
    } else {
        colours.beyond_horizon
    };
    let mut sets = vec![
        set(&m.limit_hi, colours.limit),
        set(&m.limit_lo, colours.limit),
        set(&m.now, Color::DarkGray),
    ];
    if c.forecast.is_some() {
        sets.push(set(&m.horizon, colours.beyond_horizon));
        if s.k_f > 0 {
            sets.push(set(&m.from, colours.beyond_horizon));
            sets.push(set(&s.before, colours.beyond_horizon));
        }
        sets.push(set(&s.band_hi, colours.beyond_horizon));
        sets.push(set(&s.band_lo, colours.beyond_horizon));
        sets.push(set(&s.beyond, colours.beyond_horizon));
        sets.push(set(&s.trusted, fc_colour));
    }
    sets.push(set(&s.measured, colours.measured));
    sets
}

/// The chart's title: the channel, its unit and limit, and its trusted span (or STALE); bold when
/// `selected`.
fn chart_title(c: &Console, ch: &Channel, s: &ChartSeries, selected: bool, current: bool) -> Span<'static> {
    let (from, horizon) = (s.from_s, s.horizon_s);
    let marker = if selected { "▶ " } else { "" };
    let status = if c.forecast.is_none() {
        String::new()
    } else if current && s.k_f > 0 {
        format!(" · trusted {from:.0}-{horizon:.0} s")
    } else if current {
        format!(" · trusted {horizon:.0} s")
    } else {
        " · STALE".into()
    };
    let title = format!(" {marker}{} ({}) limit ±{} {status} ", ch.name, ch.unit(), ch.limit);
    let title_style = if selected {
        Style::default().add_modifier(Modifier::BOLD)
    } else {
        Style::default()
    };
    Span::styled(title, title_style)
}

/// A line through `data`.
fn set(data: &[(f64, f64)], col: Color) -> Dataset<'_> {
    Dataset::default()
        .marker(Marker::Braille)
        .graph_type(GraphType::Line)
        .style(Style::default().fg(col))
        .data(data)
}

fn draw_side(frame: &mut Frame, area: Rect, c: &Console, now_wall_s: f64) {
    let [win, health] = Layout::vertical([Constraint::Percentage(45), Constraint::Min(4)]).areas(area);
    let d = c.settings.duration_s;
    let mut lines = vec![];
    match (c.forecast_is_current(now_wall_s), c.outlook()) {
        (true, Some(o)) => {
            if o.windows.is_empty() {
                lines.push(Line::from(format!("none in the trusted {:.0} s", o.trusted_s)));
            }
            // an open-ended window of a few seconds at the horizon's edge says nothing yet
            let shown = o.windows.iter().filter(|w| !w.open_end || w.length_s() >= d.min(10.0));
            for w in shown.take(8) {
                let go = w.length_s() >= d;
                let col = if go {
                    c.settings.colours.go
                } else {
                    c.settings.colours.caution
                };
                lines.push(Line::from(Span::styled(fmt_window(w), Style::default().fg(col))));
            }
        }
        _ => lines.push(Line::from(Span::styled(
            "no current forecast",
            Style::default().fg(c.settings.colours.no_go),
        ))),
    }
    frame.render_widget(
        Paragraph::new(lines).block(
            Block::default()
                .borders(Borders::ALL)
                .title(format!(" Quiet windows ≥ {d:.0} s ")),
        ),
        win,
    );
    let lines: Vec<Line> = health_lines(c, now_wall_s)
        .into_iter()
        .map(|(s, t)| Line::from(Span::styled(t, Style::default().fg(colour(c, s)))))
        .collect();
    frame.render_widget(
        Paragraph::new(lines)
            .wrap(Wrap { trim: true })
            .block(Block::default().borders(Borders::ALL).title(" Inputs ")),
        health,
    );
}

/// A tiny terminal: the verdict, each channel's numbers, the inputs, as text.
fn draw_text(frame: &mut Frame, area: Rect, c: &Console, now_wall_s: f64) {
    let (sev, text) = banner(c, now_wall_s);
    let mut lines = vec![Line::from(Span::styled(text, Style::default().fg(colour(c, sev))))];
    let d = c.settings.duration_s;
    for ch in &c.settings.channels {
        let fc = c.forecast_channel(ch);
        let dt = c.forecast.as_ref().map_or(1.0, |f| f.dt_s);
        let k = ((d / dt).ceil() as usize + 1).min(fc.len());
        let max = fc[..k].iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let now = fc.first().copied().unwrap_or(f64::NAN);
        lines.push(Line::from(format!(
            "{}: now {now:.2}, max {max:.2} next {d:.0} s, limit {} {}",
            ch.name,
            ch.limit,
            ch.unit()
        )));
    }
    for (s, t) in health_lines(c, now_wall_s) {
        lines.push(Line::from(Span::styled(t, Style::default().fg(colour(c, s)))));
    }
    frame.render_widget(Paragraph::new(lines).wrap(Wrap { trim: true }), area);
}

fn draw_help(frame: &mut Frame, area: Rect) {
    let w = 58.min(area.width);
    let h = 15.min(area.height);
    let r = Rect::new(area.x + (area.width - w) / 2, area.y + (area.height - h) / 2, w, h);
    let text = vec![
        Line::from("↑/↓ or k/j   choose a channel"),
        Line::from("+ / -        raise / lower its limit by 10 %"),
        Line::from("] / [        operation 10 s longer / shorter"),
        Line::from("a            add a channel (vessel DOFs, points)"),
        Line::from("x            remove the chosen channel"),
        Line::from("n            night colours / the config's colours"),
        Line::from("? or h       this help; Esc closes it"),
        Line::from("q            quit (the daemon keeps running)"),
        Line::from(""),
        Line::from("Grey trace: outside the trusted span; grey lines"),
        Line::from("around it: the band a go is judged by. Red lines:"),
        Line::from("limits. Changes here last until the console quits;"),
        Line::from("set defaults in [operation] of the config file."),
    ];
    frame.render_widget(Clear, r);
    frame.render_widget(
        Paragraph::new(text)
            .alignment(Alignment::Left)
            .block(Block::default().borders(Borders::ALL).title(" Keys ")),
        r,
    );
}

#[cfg(test)]
mod tests {
    use super::super::tests::{forecast, two_vessels};
    use super::*;
    use ratatui::Terminal;
    use ratatui::backend::TestBackend;

    fn screen(c: &Console, w: u16, h: u16, now: f64) -> String {
        let mut t = Terminal::new(TestBackend::new(w, h)).unwrap();
        t.draw(|f| draw(f, c, now)).unwrap();
        let b = t.backend().buffer();
        (0..h)
            .map(|y| (0..w).map(|x| b[(x, y)].symbol()).collect::<String>())
            .collect::<Vec<_>>()
            .join("\n")
    }

    /// A healthy daemon's status at wall time 5000 s, no latency measured yet, with `link`.
    fn health(link: Option<crate::console::LinkHealth>) -> crate::console::Health {
        crate::console::Health {
            flags: vec![],
            wave_age_s: 1.0,
            motion_age_s: vec![0.1, 0.1],
            motion_rate_hz: vec![10.0, 10.0],
            last_compute_ms: 10.0,
            latency_p50_ms: -1.0,
            latency_p99_ms: -1.0,
            overruns: 0,
            running: true,
            link,
            received_wall_s: 5000.0,
        }
    }

    #[test]
    fn the_path_s_latency_is_shown_once_the_daemon_has_measured_it() {
        let mut c = two_vessels();
        c.on_forecast(forecast(60, 30.0, |_| 0.0, |_| 0.0));
        let line = |c: &Console| {
            health_lines(c, 5000.0)
                .into_iter()
                .find(|(_, l)| l.starts_with("Forecast:"))
                .map(|(_, l)| l)
        };
        let mut h = health(None);
        c.on_health(h.clone());
        let before = line(&c).unwrap();
        assert!(!before.contains("sensor to publish"), "{before}");
        (h.latency_p50_ms, h.latency_p99_ms) = (41.6, 57.2);
        c.on_health(h);
        let after = line(&c).unwrap();
        assert!(after.ends_with("(sensor to publish 42 ms, p99 57 ms)"), "{after}");
    }

    #[test]
    fn the_ship_to_ship_link_is_shown_up_and_down() {
        let mut c = two_vessels();
        let link_line = |c: &Console| {
            health_lines(c, 5000.0)
                .into_iter()
                .find(|(_, l)| l.starts_with("Link to"))
        };
        c.on_health(health(None));
        assert_eq!(link_line(&c), None);
        c.on_health(health(Some(crate::console::LinkHealth {
            up: true,
            latency_ms: 3.2,
            loss: 0.01,
            age_s: 0.06,
        })));
        assert_eq!(
            link_line(&c),
            Some((
                Severity::Ok,
                "Link to the other ship: up, latency 3 ms, loss 1 %, last 0.1 s ago".into()
            ))
        );
        c.on_health(health(Some(crate::console::LinkHealth {
            up: false,
            latency_ms: -1.0,
            loss: -1.0,
            age_s: 21.4,
        })));
        assert_eq!(
            link_line(&c),
            Some((
                Severity::Alarm,
                "Link to the other ship: down, nothing for 21 s (loss -)".into()
            ))
        );
    }

    #[test]
    fn banners_say_go_no_go_stale_and_stopped() {
        let mut c = two_vessels();
        assert!(banner(&c, 0.0).1.starts_with("Waiting for shipcast"));
        c.on_forecast(forecast(120, 100.0, |_| 0.2, |_| 0.5));
        assert_eq!(banner(&c, 5000.5).0, Severity::Ok);
        assert!(
            banner(&c, 5000.5)
                .1
                .starts_with("GO (90 % confidence): every channel inside its limits for the next 100 s")
        );
        assert!(banner(&c, 5002.0).1.contains("NOT RESPONDING for 2 s"));
        c.on_forecast(forecast(120, 100.0, |t| if t > 10.0 { 2.0 } else { 0.0 }, |_| 0.5));
        let (s, t) = banner(&c, 5000.5);
        assert_eq!(s, Severity::Alarm);
        assert_eq!(
            t,
            "NO-GO (90 % confidence): a.heave leaves its limit in 11 s; no 30 s window within the trusted 100 s"
        );
    }

    #[test]
    fn the_screen_shows_limits_horizon_windows_and_inputs() {
        let mut c = two_vessels();
        c.on_forecast(forecast(
            120,
            80.0,
            |t| 0.5 * (t / 10.0).sin(),
            |t| if t > 50.0 { 3.0 } else { 0.5 },
        ));
        for k in 0..600 {
            let t = 940.0 + 0.1 * k as f64;
            c.on_motion(0, t, &[0.0, 0.0, 0.4 * (t / 5.0).sin(), 0.0, 0.0, 0.0]);
            c.on_motion(1, t, &[0.0; 6]);
        }
        let s = screen(&c, 120, 30, 5000.5);
        assert!(
            s.contains("GO (90 % confidence): every channel inside its limits for the next 50 s"),
            "{s}"
        );
        assert!(s.contains("▶ a.heave (m) limit ±1  · trusted 80 s"), "{s}");
        assert!(s.contains("b.roll (deg) limit ±2  · trusted 80 s"), "{s}");
        assert!(s.contains("Quiet windows ≥ 30 s"), "{s}");
        assert!(s.contains("now, 50 s long"), "{s}");
        assert!(s.contains("Trusted ahead: a 80 s"), "{s}");
        assert!(
            s.contains("-60 s") && s.contains("now") && s.contains("+60 s") && s.contains("+120 s"),
            "{s}"
        );
        // a stale forecast is marked on every chart
        let s = screen(&c, 120, 30, 5003.0);
        assert!(s.contains("NOT RESPONDING") && s.matches("STALE").count() >= 3, "{s}");
    }

    /// A band: a go needs the band inside the limits with the confidence, not only the forecast.
    #[test]
    fn the_band_decides_a_go_and_a_later_span_cannot_tell_about_now() {
        let mut c = two_vessels();
        let mut f = forecast(120, 100.0, |_| 0.5, |_| 0.5);
        // heave 0.5 m with a band widening 0.02 m per s: past 0.5 / 1.28 = 0.39 m (20 s) it is
        // likelier than 10 % to leave the 1 m limit (the 0.5 m to the far one adds nothing), and
        // 20 s is shorter than the 30 s operation
        f.sigma = vec![vec![0.0; 121]; 12];
        f.sigma[2] = (0..=120).map(|k| 0.02 * k as f64).collect();
        c.on_forecast(f.clone());
        let o = c.outlook().unwrap();
        assert!(matches!(o.verdict, Verdict::NoGo { .. }), "{o:?}");
        let (who, at) = o.first_exceedance.clone().unwrap();
        assert_eq!(who, "a.heave");
        assert_eq!(at, 20.0);
        // the same forecast trusted only from 40 s: no verdict about now
        f.sigma[2] = vec![0.05; 121];
        f.trusted_from_s = vec![40.0, 0.0];
        c.on_forecast(f);
        let (sev, text) = banner(&c, 5000.5);
        assert_eq!(sev, Severity::Caution);
        assert_eq!(
            text,
            "CAN'T TELL: the forecast is trusted from 40 s to 100 s ahead: not the next 40 s"
        );
        let s = screen(&c, 120, 30, 5000.5);
        assert!(s.contains("a.heave (m) limit ±1  · trusted 40-100 s"), "{s}");
        assert!(s.contains("Trusted ahead: a 40-100 s"), "{s}");
    }

    /// The whole screen, compared with `src/console/snapshots/` (review a change with `cargo insta
    /// review`, or accept it with `INSTA_UPDATE=always cargo test --lib console`): the band around
    /// each forecast, the span, the confidence of the verdict.
    #[test]
    fn snapshot_of_a_no_go_screen() {
        let mut c = two_vessels();
        c.selected = 1;
        let mut f = forecast(
            120,
            60.0,
            |t| 0.8 * (t / 8.0).sin(),
            |t| if t < 15.0 { 2.5 } else { 1.0 },
        );
        f.sigma = vec![(0..=120).map(|k| 0.05 + 0.004 * k as f64).collect(); 12];
        f.sigma[9] = (0..=120).map(|k| (0.1 + 0.005 * k as f64).to_radians()).collect();
        c.on_forecast(f);
        for k in 0..=60 {
            let t = 940.0 + k as f64;
            c.on_motion(0, t, &[0.0, 0.0, 0.6 * (t / 8.0).sin(), 0.0, 0.0, 0.0]);
            c.on_motion(1, t, &[0.0, 0.0, 0.0, 0.04, 0.0, 0.0]);
        }
        insta::assert_snapshot!(screen(&c, 110, 28, 5000.4));
    }

    #[test]
    fn a_tiny_terminal_gets_text() {
        let mut c = two_vessels();
        c.on_forecast(forecast(120, 100.0, |_| 0.2, |_| 0.5));
        let s = screen(&c, 50, 10, 5000.5);
        assert!(s.contains("GO (90 % confidence): every"), "{s}");
        assert!(s.contains("a.heave: now 0.20, max 0.20"), "{s}");
        assert!(!s.contains('┌'), "{s}");
    }

    #[test]
    fn help_shows_over_the_charts() {
        let mut c = two_vessels();
        c.help = true;
        let s = screen(&c, 100, 30, 0.0);
        assert!(s.contains(" Keys ") && s.contains("raise / lower its limit"), "{s}");
    }
}
