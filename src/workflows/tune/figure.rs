//! The Pareto figure of one tuned axis: every feasible candidate coloured by its shaper,
//! the candidates out of the running in grey by why they are out, the Pareto front of the
//! feasible ones, the current settings and the recommendation.

use plotters::style::RGBColor;

use super::Outcome;
use super::cells::headings;
use super::search::Score;
use crate::output::plot::{Figure, Line, Marker, PALETTE, Panel};
use settle_planner::shaper::ShaperType;

/// Greys of the groups out of the running, in order of first appearance.
const GREYS: [RGBColor; 5] = [
    RGBColor(0x9a, 0x9a, 0x9a),
    RGBColor(0xc0, 0xc0, 0xc0),
    RGBColor(0x70, 0x70, 0x70),
    RGBColor(0xb0, 0xa0, 0x90),
    RGBColor(0x80, 0x90, 0xa0),
];

/// The figure of axis `axis` of the scenario `name`.
pub fn pareto_figure(name: &str, axis: &str, o: &Outcome) -> Figure {
    let (plan, scores) = (&o.plan, &o.scores);
    let [h_move, h_res, _] = headings(plan);
    let pt = |s: &Score| (s.move_time_s * 1e3, s.residual_peak_um.max(1e-3));
    let drawable = |s: &&Score| s.move_time_s.is_finite() && s.residual_peak_um.is_finite();
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
            .filter(drawable)
            .filter(|s| s.is_feasible())
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
    let mut out_groups: Vec<&'static str> = Vec::new();
    for s in scores {
        if let Some(why) = &s.infeasible
            && !out_groups.contains(&why.group())
        {
            out_groups.push(why.group());
        }
    }
    for (gi, group) in out_groups.iter().enumerate() {
        let points: Vec<(f64, f64)> = scores
            .iter()
            .filter(drawable)
            .filter(|s| s.infeasible.as_ref().is_some_and(|w| w.group() == *group))
            .map(pt)
            .collect();
        if points.is_empty() {
            continue;
        }
        let mut l = Line::new(Some(group.to_string()), GREYS[gi % GREYS.len()], points);
        l.width = 0;
        l.marker = Some(Marker::Cross);
        lines.push(l);
    }
    let mut f = Line::new(
        Some("Pareto front (feasible)".into()),
        RGBColor(0, 0, 0),
        o.front.iter().map(|&i| pt(&scores[i])).collect(),
    );
    f.width = 2;
    lines.push(f);
    for (label, i, marker) in [
        ("current", 0, Marker::Square),
        ("recommended", o.winner, Marker::Triangle),
    ] {
        let s = &scores[i];
        if !drawable(&s) {
            continue;
        }
        let out = s
            .infeasible
            .as_ref()
            .map_or(String::new(), |w| format!(" (out: {})", w.short()));
        let mut l = Line::new(
            Some(format!("{label}: {}{out}", s.candidate.label())),
            RGBColor(0xd6, 0x27, 0x28),
            vec![pt(s)],
        );
        l.marker = Some(marker);
        l.width = 0;
        lines.push(l);
    }
    Figure {
        title: format!(
            "settle tune {name}, axis {axis}: {} vs {}",
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
