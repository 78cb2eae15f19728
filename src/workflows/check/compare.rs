//! The regression gate: compare a fresh runs table with a committed baseline.
//!
//! A baseline is a `runs.csv` (`results/baselines/<scenario>.csv`). Every cell of every run
//! is compared, parameters and metrics alike, matched by the `run` column:
//!
//! - numbers differ when `|now - baseline| > max(tolerance * |baseline|, floor)`: a
//!   relative tolerance, and an absolute floor under which no change means anything. For
//!   lengths the floor is [`DEFAULT_FLOOR_UM`] (1 nm; `_um` columns, and `_mm` ones in
//!   their unit), so that a residual of 7e-6 um becoming 4.8e-6 um (a shaper cancelling a
//!   mode down to float round-off, a "-31 %" change) is not a regression; for other
//!   columns it is float noise in their unit (`_s`: 1e-9 s, else 1e-12);
//! - `inf` (not settled) equals only `inf`; finite -> `inf` and back are changes with an
//!   infinite delta;
//! - text cells (profile kind, a run status) differ when the text differs.
//!
//! Each change is labelled by what it means for the column: for settling metrics, smaller
//! is better (move, settle and move-and-settle times, residual, overshoot, following and
//! contour error, lost steps), so a larger value or `inf` is `worse`; other columns are
//! just `changed`.
//!
//! What fails the gate: by default **any** change beyond the tolerance, worse or better.
//! settle is deterministic, so a change in either direction means the model, the planner or
//! the metrics changed behaviour; the gate's job is to make that a reviewed decision (rerun
//! with `--update` and commit the baseline, whose diff shows every number that moved). An
//! "improvement" is as often a bug (lost damping, a wrong unit) as a real gain. A caller that
//! wants improvements to pass sets `allow_improvements`.

use std::collections::HashMap;
use std::fmt::Write as _;

use crate::input::runs_table::{RunsTable, number};

/// Default relative tolerance (percent): far above float noise between machines (1e-12),
/// far below any change a user would notice (the profile kinds differ by 10-300%).
pub const DEFAULT_TOLERANCE_PCT: f64 = 0.1;

/// Default absolute floor of length columns (um): 1 nm, a thousandth of the smallest
/// settling band the checked-in scenarios use (1 um), far above float round-off of a
/// residual (a cancelled mode leaves about 1e-6 um), far below anything that moves a
/// settling time.
pub const DEFAULT_FLOOR_UM: f64 = 1e-3;

/// Which direction is an improvement for a column.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// Smaller is better.
    LowerIsBetter,
    /// Neither direction is better (parameters, unknown columns).
    Neutral,
}

/// The direction of a column, from its name.
pub fn direction(column: &str) -> Direction {
    const LOWER: [&str; 9] = [
        "move_time",
        "settle_time",
        "move_and_settle",
        "residual",
        "overshoot",
        "following_error",
        "contour_error",
        "lost_steps",
        "error_um",
    ];
    if LOWER.iter().any(|p| column.contains(p)) {
        Direction::LowerIsBetter
    } else {
        Direction::Neutral
    }
}

/// The absolute floor for a column, in its unit: `floor_um` for lengths (`_um`, `_mm`),
/// float noise for the others.
fn floor(column: &str, floor_um: f64) -> f64 {
    let unit = |u: &str| column.ends_with(u) || column.contains(&format!("{u}_"));
    if unit("_um") {
        floor_um
    } else if unit("_mm") {
        floor_um * 1e-3
    } else if unit("_s") {
        1e-9
    } else {
        1e-12
    }
}

/// What a change means.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// Worse for a settling metric.
    Worse,
    /// Better for a settling metric.
    Better,
    /// Changed where no direction is better.
    Changed,
}

impl std::fmt::Display for Verdict {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Verdict::Worse => "worse",
            Verdict::Better => "better",
            Verdict::Changed => "changed",
        })
    }
}

