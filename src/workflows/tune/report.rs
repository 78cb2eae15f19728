//! Outputs of `settle tune`: the report (Markdown, headed by "your current settings ->
//! recommended"), the candidates table (CSV) and the Pareto plot. The firmware exports are
//! in [`super::export`].

use std::fmt::Write as _;

use super::Outcome;
use super::search::{BandSource, Plan, Score};
use crate::input::runs_table::record;
use crate::output::plot::{Figure, Line, Marker, PALETTE, Panel};
use crate::studies::corner::Corner;
use crate::studies::scan::ScanSpec;
use settle_planner::ProfileKind;
use settle_planner::shaper::ShaperType;

/// The candidates table: one row per candidate of every tuned axis, with its
/// acceleration, Klipper's smoothing and the largest acceleration within the smoothing
/// limit.
pub fn candidates_csv(axes: &[(String, Outcome)]) -> String {
    let mut out = record(&[
        "axis",
        "candidate",
        "profile",
        "jmax_mm_s3",
        "pvt_asym_ki",
        "bow_scales",
        "shaper_type",
        "shaper_frequency_hz",
        "accel_mm_s2",
        "smoothing_mm",
        "max_accel_mm_s2",
        "move_time_s",
        "residual_peak_um",
        "move_and_settle_s",
        "max_contour_error_um",
    ]);
    for (axis, o) in axes {
        for (i, s) in o.scores.iter().enumerate() {
            let c = &s.candidate;
            let b = c.params.fourjerk_jerk_scale;
            let (st, sf) = match c
                .shaper
                .and_then(|sh| sh.shaper_type.map(|k| (k, sh.frequency_hz)))
            {
                Some((k, f)) => (k.name().to_string(), f.to_string()),
                None => ("none".to_string(), String::new()),
            };
            out.push_str(&record(&[
                axis.clone(),
                i.to_string(),
                c.kind.to_string(),
                c.jmax_mm_s3.map_or(String::new(), |j| j.to_string()),
                c.params.pvt_asym_ki.to_string(),
                format!("{}/{}/{}/{}", b[0], b[1], b[2], b[3]),
                st.to_string(),
                sf,
                s.accel_mm_s2.to_string(),
                s.smoothing_mm.to_string(),
                s.max_accel_mm_s2.to_string(),
                s.move_time_s.to_string(),
                s.residual_peak_um.to_string(),
                s.move_and_settle_s.to_string(),
                if s.max_contour_error_um.is_nan() {
                    String::new()
                } else {
                    s.max_contour_error_um.to_string()
                },
            ]));
        }
    }
    out
}

/// A candidate's shaper in words: `mzv @ 52.0 Hz (zeta 0.1)` or `none`.
pub fn shaper_text(s: &Score) -> String {
    match s
        .candidate
        .shaper
        .and_then(|sh| sh.shaper_type.map(|k| (k, sh)))
    {
        Some((k, sh)) => format!(
            "{} @ {:.1} Hz (zeta {})",
            k.name(),
            sh.frequency_hz,
            sh.damping_ratio
        ),
        None => "none".into(),
    }
}

/// The head of the report: per axis, the user's current settings (the scenario's point,
/// `[tune.axis.<name>]`) and the recommendation, with smoothing, max_accel and the gain
/// against the current settings.
pub fn current_to_recommended(axes: &[(String, Outcome)]) -> String {
    let mut out = String::from("## Your current settings -> recommended\n\n");
    let Some((_, first)) = axes.first() else {
        return out;
    };
    let p = &first.plan;
    let _ = writeln!(
        out,
        "Firmware: {}. Score: {}. Shaped candidates smoothing more than {} mm (Klipper's figure at 5 mm/s) are infeasible{}.\n",
        p.spec.firmware.as_deref().unwrap_or("any"),
        score_text(p),
        p.max_smoothing_mm,
        if axes
            .iter()
            .any(|(_, o)| o.plan.band_source != BandSource::Given
                && o.plan.frequency_tolerance > 0.0)
        {
            "; shaped candidates are scored on the worst of their shaper at its frequency and at either edge of their axis's frequency band (given with each axis below)".to_string()
        } else if p.frequency_tolerance > 0.0 {
            format!(
                "; shaped candidates are scored on the worst of their shaper at its frequency and {}% either side",
                p.frequency_tolerance * 100.0
            )
        } else {
            String::new()
        }
    );
    let _ = writeln!(
        out,
        "| axis | | profile | shaper | accel (mm/s^2) | smoothing (mm) | max_accel (mm/s^2) | move+settle (ms) | gain over current |"
    );
    let _ = writeln!(out, "|---|---|---|---|---:|---:|---:|---:|---|");
    for (axis, o) in axes {
        let (c, w) = (&o.scores[0], &o.scores[o.winner]);
        let base = c.simulated_move_and_settle_s;
        let gain = if base.is_finite() && w.move_and_settle_s.is_finite() {
            format!(
                "{:.1}% faster ({:.1} ms saved)",
                100.0 * (1.0 - w.move_and_settle_s / base),
                (base - w.move_and_settle_s) * 1e3
            )
        } else if w.move_and_settle_s.is_finite() {
            "current does not settle in the window".into()
        } else {
            "no candidate settles within the limits".into()
        };
        let over = if c.smoothing_mm > o.plan.max_smoothing_mm {
            format!(
                " (smooths {:.3} mm > {} mm)",
                c.smoothing_mm, o.plan.max_smoothing_mm
            )
        } else {
            String::new()
        };
        for (tag, s, g) in [("current", c, over), ("**recommended**", w, gain)] {
            let _ = writeln!(
                out,
                "| {axis} | {tag} | {} | {} | {} | {:.3} | {} | {} | {g} |",
                s.candidate.kind,
                shaper_text(s),
                s.accel_mm_s2,
                s.smoothing_mm,
                if s.max_accel_mm_s2.is_finite() {
                    format!("{:.0}", s.max_accel_mm_s2)
                } else {
                    "-".into()
                },
                ms(s.simulated_move_and_settle_s)
            );
        }
    }
    out
}

