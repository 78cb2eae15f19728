//! The ranking bar chart of a sweep (`plots/ranking.svg/png`): per band, one horizontal
//! bar per candidate, its move-and-settle time summed over the workload points, fastest on
//! top; the winner and the `[current]` candidate in their own colours, the candidates that
//! do not settle (or whose run failed) as a grey bar across the panel saying so.
//!
//! It is drawn for every sweep that ranks candidates, also one that sweeps no numeric
//! parameter (a shaper sweep), where it is the only figure. A panel shows at most
//! [`MAX_BARS`] candidates (the fastest, and the current one wherever it ranks) and says
//! how many it leaves out; every candidate is in summary.md.
//!
//! The chart is plain data ([`BarChart`]) drawn on a fixed pixel layout: the labels in a
//! column on the left (`1. zv, frequency_hz=40 (run 3)`: rank, candidate, run number),
//! the bars on a linear time axis from zero.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::{DrawResult, FONT, PALETTE, err, fmt_num, init_fonts};
use crate::error::Error;
use crate::output::ranking::Ranking;

/// The most bars a panel draws (the fastest; the current candidate is added when it ranks
/// lower).
pub const MAX_BARS: usize = 24;

/// The most panels (bands) a chart draws: [`super::MAX_PANELS`].
const MAX_PANELS: usize = super::MAX_PANELS;

/// One bar.
#[derive(Debug, Clone, PartialEq)]
pub struct Bar {
    /// The text left of the bar.
    pub label: String,
    /// Its length (ms); `None` draws the grey bar with `missing`.
    pub value: Option<f64>,
    /// What a bar without a value says (`not settled at every point`, `a run failed`).
    pub missing: String,
    /// Drawn in the winner's colour.
    pub winner: bool,
    /// Drawn in the current candidate's colour.
    pub current: bool,
}

/// One panel: a band's ranking.
#[derive(Debug, Clone, PartialEq)]
pub struct BarPanel {
    /// The panel's title.
    pub title: String,
    /// The time axis's description.
    pub axis: String,
    /// The bars, top to bottom.
    pub bars: Vec<Bar>,
    /// A line under the axis (e.g. the candidates left out); empty for none.
    pub note: String,
}

/// A bar chart: panels stacked top to bottom.
#[derive(Debug, Clone, PartialEq)]
pub struct BarChart {
    /// Title above the panels.
    pub title: String,
    /// The panels.
    pub panels: Vec<BarPanel>,
}

const WIDTH: u32 = 1400;
const TITLE_PX: u32 = 44;
const LEGEND_PX: u32 = 34;
const PANEL_TITLE_PX: i32 = 36;
const ROW_PX: i32 = 28;
const AXIS_PX: i32 = 54;
const NOTE_PX: i32 = 24;
/// Room right of the longest bar for its value.
const VALUE_PX: i32 = 150;

const WINNER: RGBColor = PALETTE[3];
const CURRENT: RGBColor = PALETTE[1];
const OTHER: RGBColor = PALETTE[0];
const MISSING: RGBColor = RGBColor(0xd9, 0xd9, 0xd9);

/// The bar label of candidate `label` ranked `rank` (1-based), with its runs.
fn bar_label(rank: usize, label: &str, runs: &[usize], current: bool) -> String {
    let ids = match runs {
        [one] => format!("run {one}"),
        [a, b] => format!("runs {a}, {b}"),
        [] => String::new(),
        many => format!("{} runs", many.len()),
    };
    let current = if current { "current, " } else { "" };
    format!("{rank}. {label} ({current}{ids})")
}

