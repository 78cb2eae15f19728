//! The figure of a G-code sweep (`plots/gcode_jobs.svg/png`): each candidate's print time
//! against its worst and its 95th-percentile contour error, one marker per candidate, the
//! Pareto front of each panel drawn as a line, the current candidate's time and error as
//! dashed rules (what lies below and left of both beats it in both).

use std::path::Path;

use plotters::style::RGBColor;

use super::{Figure, LegendEntry, Line, Marker, PALETTE, Panel, Rule};
use crate::error::Error;
use crate::output::jobs::{JobRow, Jobs, pareto};

/// The file stem of the figure inside `plots/`.
pub const STEM: &str = "gcode_jobs";

/// The figure of `jobs` in scenario `name`; `None` without two candidates that ran.
pub fn figure(name: &str, jobs: &Jobs) -> Option<Figure> {
    let ok: Vec<&JobRow> = jobs
        .rows
        .iter()
        .filter(|r| r.print_time_s.is_some() && r.worst_um.is_some())
        .collect();
    if ok.len() < 2 {
        return None;
    }
    // Candidates in run order: the colours follow the runs.
    let mut by_run = ok.clone();
    by_run.sort_by_key(|r| r.id);
    let style = |n: usize| {
        (
            PALETTE[n % PALETTE.len()],
            Marker::ALL[(n / PALETTE.len()) % Marker::ALL.len()],
        )
    };
    let panel = |title: &str, y_label: &str, err: fn(&JobRow) -> Option<f64>| {
        let mut lines = Vec::new();
        for (n, r) in by_run.iter().enumerate() {
            let (color, marker) = style(n);
            let (Some(t), Some(e)) = (r.print_time_s, err(r)) else {
                continue;
            };
            let mut l = Line::new(None, color, vec![(t, e)]);
            l.marker = Some(marker);
            l.width = 0;
            lines.push(l);
        }
        let pts: Vec<(f64, f64)> = by_run
            .iter()
            .map(|r| {
                (
                    r.print_time_s.unwrap_or(f64::INFINITY),
                    err(r).unwrap_or(f64::INFINITY),
                )
            })
            .collect();
        let mut front: Vec<(f64, f64)> = pareto(&pts).into_iter().map(|i| pts[i]).collect();
        front.sort_by(|a, b| a.0.total_cmp(&b.0).then(b.1.total_cmp(&a.1)));
        front.dedup();
        if front.len() >= 2 {
            let mut l = Line::new(None, RGBColor(0, 0, 0), front);
            l.width = 1;
            lines.push(l);
        }
        let current = jobs.current();
        Panel {
            title: title.into(),
            x_label: "print time (s)".into(),
            y_label: y_label.into(),
            lines,
            y_from_zero: true,
            vrules: current
                .and_then(|c| c.print_time_s)
                .map(|t| Rule {
                    at: t,
                    label: "current".into(),
                })
                .into_iter()
                .collect(),
            hrules: current
                .and_then(err)
                .map(|e| Rule {
                    at: e,
                    label: "current".into(),
                })
                .into_iter()
                .collect(),
            ..Panel::default()
        }
    };
    let panels = vec![
        panel(
            "worst contour error against print time",
            "worst contour error (um)",
            |r| r.worst_um,
        ),
        panel(
            "95th-percentile contour error against print time",
            "p95 contour error (um)",
            |r| r.p95_um,
        ),
    ];
    let mut legend: Vec<LegendEntry> = by_run
        .iter()
        .enumerate()
        .map(|(n, r)| {
            let (color, marker) = style(n);
            LegendEntry {
                label: format!(
                    "run {}: {}{}",
                    r.id,
                    r.label,
                    if r.current { " (current)" } else { "" }
                ),
                color,
                marker: Some(marker),
                hollow: false,
            }
        })
        .collect();
    legend.push(LegendEntry {
        label: "Pareto front".into(),
        color: RGBColor(0, 0, 0),
        marker: None,
        hollow: false,
    });
    Some(Figure {
        title: format!("{name}: print time and contour error of {}", jobs.file),
        panels,
        columns: 2,
        width: 1500,
        row_height: 520,
        legend,
    })
}

/// Write the figure of `jobs` into `dir` (created if needed); returns it for the summary
/// with paths relative to `dir`'s parent, `None` when there is no figure.
pub fn write(
    dir: &Path,
    name: &str,
    jobs: &Jobs,
) -> Result<Option<crate::output::summary::Figure>, Error> {
    let Some(f) = figure(name, jobs) else {
        return Ok(None);
    };
    crate::output::atomic::create_subdir(dir)?;
    super::write(&f, dir, STEM)?;
    let folder = dir
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    Ok(Some(crate::output::summary::Figure {
        title: "Print time against worst and p95 contour error, Pareto front marked".into(),
        svg: format!("{folder}/{STEM}.svg"),
        png: format!("{folder}/{STEM}.png"),
    }))
}
