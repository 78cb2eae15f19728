//! Figures (plotters), written as SVG and PNG.
//!
//! Text in PNGs is rasterised by plotters' `ab_glyph` backend from Noto Sans embedded in the
//! binary (crate `ttf-noto-sans`), so no system font library (fontconfig, freetype) and no
//! installed font is needed. SVGs name the family `sans-serif` and let the viewer render it.
//!
//! A figure is plain data ([`Figure`] of [`Panel`]s of [`Line`]s) drawn by one renderer;
//! [`sweep`] and [`trace`] build figures from a sweep's runs table and from one run's series,
//! [`identify`] from identified modes and their measured spectrum.

pub mod bars;
pub mod identify;
pub mod jobs;
pub mod klipper_shapers;
pub mod ringing;
pub mod scan_trace;
pub mod svg_stream;
pub mod sweep;
pub mod trace;

use std::path::Path;
use std::sync::Once;

use plotters::coord::Shift;
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::error::Error;

/// Colours for lines, by order of appearance (Tableau 10: distinct, colour-blind friendly).
pub const PALETTE: [RGBColor; 10] = [
    RGBColor(0x4e, 0x79, 0xa7),
    RGBColor(0xf2, 0x8e, 0x2b),
    RGBColor(0xe1, 0x57, 0x59),
    RGBColor(0x59, 0xa1, 0x4f),
    RGBColor(0xb0, 0x7a, 0xa1),
    RGBColor(0x76, 0xb7, 0xb2),
    RGBColor(0xed, 0xc9, 0x48),
    RGBColor(0xff, 0x9d, 0xa7),
    RGBColor(0x9c, 0x75, 0x5f),
    RGBColor(0xba, 0xb0, 0xac),
];

const FONT: &str = "sans-serif";

/// Marker drawn at each data point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Marker {
    /// Filled circle.
    Circle,
    /// Filled triangle.
    Triangle,
    /// Filled square.
    Square,
    /// Cross.
    Cross,
}

impl Marker {
    /// Markers to tell lines of one colour apart.
    pub const ALL: [Marker; 4] = [
        Marker::Circle,
        Marker::Triangle,
        Marker::Square,
        Marker::Cross,
    ];
}

/// One line of a panel.
#[derive(Debug, Clone)]
pub struct Line {
    /// Legend text (none: not in the legend).
    pub label: Option<String>,
    /// Colour.
    pub color: RGBColor,
    /// Points in x order. A non-finite y (e.g. "not settled") breaks the line and is drawn
    /// as a hollow triangle at the top edge of the panel.
    pub points: Vec<(f64, f64)>,
    /// Marker at each point, if any.
    pub marker: Option<Marker>,
    /// Stroke width (px); 0 draws the markers only (a scatter).
    pub width: u32,
    /// A shaded band `(x, low, high)` drawn under the line (e.g. min-max).
    pub band: Vec<(f64, f64, f64)>,
}

impl Line {
    /// A plain line.
    pub fn new(label: Option<String>, color: RGBColor, points: Vec<(f64, f64)>) -> Self {
        Self {
            label,
            color,
            points,
            marker: None,
            width: 2,
            band: Vec::new(),
        }
    }
}

/// A reference line across a panel.
#[derive(Debug, Clone)]
pub struct Rule {
    /// Position (x for vertical rules, y for horizontal ones).
    pub at: f64,
    /// Text drawn beside it.
    pub label: String,
}

/// One chart.
#[derive(Debug, Clone, Default)]
pub struct Panel {
    /// Caption.
    pub title: String,
    /// x axis description.
    pub x_label: String,
    /// y axis description.
    pub y_label: String,
    /// Lines.
    pub lines: Vec<Line>,
    /// Logarithmic x axis.
    pub x_log: bool,
    /// Logarithmic y axis.
    pub y_log: bool,
    /// Start the y axis at zero (when all values are >= 0).
    pub y_from_zero: bool,
    /// Vertical rules.
    pub vrules: Vec<Rule>,
    /// Horizontal rules.
    pub hrules: Vec<Rule>,
    /// Draw the labelled lines' legend inside the panel (off when the figure has one).
    pub legend: bool,
}

