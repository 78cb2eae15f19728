//! Outputs of `settle tune`: the report (Markdown), the candidates table (CSV), the Pareto
//! plot, and the winner exported as Klipper config lines and Trinamic TMC5160 registers.

use std::fmt::Write as _;

use settle_planner::ProfileKind;
use settle_planner::shaper::ShaperKind;
use settle_planner::tmc::ramp::SRampParams;
use settle_planner::tmc::registers::{TmcUnits, export};

use super::search::{Plan, Score};
use crate::input::runs_table::record;
use crate::kinds::corner::Corner;
use crate::kinds::scan::ScanSpec;
use crate::output::plot::{Figure, Line, Marker, PALETTE, Panel};

/// Klipper's `[printer]` / `[input_shaper]` lines for the winner on axis `axis`. Klipper
/// plans trapezoids: a jerk-limited winner is exported with its shaper and acceleration and
/// a comment that Klipper cannot express its jerk.
pub fn klipper(plan: &Plan, s: &Score) -> String {
    let c = &s.candidate;
    let b = &plan.base;
    let mut out = String::new();
    let _ = writeln!(out, "# settle tune: winner {}", c.label());
    if c.kind != ProfileKind::Trapezoid {
        let _ = writeln!(
            out,
            "# note: Klipper plans trapezoids; the winner's {} jerk ({} mm/s^3) has no Klipper setting",
            c.kind,
            c.jmax_mm_s3.map_or("-".into(), |j| format!("{j:.0}"))
        );
    }
    let _ = writeln!(out, "[printer]");
    let _ = writeln!(out, "max_velocity: {}", b.vmax_mm_s);
    let _ = writeln!(out, "max_accel: {}", b.amax_mm_s2);
    let _ = writeln!(out);
    let _ = writeln!(out, "[input_shaper]");
    // One line set per moving axis (a corner path moves two; settle applies one shaper
    // to both).
    for axis in b.axis.split('+') {
        match c.shaper.and_then(|sh| sh.kind.map(|k| (k, sh))) {
            Some((k, sh)) => {
                let _ = writeln!(out, "shaper_type_{axis}: {}", k.name());
                let _ = writeln!(out, "shaper_freq_{axis}: {:.1}", sh.frequency_hz);
                let _ = writeln!(out, "damping_ratio_{axis}: {}", sh.damping_ratio);
            }
            None => {
                let _ = writeln!(out, "# no shaper in the winner: shaping off on {axis}");
                let _ = writeln!(out, "shaper_freq_{axis}: 0");
            }
        }
    }
    if let Some(corner) = b.state::<Corner>()
        && corner.strategy.name() == "square_corner_velocity"
    {
        let _ = writeln!(out, "\n[printer]");
        let _ = writeln!(
            out,
            "square_corner_velocity: {}",
            corner.square_corner_velocity_mm_s
        );
    }
    out
}

/// The TMC5160 ramp registers of the winner's move (the first of the family), for
/// `usteps_per_mm` and the chip clock. The chip's ramp is the four-jerk S-ramp: a
/// trapezoid's bows would be infinite, so trapezoids and shaped winners (the chip cannot
/// shape) export nothing but the reason.
pub fn tmc(plan: &Plan, s: &Score) -> String {
    let c = &s.candidate;
    let b = &plan.base;
    let mut out = String::new();
    let units = TmcUnits {
        f_clk_hz: plan.spec.tmc_clock_hz.unwrap_or(12_000_000),
        usteps_per_unit: plan.spec.usteps_per_mm.unwrap_or(1280.0),
        direct_acc: false,
        direct_bow: false,
    };
    let _ = writeln!(
        out,
        "# settle tune: winner {} as TMC5160 ramp registers ({} usteps/mm, fCLK {} Hz)",
        c.label(),
        units.usteps_per_unit,
        units.f_clk_hz
    );
    if c.shaper.is_some_and(|sh| sh.kind.is_some()) {
        let _ = writeln!(
            out,
            "# the winner is input-shaped; the TMC5160 ramp generator cannot shape: registers of its unshaped ramp follow"
        );
    }
    let Some(j) = c.jmax_mm_s3 else {
        let _ = writeln!(
            out,
            "# a trapezoid has infinite bows; the TMC5160 S-ramp cannot express it"
        );
        return out;
    };
    let scale = match c.kind {
        ProfileKind::FourJerk => c.params.fourjerk_jerk_scale,
        _ => [1.0; 4],
    };
    let dmax = match c.kind {
        ProfileKind::FourJerk => b.amax_mm_s2 * c.params.fourjerk_dmax_scale,
        _ => b.amax_mm_s2,
    };
    let p = SRampParams {
        vstart: 0.0,
        vmax: b.vmax_mm_s,
        vstop: 0.0,
        amax: b.amax_mm_s2,
        dmax,
        bow: [j * scale[0], j * scale[1], j * scale[2], j * scale[3]],
    };
    if c.kind == ProfileKind::PvtAsym || c.kind == ProfileKind::PvtSym {
        let _ = writeln!(
            out,
            "# {} is a PVT profile; the nearest S-ramp (same vmax, amax, jerk) follows",
            c.kind
        );
    }
    let target = b.start_mm + plan.distances_mm[0];
    match export(target, &p, &units) {
        Ok(r) => {
            let names = [
                "VMAX", "VSTART", "VSTOP", "AMAX", "DMAX", "BOW1", "BOW2", "BOW3", "BOW4",
                "CLK_FREQ", "XTARGET",
            ];
            for ((addr, value), name) in r.writes().iter().zip(names) {
                let _ = writeln!(out, "{name:<8} 0x{addr:02X} = {value}");
            }
        }
        Err(e) => {
            let _ = writeln!(out, "# cannot export: {e}");
        }
    }
    out
}