/// The chart of `ranking` for scenario `name`: `None` when there is nothing to compare
/// (fewer than two candidates).
pub fn ranking_chart(name: &str, ranking: &Ranking) -> Option<BarChart> {
    if ranking.bands.iter().all(|b| b.candidates.len() < 2) {
        return None;
    }
    let over = if ranking.workload_keys.is_empty() {
        String::new()
    } else {
        format!(", summed over {}", ranking.workload_keys.join(", "))
    };
    let panels = ranking
        .bands
        .iter()
        .take(MAX_PANELS)
        .map(|b| {
            let n = b.candidates.len();
            let mut shown: Vec<usize> = (0..n.min(MAX_BARS)).collect();
            if let Some(c) = (MAX_BARS..n).find(|&i| b.candidates[i].current) {
                shown.push(c);
            }
            let winner = b.winner.as_ref().map(|w| w.label.as_str());
            let bars = shown
                .iter()
                .map(|&i| {
                    let c = &b.candidates[i];
                    Bar {
                        label: bar_label(i + 1, &c.label, &c.runs, c.current),
                        value: c.total_s.map(|t| t * 1e3),
                        missing: if c.failed {
                            "a run failed".into()
                        } else if c.runs.len() > 1 {
                            "not settled at every point".into()
                        } else {
                            "not settled in the window".into()
                        },
                        winner: winner == Some(c.label.as_str()),
                        current: c.current,
                    }
                })
                .collect();
            let note = if shown.len() < n {
                format!(
                    "The {} fastest of {n} candidates{}; every candidate is in summary.md.",
                    MAX_BARS.min(n),
                    if shown.len() > MAX_BARS {
                        " and the current one"
                    } else {
                        ""
                    }
                )
            } else {
                String::new()
            };
            BarPanel {
                title: format!("move and settle to within {} um", b.band_um),
                axis: format!("move + settle (ms{over})"),
                bars,
                note,
            }
        })
        .collect();
    Some(BarChart {
        title: format!(
            "{name}: candidates ranked by move-and-settle time ({})",
            if ranking.setting_keys.is_empty() {
                "profile".to_string()
            } else {
                ranking.setting_keys.join(", ")
            }
        ),
        panels,
    })
}

/// The file stem of the chart inside `plots/`.
pub const STEM: &str = "ranking";

/// Write the chart of `ranking` into `dir` (created if needed); returns it for the summary
/// with paths relative to `dir`'s parent, `None` when there is nothing to compare.
pub fn write(
    dir: &Path,
    name: &str,
    ranking: &Ranking,
) -> Result<Option<crate::output::summary::Figure>, Error> {
    let Some(chart) = ranking_chart(name, ranking) else {
        return Ok(None);
    };
    crate::output::atomic::create_subdir(dir)?;
    chart.write(dir, STEM)?;
    let folder = dir
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    Ok(Some(crate::output::summary::Figure {
        title: "Every candidate ranked by move-and-settle time, per band".into(),
        svg: format!("{folder}/{STEM}.svg"),
        png: format!("{folder}/{STEM}.png"),
    }))
}

fn panel_height(p: &BarPanel) -> i32 {
    PANEL_TITLE_PX
        + ROW_PX * p.bars.len() as i32
        + AXIS_PX
        + if p.note.is_empty() { 0 } else { NOTE_PX }
}

/// A tick step for an axis from 0 to `max`: 1, 2 or 5 times a power of ten, about six
/// ticks.
fn tick_step(max: f64) -> f64 {
    let raw = (max / 6.0).max(f64::MIN_POSITIVE);
    let p = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * p)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * p)
}

impl BarChart {
    /// Its size (px).
    pub fn size(&self) -> (u32, u32) {
        let panels: i32 = self.panels.iter().map(panel_height).sum();
        (WIDTH, TITLE_PX + LEGEND_PX + panels.max(0) as u32 + 10)
    }

    /// Write it as `<stem>.svg` and `<stem>.png` in `dir`.
    pub fn write(&self, dir: &Path, stem: &str) -> Result<(), Error> {
        init_fonts();
        let size = self.size();
        let fail = |path: &Path, e: String| Error::Write {
            path: path.to_path_buf(),
            source: std::io::Error::other(e),
        };
        let svg = dir.join(format!("{stem}.svg"));
        let mut text = String::new();
        self.draw(SVGBackend::with_string(&mut text, size).into_drawing_area())
            .map_err(|e| fail(&svg, e))?;
        crate::output::atomic::write_atomic(&svg, text.as_bytes())?;
        crate::output::atomic::write_png(&dir.join(format!("{stem}.png")), |tmp| {
            self.draw(BitMapBackend::new(tmp, size).into_drawing_area())
        })
    }

    /// Width of the label column (px): the longest label, within bounds.
    fn label_px(&self) -> i32 {
        let longest = self
            .panels
            .iter()
            .flat_map(|p| p.bars.iter())
            .map(|b| b.label.chars().count())
            .max()
            .unwrap_or(0);
        // About 8 px per character at 15 px.
        (longest as f64 * 8.0 + 30.0).clamp(160.0, 700.0) as i32
    }