/// A figure: panels in a grid.
#[derive(Debug, Clone)]
pub struct Figure {
    /// Title above the grid.
    pub title: String,
    /// Panels, row by row.
    pub panels: Vec<Panel>,
    /// Panels per row.
    pub columns: usize,
    /// Width (px).
    pub width: u32,
    /// Height of one panel row (px).
    pub row_height: u32,
    /// A legend for the whole figure, drawn under the title (empty: none).
    pub legend: Vec<LegendEntry>,
}

/// One entry of a figure's legend.
#[derive(Debug, Clone)]
pub struct LegendEntry {
    /// Text.
    pub label: String,
    /// Colour.
    pub color: RGBColor,
    /// Marker (none: a short line).
    pub marker: Option<Marker>,
    /// Draw the marker hollow (the "not settled" glyph).
    pub hollow: bool,
}

/// Entries per row of a figure legend at most.
const LEGEND_COLUMNS: usize = 4;

/// Entries per row of the legend of `f`: as many as fit the longest label.
fn legend_columns(f: &Figure) -> usize {
    let longest = f
        .legend
        .iter()
        .map(|e| e.label.chars().count())
        .max()
        .unwrap_or(0);
    // About 8.5 px per character at 16 px, plus the glyph and a gap.
    let need = longest as f64 * 8.5 + 60.0;
    (((f.width as f64 - 80.0) / need).floor() as usize).clamp(1, LEGEND_COLUMNS)
}
/// Height of one row of a figure legend (px).
const LEGEND_ROW_PX: u32 = 26;

pub(crate) fn init_fonts() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The embedded font is valid TrueType; if registration failed anyway, text would be
        // missing from PNGs, which the plot tests detect.
        let _ = plotters::style::register_font(FONT, FontStyle::Normal, ttf_noto_sans::REGULAR);
        let _ = plotters::style::register_font(FONT, FontStyle::Bold, ttf_noto_sans::BOLD);
    });
}

/// A number for an axis tick or a legend: short, no float noise.
pub fn fmt_num(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    let a = v.abs();
    if !(1e-3..1e6).contains(&a) {
        let s = format!("{v:.2e}");
        // 1.00e5 -> 1e5
        return s.replace(".00e", "e").replace("0e", "e");
    }
    let s = format!("{v:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    s.to_string()
}

/// A tick label on an axis spanning `span`: rounding noise around zero (e.g. -5.55e-17 on
/// an axis from -0.4 to 0.3) is shown as 0.
fn fmt_tick(v: f64, span: f64) -> String {
    if v.abs() < span.abs() * 1e-9 {
        "0".into()
    } else {
        fmt_num(v)
    }
}

/// The finite range of `values`, padded; `None` when there is no finite value.
fn range(values: impl Iterator<Item = f64>, log: bool, from_zero: bool) -> Option<(f64, f64)> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite() && (!log || *v > 0.0)) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if lo > hi {
        return None;
    }
    if log {
        let (l, h) = (lo.log10(), hi.log10());
        let pad = ((h - l) * 0.05).max(0.05);
        return Some((10f64.powf(l - pad), 10f64.powf(h + pad)));
    }
    if from_zero && lo >= 0.0 {
        lo = 0.0;
    }
    let span = hi - lo;
    let pad = if span > 0.0 {
        span * 0.06
    } else if hi == 0.0 {
        // A constant zero (e.g. the jerk of a trapezoid): show it mid-panel on +-1.
        1.0
    } else {
        hi.abs() * 0.1
    };
    let lo = if from_zero && lo == 0.0 {
        0.0
    } else {
        lo - pad
    };
    Some((lo, hi + pad))
}

type DrawResult = Result<(), String>;

fn err<E: std::fmt::Display>(e: E) -> String {
    e.to_string()
}