/// The candidates table (one row per candidate).
pub fn candidates_csv(scores: &[Score]) -> String {
    let mut out = record(&[
        "candidate",
        "profile",
        "jmax_mm_s3",
        "pvt_asym_ki",
        "bow_scales",
        "shaper_type",
        "shaper_frequency_hz",
        "move_time_s",
        "residual_peak_um",
        "move_and_settle_s",
        "max_contour_error_um",
    ]);
    for (i, s) in scores.iter().enumerate() {
        let c = &s.candidate;
        let b = c.params.fourjerk_jerk_scale;
        let (st, sf) = match c
            .shaper
            .and_then(|sh| sh.kind.map(|k| (k, sh.frequency_hz)))
        {
            Some((k, f)) => (k.name().to_string(), f.to_string()),
            None => ("none".to_string(), String::new()),
        };
        out.push_str(&record(&[
            i.to_string(),
            c.kind.to_string(),
            c.jmax_mm_s3.map_or(String::new(), |j| j.to_string()),
            c.params.pvt_asym_ki.to_string(),
            format!("{}/{}/{}/{}", b[0], b[1], b[2], b[3]),
            st.to_string(),
            sf,
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

/// The default's and the winner's rows of a `| | candidate | move | residual | score | into
/// the band |` table; `winner_tag` is how the winner's row is labelled.
pub(crate) fn default_and_winner_rows(out: &mut String, d: &Score, w: &Score, winner_tag: &str) {
    for (tag, s) in [("default", d), (winner_tag, w)] {
        let _ = writeln!(
            out,
            "| {tag} | {} | {} | {:.2} | {} | {} |",
            s.candidate.label(),
            ms(s.move_time_s),
            s.residual_peak_um,
            ms(s.move_and_settle_s),
            ms(s.at_band_s)
        );
    }
}

/// The Markdown report: winner, gain over the default, per-kind bests and the Pareto front.
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
    let gain = if w.move_and_settle_s.is_finite() && d.move_and_settle_s.is_finite() {
        format!(
            "{:.1}% {} ({:.1} ms saved{})",
            100.0 * (1.0 - w.move_and_settle_s / d.move_and_settle_s),
            if plan.base.state::<ScanSpec>().is_some() {
                "less overhead per line"
            } else {
                "faster"
            },
            (d.move_and_settle_s - w.move_and_settle_s) * 1e3,
            if plan.base.state::<ScanSpec>().is_some() {
                " per line"
            } else {
                ""
            }
        )
    } else {
        "the default does not settle in the window".into()
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
            "\nLargest contour error over the corners: default {:.1} um, winner {:.1} um.",
            d.max_contour_error_um, w.max_contour_error_um
        );
    }
    let _ = writeln!(out, "\nGain of the winner over the default: {gain}.\n");
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
/// default and the winner.
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
    let groups: Vec<(String, Option<ShaperKind>)> = std::iter::once(("unshaped".into(), None))
        .chain(ShaperKind::ALL.map(|k| (k.name().to_string(), Some(k))))
        .collect();
    for (gi, (label, kind)) in groups.iter().enumerate() {
        let points: Vec<(f64, f64)> = scores
            .iter()
            .filter(|s| s.move_time_s.is_finite())
            .filter(|s| s.candidate.shaper.and_then(|sh| sh.kind) == *kind)
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
        ("default", 0, Marker::Square),
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
