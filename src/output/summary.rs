//! `summary.md`: the overall winner per band, one ranking table per band (every swept
//! setting compared at each swept point of the workload, see [`crate::output::ranking`]),
//! the studies' sections, the figures. Read from the runs table rather than from the
//! metrics, so a summary rebuilt from a merged `runs.csv` is byte-identical to the one the
//! unsharded sweep wrote.

use std::path::Path;

use crate::input::runs_columns::RunsColumns;
use crate::input::scenario::Scenario;
use crate::output::html::Out;
use crate::output::ranking::{Ranking, SHAPER_COLUMNS, gain_text, is_current, rank, run_command};
use crate::spec::runs::RunList;

/// A time in ms with one decimal, `not settled` for none.
pub fn ms(t: Option<f64>) -> String {
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

/// `x` to four significant digits, as short as it then prints (an identified
/// 45.00161069 Hz mode is `45`, its 0.0500311 damping ratio `0.05003`, a 75.0139 Hz mode
/// `75.01`; a mode written as 40 Hz stays `40`).
pub fn significant(x: f64) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    let e = 3 - x.abs().log10().floor() as i32;
    // Divided by an exact power of ten, the result is the double nearest the decimal.
    if e >= 0 {
        let p = 10f64.powi(e);
        (x * p).round() / p
    } else {
        let p = 10f64.powi(-e);
        (x / p).round() * p
    }
}

/// The machines of `runs`, named once each in first-seen order: `printer_xy (axis x, linear
/// driver)`, or the modes of the modes form.
pub fn machines_line(runs: &dyn RunList) -> String {
    let mut names: Vec<String> = Vec::new();
    for r in runs.iter() {
        let n = if r.machine.physical().is_some() {
            format!("{} (axis {}, {} driver)", r.machine_name, r.axis, r.driver)
        } else {
            // Each axis's modes, prefixed with the axis when the machine has several.
            let several = r.machine.modes().len() > 1;
            let modes: Vec<String> = r
                .machine
                .modes()
                .iter()
                .flat_map(|a| {
                    let prefix = if several {
                        format!("{}: ", a.axis)
                    } else {
                        String::new()
                    };
                    a.modes.iter().map(move |m| {
                        format!(
                            "{prefix}{} Hz, zeta {}",
                            significant(m.frequency_hz),
                            significant(m.damping_ratio)
                        )
                    })
                })
                .collect();
            format!("modes {}", modes.join("; "))
        };
        if !names.contains(&n) {
            names.push(n);
        }
    }
    let backend = runs
        .first()
        .map_or(String::new(), |r| format!("; backend {}", r.backend));
    match names.len() {
        0 => "No runs".to_string(),
        1 => format!("Machine: {}{backend}", names[0]),
        _ => format!("Machines: {}{backend}", names.join(", ")),
    }
}

/// The summary: the overall winner per band, then per band every run ranked within its
/// workload point (the swept values that are not settings), with its run number and the
/// command that runs it alone; the failed runs with their reasons; the studies'
/// sections; the figures. `scenario` is the scenario file as the commands name it.
///
/// It reads the metrics from `table` (the runs table, row `i` = `runs.at(i)`) rather than from
/// the metrics structs, so a summary rebuilt from a merged `runs.csv` is byte-identical to
/// the one the unsharded sweep wrote.
pub fn summary_md(
    sc: &Scenario,
    scenario: &Path,
    runs: &dyn RunList,
    table: &RunsColumns,
    figures: &[Figure],
) -> String {
    let mut out = String::new();
    summary_to(&mut out, sc, scenario, runs, table, figures);
    out
}