/// One cell that changed beyond the tolerance.
#[derive(Debug, Clone, PartialEq)]
pub struct Change {
    /// The run (its `run` cell).
    pub run: String,
    /// The column.
    pub column: String,
    /// Baseline cell.
    pub baseline: String,
    /// New cell.
    pub now: String,
    /// Relative change in percent (infinite for finite <-> inf or from zero; `None` for text).
    pub delta_pct: Option<f64>,
    /// What it means.
    pub verdict: Verdict,
}

/// The outcome of a comparison.
#[derive(Debug, Clone, PartialEq)]
pub struct Comparison {
    /// Runs compared.
    pub runs: usize,
    /// Cells compared (runs x columns other than `run`).
    pub cells: usize,
    /// Changes beyond the tolerance, in run then column order.
    pub changes: Vec<Change>,
}

impl Comparison {
    /// Changes that fail the gate.
    pub fn failures(&self, allow_improvements: bool) -> usize {
        self.changes
            .iter()
            .filter(|c| !(allow_improvements && c.verdict == Verdict::Better))
            .count()
    }

    /// Count of changes with `v`.
    pub fn count(&self, v: Verdict) -> usize {
        self.changes.iter().filter(|c| c.verdict == v).count()
    }
}

fn verdict(column: &str, increased: bool) -> Verdict {
    match (direction(column), increased) {
        (Direction::LowerIsBetter, true) => Verdict::Worse,
        (Direction::LowerIsBetter, false) => Verdict::Better,
        (Direction::Neutral, _) => Verdict::Changed,
    }
}

/// Compare one cell; `None` when equal within the relative tolerance `tol` or the
/// column's absolute floor.
fn compare_cell(
    column: &str,
    base: &str,
    now: &str,
    tol: f64,
    floor_um: f64,
) -> Option<(Option<f64>, Verdict)> {
    if base == now {
        return None;
    }
    match (number(base), number(now)) {
        (Some(b), Some(n)) => {
            if b == n || (b.is_nan() && n.is_nan()) {
                return None;
            }
            if b.is_finite() && n.is_finite() {
                if (n - b).abs() <= (tol * b.abs()).max(floor(column, floor_um)) {
                    return None;
                }
                let pct = if b == 0.0 {
                    f64::INFINITY.copysign(n)
                } else {
                    (n - b) / b.abs() * 100.0
                };
                return Some((Some(pct), verdict(column, n > b)));
            }
            // inf involved (not settled), or NaN.
            if b.is_nan() || n.is_nan() {
                return Some((None, Verdict::Changed));
            }
            let increased = n > b;
            let pct = if increased {
                f64::INFINITY
            } else {
                f64::NEG_INFINITY
            };
            Some((Some(pct), verdict(column, increased)))
        }
        _ => Some((None, Verdict::Changed)),
    }
}

/// The rows of `t` by their run (column `run_col`): an error if a run is listed twice.
fn by_run(t: &RunsTable, run_col: usize) -> Result<HashMap<&str, &Vec<String>>, String> {
    let mut by_run = HashMap::with_capacity(t.rows.len());
    for r in &t.rows {
        if by_run.insert(r[run_col].as_str(), r).is_some() {
            return Err(format!(
                "the baseline has run {} twice: a baseline is a runs.csv written by settle",
                crate::error::echo(&r[run_col])
            ));
        }
    }
    Ok(by_run)
}

/// A baseline settle could have written, as far as can be told before the scenario runs:
/// no run listed twice (one without a `run` column differs from every run's columns,
/// which [`compare`] reports).
pub fn check_baseline(t: &RunsTable) -> Result<(), String> {
    t.column("run").map_or(Ok(()), |c| by_run(t, c).map(|_| ()))
}

