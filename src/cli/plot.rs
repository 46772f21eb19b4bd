//! The replay report's figures (`shipcast replay --report`), drawn with plotters and written as SVG
//! and PNG side by side (`<name>.svg`, `<name>.png`): the skill against lead time ([`skill`]) and
//! one forecast against what followed ([`forecast`]). Owns their layout (titles, axes with ticks,
//! units and labels, legends outside the data, the trusted horizon and the operation limits as
//! labelled lines) and their text: DejaVu Sans, shipped in `assets/fonts` (licence beside it) and
//! compiled in, rendered by ab_glyph, so a machine without system fonts or fontconfig draws the same
//! PNG. Shell code: takes plain numbers and writes files; what the numbers are is the caller's.

use anyhow::{Result, anyhow};
use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::register_font;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;
use std::sync::OnceLock;

/// The one font family of the figures; plotters looks it up by this name.
const FONT: &str = "sans-serif";
const FONT_FILE: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");
const WIDTH: u32 = 1200;
/// Width of the legend column right of each panel.
const LEGEND_W: u32 = 260;
const TRUTH: RGBColor = RGBColor(0, 0, 0);
const FORECAST: RGBColor = RGBColor(31, 119, 180);
const LIMIT: RGBColor = RGBColor(214, 39, 40);
const HORIZON: RGBColor = RGBColor(110, 110, 110);
const CURVES: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(140, 86, 75),
    RGBColor(23, 190, 207),
    RGBColor(227, 119, 194),
];
/// NRMSE above this is drawn at it, and the panel says so.
const NRMSE_CLIP: f64 = 3.0;

/// Registers the shipped font under [`FONT`] once.
fn font() -> Result<()> {
    static OK: OnceLock<bool> = OnceLock::new();
    let ok = *OK.get_or_init(|| register_font(FONT, FontStyle::Normal, FONT_FILE).is_ok());
    if ok {
        Ok(())
    } else {
        Err(anyhow!("the shipped font does not parse"))
    }
}

/// A figure that draws on any plotters backend.
trait Figure {
    fn size(&self) -> (u32, u32);
    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>>;
}

/// Writes `fig` as `svg` and as the PNG beside it (same name, `.png`).
fn write(fig: &impl Figure, svg: &Path) -> Result<()> {
    font()?;
    let (w, h) = fig.size();
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, (w, h)).into_drawing_area();
        fig.draw(&root).map_err(|e| anyhow!("{}: {e}", svg.display()))?;
        root.present().map_err(|e| anyhow!("{}: {e}", svg.display()))?;
    }
    std::fs::write(svg, text)?;
    let png_path = svg.with_extension("png");
    let mut rgb = vec![0u8; 3 * w as usize * h as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (w, h)).into_drawing_area();
        fig.draw(&root).map_err(|e| anyhow!("{}: {e}", png_path.display()))?;
        root.present().map_err(|e| anyhow!("{}: {e}", png_path.display()))?;
    }
    let file = std::io::BufWriter::new(std::fs::File::create(&png_path)?);
    let mut enc = png::Encoder::new(file, w, h);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    enc.set_compression(png::Compression::Best);
    enc.set_adaptive_filter(png::AdaptiveFilterType::Adaptive);
    let mut writer = enc.write_header()?;
    writer.write_image_data(&rgb)?;
    writer.finish()?;
    Ok(())
}

fn style(size: u32) -> TextStyle<'static> {
    (FONT, size).into_font().color(&BLACK)
}

/// The finite runs of `pts` (a gap where a value is not finite).
fn runs(pts: &[(f64, f64)]) -> Vec<Vec<(f64, f64)>> {
    pts.split(|p| !(p.0.is_finite() && p.1.is_finite()))
        .filter(|r| !r.is_empty())
        .map(|r| r.to_vec())
        .collect()
}

