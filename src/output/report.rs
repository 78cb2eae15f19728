//! Sinks for a sweep: `runs.csv` (one row per run) and `summary.md` (profile kinds side by
//! side). Files are written atomically: a temporary file in the same folder, then a rename.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use settle_planner::ProfileKind;

use crate::error::Error;
use crate::expand::RunSpec;
use crate::input::runs_table::RunsTable;
use crate::input::scenario::Scenario;
use crate::measure::metrics::Metrics;

/// Write `contents` to `path` atomically (temporary file + rename).
pub fn write_atomic(path: &Path, contents: &[u8]) -> Result<(), Error> {
    let err = |source| Error::Write {
        path: path.to_path_buf(),
        source,
    };
    let dir = path.parent().unwrap_or(Path::new("."));
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tmp: PathBuf = dir.join(format!(".{name}.tmp{}", std::process::id()));
    std::fs::write(&tmp, contents).map_err(err)?;
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        err(e)
    })
}

fn band_label(b: f64) -> String {
    format!("{b}um")
}

/// Format a time that may be "not settled" for the CSV: `inf` when not settled.
fn csv_time(t: Option<f64>) -> String {
    t.map_or_else(|| "inf".to_string(), |x| x.to_string())
}

/// Free text as one CSV cell without quoting: separators and line breaks become `;` and
/// spaces, quotes apostrophes.
fn csv_text(s: &str) -> String {
    s.replace(',', ";")
        .replace(['\n', '\r'], " ")
        .replace('"', "'")
}

/// The CSV: run parameters, then metrics. `settle_time_s_<band>` and
/// `move_and_settle_s_<band>` are `inf` when the run did not settle within the window.
pub fn runs_csv(runs: &[RunSpec], metrics: &[Metrics]) -> String {
    runs_csv_with(runs, runs.iter().zip(metrics))
}

/// The row of runs.csv (with its newline) of run `run` with metrics `m` in the sweep
/// `runs`: exactly the line [`runs_csv`] writes for it (the columns depend on the whole
/// sweep, e.g. the union of the axes of swept presets). The sweep journal stores these.
pub fn runs_csv_row(runs: &[RunSpec], run: &RunSpec, m: &Metrics) -> String {
    let text = runs_csv_with(runs, std::iter::once((run, m)));
    let header_end = text.find('\n').map_or(text.len(), |i| i + 1);
    text[header_end..].to_string()
}

