//! Ranking and refining candidates of `settle tune`: evaluate them (all runs in one
//! parallel batch), the best, the Pareto front, and the compass search around the grid
//! winner.

use crate::error::Error;
use crate::execute::pool::{Progress, quiet, run_all};
use crate::studies::shaping::ShaperSetting;
use crate::workflows::tune::search::{Candidate, Plan, Score};

/// Default rounds of refinement around the grid winner: 0 (grid only). Each round looks
/// at up to 8 neighbours (the shaper frequency +-1 and +-2 steps, the jerk likewise), the
/// step halving each round from half the grid's spacing, so 4 rounds resolve the frequency
/// to ~0.3% for ~1% of the grid's cost. Off by default because on the shipped scenarios it
/// gained 0.02-0.4 ms and, by pushing the shaper frequency up until the residual touches
/// the scored band, gave back the robustness the margin buys (tune_corner: rapier settles
/// the refined winner 4.9 ms later than modal predicted; the grid winner on time).
pub const DEFAULT_REFINE_ROUNDS: usize = 0;

/// Index of the best feasible score: lowest move-and-settle, then lowest residual
/// (candidates that are inside the band when their move ends tie on move-and-settle); the
/// first among equals.
pub fn best(scores: &[Score]) -> Option<usize> {
    let mut best: Option<usize> = None;
    for (i, s) in scores.iter().enumerate() {
        let better = |b: &Score| {
            s.move_and_settle_s < b.move_and_settle_s
                || (s.move_and_settle_s == b.move_and_settle_s
                    && s.residual_peak_um < b.residual_peak_um)
        };
        if s.is_feasible()
            && s.move_and_settle_s.is_finite()
            && best.is_none_or(|b| better(&scores[b]))
        {
            best = Some(i);
        }
    }
    best
}

/// Indices of the Pareto front of (move time, residual peak) among the feasible
/// candidates: no other feasible candidate is at least as good in both and better in one.
/// Sorted by move time.
pub fn pareto(scores: &[Score]) -> Vec<usize> {
    let ok: Vec<usize> = (0..scores.len())
        .filter(|&i| {
            scores[i].is_feasible()
                && scores[i].move_time_s.is_finite()
                && scores[i].residual_peak_um.is_finite()
        })
        .collect();
    let mut idx: Vec<usize> = ok
        .iter()
        .copied()
        .filter(|&i| {
            let a = &scores[i];
            !ok.iter().any(|&j| {
                let b = &scores[j];
                b.move_time_s <= a.move_time_s
                    && b.residual_peak_um <= a.residual_peak_um
                    && (b.move_time_s < a.move_time_s || b.residual_peak_um < a.residual_peak_um)
            })
        })
        .collect();
    idx.sort_by(|&a, &b| scores[a].move_time_s.total_cmp(&scores[b].move_time_s));
    idx.dedup_by(|a, b| {
        scores[*a].move_time_s == scores[*b].move_time_s
            && scores[*a].residual_peak_um == scores[*b].residual_peak_um
    });
    idx
}

/// Evaluate every candidate of `plan` (all runs in one parallel batch, reporting to
/// `progress`).
pub fn evaluate(
    plan: &Plan,
    candidates: &[Candidate],
    jobs: Option<usize>,
    progress: Progress,
) -> Result<Vec<Score>, Error> {
    let runs = plan.runs(candidates);
    let results = run_all(&runs, jobs, progress)?;
    Ok(plan.scores(candidates, &results))
}

/// The neighbours of `c` one refinement round looks at: the shaper frequency times
/// `1 +- k df` and the jerk times `jr^+-k` (k = 1, 2), never above the scenario's jerk limit
/// `jmax` (a trapezoid has no jerk; an unshaped candidate no frequency).
pub fn neighbours(c: &Candidate, df: f64, jr: f64, jmax: f64) -> Vec<Candidate> {
    let mut out = Vec::new();
    if let Some(sh) = c.shaper.filter(|s| s.shaper_type.is_some()) {
        for k in [-2.0, -1.0, 1.0, 2.0] {
            let f = sh.frequency_hz * (1.0 + k * df);
            if f > 0.0 {
                out.push(Candidate {
                    shaper: Some(ShaperSetting {
                        frequency_hz: f,
                        ..sh
                    }),
                    ..*c
                });
            }
        }
    }
    if let Some(j) = c.jmax_mm_s3 {
        for k in [-2, -1, 1, 2] {
            let jj = j * jr.powi(k);
            if jj <= jmax * (1.0 + 1e-12) {
                out.push(Candidate {
                    jmax_mm_s3: Some(jj.min(jmax)),
                    ..*c
                });
            }
        }
    }
    out
}

/// Refine around the grid winner: `rounds` rounds of [`neighbours`] of the current best,
/// the steps halving each round (from half the grid's frequency and jerk spacing). The
/// evaluated candidates are appended to `scores`; returns the index of the final winner
/// (the grid winner when nothing beats it: [`best`] keeps the first among equals).
pub fn refine(
    plan: &Plan,
    scores: &mut Vec<Score>,
    grid_winner: usize,
    jobs: Option<usize>,
) -> Result<usize, Error> {
    let rounds = plan.spec.refine_rounds.unwrap_or(DEFAULT_REFINE_ROUNDS);
    let jmax = plan.base.jmax_mm_s3.unwrap_or(f64::INFINITY);
    let steps = plan.spec.jerk_steps.unwrap_or(6).max(2);
    let span = plan.spec.jerk_span.unwrap_or(30.0);
    let mut df = 0.025;
    let mut jr = span.powf(0.5 / (steps - 1) as f64).max(1.0 + 1e-3);
    let mut winner = grid_winner;
    for _ in 0..rounds {
        let c = scores[winner].candidate;
        // Never a frequency the firmware would clamp.
        let takes = |n: &Candidate| {
            n.shaper
                .filter(|s| s.shaper_type.is_some())
                .is_none_or(|s| plan.firmware.takes_frequency(s.frequency_hz))
        };
        let next: Vec<Candidate> = neighbours(&c, df, jr, jmax)
            .into_iter()
            .filter(|n| takes(n) && !scores.iter().any(|s| s.candidate == *n))
            .collect();
        if !next.is_empty() {
            let found = evaluate(plan, &next, jobs, &quiet)?;
            scores.extend(found);
            winner = best(scores).unwrap_or(winner);
        }
        df *= 0.5;
        jr = jr.sqrt();
    }
    Ok(winner)
}