    fn draw<DB: DrawingBackend>(&self, root: DrawingArea<DB, Shift>) -> DrawResult {
        root.fill(&WHITE).map_err(err)?;
        let body = root
            .titled(&self.title, (FONT, 22).into_font().style(FontStyle::Bold))
            .map_err(err)?;
        let (legend, mut rest) = body.split_vertically(LEGEND_PX);
        let bars = || self.panels.iter().flat_map(|p| p.bars.iter());
        draw_legend(
            &legend,
            bars().any(|b| b.current),
            bars().any(|b| b.value.is_none_or(|v| !v.is_finite())),
        )?;
        let label_px = self.label_px();
        for p in &self.panels {
            let (area, below) = rest.split_vertically(panel_height(p));
            draw_panel(&area, p, label_px)?;
            rest = below;
        }
        root.present().map_err(err)
    }
}

/// The legend: the colours in use (current and missing only when a bar has them).
fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    current: bool,
    missing: bool,
) -> DrawResult {
    let font = (FONT, 15).into_font().color(&BLACK);
    let entries = [
        (WINNER, "winner", true),
        (CURRENT, "current settings", current),
        (OTHER, "other candidates", true),
        (MISSING, "does not settle / failed", missing),
    ];
    let mut x = 30;
    for (color, text, _) in entries.into_iter().filter(|e| e.2) {
        area.draw(&Rectangle::new([(x, 8), (x + 22, 22)], color.filled()))
            .map_err(err)?;
        area.draw(&Text::new(text, (x + 30, 6), font.clone()))
            .map_err(err)?;
        x += 50 + 8 * text.chars().count() as i32;
    }
    Ok(())
}

fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    p: &BarPanel,
    label_px: i32,
) -> DrawResult {
    let (w, _) = area.dim_in_pixel();
    let x0 = label_px + 14;
    let x1 = (w as i32 - VALUE_PX).max(x0 + 100);
    let top = PANEL_TITLE_PX;
    let bottom = top + ROW_PX * p.bars.len() as i32;
    area.draw(&Text::new(
        p.title.clone(),
        (14, 8),
        (FONT, 19).into_font().style(FontStyle::Bold).color(&BLACK),
    ))
    .map_err(err)?;
    let max = p
        .bars
        .iter()
        .filter_map(|b| b.value)
        .filter(|v| v.is_finite())
        .fold(0.0_f64, f64::max);
    let step = tick_step(if max > 0.0 { max } else { 1.0 });
    let axis_max = (max / step).ceil().max(1.0) * step;
    let px = |v: f64| x0 + ((v / axis_max).clamp(0.0, 1.0) * f64::from(x1 - x0)).round() as i32;
    let grey = RGBColor(90, 90, 90);
    let tick_font = (FONT, 14)
        .into_font()
        .color(&grey)
        .pos(Pos::new(HPos::Center, VPos::Top));
    let ticks = (axis_max / step).round() as i32;
    for k in 0..=ticks {
        let v = f64::from(k) * step;
        let x = px(v);
        area.draw(&PathElement::new(
            vec![(x, top), (x, bottom)],
            BLACK.mix(if k == 0 { 0.6 } else { 0.1 }).stroke_width(1),
        ))
        .map_err(err)?;
        area.draw(&Text::new(fmt_num(v), (x, bottom + 4), tick_font.clone()))
            .map_err(err)?;
    }
    area.draw(&Text::new(
        p.axis.clone(),
        ((x0 + x1) / 2, bottom + 24),
        (FONT, 15)
            .into_font()
            .color(&BLACK)
            .pos(Pos::new(HPos::Center, VPos::Top)),
    ))
    .map_err(err)?;
    let label_font = (FONT, 15)
        .into_font()
        .color(&BLACK)
        .pos(Pos::new(HPos::Right, VPos::Center));
    let value_font = (FONT, 14)
        .into_font()
        .color(&BLACK)
        .pos(Pos::new(HPos::Left, VPos::Center));
    for (i, b) in p.bars.iter().enumerate() {
        let cy = top + ROW_PX * i as i32 + ROW_PX / 2;
        area.draw(&Text::new(
            b.label.clone(),
            (label_px, cy),
            label_font.clone(),
        ))
        .map_err(err)?;
        match b.value.filter(|v| v.is_finite()) {
            Some(v) => {
                let color = if b.winner {
                    WINNER
                } else if b.current {
                    CURRENT
                } else {
                    OTHER
                };
                let end = px(v).max(x0 + 1);
                area.draw(&Rectangle::new(
                    [(x0, cy - 9), (end, cy + 9)],
                    color.filled(),
                ))
                .map_err(err)?;
                let mut text = format!("{v:.1} ms");
                if b.winner {
                    text.push_str("  winner");
                }
                area.draw(&Text::new(text, (end + 6, cy), value_font.clone()))
                    .map_err(err)?;
            }
            None => {
                area.draw(&Rectangle::new(
                    [(x0, cy - 9), (x1, cy + 9)],
                    MISSING.filled(),
                ))
                .map_err(err)?;
                let stroke = if b.current { CURRENT } else { grey };
                area.draw(&Rectangle::new(
                    [(x0, cy - 9), (x1, cy + 9)],
                    stroke.stroke_width(1),
                ))
                .map_err(err)?;
                area.draw(&Text::new(
                    b.missing.clone(),
                    (x0 + 8, cy),
                    value_font.clone(),
                ))
                .map_err(err)?;
            }
        }
    }
    if !p.note.is_empty() {
        area.draw(&Text::new(
            p.note.clone(),
            (x0, bottom + AXIS_PX - 4),
            (FONT, 14).into_font().color(&grey),
        ))
        .map_err(err)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_are_one_two_five() {
        assert_eq!(tick_step(270.2), 50.0);
        assert_eq!(tick_step(6.0), 1.0);
        assert_eq!(tick_step(11.0), 2.0);
    }

    use crate::output::ranking::{Band, Candidate, Ranking, Winner};

    /// 30 candidates, the last three unsettled, the current one 29th: the panel shows the
    /// 24 fastest and the current one, says what it leaves out, and draws the unsettled
    /// current candidate as such.
    #[test]
    fn many_candidates_show_the_fastest_and_current_and_say_so() {
        let candidates: Vec<Candidate> = (0..30)
            .map(|i| Candidate {
                label: format!("c{i}"),
                total_s: (i < 27).then_some(0.1 + 0.01 * i as f64),
                runs: vec![i],
                current: i == 28,
                failed: false,
            })
            .collect();
        let ranking = Ranking {
            setting_keys: vec!["shaper.type".into()],
            workload_keys: Vec::new(),
            has_current: true,
            current_label: Some("c28".into()),
            shapers: false,
            candidates: Vec::new(),
            bands: vec![Band {
                band_um: 10.0,
                points: Vec::new(),
                order: Vec::new(),
                winner: Some(Winner {
                    label: "c0".into(),
                    total_s: 0.1,
                    points: 1,
                    reference: None,
                }),
                candidates,
            }],
            repeats: Vec::new(),
            unused: Vec::new(),
        };
        let chart = ranking_chart("demo", &ranking).expect("a chart");
        let p = &chart.panels[0];
        assert_eq!(p.bars.len(), MAX_BARS + 1);
        assert_eq!(p.bars[0].label, "1. c0 (run 0)");
        assert!(p.bars[0].winner && !p.bars[1].winner);
        assert_eq!(p.bars[MAX_BARS - 1].label, "24. c23 (run 23)");
        let last = &p.bars[MAX_BARS];
        assert_eq!(last.label, "29. c28 (current, run 28)");
        assert!(last.current && last.value.is_none());
        assert_eq!(
            p.note,
            "The 24 fastest of 30 candidates and the current one; every candidate is in summary.md."
        );
        init_fonts();
        let mut svg = String::new();
        chart
            .draw(SVGBackend::with_string(&mut svg, chart.size()).into_drawing_area())
            .expect("drawn");
        // plotters writes each text on a line of its own inside its element.
        let text = |t: &str| format!(">\n{t}\n</text>");
        assert_eq!(svg.matches(&text("not settled in the window")).count(), 1);
        assert!(svg.contains(&text("29. c28 (current, run 28)")));
        assert!(svg.contains(&text("100.0 ms  winner")));
        assert!(svg.contains(&text("does not settle / failed")), "legend");
    }

    #[test]
    fn labels_name_rank_candidate_and_runs() {
        assert_eq!(bar_label(1, "zv", &[3], false), "1. zv (run 3)");
        assert_eq!(
            bar_label(2, "mzv", &[4, 9], true),
            "2. mzv (current, runs 4, 9)"
        );
        assert_eq!(bar_label(3, "ei", &[1, 5, 9], false), "3. ei (3 runs)");
    }
}
