//! The optional paragraphs of an axis's section: the refinement around the grid winner
//! and the re-check on a second backend.

use std::fmt::Write as _;

use super::cells::{headings, ms, row, rows_header};
use super::{Outcome, rank};

/// The refinement paragraph of the report: the grid winner, how many candidates the
/// refinement evaluated, and what it gained.
pub fn refine_text(o: &Outcome) -> String {
    let extra = o.scores.len() - o.plan.candidates.len();
    if o.plan
        .spec
        .refine_rounds
        .unwrap_or(rank::DEFAULT_REFINE_ROUNDS)
        == 0
    {
        return String::new();
    }
    let (g, w) = (&o.scores[o.grid_winner], &o.scores[o.winner]);
    let [_, _, h_score] = headings(&o.plan);
    let mut out = format!(
        "\n### Refinement around the grid winner\n\n{} grid candidates, then {} rounds around the grid winner ({extra} more candidates). ",
        o.plan.candidates.len(),
        o.plan
            .spec
            .refine_rounds
            .unwrap_or(rank::DEFAULT_REFINE_ROUNDS),
    );
    if o.winner == o.grid_winner {
        let _ = writeln!(
            out,
            "The grid winner {} stays the winner.",
            g.candidate.label()
        );
    } else {
        let _ = writeln!(
            out,
            "Grid winner {}: {} {:.2} ms; refined {}: {:.2} ms ({:.2} ms better).",
            g.candidate.label(),
            h_score.trim_end_matches(" (ms)"),
            g.move_and_settle_s * 1e3,
            w.candidate.label(),
            w.move_and_settle_s * 1e3,
            (g.move_and_settle_s - w.move_and_settle_s) * 1e3
        );
    }
    out
}

/// The second-backend paragraph of the report.
pub fn check_text(o: &Outcome) -> String {
    let Some((b, d, w)) = &o.check else {
        return String::new();
    };
    let plan = &o.plan;
    let band = plan.base.bands_um[plan.band_index];
    let mut out = String::new();
    let _ = writeln!(out, "\n### Checked on a second backend: {b}\n");
    out.push_str(&rows_header(plan));
    row(&mut out, "current", d);
    row(&mut out, "recommended", w);
    let verdict = if w.move_and_settle_s < d.simulated_move_and_settle_s {
        format!(
            "the recommendation still beats the current settings on {b}: {:.1}% better",
            100.0 * (1.0 - w.move_and_settle_s / d.simulated_move_and_settle_s)
        )
    } else {
        format!("the recommendation does NOT beat the current settings on {b}")
    };
    let _ = writeln!(out, "\nVerdict: {verdict}.");
    let searched = &o.scores[o.winner];
    let _ = writeln!(
        out,
        "Into the {band} um band the recommendation takes {} ms on {b} ({} ms on {}, {}).",
        ms(w.at_band_s),
        ms(searched.at_band_s),
        plan.base.backend,
        if w.at_band_s <= searched.at_band_s + 1.0 / plan.base.sample_rate_hz {
            "confirmed within one sample"
        } else {
            "later than predicted: consider a smaller [tune] margin"
        }
    );
    out
}
