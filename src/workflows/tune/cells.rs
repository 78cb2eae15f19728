//! How one candidate's figures are shown in the report's tables: its shaper, the
//! columns' headings, times in ms, its standing, and a row of a `current / recommended`
//! table.

use std::fmt::Write as _;

use super::search::{Plan, Score};
use crate::studies::scan::ScanSpec;

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

/// Seconds as milliseconds with one decimal, or "not settled".
pub fn ms(x: f64) -> String {
    if x.is_finite() {
        format!("{:.1}", x * 1e3)
    } else {
        "not settled".into()
    }
}

/// A candidate's standing: `ok`, or why it is out.
pub fn status(s: &Score) -> String {
    match &s.infeasible {
        None => "ok".into(),
        Some(why) => format!("out: {}", why.short()),
    }
}

/// The header of a `| | candidate | ... | status |` table of `plan`.
pub fn rows_header(plan: &Plan) -> String {
    let band = plan.base.bands_um[plan.band_index];
    let scored = plan.bands_um[plan.score_band_index];
    let [h_move, h_res, h_score] = headings(plan);
    let h_score = h_score.replace(" (ms)", &format!(" into {scored} um (ms)"));
    format!(
        "| | candidate | accel (mm/s^2) | {h_move} | {h_res} | {h_score} | into {band} um (ms) | status |\n|---|---|---:|---:|---:|---:|---:|---|\n"
    )
}

/// One row of a [`rows_header`] table: the simulated figures (an infeasible candidate's
/// too) and its status.
pub fn row(out: &mut String, tag: &str, s: &Score) {
    let _ = writeln!(
        out,
        "| {tag} | {} | {} | {} | {:.2} | {} | {} | {} |",
        s.candidate.label(),
        s.accel_mm_s2,
        ms(s.move_time_s),
        s.residual_peak_um,
        ms(s.simulated_move_and_settle_s),
        ms(s.at_band_s),
        status(s)
    );
}
