//! The head of the `settle tune` report: the machine it ran on (and a warning when a
//! built-in preset stands in for the user's printer), "your current settings ->
//! recommended" per axis, and what changes in each export written.

use std::fmt::Write as _;

use super::Outcome;
use super::cells::{ms, shaper_text};
use super::report::gain_text;
use super::search::BandSource;

/// The warning when the machine is a built-in preset while the scenario holds a printer's
/// current settings (`settle import` without `--machine`): every number is the preset's.
pub fn stand_in(axes: &[(String, Outcome)]) -> Option<String> {
    let (_, o) = axes.first()?;
    let preset = o.plan.builtin_preset.as_ref()?;
    o.plan.spec.axis.as_ref()?;
    Some(format!(
        "These values are for the built-in preset `{preset}`, which stands in for your printer (no machine file was given to settle import): measure your printer's modes (settle identify) and import again with --machine."
    ))
}

/// The head's table: per axis, the current settings and the recommendation, with
/// smoothing, max_accel, the simulated move-and-settle and the standing or the gain.
pub fn current_to_recommended(axes: &[(String, Outcome)], joint: Option<&str>) -> String {
    let mut out = String::new();
    if let Some(w) = stand_in(axes) {
        let _ = writeln!(out, "**Stand-in machine.** {w}\n");
    }
    out.push_str("## Your current settings -> recommended\n\n");
    let Some((_, first)) = axes.first() else {
        return out;
    };
    let p = &first.plan;
    let _ = writeln!(
        out,
        "Firmware: {}. Score: {}. Shaped candidates smoothing more than {} mm at their acceleration (Klipper's figure at 5 mm/s) are out{}.\n",
        p.firmware.name(),
        super::report::score_text(p),
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
    if let Some(j) = joint {
        let _ = writeln!(out, "{j}\n");
    }
    let _ = writeln!(
        out,
        "| axis | | profile | shaper | accel (mm/s^2) | smoothing (mm) | max_accel (mm/s^2) | move+settle (ms) | standing or gain |"
    );
    let _ = writeln!(out, "|---|---|---|---|---:|---:|---:|---:|---|");
    for (axis, o) in axes {
        let (c, w) = (&o.scores[0], &o.scores[o.winner]);
        let current = match &c.infeasible {
            Some(why) => format!("out: {}", why.short()),
            None => String::new(),
        };
        let gain = gain_text(&o.plan, c, w);
        for (tag, s, g) in [("current", c, current), ("**recommended**", w, gain)] {
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
    out.push('\n');
    out
}
