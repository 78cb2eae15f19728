//! The summary's scan section: the step axis's error at re-entry, per swept point and kind.

use std::fmt::Write as _;

use crate::input::runs_columns::RunsColumns;
use crate::spec::groups::{SweptGroups, is_setting};
use crate::spec::run_spec::RunSpec;
use crate::spec::runs::RunList;

/// The summary's scan section (for a table with the scan columns): per band, the
/// step-axis error at re-entry for every kind side by side, settled or not, with the
/// window and the step's settle time; the `current` runs marked, and compared with the
/// best of their workload point ([`against_current`]). Read from the runs table, like the
/// rest of the summary, so a merged sweep's summary is the same.
pub fn section(
    runs: &dyn RunList,
    table: &RunsColumns,
    current: &dyn Fn(&RunSpec) -> bool,
) -> String {
    let mut out = String::new();
    let SweptGroups {
        kinds,
        groups,
        params,
    } = SweptGroups::of(runs);
    let bands = runs.first().map(|r| r.bands_um.clone()).unwrap_or_default();
    let _ = writeln!(
        out,
        "## Scan steps: step-axis error when the fly axis re-enters the region\n\n\
Each cell: |error| at re-entry (um), then per band whether the error stays inside the band \
for the whole next line (yes/no), then window = exit to re-entry (ms) and the step's own \
settle time to within {} um after its end (ms, `not settled` = still outside at the next \
exit). The move is the step-over (`move.distance_mm`).\n",
        bands.last().copied().unwrap_or_default()
    );
    let mut header: Vec<String> = params.iter().map(|p| p.to_string()).collect();
    header.extend(kinds.iter().map(|k| k.to_string()));
    let _ = writeln!(out, "| {} |", header.join(" | "));
    let _ = writeln!(out, "|{}", "---:|".repeat(header.len()));
    let last_band = bands.last().copied().unwrap_or_default();
    for (key, idx) in &groups {
        let mut row: Vec<String> = if params.is_empty() {
            Vec::new()
        } else {
            key.split(" | ").map(str::to_string).collect()
        };
        for k in &kinds {
            let cell =
                idx.iter()
                    .copied()
                    .find(|&i| runs.at(i).profile == *k)
                    .map_or("-".to_string(), |i| {
                        if table.cell(i, "status").is_some_and(|s| s != "ok") {
                            return "lost steps".to_string();
                        }
                        let e = table.num(i, "scan_reentry_error_um").unwrap_or(f64::NAN);
                        let settled: Vec<&str> = bands
                            .iter()
                            .map(|b| match table.num(i, &format!("scan_settled_{b}um")) {
                                Some(1.0) => "yes",
                                _ => "no",
                            })
                            .collect();
                        let w = table.num(i, "scan_window_s").unwrap_or(f64::NAN) * 1e3;
                        let s = table
                            .num(i, &format!("scan_step_settle_time_s_{last_band}um"))
                            .filter(|x| x.is_finite())
                            .map_or("not settled".to_string(), |x| format!("{:.1}", x * 1e3));
                        let mark = if current(&runs.at(i)) { " (current)" } else { "" };
                        format!("{e:.2} {} (w {w:.1}, s {s}){mark}", settled.join("/"))
                    });
            row.push(cell);
        }
        let _ = writeln!(out, "| {} |", row.join(" | "));
    }
    out.push('\n');
    out.push_str(&against_current(runs, table, current));
    out
}

/// A run's standing at re-entry: `(bands it does not stay in, |error| at re-entry um)`,
/// the lower the better; `None` for a failed run.
fn standing(table: &RunsColumns, i: usize, bands: &[f64]) -> Option<(usize, f64)> {
    if table.cell(i, "status").is_some_and(|s| s != "ok") {
        return None;
    }
    let missed = bands
        .iter()
        .filter(|b| table.num(i, &format!("scan_settled_{b}um")) != Some(1.0))
        .count();
    let e = table.num(i, "scan_reentry_error_um")?;
    e.is_finite().then_some((missed, e))
}

