//! Sweep figures: settle time and residual vibration against each swept numeric parameter,
//! one line per profile kind.
//!
//! One figure per swept numeric parameter `P` (file `vs_<P>.svg/png`). Panels: for each
//! band, the settle time and the move-and-settle time (ms); then the residual peak and RMS
//! after the move (um). The x axis is logarithmic when `P` spans a decade or more (all
//! values > 0), the residual axes when they span more than a factor of 20.
//!
//! When other parameters are swept too, each point of `P` has several runs per kind: up to
//! sixteen candidates (a kind with one combination of the other swept values, e.g.
//! `trapezoid, mzv`) are drawn as lines of their own; beyond that each kind shows the median
//! over the other parameters (named in its label) with a shaded min-max band. Not-settled runs (`inf`) are hollow triangles at
//! the top edge of their panel.

use std::path::Path;

use settle_planner::ProfileKind;

use plotters::style::RGBColor;

use super::{Figure, LegendEntry, Line, Marker, PALETTE, Panel, fmt_num};
use crate::error::Error;
use crate::input::runs_columns::RunsColumns;
use crate::spec::run_spec::RunSpec;
use crate::spec::runs::RunList;
use crate::spec::value::Value;
use crate::studies::{self, PlotColumn};

/// The panels of a sweep figure: a study's that replace the common ones when the table
/// has them (a scan's step-axis panels: the common ones would measure the run-out), else the
/// common ones (per band the settle and move-and-settle times, the residual peak and RMS)
/// and the other studies' (a corner's contour error); only columns the table has.
fn columns(bands: &[f64], table: &RunsColumns) -> Vec<PlotColumn> {
    let present = |p: &PlotColumn| table.column(&p.column).is_some();
    for k in studies::all().iter().filter(|k| k.replaces_move_tables()) {
        let own: Vec<PlotColumn> = k.figures(bands).into_iter().filter(present).collect();
        if !own.is_empty() {
            return own;
        }
    }
    let mut out = Vec::new();
    for b in bands {
        out.push(PlotColumn::new(
            format!("settle_time_s_{b}um"),
            format!("settle time to within {b} um"),
            "settle time",
            "ms",
            1e3,
            false,
        ));
        out.push(PlotColumn::new(
            format!("move_and_settle_s_{b}um"),
            format!("move + settle to within {b} um"),
            "move + settle",
            "ms",
            1e3,
            false,
        ));
    }
    out.push(PlotColumn::new(
        "residual_peak_um",
        "residual vibration after the move: peak",
        "peak",
        "um",
        1.0,
        true,
    ));
    out.push(PlotColumn::new(
        "residual_rms_um",
        "residual vibration after the move: RMS",
        "RMS",
        "um",
        1.0,
        true,
    ));
    for k in studies::all().iter().filter(|k| !k.replaces_move_tables()) {
        out.extend(k.figures(bands));
    }
    out.into_iter().filter(present).collect()
}

/// File-name-safe form of a parameter (`move.distance_mm` -> `move_distance_mm`).
pub fn slug(param: &str) -> String {
    param
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect()
}

fn number(v: &Value) -> Option<f64> {
    v.number()
}

/// The swept numeric parameters of a sweep, in axis order.
pub fn numeric_params(runs: &dyn RunList) -> Vec<String> {
    runs.first()
        .map(|r| {
            r.swept
                .iter()
                .filter(|(_, v)| number(v).is_some())
                .map(|(p, _)| p.clone())
                .collect()
        })
        .unwrap_or_default()
}

/// Lines drawn one per candidate at most; beyond, one median line per profile kind.
const MAX_LINES: usize = 16;

/// The lines of one metric against `param`.
fn lines(runs: &dyn RunList, table: &RunsColumns, param: &str, m: &PlotColumn) -> Vec<Line> {
    let mut kinds: Vec<ProfileKind> = Vec::new();
    let mut combos: Vec<String> = Vec::new();
    for r in runs.iter() {
        if !kinds.contains(&r.profile) {
            kinds.push(r.profile);
        }
        let c = other_label(&r, param);
        if !combos.contains(&c) {
            combos.push(c);
        }
    }
    let value = |i: usize| table.num(i, &m.column).map(|y| y * m.scale);
    let x_of = |r: &RunSpec| {
        r.swept
            .iter()
            .find(|(p, _)| p == param)
            .and_then(|(_, v)| number(v))
    };
    let mut out = Vec::new();
    // Few enough candidates: one line each (every swept value but `param`), a colour each.
    if kinds.len() * combos.len() <= MAX_LINES {
        let mut n = 0usize;
        for k in &kinds {
            for c in &combos {
                let mut pts: Vec<(f64, f64)> = runs
                    .iter()
                    .enumerate()
                    .filter(|(_, r)| r.profile == *k && other_label(r, param) == *c)
                    .filter_map(|(i, r)| Some((x_of(&r)?, value(i)?)))
                    .collect();
                pts.sort_by(|a, b| a.0.total_cmp(&b.0));
                let label = if c.is_empty() {
                    k.to_string()
                } else {
                    format!("{k}, {c}")
                };
                let mut l = Line::new(Some(label), PALETTE[n % PALETTE.len()], pts);
                l.marker = Some(Marker::ALL[(n / PALETTE.len()) % Marker::ALL.len()]);
                out.push(l);
                n += 1;
            }
        }
        return out;
    }
    for (ki, k) in kinds.iter().enumerate() {
        let color = PALETTE[ki % PALETTE.len()];
        // Median over the other parameters, min-max band.
        let mut xs: Vec<f64> = runs.iter().filter_map(|r| x_of(&r)).collect();
        xs.sort_by(f64::total_cmp);
        xs.dedup();
        let mut pts = Vec::new();
        let mut band = Vec::new();
        for x in xs {
            let mut ys: Vec<f64> = runs
                .iter()
                .enumerate()
                .filter(|(_, r)| r.profile == *k && x_of(r) == Some(x))
                .filter_map(|(i, _)| value(i))
                .collect();
            if ys.is_empty() {
                continue;
            }
            ys.sort_by(f64::total_cmp);
            let n = ys.len();
            let median = if n % 2 == 1 {
                ys[n / 2]
            } else {
                0.5 * (ys[n / 2 - 1] + ys[n / 2])
            };
            pts.push((x, median));
            let finite: Vec<f64> = ys.iter().copied().filter(|y| y.is_finite()).collect();
            if let (Some(lo), Some(hi)) = (finite.first(), finite.last()) {
                band.push((x, *lo, *hi));
            }
        }
        let others: Vec<String> = runs
            .first()
            .map(|r| {
                r.swept
                    .iter()
                    .filter(|(p, v)| p != param && !matches!(v, Value::Study(_)))
                    .map(|(p, _)| p.clone())
                    .collect()
            })
            .unwrap_or_default();
        let what = if others.len() == 1 {
            "values of"
        } else {
            "combinations of"
        };
        let mut l = Line::new(
            Some(format!(
                "{k}: median over {} {what} {} (band: min-max)",
                combos.len(),
                others.join(", ")
            )),
            color,
            pts,
        );
        l.marker = Some(Marker::Circle);
        l.band = band;
        out.push(l);
    }
    out
}