/// The header from the sweep `runs`, then one row per `(run, metrics)` pair.
fn runs_csv_with<'a>(
    runs: &[RunSpec],
    rows: impl Iterator<Item = (&'a RunSpec, &'a Metrics)>,
) -> String {
    let mut out = String::new();
    let bands = runs.first().map(|r| r.bands_um.clone()).unwrap_or_default();
    let n_modes = runs.first().map_or(0, |r| r.modes.len());
    out.push_str("run,profile,start_mm,distance_mm,vmax_mm_s,amax_mm_s2,jmax_mm_s3");
    for i in 0..n_modes {
        let _ = write!(
            out,
            ",mode{i}_frequency_hz,mode{i}_damping_ratio,mode{i}_weight"
        );
    }
    out.push_str(",machine,axis,driver,backend,status,lost_steps,reason");
    out.push_str(",move_time_s,residual_peak_um,residual_rms_um");
    for b in &bands {
        let _ = write!(out, ",settle_time_s_{}", band_label(*b));
    }
    for b in &bands {
        let _ = write!(out, ",move_and_settle_s_{}", band_label(*b));
    }
    out.push_str(",overshoot_um,max_following_error_um");
    // Per-axis metrics for physical machines (the modes form has one axis: the above).
    // The columns come from the runs (their machines; a swept preset can change the axes:
    // the union, in first-seen order), so the header is the same whatever the runs'
    // results (the sweep journal relies on it: see `journal`).
    let mut axis_names: Vec<String> = Vec::new();
    if runs.first().is_some_and(|r| r.machine.is_some()) {
        for a in runs
            .iter()
            .filter_map(|r| r.machine.as_ref())
            .flat_map(|m| &m.axes)
        {
            if !axis_names.contains(&a.name) {
                axis_names.push(a.name.clone());
            }
        }
    }
    for a in &axis_names {
        let _ = write!(out, ",{a}_residual_peak_um,{a}_residual_rms_um");
        for b in &bands {
            let _ = write!(out, ",{a}_settle_time_s_{}", band_label(*b));
        }
        let _ = write!(out, ",{a}_max_following_error_um,{a}_max_load_angle_deg");
    }
    // Corner paths (issue 5): their parameters, then the path metrics.
    // From the runs, not their results, so the header is the same whatever the results
    // (the sweep journal relies on it).
    let any_path = runs.iter().any(|r| r.corner.is_some());
    out.push_str(&crate::kinds::corner::csv_param_header(runs));
    out.push_str(&crate::measure::path_metrics::csv_header(any_path));
    out.push_str(&crate::kinds::shaping::csv_header(runs));
    // Extra columns of a run kind (scan steps), named from the first run that has them.
    let extra: Vec<String> = runs
        .iter()
        .find_map(crate::kinds::scan::extra_columns)
        .unwrap_or_default();
    for e in &extra {
        let _ = write!(out, ",{e}");
    }
    out.push('\n');
    for (r, m) in rows {
        let _ = write!(
            out,
            "{},{},{},{},{},{},{}",
            r.id,
            r.profile,
            r.start_mm,
            r.distance_mm,
            r.vmax_mm_s,
            r.amax_mm_s2,
            r.jmax_mm_s3.map_or(String::new(), |j| j.to_string())
        );
        for md in &r.modes {
            let _ = write!(
                out,
                ",{},{},{}",
                md.frequency_hz, md.damping_ratio, md.weight
            );
        }
        let _ = write!(
            out,
            ",{},{},{},{},{},{},{}",
            r.machine_name,
            r.axis,
            r.driver,
            r.backend,
            m.status.name(),
            m.status.lost_steps(),
            csv_text(&m.status.reason())
        );
        if !m.is_ok() {
            // A run that lost steps has no settling result: its metric cells stay empty
            // so that nothing downstream averages them.
            let cells = 5 + 2 * m.settle_time_s.len() + axis_names.len() * (4 + bands.len());
            out.push_str(&",".repeat(cells));
            out.push_str(&crate::kinds::corner::csv_param_cells(runs, r));
            out.push_str(&crate::measure::path_metrics::csv_cells(any_path, None));
            out.push_str(&crate::kinds::shaping::csv_cells(runs, r));
            out.push_str(&",".repeat(extra.len()));
            out.push('\n');
            continue;
        }
        let _ = write!(
            out,
            ",{},{},{}",
            m.move_time_s, m.residual_peak_um, m.residual_rms_um
        );
        for t in &m.settle_time_s {
            let _ = write!(out, ",{}", csv_time(*t));
        }
        for i in 0..m.settle_time_s.len() {
            let _ = write!(out, ",{}", csv_time(m.move_and_settle_s(i)));
        }
        let _ = write!(out, ",{},{}", m.overshoot_um, m.max_following_error_um);
        for name in &axis_names {
            let Some(a) = m.axes.iter().find(|a| &a.name == name) else {
                // The run's machine has no such axis (swept presets).
                out.push_str(&",".repeat(4 + bands.len()));
                continue;
            };
            let _ = write!(out, ",{},{}", a.residual_peak_um, a.residual_rms_um);
            for t in &a.settle_time_s {
                let _ = write!(out, ",{}", csv_time(*t));
            }
            let _ = write!(
                out,
                ",{},{}",
                a.max_following_error_um,
                a.max_load_angle_deg
                    .map_or(String::new(), |d| d.to_string())
            );
        }
        out.push_str(&crate::kinds::corner::csv_param_cells(runs, r));
        out.push_str(&crate::measure::path_metrics::csv_cells(
            any_path,
            m.path.as_ref(),
        ));
        out.push_str(&crate::kinds::shaping::csv_cells(runs, r));
        for e in &extra {
            let v = m.extra.iter().find(|(n, _)| n == e);
            let _ = write!(out, ",{}", v.map_or(String::new(), |(_, x)| x.to_string()));
        }
        out.push('\n');
    }
    out
}

fn ms(t: Option<f64>) -> String {
    t.map_or_else(|| "not settled".to_string(), |x| format!("{:.1}", x * 1e3))
}

/// A figure linked from the summary.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// Caption.
    pub title: String,
    /// Path of the SVG, relative to the summary's folder.
    pub svg: String,
    /// Path of the PNG, relative to the summary's folder.
    pub png: String,
}

/// Runs grouped by their swept values other than `profile` (first-seen order): the rows of
/// the summary's side-by-side tables.
#[derive(Debug)]
pub struct SweptGroups<'a> {
    /// The profile kinds, in first-seen order (the tables' column groups).
    pub kinds: Vec<ProfileKind>,
    /// Per swept point: its values joined by ` | `, and the indices of its runs.
    pub groups: Vec<(String, Vec<usize>)>,
    /// The swept parameters other than `profile`, in sweep order.
    pub params: Vec<&'a str>,
}