/// Compare `now` with `baseline` at relative tolerance `tolerance_pct` (percent) and the
/// absolute floor `floor_um` of length columns (um).
///
/// Errors (not regressions, but a baseline that does not describe this scenario): columns
/// added or missing, runs added or missing, no `run` column.
pub fn compare(
    baseline: &RunsTable,
    now: &RunsTable,
    tolerance_pct: f64,
    floor_um: f64,
) -> Result<Comparison, String> {
    if baseline.header != now.header {
        let missing: Vec<&str> = baseline
            .header
            .iter()
            .filter(|h| !now.header.contains(h))
            .map(String::as_str)
            .collect();
        let added: Vec<&str> = now
            .header
            .iter()
            .filter(|h| !baseline.header.contains(h))
            .map(String::as_str)
            .collect();
        return Err(format!(
            "the baseline's columns differ from this run's (missing now: [{}]; new: [{}]{}): \
the outputs changed shape; if intended, rewrite the baseline with --update",
            missing.join(", "),
            added.join(", "),
            if missing.is_empty() && added.is_empty() {
                "; same columns in another order"
            } else {
                ""
            }
        ));
    }
    let run_col = now
        .column("run")
        .ok_or("no `run` column: a baseline is a runs.csv written by settle")?;
    // Rows are matched by run, whatever their order in the file.
    let by_run = by_run(baseline, run_col)?;
    let sorted_ids = |t: &RunsTable| -> Vec<String> {
        let mut ids: Vec<String> = t.rows.iter().map(|r| r[run_col].clone()).collect();
        ids.sort_by_cached_key(|id| (id.parse::<u64>().ok(), id.clone()));
        ids
    };
    let (b_ids, n_ids) = (sorted_ids(baseline), sorted_ids(now));
    if b_ids != n_ids {
        return Err(format!(
            "the baseline has {} runs ({}), this scenario has {} ({}): the sweep changed; \
if intended, rewrite the baseline with --update",
            b_ids.len(),
            span(&b_ids),
            n_ids.len(),
            span(&n_ids)
        ));
    }
    let tol = tolerance_pct / 100.0;
    let mut changes = Vec::new();
    for n_row in &now.rows {
        let b_row = by_run[n_row[run_col].as_str()];
        for (c, column) in now.header.iter().enumerate() {
            if c == run_col {
                continue;
            }
            if let Some((delta_pct, verdict)) =
                compare_cell(column, &b_row[c], &n_row[c], tol, floor_um)
            {
                changes.push(Change {
                    run: n_row[run_col].clone(),
                    column: column.clone(),
                    baseline: b_row[c].clone(),
                    now: n_row[c].clone(),
                    delta_pct,
                    verdict,
                });
            }
        }
    }
    Ok(Comparison {
        runs: now.rows.len(),
        cells: now.rows.len() * (now.header.len() - 1),
        changes,
    })
}

/// The backend a baseline was made on: the single value of its `backend` column (`None`
/// when it has no such column). Several backends in one baseline are an error.
pub fn baseline_backend(t: &RunsTable) -> Result<Option<String>, String> {
    let Some(c) = t.column("backend") else {
        return Ok(None);
    };
    let mut names: Vec<&str> = t.rows.iter().map(|r| r[c].as_str()).collect();
    names.sort_unstable();
    names.dedup();
    match names.as_slice() {
        [] => Ok(None),
        [one] => Ok(Some(one.to_string())),
        many => Err(format!(
            "the baseline mixes backends ({}): keep one baseline per backend",
            many.join(", ")
        )),
    }
}

fn span(ids: &[String]) -> String {
    match (ids.first(), ids.last()) {
        (Some(a), Some(b)) => format!("run {a} to {b}"),
        _ => "none".into(),
    }
}

/// Format a delta for the table.
fn delta(d: Option<f64>) -> String {
    match d {
        None => "-".into(),
        Some(x) if x == f64::INFINITY => "+inf".into(),
        Some(x) if x == f64::NEG_INFINITY => "-inf".into(),
        Some(x) => format!("{x:+.3}%"),
    }
}