/// The name of run `i` in the comparison: its setting values, or its profile kind.
fn setting_label(r: &RunSpec) -> String {
    let s: Vec<String> = r
        .swept
        .iter()
        .filter(|(p, _)| is_setting(p))
        .map(|(p, v)| format!("{p} = {v}"))
        .collect();
    if s.is_empty() {
        r.profile.to_string()
    } else {
        s.join(", ")
    }
}

/// Per workload point (the swept values that are not settings: the step-over, the scan
/// speed...), the `current` run against the best run of the point: the one that stays in
/// the most bands over the next line, then the least error at re-entry. Empty without a
/// current run.
fn against_current(
    runs: &dyn RunList,
    table: &RunsColumns,
    current: &dyn Fn(&RunSpec) -> bool,
) -> String {
    let bands = runs.first().map(|r| r.bands_um.clone()).unwrap_or_default();
    // Per point: its workload values, its current run, its best run.
    let mut points: Vec<(String, Option<usize>, Option<usize>)> = Vec::new();
    for (i, r) in runs.iter().enumerate() {
        let w: Vec<String> = r
            .swept
            .iter()
            .filter(|(p, _)| !is_setting(p))
            .map(|(p, v)| format!("{p} = {v}"))
            .collect();
        let w = w.join(", ");
        let k = match points.iter().position(|p| p.0 == w) {
            Some(k) => k,
            None => {
                points.push((w, None, None));
                points.len() - 1
            }
        };
        if current(&r) {
            points[k].1 = Some(i);
        }
        if let Some(s) = standing(table, i, &bands) {
            let better = points[k].2.is_none_or(|b| {
                standing(table, b, &bands).is_none_or(|t| s.0 < t.0 || (s.0 == t.0 && s.1 < t.1))
            });
            if better {
                points[k].2 = Some(i);
            }
        }
    }
    if points.iter().all(|p| p.1.is_none()) {
        return String::new();
    }
    let mut out = format!(
        "### Against your current settings\n\nAt each point of the workload, your current settings (`[current]`, marked *(current)* above) against the best: the step that stays inside the most bands ({} um) over the next line, then the least error at re-entry.\n\n| point | current | error at re-entry (um) | best | error at re-entry (um) | stays inside (um) |\n|---|---|---:|---|---:|---|\n",
        bands
            .iter()
            .map(f64::to_string)
            .collect::<Vec<_>>()
            .join(", ")
    );
    let inside = |i: usize| {
        let b: Vec<String> = bands
            .iter()
            .filter(|b| table.num(i, &format!("scan_settled_{b}um")) == Some(1.0))
            .map(f64::to_string)
            .collect();
        if b.is_empty() {
            "none".to_string()
        } else {
            b.join(", ")
        }
    };
    for (w, cur, best) in &points {
        let Some(c) = *cur else { continue };
        let err = |i: usize| match standing(table, i, &bands) {
            Some((_, e)) => format!("{e:.2}"),
            None => format!("failed ({})", table.cell(i, "status").unwrap_or_default()),
        };
        let (best_label, best_err, best_inside) = match *best {
            Some(b) if b == c => ("your current settings".to_string(), err(b), inside(b)),
            Some(b) => (
                format!("{} (run {})", setting_label(&runs.at(b)), runs.at(b).id),
                err(b),
                inside(b),
            ),
            None => ("none ran".to_string(), "-".to_string(), "-".to_string()),
        };
        let _ = writeln!(
            out,
            "| {} | {} (run {}) | {} | {best_label} | {best_err} | current: {}; best: {best_inside} |",
            if w.is_empty() { "the scan" } else { w },
            setting_label(&runs.at(c)),
            runs.at(c).id,
            err(c),
            inside(c),
        );
    }
    out.push('\n');
    out
}
