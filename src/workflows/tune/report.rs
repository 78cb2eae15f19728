//! One axis's section of the `settle tune` report (Markdown, `## Axis <name>`): the
//! search, the current settings against the recommendation, Klipper's choice, the best
//! per profile kind, the candidates out of the running and why, and the Pareto front of
//! the feasible candidates with its figure. The head of the report is in [`super::head`],
//! the candidates table in [`super::candidates`], the figure in [`super::figure`].

use std::fmt::Write as _;

use super::Outcome;
use super::cells::{headings, ms, row, rows_header};
use super::search::{Plan, Score};
use crate::studies::corner::Corner;
use crate::studies::scan::ScanSpec;
use settle_planner::ProfileKind;

/// The score in words (band, margin; scan steps: the overhead per line).
pub fn score_text(plan: &Plan) -> String {
    let band = plan.base.bands_um[plan.band_index];
    let tight = plan.bands_um[plan.score_band_index];
    let into = if plan.margin < 1.0 {
        format!(
            "{tight} um (robustness margin {} x the {band} um band)",
            plan.margin
        )
    } else {
        format!("{band} um")
    };
    if plan.base.state::<ScanSpec>().is_some() {
        format!(
            "mean overhead per line (from the fly axis leaving the region to the step axis settled into {into} and staying there over the next line; at least the fastest turnaround)"
        )
    } else {
        format!("mean move-and-settle into {into}")
    }
}

/// The move family in words.
fn family(plan: &Plan) -> String {
    if let Some(scan) = plan.base.state::<ScanSpec>() {
        return format!(
            "Scan steps: step-overs {:?} mm on axis `{}` (placement {}, settle margin {} s) while the fly axis `{}` scans {} mm at {} mm/s, turnarounds at {} mm/s^2",
            plan.distances_mm,
            plan.base.axis,
            scan.placement,
            scan.settle_margin_s,
            scan.fly_axis,
            scan.width_mm,
            scan.v_scan_mm_s,
            scan.fly_amax_mm_s2
        );
    }
    match plan.base.state::<Corner>() {
        Some(c) => format!(
            "Corners: {} x {} mm legs at {:?} degrees, strategy {}{}",
            c.leg_in_mm,
            c.leg_out_mm,
            plan.angles_deg,
            c.strategy.name(),
            plan.spec
                .max_contour_error_um
                .map_or(String::new(), |e| format!(", contour error <= {e} um"))
        ),
        None => format!("Moves: {:?} mm", plan.distances_mm),
    }
}

/// The gain of `w` over the current `d`, in words.
pub fn gain_text(plan: &Plan, d: &Score, w: &Score) -> String {
    let scan = plan.base.state::<ScanSpec>().is_some();
    let (base, now) = (d.simulated_move_and_settle_s, w.move_and_settle_s);
    if !now.is_finite() {
        return "no candidate is feasible".into();
    }
    let per_line = if scan { " per line" } else { "" };
    let faster = if !base.is_finite() {
        "the current settings do not settle in the window".to_string()
    } else if now <= base {
        format!(
            "{:.1}% {} ({:.1} ms saved{per_line})",
            100.0 * (1.0 - now / base),
            if scan {
                "less overhead per line"
            } else {
                "faster"
            },
            (base - now) * 1e3,
        )
    } else {
        format!(
            "{:.1}% {} than the current settings ({:.1} ms more{per_line})",
            100.0 * (now / base - 1.0),
            if scan {
                "more overhead per line"
            } else {
                "slower"
            },
            (now - base) * 1e3,
        )
    };
    match &d.infeasible {
        Some(why) if base.is_finite() => {
            format!("{faster}; the current settings are out: {}", why.short())
        }
        _ => faster,
    }
}

/// The search in words: machine, modes, damping, family, limits, score, band, notes.
fn search_text(out: &mut String, o: &Outcome) {
    let plan = &o.plan;
    let modes: Vec<String> = plan
        .modes
        .iter()
        .map(|(f, z)| format!("{f:.1} Hz (zeta {z:.3})"))
        .collect();
    let _ = writeln!(
        out,
        "Machine `{}`, backend `{}`; modes ({}): {}. {} at vmax {} mm/s, amax {} mm/s^2{}. Score: {}. {} candidates.\n",
        plan.base.machine_name,
        plan.base.backend,
        plan.modes_source,
        if modes.is_empty() {
            "none found".to_string()
        } else {
            modes.join(", ")
        },
        family(plan),
        plan.base.vmax_mm_s,
        plan.base.amax_mm_s2,
        plan.base
            .jmax_mm_s3
            .map_or(String::new(), |j| format!(", jerk <= {j} mm/s^3")),
        score_text(plan),
        o.scores.len()
    );
    if plan
        .candidates
        .iter()
        .any(|c| c.shaper.is_some_and(|s| s.shaper_type.is_some()))
    {
        let _ = writeln!(
            out,
            "{} A shaped candidate smoothing more than {} mm at its acceleration (Klipper's figure at 5 mm/s) is out.\n",
            plan.damping_source, plan.max_smoothing_mm
        );
    }
    if plan.frequency_tolerance > 0.0 {
        let _ = writeln!(
            out,
            "Frequency band: {}; a shaped candidate scores the worst of its shaper at its frequency and at either edge.\n",
            plan.band_source.describe(plan.frequency_tolerance)
        );
    }
    for n in &plan.notes {
        let _ = writeln!(out, "{n}\n");
    }
}