/// The other swept numeric parameters of a run, e.g. `jmax_mm_s3=1e5` (empty if none).
fn other_label(r: &RunSpec, param: &str) -> String {
    r.swept
        .iter()
        .filter(|(p, v)| p != param && !matches!(v, Value::Study(_)))
        .map(|(p, v)| {
            let short = p.rsplit('.').next().unwrap_or(p);
            // Names (a swept machine preset) label themselves.
            number(v).map_or(v.to_string(), |x| format!("{short}={}", fmt_num(x)))
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// The figure of `param`.
pub fn figure(scenario: &str, runs: &dyn RunList, table: &RunsColumns, param: &str) -> Figure {
    let bands = runs.first().map(|r| r.bands_um.clone()).unwrap_or_default();
    let xs: Vec<f64> = runs
        .iter()
        .filter_map(|r| {
            r.swept
                .iter()
                .find(|(p, _)| p == param)
                .and_then(|(_, v)| number(v))
        })
        .collect();
    let (lo, hi) = xs
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        });
    let x_log = lo > 0.0 && hi / lo >= 10.0;
    let mut panels = Vec::new();
    for m in columns(&bands, table) {
        let lines = lines(runs, table, param, &m);
        let ys: Vec<f64> = lines
            .iter()
            .flat_map(|l| l.points.iter().map(|q| q.1))
            .filter(|y| y.is_finite())
            .collect();
        let (ylo, yhi) = ys
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &y| {
                (a.min(y), b.max(y))
            });
        let y_log = m.log_ok && ylo > 0.0 && yhi / ylo > 20.0;
        panels.push(Panel {
            title: m.title.clone(),
            x_label: param.to_string(),
            y_label: format!("{} ({})", m.quantity, m.unit),
            lines,
            x_log,
            y_log,
            y_from_zero: true,
            ..Panel::default()
        });
    }
    // One legend for the figure: the lines are the same in every panel.
    let mut legend: Vec<LegendEntry> = panels
        .first()
        .map(|p| {
            p.lines
                .iter()
                .filter_map(|l| {
                    Some(LegendEntry {
                        label: l.label.clone()?,
                        color: l.color,
                        marker: l.marker,
                        hollow: false,
                    })
                })
                .collect()
        })
        .unwrap_or_default();
    let any_inf = panels
        .iter()
        .flat_map(|p| p.lines.iter())
        .any(|l| l.points.iter().any(|q| !q.1.is_finite()));
    if any_inf {
        legend.push(LegendEntry {
            label: "not settled in the window (drawn at the top)".into(),
            color: RGBColor(90, 90, 90),
            marker: None,
            hollow: true,
        });
    }
    Figure {
        title: format!("{scenario}: settling against {param}"),
        panels,
        columns: 2,
        width: 1500,
        row_height: 380,
        legend,
    }
}

/// Write every sweep figure into `dir` (created if needed); returns them for the summary
/// with paths relative to `dir`'s parent (`plots/...`).
pub fn write_all(
    dir: &Path,
    scenario: &str,
    runs: &dyn RunList,
    table: &RunsColumns,
) -> Result<Vec<crate::output::summary::Figure>, Error> {
    let params = numeric_params(runs);
    if params.is_empty() || table.is_empty() {
        return Ok(Vec::new());
    }
    crate::output::atomic::create_subdir(dir)?;
    let folder = dir
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut out = Vec::new();
    for p in params {
        let stem = format!("vs_{}", slug(&p));
        super::write(&figure(scenario, runs, table, &p), dir, &stem)?;
        out.push(crate::output::summary::Figure {
            title: format!("Settle time and residual vibration against {p}"),
            svg: format!("{folder}/{stem}.svg"),
            png: format!("{folder}/{stem}.png"),
        });
    }
    Ok(out)
}
