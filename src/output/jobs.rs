//! G-code jobs in a sweep (the `[gcode]` study): what each candidate (a combination of
//! the swept firmware, shaper and limits) costs in print time and gives in contour error,
//! for summary.md, report.html and the figure `plots/gcode_jobs.svg/png`.
//!
//! Candidates are ranked by their worst contour error while printing (ties: the shorter
//! print time, then the lower run number); a run that failed comes last. A candidate is on
//! the *Pareto front* when no other one is both at least as fast and at most as
//! wrong (worst contour error) and better in one of them. Where the scenario names a
//! `[current]` candidate, each one's print time and worst error are given against it:
//! `+4.9 %` time = 4.9 % longer than current, `-76 %` worst = 76 % less error.
//!
//! Everything is read from the runs table, like the rest of the summary.

use std::fmt::Write as _;
use std::path::Path;

use crate::input::runs_columns::RunsColumns;
use crate::input::scenario::Scenario;
use crate::output::ranking::{is_current, is_setting, label_part, run_command};
use crate::spec::runs::RunList;

/// One candidate (run) of a G-code sweep.
#[derive(Debug, Clone, PartialEq)]
pub struct JobRow {
    /// Row in the runs table (= index into the runs).
    pub row: usize,
    /// The run's id (`--case`).
    pub id: usize,
    /// Rank (1 = least worst error); `None` for a failed run.
    pub rank: Option<usize>,
    /// The swept values, as shown (one per swept key).
    pub values: Vec<String>,
    /// The candidate's label (settings joined by `, `).
    pub label: String,
    /// The print time of the whole file (s).
    pub print_time_s: Option<f64>,
    /// Worst contour error while printing (um).
    pub worst_um: Option<f64>,
    /// 95th percentile of the contour error while printing (um).
    pub p95_um: Option<f64>,
    /// The G-code line of the worst error.
    pub worst_line: Option<u64>,
    /// Whether this is the `[current]` candidate.
    pub current: bool,
    /// Whether it is on the Pareto front of (print time, worst error).
    pub pareto: bool,
    /// Why the run failed.
    pub failure: Option<String>,
    /// `print time / current's - 1`, when a current is given.
    pub time_vs_current: Option<f64>,
    /// `worst error / current's - 1`, when a current is given.
    pub worst_vs_current: Option<f64>,
}

/// The G-code candidates of a sweep, ranked.
#[derive(Debug, Clone, PartialEq)]
pub struct Jobs {
    /// The G-code file (its name).
    pub file: String,
    /// The swept keys (sweep order).
    pub keys: Vec<String>,
    /// Ranked: least worst error first, failed runs last.
    pub rows: Vec<JobRow>,
    /// Whether the scenario names a `[current]` candidate.
    pub has_current: bool,
}

impl Jobs {
    /// The current candidate's row.
    pub fn current(&self) -> Option<&JobRow> {
        self.rows.iter().find(|r| r.current && r.failure.is_none())
    }

    /// The fastest candidate (ties: the lower worst error, then run number).
    pub fn fastest(&self) -> Option<&JobRow> {
        self.rows
            .iter()
            .filter(|r| r.failure.is_none())
            .min_by(|a, b| {
                let t = |r: &JobRow| r.print_time_s.unwrap_or(f64::INFINITY);
                let e = |r: &JobRow| r.worst_um.unwrap_or(f64::INFINITY);
                t(a).total_cmp(&t(b))
                    .then(e(a).total_cmp(&e(b)))
                    .then(a.id.cmp(&b.id))
            })
    }

    /// The candidate with the least worst error.
    pub fn least_error(&self) -> Option<&JobRow> {
        self.rows.first().filter(|r| r.failure.is_none())
    }
}

/// A duration as a reader takes it in: seconds below two minutes (`14.78 s`), else minutes
/// (`41.2 min`).
pub fn duration(s: f64) -> String {
    if s < 120.0 {
        format!("{s:.2} s")
    } else {
        format!("{:.1} min", s / 60.0)
    }
}

/// A relative change as shown: `+4.9 %`, `-76 %`, `-`.
pub fn change(x: Option<f64>) -> String {
    match x {
        Some(x) if x.is_finite() && (x * 100.0).abs() < 10.0 => format!("{:+.1} %", x * 100.0),
        Some(x) if x.is_finite() => format!("{:+.0} %", x * 100.0),
        _ => "-".into(),
    }
}