/// How a line is drawn, in the plot and in its legend.
#[derive(Clone, Copy)]
struct Stroke {
    colour: RGBColor,
    width: u32,
    dashed: bool,
}

fn line<DB: DrawingBackend, CT: CoordTranslate<From = (f64, f64)>>(
    chart: &mut ChartContext<DB, CT>,
    pts: &[(f64, f64)],
    s: Stroke,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let st = s.colour.stroke_width(s.width);
    for r in runs(pts) {
        if s.dashed {
            chart.draw_series(DashedLineSeries::new(r, 7, 5, st))?;
        } else {
            chart.draw_series(LineSeries::new(r, st))?;
        }
    }
    Ok(())
}

/// A legend in `area` (pixel coordinates): a line sample and its label per entry, from the top.
fn legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    top: i32,
    entries: &[(String, Stroke)],
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let x0 = 12;
    for (i, (label, s)) in entries.iter().enumerate() {
        let y = top + 24 * i as i32;
        let st = s.colour.stroke_width(s.width);
        if s.dashed {
            for k in 0..3 {
                area.draw(&PathElement::new(vec![(x0 + 12 * k, y), (x0 + 12 * k + 7, y)], st))?;
            }
        } else {
            area.draw(&PathElement::new(vec![(x0, y), (x0 + 31, y)], st))?;
        }
        area.draw(&Text::new(
            label.clone(),
            (x0 + 40, y),
            style(15).pos(Pos::new(HPos::Left, VPos::Center)),
        ))?;
    }
    Ok(())
}

/// One operation channel of a forecast plot: the channel along the forecast and along the motion
/// that followed, both against lead time (s), in `unit`.
pub struct ForecastPanel {
    /// The channel, e.g. `carrier.heave`.
    pub name: String,
    pub unit: String,
    pub limit: f64,
    /// Lead time up to which the forecast is trusted, s.
    pub trusted_s: f64,
    /// ... and from which, s.
    pub trusted_from_s: f64,
    /// The forecast's 90 % band: (lead, low, high) (empty: none).
    pub band: Vec<(f64, f64, f64)>,
    pub forecast: Vec<(f64, f64)>,
    pub actual: Vec<(f64, f64)>,
}

struct ForecastFigure<'a> {
    title: String,
    /// `truth` or `measured`.
    reference: &'a str,
    span_s: f64,
    panels: &'a [ForecastPanel],
}

const PANEL_H: u32 = 300;
const TITLE_H: u32 = 44;

impl Figure for ForecastFigure<'_> {
    fn size(&self) -> (u32, u32) {
        (WIDTH, TITLE_H + PANEL_H * self.panels.len().max(1) as u32)
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        root.fill(&WHITE)?;
        let body = root.titled(&self.title, style(20))?;
        let span = self.span_s.max(1.0);
        for (p, area) in self.panels.iter().zip(body.split_evenly((self.panels.len().max(1), 1))) {
            let (plot, side) = area.split_horizontally(WIDTH - LEGEND_W);
            let peak = p
                .forecast
                .iter()
                .chain(&p.actual)
                .map(|q| q.1.abs())
                .chain(p.band.iter().map(|b| b.1.abs().max(b.2.abs())))
                .filter(|v| v.is_finite())
                .fold(1.2 * p.limit.abs(), f64::max)
                .max(1e-9)
                * 1.1;
            let mut chart = ChartBuilder::on(&plot)
                .caption(
                    if p.trusted_from_s > 0.0 {
                        format!(
                            "{}: limit ±{} {}, trusted {:.0}-{:.0} s",
                            p.name, p.limit, p.unit, p.trusted_from_s, p.trusted_s
                        )
                    } else {
                        format!(
                            "{}: limit ±{} {}, trusted {:.0} s",
                            p.name, p.limit, p.unit, p.trusted_s
                        )
                    },
                    style(16),
                )
                .margin(8)
                .margin_right(20)
                .x_label_area_size(46)
                .y_label_area_size(72)
                .build_cartesian_2d(0.0..span, -peak..peak)?;
            chart
                .configure_mesh()
                .x_desc("lead time (s)")
                .x_label_formatter(&|v| format!("{v:.0}"))
                .y_desc(format!("{} ({})", p.name, p.unit))
                .label_style(style(14))
                .axis_desc_style(style(15))
                .light_line_style(RGBColor(238, 238, 238))
                .bold_line_style(RGBColor(215, 215, 215))
                .draw()?;
            let (t_f, t_h) = panel_marks(&mut chart, p, span, peak)?;
            forecast_lines(&mut chart, p, t_f, t_h)?;
            legend(
                &side,
                64,
                &[
                    (format!("{} motion", self.reference), TRUTH_STROKE),
                    ("forecast (trusted)".into(), FORECAST_STROKE),
                    ("forecast outside the span".into(), FORECAST_PAST_STROKE),
                    (format!("limits ±{} {}", p.limit, p.unit), LIMIT_STROKE),
                    (format!("trusted horizon {t_h:.0} s"), HORIZON_STROKE),
                ],
            )?;
        }
        Ok(())
    }
}

