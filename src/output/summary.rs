//! `summary.md`: one table per band of move-and-settle times, profile kinds side by side
//! for each swept point, the residual vibration, the run kinds' sections, the figures.
//! Read from the runs table rather than from the metrics, so a summary rebuilt from a
//! merged `runs.csv` is byte-identical to the one the unsharded sweep wrote.

use std::fmt::Write as _;

use settle_planner::ProfileKind;

use crate::input::runs_table::RunsTable;
use crate::input::scenario::Scenario;
use crate::output::runs_csv::band_label;
use crate::spec::groups::SweptGroups;
use crate::spec::run_spec::RunSpec;

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
/// the metrics structs, so a summary rebuilt from a merged `runs.csv` is byte-identical to the one
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
    // The modes as written: `[machine] modes` (axis x), then each axis table's (prefixed
    // with its axis).
    let axis_modes = sc
        .machine
        .axis
        .iter()
        .filter_map(|(name, a)| Some((format!("{name}: "), a.modes.as_ref()?)));
    let mode_text = |p: &str, m: &crate::input::modes::ModeSpec| {
        format!("{p}{} Hz, zeta {}", m.frequency_hz, m.damping_ratio)
    };
    let mut modes: Vec<String> = std::iter::once((String::new(), &sc.machine.modes))
        .chain(axis_modes)
        .flat_map(|(p, ms)| ms.iter().map(move |m| mode_text(&p, m)))
        .collect();
    // A machine file of modes (`preset = "machine.toml"`): the first run's.
    if modes.is_empty()
        && let Some(r) = runs.first()
    {
        for a in &r.modes {
            let p = format!("{}: ", a.axis);
            modes.extend(a.modes.iter().map(|m| mode_text(&p, m)));
        }
    }
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
    // The run kinds' sections: those that replace the move-and-settle tables (which would
    // not measure what the kind is about) stand in their place, the others follow them.
    let mut replaced = false;
    let mut after: Vec<String> = Vec::new();
    for k in crate::kinds::all() {
        let Some(section) = k.summary(runs, table) else {
            continue;
        };
        if k.replaces_move_tables() {
            out.push_str(&section);
            replaced = true;
        } else {
            after.push(section);
        }
    }
    let bands = if replaced {
        Vec::new()
    } else {
        runs.first().map(|r| r.bands_um.clone()).unwrap_or_default()
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
    if !replaced {
        let _ = writeln!(out, "## Residual vibration after the move (peak um)\n");
        let mut header: Vec<String> = params.iter().map(|p| p.to_string()).collect();
        header.extend(kinds.iter().map(|k| k.to_string()));
        let _ = writeln!(out, "| {} |", header.join(" | "));
        let _ = writeln!(out, "|{}", "---:|".repeat(header.len()));
    }
    for (key, idx) in groups.iter().filter(|_| !replaced) {
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
    for section in after.iter().filter(|s| !s.is_empty()) {
        out.push('\n');
        out.push_str(section.trim_end());
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