/// Indices (into `pts`) of the Pareto front of `(time, error)` pairs: no other point is
/// at most as large in both and smaller in one. Non-finite points are never on it.
pub fn pareto(pts: &[(f64, f64)]) -> Vec<usize> {
    let ok = |p: &(f64, f64)| p.0.is_finite() && p.1.is_finite();
    (0..pts.len())
        .filter(|&i| {
            ok(&pts[i])
                && !pts.iter().any(|q| {
                    ok(q)
                        && q.0 <= pts[i].0
                        && q.1 <= pts[i].1
                        && (q.0 < pts[i].0 || q.1 < pts[i].1)
                })
        })
        .collect()
}

/// The G-code candidates of `runs` (row `i` of `table` is `runs.at(i)`); `None` when the
/// table has no G-code columns.
pub fn jobs(sc: &Scenario, runs: &dyn RunList, table: &RunsColumns) -> Option<Jobs> {
    table.column("contour_worst_um")?;
    table.column("print_time_s")?;
    let keys: Vec<String> = runs
        .first()
        .map(|r| r.swept.iter().map(|(p, _)| p.clone()).collect())
        .unwrap_or_default();
    let file = (0..runs.len())
        .find_map(|i| table.cell(i, "gcode_file").filter(|f| !f.is_empty()))
        .map(|f| {
            Path::new(&*f)
                .file_name()
                .map_or(f.to_string(), |n| n.to_string_lossy().into_owned())
        })
        .unwrap_or_default();
    let mut rows: Vec<JobRow> = runs
        .iter()
        .enumerate()
        .map(|(i, r)| {
            let ok = table.cell(i, "status").is_none_or(|s| s == "ok");
            let num = |c: &str| table.num(i, c).filter(|x| x.is_finite() && ok);
            let settings: Vec<String> = r
                .swept
                .iter()
                .filter(|(p, _)| is_setting(p))
                .map(|(p, v)| label_part(p, v))
                .collect();
            JobRow {
                row: i,
                id: r.id,
                rank: None,
                values: r.swept.iter().map(|(_, v)| v.to_string()).collect(),
                label: if settings.is_empty() {
                    table.cell(i, "firmware").unwrap_or_default().to_string()
                } else {
                    settings.join(", ")
                },
                print_time_s: num("print_time_s"),
                worst_um: num("contour_worst_um"),
                p95_um: num("contour_p95_um"),
                worst_line: num("contour_worst_line").map(|l| l as u64),
                current: is_current(sc, &r),
                pareto: false,
                failure: (!ok).then(|| {
                    let status = table.cell(i, "status").unwrap_or_default();
                    match table.cell(i, "reason").filter(|s| !s.is_empty()) {
                        Some(reason) => format!("{status}: {reason}"),
                        None => status.to_string(),
                    }
                }),
                time_vs_current: None,
                worst_vs_current: None,
            }
        })
        .collect();
    let pts: Vec<(f64, f64)> = rows
        .iter()
        .map(|r| {
            (
                r.print_time_s.unwrap_or(f64::INFINITY),
                r.worst_um.unwrap_or(f64::INFINITY),
            )
        })
        .collect();
    for i in pareto(&pts) {
        rows[i].pareto = true;
    }
    rows.sort_by(|a, b| {
        let key = |r: &JobRow| {
            (
                r.failure.is_some(),
                r.worst_um.unwrap_or(f64::INFINITY),
                r.print_time_s.unwrap_or(f64::INFINITY),
            )
        };
        let (fa, ea, ta) = key(a);
        let (fb, eb, tb) = key(b);
        fa.cmp(&fb)
            .then(ea.total_cmp(&eb))
            .then(ta.total_cmp(&tb))
            .then(a.id.cmp(&b.id))
    });
    for (n, r) in rows.iter_mut().enumerate() {
        r.rank = r.failure.is_none().then_some(n + 1);
    }
    let current = rows
        .iter()
        .find(|r| r.current && r.failure.is_none())
        .map(|c| (c.print_time_s, c.worst_um));
    if let Some((ct, cw)) = current {
        let rel = |x: Option<f64>, c: Option<f64>| match (x, c) {
            (Some(x), Some(c)) if c > 0.0 => Some(x / c - 1.0),
            _ => None,
        };
        for r in &mut rows {
            r.time_vs_current = rel(r.print_time_s, ct);
            r.worst_vs_current = rel(r.worst_um, cw);
        }
    }
    Some(Jobs {
        file,
        keys,
        rows,
        has_current: !sc.current.is_empty(),
    })
}

/// A candidate in words: `klipper, mzv: 14.78 s, 38.1 um worst (p95 25.9 um)`.
pub fn in_words(r: &JobRow) -> String {
    let um = |x: Option<f64>| x.map_or("-".into(), |x| format!("{x:.1} um"));
    format!(
        "{}: {}, {} worst (p95 {})",
        r.label,
        r.print_time_s.map_or("-".into(), duration),
        um(r.worst_um),
        um(r.p95_um)
    )
}