fn draw_panel<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, p: &Panel) -> DrawResult {
    let xs = p.lines.iter().flat_map(|l| l.points.iter().map(|q| q.0));
    let ys = p.lines.iter().flat_map(|l| {
        l.points
            .iter()
            .map(|q| q.1)
            .chain(l.band.iter().flat_map(|b| [b.1, b.2]))
    });
    let ys = ys.chain(p.hrules.iter().map(|r| r.at));
    let (Some(xr), Some(yr0)) = (range(xs, p.x_log, false), range(ys, p.y_log, p.y_from_zero))
    else {
        return Ok(());
    };
    let xr = if p.x_log {
        xr
    } else {
        // Lines that span the data exactly (time series) need no padding on x.
        let (lo, hi) = range(
            p.lines.iter().flat_map(|l| l.points.iter().map(|q| q.0)),
            false,
            false,
        )
        .unwrap_or(xr);
        let pad = (hi - lo) * 0.06;
        let exact = p.lines.iter().all(|l| l.marker.is_none());
        if exact && hi > lo {
            (
                p.lines
                    .iter()
                    .flat_map(|l| l.points.first().map(|q| q.0))
                    .fold(f64::INFINITY, f64::min),
                p.lines
                    .iter()
                    .flat_map(|l| l.points.last().map(|q| q.0))
                    .fold(f64::NEG_INFINITY, f64::max),
            )
        } else {
            (lo - pad, hi + pad)
        }
    };
    // Room at the top for "not settled" markers.
    let any_inf = p
        .lines
        .iter()
        .any(|l| l.points.iter().any(|q| !q.1.is_finite()));
    let yr = if any_inf {
        if p.y_log {
            (yr0.0, yr0.1 * (yr0.1 / yr0.0).powf(0.12))
        } else {
            (yr0.0, yr0.1 + (yr0.1 - yr0.0) * 0.12)
        }
    } else {
        yr0
    };
    let top = yr.1 - if p.y_log { 0.0 } else { (yr.1 - yr.0) * 0.03 };
    let top = if p.y_log {
        yr.1 / (yr.1 / yr.0).powf(0.03)
    } else {
        top
    };
    match (p.x_log, p.y_log) {
        (false, false) => draw_in(area, p, xr.0..xr.1, yr.0..yr.1, top),
        (true, false) => draw_in(area, p, (xr.0..xr.1).log_scale(), yr.0..yr.1, top),
        (false, true) => draw_in(area, p, xr.0..xr.1, (yr.0..yr.1).log_scale(), top),
        (true, true) => draw_in(
            area,
            p,
            (xr.0..xr.1).log_scale(),
            (yr.0..yr.1).log_scale(),
            top,
        ),
    }
}