/// The changes as an aligned text table (run, metric, baseline, now, delta%, verdict), at
/// most `max_rows` rows (then a line saying how many more).
pub fn table(changes: &[Change], max_rows: usize) -> String {
    let mut rows: Vec<[String; 6]> = vec![[
        "run".into(),
        "metric".into(),
        "baseline".into(),
        "now".into(),
        "delta%".into(),
        "".into(),
    ]];
    for c in changes.iter().take(max_rows) {
        rows.push([
            c.run.clone(),
            c.column.clone(),
            c.baseline.clone(),
            c.now.clone(),
            delta(c.delta_pct),
            c.verdict.to_string(),
        ]);
    }
    let mut w = [0usize; 6];
    for r in &rows {
        for (i, cell) in r.iter().enumerate() {
            w[i] = w[i].max(cell.chars().count());
        }
    }
    let mut out = String::new();
    for (k, r) in rows.iter().enumerate() {
        let line: Vec<String> = r
            .iter()
            .enumerate()
            .map(|(i, cell)| {
                if i == 1 || i == 5 {
                    format!("{cell:<width$}", width = w[i])
                } else {
                    format!("{cell:>width$}", width = w[i])
                }
            })
            .collect();
        let _ = writeln!(out, "{}", line.join("  ").trim_end());
        if k == 0 {
            let total = w.iter().sum::<usize>() + 2 * 5;
            let _ = writeln!(out, "{}", "-".repeat(total));
        }
    }
    if changes.len() > max_rows {
        let _ = writeln!(out, "... and {} more", changes.len() - max_rows);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const BASE: &str = "run,profile,distance_mm,move_time_s,residual_peak_um,settle_time_s_10um\n\
0,trapezoid,1,0.05,80,0.2\n1,scurve,1,0.07,20,inf\n";

    fn cmp(now: &str, tol: f64) -> Result<Comparison, String> {
        compare(
            &RunsTable::parse(BASE).expect("base"),
            &RunsTable::parse(now).expect("now"),
            tol,
            DEFAULT_FLOOR_UM,
        )
    }

    #[test]
    fn unchanged_passes_and_small_changes_are_within_tolerance() {
        let c = cmp(BASE, 0.1).expect("same shape");
        assert_eq!(c.changes, vec![]);
        assert_eq!((c.runs, c.cells), (2, 10));
        let c = cmp(&BASE.replace(",80,", ",80.05,"), 0.1).expect("same shape");
        assert_eq!(c.changes, vec![], "0.0625% < 0.1%");
    }

    #[test]
    fn worse_better_and_not_settled() {
        let now = "run,profile,distance_mm,move_time_s,residual_peak_um,settle_time_s_10um\n\
0,trapezoid,1,0.05,88,inf\n1,scurve,1,0.07,18,0.3\n";
        let c = cmp(now, 0.1).expect("same shape");
        let got: Vec<(&str, &str, Option<f64>, Verdict)> = c
            .changes
            .iter()
            .map(|x| (x.run.as_str(), x.column.as_str(), x.delta_pct, x.verdict))
            .collect();
        assert_eq!(
            got,
            vec![
                ("0", "residual_peak_um", Some(10.0), Verdict::Worse),
                (
                    "0",
                    "settle_time_s_10um",
                    Some(f64::INFINITY),
                    Verdict::Worse
                ),
                ("1", "residual_peak_um", Some(-10.0), Verdict::Better),
                (
                    "1",
                    "settle_time_s_10um",
                    Some(f64::NEG_INFINITY),
                    Verdict::Better
                ),
            ]
        );
        assert_eq!(c.failures(false), 4);
        assert_eq!(c.failures(true), 2);
        let t = table(&c.changes, 100);
        assert!(
            t.contains("+10.000%") && t.contains("+inf") && t.contains("worse"),
            "{t}"
        );
    }

    #[test]
    fn parameters_and_text_are_changes_and_shape_changes_are_errors() {
        let c = cmp(&BASE.replace("0,trapezoid,1,", "0,scurve,2,"), 0.1).expect("shape");
        assert_eq!(c.count(Verdict::Changed), 2);
        let e = cmp(
            &BASE.replace(",settle_time_s_10um", ",settle_time_s_20um"),
            0.1,
        )
        .expect_err("columns differ");
        assert!(
            e.contains("settle_time_s_10um") && e.contains("--update"),
            "{e}"
        );
        let e = cmp(
            "run,profile,distance_mm,move_time_s,residual_peak_um,settle_time_s_10um\n0,trapezoid,1,0.05,80,0.2\n",
            0.1,
        )
        .expect_err("runs differ");
        assert!(e.contains("2 runs") && e.contains("has 1"), "{e}");
    }

    /// The baseline's rows in another order are the same runs: matched by `run`, a change
    /// is reported on its own run, and a run listed twice is an error.
    #[test]
    fn rows_are_matched_by_run_in_any_order() {
        let reordered = "run,profile,distance_mm,move_time_s,residual_peak_um,settle_time_s_10um\n\
1,scurve,1,0.07,20,inf\n0,trapezoid,1,0.05,80,0.2\n";
        let c = cmp(reordered, 0.1).expect("the same runs");
        assert_eq!(c.changes, vec![]);
        assert_eq!((c.runs, c.cells), (2, 10));
        let c = cmp(&reordered.replace(",20,inf", ",22,inf"), 0.1).expect("the same runs");
        let got: Vec<(&str, &str, &str, &str)> = c
            .changes
            .iter()
            .map(|x| {
                (
                    x.run.as_str(),
                    x.column.as_str(),
                    x.baseline.as_str(),
                    x.now.as_str(),
                )
            })
            .collect();
        assert_eq!(got, vec![("1", "residual_peak_um", "20", "22")]);
        let twice = "run,profile,distance_mm,move_time_s,residual_peak_um,settle_time_s_10um\n\
0,trapezoid,1,0.05,80,0.2\n0,trapezoid,1,0.05,80,0.2\n";
        let e = compare(
            &RunsTable::parse(twice).expect("table"),
            &RunsTable::parse(BASE).expect("table"),
            0.1,
            DEFAULT_FLOOR_UM,
        )
        .expect_err("run 0 twice");
        assert!(e.contains("run 0 twice"), "{e}");
        // Another run set is still the sweep changing.
        let e = cmp(&BASE.replace("\n1,scurve", "\n2,scurve"), 0.1).expect_err("runs differ");
        assert!(e.contains("the sweep changed"), "{e}");
    }

    #[test]
    fn zero_baseline_uses_the_noise_floor() {
        // A settle time of exactly 0 s that becomes 1e-12 s is float noise, 1e-6 s is not.
        let cell = |c, b, n| compare_cell(c, b, n, 1e-3, DEFAULT_FLOOR_UM);
        assert_eq!(cell("settle_time_s_10um", "0", "1e-12"), None);
        assert_eq!(
            cell("settle_time_s_10um", "0", "0.000001"),
            Some((Some(f64::INFINITY), Verdict::Worse))
        );
    }

    /// A residual at float round-off that moves by a third is no change (it is far under
    /// the 1 nm floor); a change of a nanometre and more is, and so is a relative change
    /// beyond the tolerance above the floor. Millimetre columns take the same floor in
    /// their unit.
    #[test]
    fn lengths_under_the_absolute_floor_are_no_change() {
        let cell = |c, b, n, floor| compare_cell(c, b, n, 1e-3, floor);
        assert_eq!(cell("residual_peak_um", "7e-6", "4.8e-6", 1e-3), None);
        assert_eq!(cell("y_residual_rms_um", "0", "0.0009", 1e-3), None);
        assert_eq!(
            cell("residual_peak_um", "0.0001", "0.0021", 1e-3),
            Some((Some(2000.0), Verdict::Worse))
        );
        assert_eq!(
            cell("residual_peak_um", "10", "10.5", 1e-3),
            Some((Some(5.0), Verdict::Worse))
        );
        assert_eq!(cell("smoothing_mm", "0.1", "0.1000009", 1e-3), None);
        assert!(cell("smoothing_mm", "0.1", "0.1002", 1e-3).is_some());
        // The floor is the caller's: at 1e-7 um the round-off change shows.
        assert!(cell("residual_peak_um", "7e-6", "4.8e-6", 1e-7).is_some());
    }
}