const TRUTH_STROKE: Stroke = Stroke {
    colour: TRUTH,
    width: 2,
    dashed: false,
};
const FORECAST_STROKE: Stroke = Stroke {
    colour: FORECAST,
    width: 2,
    dashed: false,
};
const FORECAST_PAST_STROKE: Stroke = Stroke {
    colour: FORECAST,
    width: 2,
    dashed: true,
};
const LIMIT_STROKE: Stroke = Stroke {
    colour: LIMIT,
    width: 1,
    dashed: false,
};
const HORIZON_STROKE: Stroke = Stroke {
    colour: HORIZON,
    width: 1,
    dashed: true,
};

type Chart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// A panel's limits (labelled at their left end), its band (shaded under everything else) and the
/// trusted span's ends (labelled on the side with room); the span's start and end, s.
fn panel_marks<DB: DrawingBackend>(
    chart: &mut Chart<'_, DB>,
    p: &ForecastPanel,
    span: f64,
    peak: f64,
) -> Result<(f64, f64), DrawingAreaErrorKind<DB::ErrorType>> {
    for l in [p.limit, -p.limit] {
        line(chart, &[(0.0, l), (span, l)], LIMIT_STROKE)?;
        let below = l < 0.0;
        chart.draw_series(std::iter::once(
            EmptyElement::at((0.0, l))
                + Text::new(
                    format!("limit {}{} {}", if below { "−" } else { "+" }, p.limit, p.unit),
                    (6, if below { 4 } else { -4 }),
                    style(13)
                        .color(&LIMIT)
                        .pos(Pos::new(HPos::Left, if below { VPos::Top } else { VPos::Bottom })),
                ),
        ))?;
    }
    if !p.band.is_empty() {
        let outline: Vec<(f64, f64)> = p
            .band
            .iter()
            .map(|b| (b.0, b.2))
            .chain(p.band.iter().rev().map(|b| (b.0, b.1)))
            .filter(|q| q.1.is_finite())
            .collect();
        chart.draw_series(std::iter::once(Polygon::new(outline, FORECAST.mix(0.18).filled())))?;
    }
    let t_h = p.trusted_s.clamp(0.0, span);
    let t_f = p.trusted_from_s.clamp(0.0, t_h);
    line(chart, &[(t_h, -peak), (t_h, peak)], HORIZON_STROKE)?;
    if t_f > 0.0 {
        line(chart, &[(t_f, -peak), (t_f, peak)], HORIZON_STROKE)?;
        chart.draw_series(std::iter::once(
            EmptyElement::at((t_f, -peak))
                + Text::new(
                    format!("trusted from {t_f:.0} s"),
                    (5, -4),
                    style(13).color(&HORIZON).pos(Pos::new(HPos::Left, VPos::Bottom)),
                ),
        ))?;
    }
    let left = t_h > 0.6 * span;
    chart.draw_series(std::iter::once(
        EmptyElement::at((t_h, peak))
            + Text::new(
                format!("trusted horizon {t_h:.0} s"),
                (if left { -5 } else { 5 }, 4),
                style(13)
                    .color(&HORIZON)
                    .pos(Pos::new(if left { HPos::Right } else { HPos::Left }, VPos::Top)),
            ),
    ))?;
    Ok((t_f, t_h))
}