fn draw_in<'a, DB, X, Y>(
    area: &'a DrawingArea<DB, Shift>,
    p: &Panel,
    x: X,
    y: Y,
    top: f64,
) -> DrawResult
where
    DB: DrawingBackend + 'a,
    X: AsRangedCoord<Value = f64>,
    Y: AsRangedCoord<Value = f64>,
    X::CoordDescType: ValueFormatter<f64>,
    Y::CoordDescType: ValueFormatter<f64>,
{
    let mut chart = ChartBuilder::on(area)
        .caption(&p.title, (FONT, 21).into_font().style(FontStyle::Bold))
        .margin(10)
        .x_label_area_size(44)
        .y_label_area_size(78)
        .build_cartesian_2d(x, y)
        .map_err(err)?;
    let (xlo, xhi) = {
        let r = chart.x_range();
        (r.start, r.end)
    };
    let (ylo, yhi) = {
        let r = chart.y_range();
        (r.start, r.end)
    };
    chart
        .configure_mesh()
        .x_desc(p.x_label.as_str())
        .y_desc(p.y_label.as_str())
        .x_label_formatter(&|v| fmt_tick(*v, xhi - xlo))
        .y_label_formatter(&|v| fmt_tick(*v, yhi - ylo))
        .label_style((FONT, 15))
        .axis_desc_style((FONT, 16))
        .bold_line_style(BLACK.mix(0.12))
        .light_line_style(BLACK.mix(0.04))
        .x_labels(8)
        .y_labels(6)
        .draw()
        .map_err(err)?;
    let grey = RGBColor(90, 90, 90);
    for (i, r) in p.vrules.iter().enumerate() {
        chart
            .draw_series(DashedLineSeries::new(
                [(r.at, ylo), (r.at, yhi)],
                6,
                4,
                grey.stroke_width(1),
            ))
            .map_err(err)?;
        // Labels step down one line each, so that rules close together stay readable.
        chart
            .draw_series(std::iter::once(
                EmptyElement::at((r.at, yhi))
                    + Text::new(
                        format!(" {}", r.label),
                        (0, 16 * i as i32),
                        (FONT, 14).into_font().color(&grey),
                    ),
            ))
            .map_err(err)?;
    }
    for r in &p.hrules {
        chart
            .draw_series(DashedLineSeries::new(
                [(xlo, r.at), (xhi, r.at)],
                6,
                4,
                grey.stroke_width(1),
            ))
            .map_err(err)?;
        if !r.label.is_empty() {
            // At the right end, above the rule.
            let style = (FONT, 14)
                .into_font()
                .color(&grey)
                .pos(Pos::new(HPos::Right, VPos::Bottom));
            chart
                .draw_series(std::iter::once(Text::new(
                    format!("{} ", r.label),
                    (xhi, r.at),
                    style,
                )))
                .map_err(err)?;
        }
    }
    let mut any_inf = false;
    for l in &p.lines {
        if l.band.len() >= 2 {
            let mut poly: Vec<(f64, f64)> = l.band.iter().map(|b| (b.0, b.2.min(top))).collect();
            poly.extend(l.band.iter().rev().map(|b| (b.0, b.1.min(top))));
            chart
                .draw_series(std::iter::once(Polygon::new(
                    poly,
                    l.color.mix(0.18).filled(),
                )))
                .map_err(err)?;
        }
        // Width 0: markers only (a scatter), the line drawn fully transparent.
        let style = if l.width == 0 {
            l.color.mix(0.0).stroke_width(1)
        } else {
            l.color.stroke_width(l.width)
        };
        // Split at non-finite values.
        let mut segments: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
        for &(px, py) in &l.points {
            if py.is_finite() {
                if let Some(s) = segments.last_mut() {
                    s.push((px, py));
                }
            } else if segments.last().is_some_and(|s| !s.is_empty()) {
                segments.push(Vec::new());
            }
        }
        let mut labelled = false;
        for seg in segments.iter().filter(|s| !s.is_empty()) {
            let ann = chart
                .draw_series(LineSeries::new(seg.iter().copied(), style))
                .map_err(err)?;
            if let (Some(label), false) = (&l.label, labelled) {
                set_legend(ann, label, l.color, l.marker);
                labelled = true;
            }
        }
        if let (Some(label), false) = (&l.label, labelled) {
            let ann = chart
                .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
                .map_err(err)?;
            set_legend(ann, label, l.color, l.marker);
        }
        if let Some(m) = l.marker {
            let pts = l.points.iter().filter(|q| q.1.is_finite());
            draw_markers(&mut chart, pts.copied(), m, l.color)?;
        }
        let inf: Vec<(f64, f64)> = l
            .points
            .iter()
            .filter(|q| !q.1.is_finite())
            .map(|q| (q.0, top))
            .collect();
        if !inf.is_empty() {
            any_inf = true;
            chart
                .draw_series(
                    inf.iter()
                        .map(|&q| TriangleMarker::new(q, 7, l.color.stroke_width(2))),
                )
                .map_err(err)?;
        }
    }
    if any_inf && p.legend {
        chart
            .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
            .map_err(err)?
            .label("not settled (drawn at the top)")
            .legend(|(lx, ly)| {
                EmptyElement::at((lx + 10, ly))
                    + TriangleMarker::new((0, 0), 7, RGBColor(90, 90, 90).stroke_width(2))
            });
    }
    if p.legend && p.lines.iter().any(|l| l.label.is_some()) {
        let frac = |v: f64, lo: f64, hi: f64, log: bool| {
            if log {
                (v.max(lo).ln() - lo.ln()) / (hi.ln() - lo.ln())
            } else {
                (v - lo) / (hi - lo)
            }
        };
        let pts: Vec<(f64, f64)> = p
            .lines
            .iter()
            .flat_map(|l| l.points.iter())
            .map(|&(px, py)| {
                let py = if py.is_finite() { py } else { top };
                (frac(px, xlo, xhi, p.x_log), frac(py, ylo, yhi, p.y_log))
            })
            .collect();
        let position = legend_corner(&pts, p.lines.len());
        chart
            .configure_series_labels()
            .position(position)
            .background_style(WHITE.mix(0.88))
            .border_style(BLACK.mix(0.25))
            .label_font((FONT, 15))
            .draw()
            .map_err(err)?;
    }
    Ok(())
}