/// The lines that say what the table means: the least error, the fastest and the current
/// candidate, with the cost and gain against current.
pub fn headline(j: &Jobs) -> Vec<String> {
    let vs = |r: &JobRow| {
        if j.current().is_some() && !r.current {
            format!(
                "; print time {}, worst error {} vs current",
                change(r.time_vs_current),
                change(r.worst_vs_current)
            )
        } else {
            String::new()
        }
    };
    let mut out = Vec::new();
    if let Some(r) = j.least_error() {
        out.push(format!("least contour error: **{}**{}", in_words(r), vs(r)));
    }
    if let Some(r) = j.fastest() {
        out.push(format!("fastest: **{}**{}", in_words(r), vs(r)));
    }
    if let Some(r) = j.current() {
        out.push(format!("current: {}", in_words(r)));
    }
    out
}

/// The column headers of the table (summary.md and report.html).
pub fn header(j: &Jobs) -> Vec<String> {
    let mut h = vec!["rank".to_string()];
    h.extend(j.keys.iter().cloned());
    for c in ["print time (s)", "worst (um)", "p95 (um)", "worst line"] {
        h.push(c.into());
    }
    if j.current().is_some() {
        h.push("time vs current".into());
        h.push("worst vs current".into());
    }
    for c in ["Pareto", "run", "command"] {
        h.push(c.into());
    }
    h
}

/// What the table's columns mean.
pub const NOTE: &str = "Print time: the firmware planner's clock for the whole file. Contour error: distance in XY from the simulated toolhead to the commanded path, over working moves; worst line: the G-code line where the worst error happens. Ranked by worst error (ties: print time). Pareto: no other candidate is both faster and less wrong. Vs current: +5 % = 5 % longer or more error than current, -76 % = 76 % less.";

/// The summary.md section.
pub fn section(j: &Jobs, scenario: &Path, runs: &dyn RunList) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "## G-code jobs: print time and contour error ({})\n",
        j.file
    );
    let _ = writeln!(out, "{NOTE}\n");
    for l in headline(j) {
        let _ = writeln!(out, "- {l}");
    }
    out.push('\n');
    let h = header(j);
    let _ = writeln!(out, "| {} |", h.join(" | "));
    let _ = writeln!(out, "|{}", "---:|".repeat(h.len()));
    let best = j.least_error().map(|r| r.id);
    for r in &j.rows {
        let mut row = vec![match r.rank {
            Some(n) if r.current => format!("{n} (current)"),
            Some(n) => n.to_string(),
            None => "-".into(),
        }];
        row.extend(r.values.iter().cloned());
        match &r.failure {
            Some(f) => {
                row.push(f.clone());
                row.extend(["-".to_string(), "-".to_string(), "-".to_string()]);
            }
            None => {
                let f = |x: Option<f64>| x.map_or("-".into(), |x| format!("{x:.2}"));
                row.push(f(r.print_time_s));
                let worst = f(r.worst_um);
                row.push(if best == Some(r.id) {
                    format!("**{worst}**")
                } else {
                    worst
                });
                row.push(f(r.p95_um));
                row.push(r.worst_line.map_or("-".into(), |l| l.to_string()));
            }
        }
        if j.current().is_some() {
            row.push(change(r.time_vs_current));
            row.push(change(r.worst_vs_current));
        }
        row.push(if r.pareto { "yes" } else { "" }.into());
        row.push(r.id.to_string());
        row.push(format!("`{}`", run_command(scenario, &runs.at(r.row))));
        let _ = writeln!(out, "| {} |", row.join(" | "));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_pareto_front_keeps_the_points_nothing_beats_in_both() {
        let pts = [
            (10.0, 5.0),
            (12.0, 3.0),
            (11.0, 6.0),
            (12.0, 3.0),
            (9.0, f64::INFINITY),
            (13.0, 3.0),
        ];
        // (11, 6) is beaten by (10, 5); (13, 3) by (12, 3); equal points are both on it.
        assert_eq!(pareto(&pts), [0, 1, 3]);
    }

    #[test]
    fn durations_and_changes_read_as_written() {
        assert_eq!(duration(14.781), "14.78 s");
        assert_eq!(duration(2460.0), "41.0 min");
        assert_eq!(change(Some(0.049)), "+4.9 %");
        assert_eq!(change(Some(-0.761)), "-76 %");
        assert_eq!(change(None), "-");
    }
}