/// The section of axis `axis`: see the module documentation. `figure` is the Pareto
/// figure's file name.
pub fn axis_section(axis: &str, o: &Outcome, figure: &str) -> String {
    let plan = &o.plan;
    let (d, w) = (&o.scores[0], &o.scores[o.winner]);
    let [h_move, h_res, h_score] = headings(plan);
    let mut out = format!("## Axis {axis}\n\n");
    search_text(&mut out, o);
    let _ = writeln!(out, "### Current and recommended\n");
    out.push_str(&rows_header(plan));
    row(&mut out, "current", d);
    row(&mut out, "**recommended**", w);
    if let Some(a) = o.alone {
        row(&mut out, "alone on this axis", &o.scores[a]);
    }
    if plan.base.state::<Corner>().is_some() {
        let _ = writeln!(
            out,
            "\nLargest contour error over the corners: current {:.1} um, recommended {:.1} um.",
            d.max_contour_error_um, w.max_contour_error_um
        );
    }
    let _ = writeln!(
        out,
        "\nGain of the recommendation over the current settings: {}.\n",
        gain_text(plan, d, w)
    );
    if let Some(k) = &o.klipper {
        out.push_str(&super::klipper_section::section(plan, w, k));
    }
    let _ = writeln!(out, "### Best per profile kind\n");
    let _ = writeln!(
        out,
        "| kind | best feasible candidate | {h_move} | {h_res} | {h_score} |"
    );
    let _ = writeln!(out, "|---|---|---:|---:|---:|");
    for k in ProfileKind::ALL {
        if !o.scores.iter().any(|s| s.candidate.kind == k) {
            continue;
        }
        let masked: Vec<Score> = o
            .scores
            .iter()
            .map(|s| {
                let mut s = s.clone();
                if s.candidate.kind != k {
                    s.move_and_settle_s = f64::INFINITY;
                }
                s
            })
            .collect();
        match super::rank::best(&masked) {
            Some(i) => {
                let s = &o.scores[i];
                let _ = writeln!(
                    out,
                    "| {k} | {} | {} | {:.2} | {} |",
                    s.candidate.label(),
                    ms(s.move_time_s),
                    s.residual_peak_um,
                    ms(s.move_and_settle_s)
                );
            }
            None => {
                let _ = writeln!(out, "| {k} | none feasible | | | |");
            }
        }
    }
    out_of_the_running(&mut out, o);
    let _ = writeln!(
        out,
        "\n### Pareto front ({h_move} vs {h_res}, feasible candidates)\n"
    );
    let _ = writeln!(out, "| candidate | {h_move} | {h_res} | {h_score} |");
    let _ = writeln!(out, "|---|---:|---:|---:|");
    for &i in &o.front {
        let s = &o.scores[i];
        let _ = writeln!(
            out,
            "| {} | {} | {:.3} | {} |",
            s.candidate.label(),
            ms(s.move_time_s),
            s.residual_peak_um,
            ms(s.move_and_settle_s)
        );
    }
    let _ = writeln!(out, "\n![Pareto front, axis {axis}]({figure})");
    out
}

/// How many candidates are out and why, with the best of each (by its simulated score).
fn out_of_the_running(out: &mut String, o: &Outcome) {
    let mut groups: Vec<(&'static str, usize, usize)> = Vec::new();
    for (i, s) in o.scores.iter().enumerate() {
        let Some(why) = &s.infeasible else { continue };
        match groups.iter_mut().find(|g| g.0 == why.group()) {
            Some(g) => {
                g.1 += 1;
                let b = &o.scores[g.2];
                if s.simulated_move_and_settle_s < b.simulated_move_and_settle_s {
                    g.2 = i;
                }
            }
            None => groups.push((why.group(), 1, i)),
        }
    }
    if groups.is_empty() {
        return;
    }
    let _ = writeln!(
        out,
        "\n### Out of the running\n\nThese candidates never win and are left off the Pareto front.\n\n| reason | candidates | fastest of them | simulated (ms) | why |\n|---|---:|---|---:|---|"
    );
    for (group, n, i) in groups {
        let s = &o.scores[i];
        let _ = writeln!(
            out,
            "| {} | {n} | {} | {} | {} |",
            group.trim_start_matches("out: "),
            s.candidate.label(),
            ms(s.simulated_move_and_settle_s),
            s.infeasible.as_ref().map_or(String::new(), |w| w.short())
        );
    }
}