/// The motion that followed, and the forecast: solid over the trusted span `t_f..t_h`, dashed before
/// and after it (joined at its ends).
fn forecast_lines<DB: DrawingBackend>(
    chart: &mut Chart<'_, DB>,
    p: &ForecastPanel,
    t_f: f64,
    t_h: f64,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    line(chart, &p.actual, TRUTH_STROKE)?;
    let early: Vec<(f64, f64)> = p.forecast.iter().copied().filter(|q| q.0 <= t_f).collect();
    let before: Vec<(f64, f64)> = p
        .forecast
        .iter()
        .copied()
        .filter(|q| q.0 >= t_f && q.0 <= t_h)
        .collect();
    let after: Vec<(f64, f64)> = match before.last() {
        Some(&b) => std::iter::once(b)
            .chain(p.forecast.iter().copied().filter(|q| q.0 > t_h))
            .collect(),
        None => p.forecast.clone(),
    };
    if t_f > 0.0 {
        line(chart, &early, FORECAST_PAST_STROKE)?;
    }
    line(chart, &before, FORECAST_STROKE)?;
    line(chart, &after, FORECAST_PAST_STROKE)?;
    Ok(())
}

/// Writes one forecast against the motion that followed (`reference`: `truth` or `measured`),
/// a panel per operation channel over lead times 0 to `span_s`, as `svg` and the PNG beside it.
pub fn forecast(svg: &Path, issue_time_s: f64, reference: &str, span_s: f64, panels: &[ForecastPanel]) -> Result<()> {
    let fig = ForecastFigure {
        title: format!("Forecast issued {issue_time_s:.1} s into the log against the {reference} motion that followed"),
        reference,
        span_s,
        panels,
    };
    write(&fig, svg)
}

/// One curve of the skill plot: correlation and NRMSE at each lead time.
pub struct SkillCurve {
    /// e.g. `carrier heave`.
    pub label: String,
    pub correlation: Vec<f64>,
    pub nrmse: Vec<f64>,
}

type SkillPanel = (String, String, f64, f64, fn(&SkillCurve) -> &Vec<f64>);

struct SkillFigure<'a> {
    title: String,
    /// What the forecasts are scored against: `truth` or `measured`.
    reference: &'a str,
    lead_s: &'a [f64],
    curves: &'a [SkillCurve],
}