impl<'a> SweptGroups<'a> {
    /// Group `runs`.
    pub fn of(runs: &'a [RunSpec]) -> Self {
        let mut kinds: Vec<ProfileKind> = Vec::new();
        let mut groups: Vec<(String, Vec<usize>)> = Vec::new();
        for (i, r) in runs.iter().enumerate() {
            if !kinds.contains(&r.profile) {
                kinds.push(r.profile);
            }
            let key: Vec<String> = r
                .swept
                .iter()
                .filter(|(p, _)| p != "profile")
                .map(|(_, v)| v.to_string())
                .collect();
            let key = key.join(" | ");
            match groups.iter_mut().find(|(k, _)| *k == key) {
                Some((_, v)) => v.push(i),
                None => groups.push((key, vec![i])),
            }
        }
        let params: Vec<&str> = runs
            .first()
            .map(|r| {
                r.swept
                    .iter()
                    .filter(|(p, _)| p != "profile")
                    .map(|(p, _)| p.as_str())
                    .collect()
            })
            .unwrap_or_default();
        Self {
            kinds,
            groups,
            params,
        }
    }
}

/// The metrics the summary shows, read from one row of the runs table.
struct RowView<'a> {
    table: &'a RunsTable,
    row: usize,
}

impl RowView<'_> {
    fn num(&self, col: &str) -> Option<f64> {
        self.table.num(self.row, col)
    }
    /// A time that is `inf` when not settled.
    fn time(&self, col: &str) -> Option<f64> {
        self.num(col).filter(|x| x.is_finite())
    }
    fn move_time_s(&self) -> f64 {
        self.num("move_time_s").unwrap_or(f64::NAN)
    }
    fn settle_time_s(&self, band: f64) -> Option<f64> {
        self.time(&format!("settle_time_s_{}", band_label(band)))
    }
    fn move_and_settle_s(&self, band: f64) -> Option<f64> {
        self.time(&format!("move_and_settle_s_{}", band_label(band)))
    }
    fn residual_peak_um(&self) -> f64 {
        self.num("residual_peak_um").unwrap_or(f64::NAN)
    }
    /// A run that lost steps is a failed run (status other than `ok`).
    fn is_ok(&self) -> bool {
        self.table
            .cell(self.row, "status")
            .is_none_or(|s| s == "ok")
    }
    /// What the summary shows instead of a failed run's numbers.
    fn failure(&self) -> String {
        match self.table.cell(self.row, "status") {
            Some("lost_steps") => {
                format!(
                    "lost {} steps",
                    self.num("lost_steps").map_or(0, |x| x as u64)
                )
            }
            Some(other) => other.to_string(),
            None => String::new(),
        }
    }
}