/// The corner of a panel whose legend box would cover the fewest data points (`pts` in
/// fractions of the plot area, 0..1 from the lower left); ties keep the upper right.
fn legend_corner(pts: &[(f64, f64)], entries: usize) -> SeriesLabelPosition {
    let h = (0.1 + 0.075 * entries as f64).min(0.6);
    let w = 0.42;
    let corners = [
        (SeriesLabelPosition::UpperRight, 1.0 - w, 1.0, 1.0 - h, 1.0),
        (SeriesLabelPosition::UpperLeft, 0.0, w, 1.0 - h, 1.0),
        (SeriesLabelPosition::LowerRight, 1.0 - w, 1.0, 0.0, h),
        (SeriesLabelPosition::LowerLeft, 0.0, w, 0.0, h),
    ];
    let mut best = (usize::MAX, SeriesLabelPosition::UpperRight);
    for (pos, x0, x1, y0, y1) in corners {
        let n = pts
            .iter()
            .filter(|(x, y)| (x0..=x1).contains(x) && (y0..=y1).contains(y))
            .count();
        if n < best.0 {
            best = (n, pos);
        }
    }
    best.1
}

/// Set the legend glyph of a series: the line's marker (colour and shape tell lines apart),
/// or a short stroke for lines without markers. (Each arm passes a concrete element: plotters
/// only accepts a dynamic element here for `'static` backends.)
fn set_legend<'a, DB: DrawingBackend + 'a>(
    anno: &mut plotters::chart::SeriesAnno<'a, DB>,
    label: &str,
    color: RGBColor,
    marker: Option<Marker>,
) {
    anno.label(label);
    match marker {
        Some(Marker::Circle) => {
            anno.legend(move |(x, y)| Circle::new((x + 11, y), 5, color.filled()));
        }
        Some(Marker::Triangle) => {
            anno.legend(move |(x, y)| TriangleMarker::new((x + 11, y), 6, color.filled()));
        }
        Some(Marker::Square) => {
            anno.legend(move |(x, y)| {
                Rectangle::new([(x + 6, y - 5), (x + 16, y + 5)], color.filled())
            });
        }
        Some(Marker::Cross) => {
            anno.legend(move |(x, y)| Cross::new((x + 11, y), 5, color.stroke_width(2)));
        }
        None => {
            anno.legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 22, y)], color.stroke_width(3))
            });
        }
    }
}

fn draw_markers<DB, X, Y>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<X, Y>>,
    pts: impl Iterator<Item = (f64, f64)>,
    m: Marker,
    color: RGBColor,
) -> DrawResult
where
    DB: DrawingBackend,
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    let pts: Vec<(f64, f64)> = pts.collect();
    match m {
        Marker::Circle => chart
            .draw_series(pts.iter().map(|&q| Circle::new(q, 4, color.filled())))
            .map(|_| ()),
        Marker::Triangle => chart
            .draw_series(
                pts.iter()
                    .map(|&q| TriangleMarker::new(q, 5, color.filled())),
            )
            .map(|_| ()),
        Marker::Square => {
            chart
                .draw_series(pts.iter().map(|&q| {
                    EmptyElement::at(q) + Rectangle::new([(-4, -4), (4, 4)], color.filled())
                }))
                .map(|_| ())
        }
        Marker::Cross => chart
            .draw_series(pts.iter().map(|&q| Cross::new(q, 4, color.stroke_width(2))))
            .map(|_| ()),
    }
    .map_err(err)
}

fn draw_figure<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, f: &Figure) -> DrawResult {
    root.fill(&WHITE).map_err(err)?;
    let body = root
        .titled(&f.title, (FONT, 24).into_font().style(FontStyle::Bold))
        .map_err(err)?;
    let body = if f.legend.is_empty() {
        body
    } else {
        let (legend, rest) = body.split_vertically(legend_height(f));
        draw_legend(&legend, &f.legend, legend_columns(f))?;
        rest
    };
    let cols = f.columns.max(1);
    let rows = f.panels.len().div_ceil(cols).max(1);
    let areas = body.split_evenly((rows, cols));
    for (area, p) in areas.iter().zip(&f.panels) {
        draw_panel(area, p)?;
    }
    root.present().map_err(err)
}