impl Figure for SkillFigure<'_> {
    fn size(&self) -> (u32, u32) {
        (WIDTH, TITLE_H + 2 * 380)
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        root.fill(&WHITE)?;
        let body = root.titled(&self.title, style(20))?;
        let (plots, side) = body.split_horizontally(WIDTH - LEGEND_W);
        let halves = plots.split_evenly((2, 1));
        let lmax = self.lead_s.last().copied().unwrap_or(1.0).max(1.0);
        let finite = |f: fn(&SkillCurve) -> &Vec<f64>| {
            self.curves
                .iter()
                .flat_map(move |c| f(c).iter().copied())
                .filter(|v| v.is_finite())
        };
        // correlation: [-1, 1] at most; from 0 (or below, when the data go there) to 1
        let c_lo = finite(|c| &c.correlation).fold(0.0, f64::min);
        let c_lo = if c_lo < 0.0 { (c_lo * 10.0).floor() / 10.0 } else { 0.0 };
        let n_max = finite(|c| &c.nrmse).fold(0.0, f64::max);
        let clipped = n_max > NRMSE_CLIP;
        let n_hi = if clipped { NRMSE_CLIP } else { (n_max * 1.08).max(0.1) };
        // per panel: y label, caption, y range, the curve's values
        let panels: [SkillPanel; 2] = [
            (
                format!("correlation (forecast, {})", self.reference),
                format!("Correlation of forecast and {} motion", self.reference),
                c_lo,
                1.02,
                |c| &c.correlation,
            ),
            (
                format!("NRMSE (RMS error / {} std)", self.reference),
                if clipped {
                    format!(
                        "Normalized RMS error (clipped at {NRMSE_CLIP}: the largest is {n_max:.1}, drawn at {NRMSE_CLIP})"
                    )
                } else {
                    "Normalized RMS error".into()
                },
                0.0,
                n_hi,
                |c| &c.nrmse,
            ),
        ];
        for ((y_desc, caption, lo, hi, values), area) in panels.into_iter().zip(&halves) {
            let mut chart = ChartBuilder::on(area)
                .caption(caption, style(16))
                .margin(8)
                .margin_right(20)
                .x_label_area_size(46)
                .y_label_area_size(72)
                .build_cartesian_2d(0.0..lmax, lo..hi)?;
            chart
                .configure_mesh()
                .x_desc("lead time (s)")
                .x_label_formatter(&|v| format!("{v:.0}"))
                .y_desc(y_desc)
                .label_style(style(14))
                .axis_desc_style(style(15))
                .light_line_style(RGBColor(238, 238, 238))
                .bold_line_style(RGBColor(215, 215, 215))
                .draw()?;
            for (i, c) in self.curves.iter().enumerate() {
                let pts: Vec<(f64, f64)> = self
                    .lead_s
                    .iter()
                    .zip(values(c))
                    .map(|(&l, &v)| (l, if v.is_finite() { v.clamp(lo, hi) } else { v }))
                    .collect();
                line(
                    &mut chart,
                    &pts,
                    Stroke {
                        colour: CURVES[i % CURVES.len()],
                        width: 2,
                        dashed: false,
                    },
                )?;
            }
        }
        let entries: Vec<(String, Stroke)> = self
            .curves
            .iter()
            .enumerate()
            .map(|(i, c)| {
                (
                    c.label.clone(),
                    Stroke {
                        colour: CURVES[i % CURVES.len()],
                        width: 2,
                        dashed: false,
                    },
                )
            })
            .collect();
        legend(&side, 64, &entries)
    }
}