/// Markdown headings one level deeper (`#` -> `##`), to nest a report under an axis.
pub fn demote(md: &str) -> String {
    let mut out = String::with_capacity(md.len() + 64);
    for line in md.lines() {
        if line.starts_with('#') {
            out.push('#');
        }
        out.push_str(line);
        out.push('\n');
    }
    out
}

/// Column headings of the report's tables: (move time, residual, score), which for scan
/// steps are the step, the error over the next line, and the overhead per line.
pub fn headings(plan: &Plan) -> [&'static str; 3] {
    if plan.base.state::<ScanSpec>().is_some() {
        [
            "step (ms)",
            "line residual peak (um)",
            "overhead per line (ms)",
        ]
    } else {
        ["move (ms)", "residual peak (um)", "move+settle (ms)"]
    }
}

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

/// Seconds as milliseconds with one decimal, or "not settled".
pub(crate) fn ms(x: f64) -> String {
    if x.is_finite() {
        format!("{:.1}", x * 1e3)
    } else {
        "not settled".into()
    }
}

/// The current settings' and the winner's rows of a `| | candidate | move | residual | score | into
/// the band |` table; `winner_tag` is how the winner's row is labelled.
pub(crate) fn default_and_winner_rows(out: &mut String, d: &Score, w: &Score, winner_tag: &str) {
    for (tag, s) in [("current", d), (winner_tag, w)] {
        let _ = writeln!(
            out,
            "| {tag} | {} | {} | {:.2} | {} | {} |",
            s.candidate.label(),
            ms(s.move_time_s),
            s.residual_peak_um,
            ms(s.simulated_move_and_settle_s),
            ms(s.at_band_s)
        );
    }
}