fn legend_height(f: &Figure) -> u32 {
    if f.legend.is_empty() {
        0
    } else {
        f.legend.len().div_ceil(legend_columns(f)) as u32 * LEGEND_ROW_PX + 10
    }
}

/// The figure legend: entries in rows of `columns`, centred.
fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[LegendEntry],
    columns: usize,
) -> DrawResult {
    let (w, _) = area.dim_in_pixel();
    let col_w = (w as i32 - 80) / columns as i32;
    let per_row = columns.min(entries.len()).max(1);
    let x0 = (w as i32 - col_w * per_row as i32) / 2;
    let font = (FONT, 16).into_font().color(&BLACK);
    for (i, e) in entries.iter().enumerate() {
        let x = x0 + col_w * (i % columns) as i32;
        let y = (i / columns) as i32 * LEGEND_ROW_PX as i32 + 14;
        let c = (x + 11, y);
        let filled = e.color.filled();
        let stroke = e.color.stroke_width(2);
        let r = match (e.marker, e.hollow) {
            (_, true) => area.draw(&TriangleMarker::new(c, 7, stroke)),
            (Some(Marker::Circle), _) => area.draw(&Circle::new(c, 5, filled)),
            (Some(Marker::Triangle), _) => area.draw(&TriangleMarker::new(c, 6, filled)),
            (Some(Marker::Square), _) => {
                area.draw(&Rectangle::new([(x + 6, y - 5), (x + 16, y + 5)], filled))
            }
            (Some(Marker::Cross), _) => area.draw(&Cross::new(c, 5, stroke)),
            (None, _) => area.draw(&PathElement::new(
                vec![(x, y), (x + 22, y)],
                e.color.stroke_width(3),
            )),
        };
        r.map_err(err)?;
        area.draw(&Text::new(e.label.clone(), (x + 30, y - 9), font.clone()))
            .map_err(err)?;
    }
    Ok(())
}

/// Height (px) of a figure.
fn height(f: &Figure) -> u32 {
    let rows = f.panels.len().div_ceil(f.columns.max(1)).max(1) as u32;
    rows * f.row_height + 50 + legend_height(f)
}

/// The most panels a figure draws (the rest are left out): with [`MAX_LEGEND`] this keeps
/// every figure a few thousand pixels high whatever the sweep.
pub const MAX_PANELS: usize = 32;

/// The most entries a figure's legend draws (the rest are left out).
pub const MAX_LEGEND: usize = 64;

/// Write `f` as `<stem>.svg` and `<stem>.png` in `dir` (at most [`MAX_PANELS`] panels and
/// [`MAX_LEGEND`] legend entries of it).
pub fn write(f: &Figure, dir: &Path, stem: &str) -> Result<(), Error> {
    let bounded;
    let f = if f.panels.len() > MAX_PANELS || f.legend.len() > MAX_LEGEND {
        let mut b = f.clone();
        b.panels.truncate(MAX_PANELS);
        b.legend.truncate(MAX_LEGEND);
        bounded = b;
        &bounded
    } else {
        f
    };
    init_fonts();
    let size = (f.width, height(f));
    let fail = |path: &Path, e: String| Error::Write {
        path: path.to_path_buf(),
        source: std::io::Error::other(e),
    };
    let svg = dir.join(format!("{stem}.svg"));
    // Written as it is drawn: a figure of many runs is never held as text.
    crate::output::atomic::write_atomic_with(&svg, |w| {
        let error = std::cell::RefCell::new(None);
        let drawn = draw_figure(
            svg_stream::SvgStream::new(w, size, &error).into_drawing_area(),
            f,
        );
        match (drawn, error.into_inner()) {
            (_, Some(e)) => Err(Error::write(&svg, e)),
            (Err(e), None) => Err(fail(&svg, e)),
            (Ok(()), None) => Ok(()),
        }
    })?;
    crate::output::atomic::write_png(&dir.join(format!("{stem}.png")), |tmp| {
        draw_figure(BitMapBackend::new(tmp, size).into_drawing_area(), f)
    })
}