/// Writes the skill of `curves` against lead time (`lead_s`, s) over `forecasts` forecasts as `svg`
/// and the PNG beside it: correlation above, NRMSE below, a shared legend right of both.
pub fn skill(svg: &Path, forecasts: usize, reference: &str, lead_s: &[f64], curves: &[SkillCurve]) -> Result<()> {
    let fig = SkillFigure {
        title: format!("Forecast skill against lead time: {forecasts} forecasts against the {reference} motion"),
        reference,
        lead_s,
        curves,
    };
    write(&fig, svg)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> std::path::PathBuf {
        let d = std::env::temp_dir().join(format!("shipcast-plot-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    /// Decodes the PNG: its size, and whether the band of rows `rows` holds dark (text) pixels.
    fn png_info(p: &Path, rows: std::ops::Range<usize>) -> ((u32, u32), bool) {
        let dec = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(p).unwrap()));
        let mut r = dec.read_info().unwrap();
        let mut buf = vec![0; r.output_buffer_size()];
        let info = r.next_frame(&mut buf).unwrap();
        assert_eq!(info.color_type, png::ColorType::Rgb);
        let w = info.width as usize;
        let dark = rows
            .flat_map(|y| (0..w).map(move |x| 3 * (y * w + x)))
            .any(|i| buf[i..i + 3].iter().all(|&c| c < 80));
        ((info.width, info.height), dark)
    }

    #[test]
    fn forecast_plot_is_svg_and_png_with_labelled_axes_legend_horizon_and_limits() {
        let dir = scratch("forecast");
        let svg = dir.join("forecast-300.svg");
        let wave = |a: f64, k: f64| {
            (0..=1200)
                .map(|i| (i as f64 * 0.1, a * (k * i as f64 * 0.1).sin()))
                .collect()
        };
        let mut actual: Vec<(f64, f64)> = wave(0.8, 0.7);
        actual[500].1 = f64::NAN; // a gap
        let panels = [
            ForecastPanel {
                name: "carrier.heave".into(),
                unit: "m".into(),
                limit: 1.0,
                trusted_s: 80.0,
                trusted_from_s: 0.0,
                band: wave(0.75, 0.7)
                    .into_iter()
                    .map(|(t, v)| (t, v - 0.2, v + 0.2))
                    .collect(),
                forecast: wave(0.75, 0.7),
                actual,
            },
            ForecastPanel {
                name: "carrier.roll".into(),
                unit: "deg".into(),
                limit: 2.0,
                trusted_s: 95.0,
                trusted_from_s: 20.0,
                band: vec![],
                forecast: wave(2.5, 0.5),
                actual: wave(2.4, 0.5),
            },
        ];
        forecast(&svg, 300.0, "truth", 120.0, &panels).unwrap();
        let text = std::fs::read_to_string(&svg).unwrap();
        for s in [
            "Forecast issued 300.0 s into the log against the truth motion",
            "lead time (s)",
            "carrier.heave (m)",
            "carrier.roll (deg)",
            "truth motion",
            "forecast (trusted)",
            "forecast outside the span",
            "trusted from 20 s",
            "limits ±1 m",
            "limit +2 deg",
            "trusted horizon 80 s",
            "trusted horizon 95 s",
        ] {
            assert!(text.contains(s), "the SVG lacks {s:?}");
        }
        // tick numbers on both axes
        assert!(
            text.contains(">\n100\n</text>") || text.contains(">100</text>"),
            "no x tick 100"
        );
        let (size, dark) = png_info(&svg.with_extension("png"), 5..30);
        assert_eq!(size, (WIDTH, TITLE_H + 2 * PANEL_H));
        assert!(dark, "the PNG's title band has no text");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn skill_plot_is_svg_and_png_and_says_when_it_clips() {
        let dir = scratch("skill");
        let svg = dir.join("skill.svg");
        let lead: Vec<f64> = (0..=24).map(|i| 5.0 * i as f64).collect();
        let curves = [
            SkillCurve {
                label: "carrier heave".into(),
                correlation: lead.iter().map(|l| 1.0 - l / 200.0).collect(),
                nrmse: lead.iter().map(|l| l / 100.0).collect(),
            },
            SkillCurve {
                label: "carrier roll".into(),
                correlation: lead.iter().map(|l| -0.3 + 0.0 * l).collect(),
                nrmse: lead.iter().map(|l| if *l > 60.0 { 5.0 } else { f64::NAN }).collect(),
            },
        ];
        skill(&svg, 42, "measured", &lead, &curves).unwrap();
        let text = std::fs::read_to_string(&svg).unwrap();
        for s in [
            "Forecast skill against lead time: 42 forecasts",
            "lead time (s)",
            "correlation (forecast, measured)",
            "NRMSE (RMS error / measured std)",
            "carrier heave",
            "carrier roll",
            "clipped at 3: the largest is 5.0",
        ] {
            assert!(text.contains(s), "the SVG lacks {s:?}");
        }
        let (size, dark) = png_info(&svg.with_extension("png"), 5..30);
        assert_eq!(size, (WIDTH, TITLE_H + 2 * 380));
        assert!(dark, "the PNG's title band has no text");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