/// [`summary_md`], written to `out` as it is made (a summary of 100,000 runs is never
/// held whole).
pub(crate) fn summary_to(
    out: &mut impl Out,
    sc: &Scenario,
    scenario: &Path,
    runs: &dyn RunList,
    table: &RunsColumns,
    figures: &[Figure],
) {
    let _ = writeln!(out, "# {}\n", sc.name);
    if !sc.description.is_empty() {
        let _ = writeln!(out, "{}\n", sc.description.trim());
    }
    let _ = writeln!(out, "{}. {} runs.\n", machines_line(runs), runs.len());
    let failed: Vec<usize> = (0..runs.len())
        .filter(|&i| table.cell(i, "status").is_some_and(|s| s != "ok"))
        .collect();
    if !failed.is_empty() {
        let _ = writeln!(
            out,
            "**{} run(s) failed**: `lost_steps` (a stepper's load angle passed 90 electrical degrees) or `fault` (the simulation broke down), never compared or averaged. Why, per run:\n",
            failed.len()
        );
        for &i in &failed {
            let _ = writeln!(
                out,
                "- run {}: {}: {}",
                runs.at(i).id,
                table.cell(i, "status").unwrap_or_default(),
                table.cell(i, "reason").unwrap_or_default()
            );
        }
        out.push('\n');
    }
    if let Some(j) = crate::output::jobs::jobs(sc, runs, table) {
        out.push_str(&crate::output::jobs::section(&j, scenario, runs));
        out.push('\n');
    }
    // The studies' sections: those that replace the move-and-settle tables (which would
    // not measure what the study is about) stand in their place, the others follow them.
    let mut replaced = false;
    let mut after: Vec<String> = Vec::new();
    for k in crate::studies::all() {
        let Some(section) = k.summary(runs, table, &|r| is_current(sc, r)) else {
            continue;
        };
        if k.replaces_move_tables() {
            out.push_str(&section);
            replaced = true;
        } else {
            after.push(section);
        }
    }
    if !replaced {
        push_ranking(out, &rank(sc, runs, table), runs, table, scenario);
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
}

/// Whether the summary ranks candidates by move-and-settle time: no study's section
/// replaces the ranking (a raster scan's does).
pub fn ranks_candidates(runs: &dyn RunList, table: &RunsColumns) -> bool {
    !crate::studies::all()
        .iter()
        .any(|k| k.replaces_move_tables() && k.summary(runs, table, &|_| false).is_some())
}

/// The winners and the ranking tables.
fn push_ranking(
    out: &mut impl Out,
    ranking: &Ranking,
    runs: &dyn RunList,
    table: &RunsColumns,
    scenario: &Path,
) {
    let reference = ranking.reference_name();
    let _ = writeln!(out, "## Winner per band\n");
    let compared = if ranking.setting_keys.is_empty() {
        "the profile kind".to_string()
    } else {
        ranking.setting_keys.join(", ")
    };
    let over = if ranking.workload_keys.is_empty() {
        String::new()
    } else {
        format!(
            ", summed over every swept point of {}",
            ranking.workload_keys.join(", ")
        )
    };
    let _ = writeln!(
        out,
        "Compared: {compared}. Winner: the least move-and-settle time{over}. Gain {reference}: how much longer the reference takes (+38 % = the reference takes 38 % longer).\n"
    );
    if let Some(note) = ranking.repeats_note(runs) {
        let _ = writeln!(out, "{note}\n");
    }
    for b in &ranking.bands {
        match &b.winner {
            Some(w) => {
                let gain = match &w.reference {
                    Some((label, t)) if t.is_finite() => format!(
                        "; {} {reference} ({label}, {:.1} ms)",
                        gain_text(Some(t / w.total_s - 1.0)),
                        t * 1e3
                    ),
                    Some((label, _)) => {
                        format!("; {reference} ({label}): never settles everywhere")
                    }
                    None => String::new(),
                };
                let _ = writeln!(
                    out,
                    "- within {} um: **{}**, {:.1} ms{}{gain}",
                    b.band_um,
                    w.label,
                    w.total_s * 1e3,
                    if w.points > 1 {
                        format!(" over {} points", w.points)
                    } else {
                        String::new()
                    }
                );
            }
            None => {
                let _ = writeln!(
                    out,
                    "- within {} um: no candidate settles at every point",
                    b.band_um
                );
            }
        }
    }
    out.push('\n');
    for (bi, b) in ranking.bands.iter().enumerate() {
        let _ = writeln!(
            out,
            "## Ranking: move and settle to within {} um (ms)\n",
            b.band_um
        );
        let mut header: Vec<String> = ranking.workload_keys.clone();
        header.push("rank".into());
        if ranking.setting_keys.is_empty() {
            header.push("profile".into());
        } else {
            header.extend(ranking.setting_keys.iter().cloned());
        }
        for h in ["move", "settle", "total", "residual peak (um)"] {
            header.push(h.into());
        }
        header.push(format!("gain {reference}"));
        if ranking.shapers {
            header.extend(SHAPER_COLUMNS.map(String::from));
        }
        header.push("run".into());
        header.push("command".into());
        let _ = writeln!(out, "| {} |", header.join(" | "));
        let _ = writeln!(out, "|{}", "---:|".repeat(header.len()));
        for p in (0..b.points.len()).filter_map(|p| ranking.point(bi, p, runs, table)) {
            for r in &p.runs {
                let mut row = p.workload.clone();
                let mark = |s: String| {
                    if r.rank == Some(1) {
                        format!("**{s}**")
                    } else {
                        s
                    }
                };
                let rank = r.rank.map_or("-".into(), |n| n.to_string());
                row.push(if r.current {
                    format!("{rank} (current)")
                } else {
                    rank
                });
                if r.settings.is_empty() {
                    row.push(r.label.clone());
                } else {
                    row.extend(r.settings.iter().cloned());
                }
                match &r.failure {
                    Some(f) => {
                        row.extend(["-".to_string(), "-".to_string(), f.clone(), "-".to_string()]);
                        row.push("-".into());
                    }
                    None => {
                        row.push(format!("{:.1}", r.move_s * 1e3));
                        row.push(ms(r.settle_s));
                        row.push(mark(ms(r.total_s)));
                        row.push(format!("{:.2}", r.residual_peak_um));
                        row.push(gain_text(r.gain));
                    }
                }
                if let Some(sh) = &r.shaper {
                    let f = |x: Option<f64>, prec: usize| {
                        x.map_or("-".to_string(), |x| format!("{x:.prec$}"))
                    };
                    row.push(f(sh[0], 3));
                    row.push(f(sh[1], 1));
                    row.push(f(sh[2], 0));
                }
                row.push(r.id.to_string());
                row.push(format!("`{}`", run_command(scenario, &runs.at(r.row))));
                let _ = writeln!(out, "| {} |", row.join(" | "));
            }
        }
        out.push('\n');
    }
}