/// The Markdown report: winner, gain over the current settings, per-kind bests and the Pareto front.
pub fn markdown(
    name: &str,
    plan: &Plan,
    scores: &[Score],
    winner: usize,
    front: &[usize],
) -> String {
    let d = &scores[0];
    let w = &scores[winner];
    let band = plan.base.bands_um[plan.band_index];
    let [h_move, h_res, h_score] = headings(plan);
    let mut out = String::new();
    let _ = writeln!(out, "# settle tune: {name}\n");
    let modes: Vec<String> = plan
        .modes
        .iter()
        .map(|(f, z)| format!("{f:.1} Hz (zeta {z:.3})"))
        .collect();
    let _ = writeln!(
        out,
        "Machine `{}`, axis `{}`, backend `{}`; modes tuned to: {}. {} at vmax {} mm/s, amax {} mm/s^2, jerk <= {} mm/s^3. Score: {}. {} candidates.\n",
        plan.base.machine_name,
        plan.base.axis,
        plan.base.backend,
        modes.join(", "),
        family(plan),
        plan.base.vmax_mm_s,
        plan.base.amax_mm_s2,
        plan.base.jmax_mm_s3.map_or("-".into(), |j| j.to_string()),
        score_text(plan),
        scores.len()
    );
    if plan.frequency_tolerance > 0.0 {
        let _ = writeln!(
            out,
            "Frequency band: {}; a shaped candidate scores the worst of its shaper at its frequency and at either edge.\n",
            plan.band_source.describe(plan.frequency_tolerance)
        );
    }
    let gain = if w.move_and_settle_s.is_finite() && d.simulated_move_and_settle_s.is_finite() {
        format!(
            "{:.1}% {} ({:.1} ms saved{})",
            100.0 * (1.0 - w.move_and_settle_s / d.simulated_move_and_settle_s),
            if plan.base.state::<ScanSpec>().is_some() {
                "less overhead per line"
            } else {
                "faster"
            },
            (d.simulated_move_and_settle_s - w.move_and_settle_s) * 1e3,
            if plan.base.state::<ScanSpec>().is_some() {
                " per line"
            } else {
                ""
            }
        )
    } else {
        "the current settings do not settle in the window".into()
    };
    let _ = writeln!(
        out,
        "| | candidate | {h_move} | {h_res} | {h_score} | into {band} um (ms) |"
    );
    let _ = writeln!(out, "|---|---|---:|---:|---:|---:|");
    default_and_winner_rows(&mut out, d, w, "**winner**");
    if plan.base.state::<Corner>().is_some() {
        let _ = writeln!(
            out,
            "\nLargest contour error over the corners: current {:.1} um, winner {:.1} um.",
            d.max_contour_error_um, w.max_contour_error_um
        );
    }
    let _ = writeln!(
        out,
        "\nGain of the winner over the current settings: {gain}.\n"
    );
    let _ = writeln!(out, "## Best per profile kind\n");
    let _ = writeln!(
        out,
        "| kind | best candidate | {h_move} | {h_res} | {h_score} |"
    );
    let _ = writeln!(out, "|---|---|---:|---:|---:|");
    for k in ProfileKind::ALL {
        if let Some(i) = super::rank::best(
            &scores
                .iter()
                .map(|s| {
                    let mut s = s.clone();
                    if s.candidate.kind != k {
                        s.move_and_settle_s = f64::INFINITY;
                    }
                    s
                })
                .collect::<Vec<_>>(),
        ) {
            let s = &scores[i];
            let _ = writeln!(
                out,
                "| {k} | {} | {} | {:.2} | {} |",
                s.candidate.label(),
                ms(s.move_time_s),
                s.residual_peak_um,
                ms(s.move_and_settle_s)
            );
        }
    }
    let _ = writeln!(out, "\n## Pareto front ({h_move} vs {h_res})\n");
    let _ = writeln!(out, "| candidate | {h_move} | {h_res} | {h_score} |");
    let _ = writeln!(out, "|---|---:|---:|---:|");
    for &i in front {
        let s = &scores[i];
        let _ = writeln!(
            out,
            "| {} | {} | {:.3} | {} |",
            s.candidate.label(),
            ms(s.move_time_s),
            s.residual_peak_um,
            ms(s.move_and_settle_s)
        );
    }
    out
}

/// The Pareto plot: every candidate (grey, shaped ones by shaper colour), the front, the
/// current settings and the winner.
pub fn pareto_figure(
    name: &str,
    plan: &Plan,
    scores: &[Score],
    winner: usize,
    front: &[usize],
) -> Figure {
    let [h_move, h_res, _] = headings(plan);
    let pt = |s: &Score| (s.move_time_s * 1e3, s.residual_peak_um.max(1e-3));
    let mut lines = Vec::new();
    // One group per shaper the search holds (any firmware's), in order of appearance.
    let mut groups: Vec<(String, Option<ShaperType>)> = vec![("unshaped".into(), None)];
    for s in scores {
        if let Some(k) = s.candidate.shaper.and_then(|sh| sh.shaper_type)
            && !groups.iter().any(|(_, g)| *g == Some(k))
        {
            groups.push((k.name(), Some(k)));
        }
    }
    for (gi, (label, kind)) in groups.iter().enumerate() {
        let points: Vec<(f64, f64)> = scores
            .iter()
            .filter(|s| s.move_time_s.is_finite())
            .filter(|s| s.candidate.shaper.and_then(|sh| sh.shaper_type) == *kind)
            .map(pt)
            .collect();
        if points.is_empty() {
            continue;
        }
        let mut l = Line::new(Some(label.clone()), PALETTE[gi % PALETTE.len()], points);
        l.width = 0;
        l.marker = Some(Marker::Circle);
        lines.push(l);
    }
    let mut f = Line::new(
        Some("Pareto front".into()),
        plotters::style::RGBColor(0, 0, 0),
        front.iter().map(|&i| pt(&scores[i])).collect(),
    );
    f.width = 2;
    lines.push(f);
    for (label, i, marker) in [
        ("current", 0, Marker::Square),
        ("winner", winner, Marker::Triangle),
    ] {
        let mut l = Line::new(
            Some(format!("{label}: {}", scores[i].candidate.label())),
            plotters::style::RGBColor(0xd6, 0x27, 0x28),
            vec![pt(&scores[i])],
        );
        l.marker = Some(marker);
        l.width = 0;
        lines.push(l);
    }
    Figure {
        title: format!(
            "settle tune {name}: {} vs {}",
            h_move.replace(" (ms)", " time"),
            h_res.replace(" peak (um)", "")
        ),
        panels: vec![Panel {
            title: "every candidate (mean over the move family)".into(),
            x_label: h_move.replace("(ms)", "time (ms)"),
            y_label: h_res.replace("(um)", "(um, log)"),
            lines,
            y_log: true,
            legend: true,
            ..Panel::default()
        }],
        columns: 1,
        width: 1000,
        row_height: 650,
        legend: Vec::new(),
    }
}