/// The summary: one table per band of move-and-settle times, profile kinds side by side
/// for each swept point (all swept parameters except `profile`), the best marked; then the
/// residual vibration; then the figures.
///
/// It reads the metrics from `table` (the runs table, row `i` = `runs[i]`) rather than from
/// [`Metrics`], so a summary rebuilt from a merged `runs.csv` is byte-identical to the one
/// the unsharded sweep wrote.
pub fn summary_md(
    sc: &Scenario,
    runs: &[RunSpec],
    table: &RunsTable,
    figures: &[Figure],
) -> String {
    let view = |i: usize| RowView { table, row: i };
    let mut out = String::new();
    let _ = writeln!(out, "# {}\n", sc.name);
    if !sc.description.is_empty() {
        let _ = writeln!(out, "{}\n", sc.description.trim());
    }
    let modes: Vec<String> = sc
        .machine
        .modes
        .iter()
        .map(|m| format!("{} Hz, zeta {}", m.frequency_hz, m.damping_ratio))
        .collect();
    let machine = match runs.first() {
        Some(r) if r.machine.is_some() => format!(
            "Machine: {} (axis {}, {} driver), backend {}",
            r.machine_name, r.axis, r.driver, r.backend
        ),
        Some(r) => format!("Machine modes: {}; backend {}", modes.join("; "), r.backend),
        None => format!("Machine modes: {}", modes.join("; ")),
    };
    let _ = writeln!(
        out,
        "{machine}. {} runs. Times in ms; **bold** = fastest move-and-settle at that point; \
gain = how much longer the slowest kind takes than the fastest.\n",
        runs.len()
    );
    let failed: Vec<usize> = (0..runs.len()).filter(|&i| !view(i).is_ok()).collect();
    if !failed.is_empty() {
        let _ = writeln!(
            out,
            "**{} run(s) failed**: shown as `lost N steps` (a stepper's load angle passed 90 electrical degrees) or `fault` (the simulation broke down), never compared or averaged. Why, per run:\n",
            failed.len()
        );
        for &i in &failed {
            let _ = writeln!(
                out,
                "- run {}: {}",
                runs[i].id,
                table
                    .cell(i, "reason")
                    .unwrap_or(view(i).failure().as_str())
            );
        }
        out.push('\n');
    }
    let SweptGroups {
        kinds,
        groups,
        params,
    } = SweptGroups::of(runs);
    // A scan sweep's own tables replace the move-and-settle ones (which would measure the
    // raster's run-out, not the step).
    let scan = crate::kinds::scan::summary_section(runs, table);
    out.push_str(&scan);
    let bands = if scan.is_empty() {
        runs.first().map(|r| r.bands_um.clone()).unwrap_or_default()
    } else {
        Vec::new()
    };
    for band in &bands {
        let band = *band;
        let _ = writeln!(out, "## Move and settle to within {band} um (ms)\n");
        let mut header: Vec<String> = params.iter().map(|p| p.to_string()).collect();
        for k in &kinds {
            header.push(format!("{k} move"));
            header.push(format!("{k} settle"));
            header.push(format!("{k} total"));
        }
        header.push("best".into());
        header.push("gain".into());
        let _ = writeln!(out, "| {} |", header.join(" | "));
        let _ = writeln!(out, "|{}", "---:|".repeat(header.len()));
        for (key, idx) in &groups {
            let mut row: Vec<String> = if params.is_empty() {
                Vec::new()
            } else {
                key.split(" | ").map(str::to_string).collect()
            };
            let of_kind = |k: ProfileKind| idx.iter().copied().find(|&i| runs[i].profile == k);
            let totals: Vec<(ProfileKind, Option<f64>)> = kinds
                .iter()
                .map(|k| {
                    (
                        *k,
                        of_kind(*k)
                            .filter(|&i| view(i).is_ok())
                            .and_then(|i| view(i).move_and_settle_s(band)),
                    )
                })
                .collect();
            let best = totals
                .iter()
                .filter_map(|(k, t)| t.map(|t| (*k, t)))
                .min_by(|a, b| a.1.total_cmp(&b.1));
            for k in &kinds {
                match of_kind(*k).map(view) {
                    Some(m) if !m.is_ok() => {
                        row.extend(["-".to_string(), m.failure(), "-".to_string()])
                    }
                    Some(m) => {
                        let total = ms(m.move_and_settle_s(band));
                        let is_best = best.is_some_and(|(bk, _)| bk == *k);
                        row.push(format!("{:.1}", m.move_time_s() * 1e3));
                        row.push(ms(m.settle_time_s(band)));
                        row.push(if is_best {
                            format!("**{total}**")
                        } else {
                            total
                        });
                    }
                    None => row.extend(["-".to_string(), "-".to_string(), "-".to_string()]),
                }
            }
            let worst = totals
                .iter()
                .map(|(_, t)| t.unwrap_or(f64::INFINITY))
                .fold(0.0, f64::max);
            match best {
                Some((k, t)) => {
                    row.push(k.to_string());
                    row.push(if worst.is_finite() {
                        format!("{:.0}%", (worst / t - 1.0) * 100.0)
                    } else {
                        "other not settled".to_string()
                    });
                }
                None => row.extend(["none settled".to_string(), "-".to_string()]),
            }
            let _ = writeln!(out, "| {} |", row.join(" | "));
        }
        out.push('\n');
    }
    if scan.is_empty() {
        let _ = writeln!(out, "## Residual vibration after the move (peak um)\n");
        let mut header: Vec<String> = params.iter().map(|p| p.to_string()).collect();
        header.extend(kinds.iter().map(|k| k.to_string()));
        let _ = writeln!(out, "| {} |", header.join(" | "));
        let _ = writeln!(out, "|{}", "---:|".repeat(header.len()));
    }
    for (key, idx) in groups.iter().filter(|_| scan.is_empty()) {
        let mut row: Vec<String> = if params.is_empty() {
            Vec::new()
        } else {
            key.split(" | ").map(str::to_string).collect()
        };
        for k in &kinds {
            row.push(
                idx.iter().find(|&&i| runs[i].profile == *k).map_or(
                    "-".to_string(),
                    |&i| match view(i) {
                        m if !m.is_ok() => m.failure(),
                        m => format!("{:.2}", m.residual_peak_um()),
                    },
                ),
            );
        }
        let _ = writeln!(out, "| {} |", row.join(" | "));
    }
    let corners = crate::kinds::corner::summary_section(runs, table);
    if !corners.is_empty() {
        out.push('\n');
        out.push_str(corners.trim_end());
        out.push('\n');
    }
    if !figures.is_empty() {
        let _ = writeln!(out, "\n## Figures\n");
        for f in figures {
            let _ = writeln!(out, "![{}]({})\n", f.title, f.svg);
            let _ = writeln!(out, "{} ([SVG]({}), [PNG]({}))\n", f.title, f.svg, f.png);
        }
    }
    out
}
