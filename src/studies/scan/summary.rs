//! The summary's scan section: the step axis's error at re-entry, per swept point and kind.

use std::fmt::Write as _;

use crate::input::runs_columns::RunsColumns;
use crate::spec::groups::SweptGroups;
use crate::spec::runs::RunList;

/// The summary's scan section (for a table with the scan columns): per band, the
/// step-axis error at re-entry for every kind side by side, settled or not, with the
/// window and the step's settle time. Read from the runs table, like the rest of the
/// summary, so a merged sweep's summary is the same.
pub fn section(runs: &dyn RunList, table: &RunsColumns) -> String {
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
                        format!("{e:.2} {} (w {w:.1}, s {s})", settled.join("/"))
                    });
            row.push(cell);
        }
        let _ = writeln!(out, "| {} |", row.join(" | "));
    }
    out.push('\n');
    out
}
