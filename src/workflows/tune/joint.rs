//! One acceleration for every axis: Klipper (`[printer] max_accel`), RepRapFirmware and
//! Marlin (`M204 P`) move every axis at the same acceleration, so a recommendation for
//! several axes must share it. Each axis's search scores its candidates at every
//! acceleration of the grid; the common acceleration is the one with the least
//! move-and-settle summed over the axes (each axis's best feasible candidate at it), and
//! each axis's recommendation is its best there.

use std::fmt::Write as _;

use super::Outcome;
use super::rank;

/// Make the axes' recommendations share one acceleration (see the module documentation).
/// Where an axis's own best moved, its [`Outcome::alone`] keeps it. Returns the sentence
/// the report gives, or `None` when the axes already agree (or there is one axis).
pub fn share_acceleration(axes: &mut [(String, Outcome)]) -> Option<String> {
    if axes.len() < 2 {
        return None;
    }
    let accel_of = |o: &Outcome| o.scores[o.winner].accel_mm_s2;
    let first = accel_of(&axes[0].1);
    if axes.iter().all(|(_, o)| accel_of(o) == first) {
        return None;
    }
    // Every acceleration some axis has a feasible candidate at, in increasing order.
    let mut accels: Vec<f64> = axes
        .iter()
        .flat_map(|(_, o)| o.scores.iter().filter(|s| s.is_feasible()))
        .map(|s| s.accel_mm_s2)
        .collect();
    accels.sort_by(f64::total_cmp);
    accels.dedup();
    let best_at = |o: &Outcome, a: f64| {
        let masked: Vec<_> = o
            .scores
            .iter()
            .map(|s| {
                let mut s = s.clone();
                if s.accel_mm_s2 != a {
                    s.move_and_settle_s = f64::INFINITY;
                }
                s
            })
            .collect();
        rank::best(&masked)
    };
    let mut pick: Option<(f64, f64, Vec<usize>)> = None;
    for &a in &accels {
        let Some(winners) = axes
            .iter()
            .map(|(_, o)| best_at(o, a))
            .collect::<Option<Vec<usize>>>()
        else {
            continue;
        };
        let total: f64 = axes
            .iter()
            .zip(&winners)
            .map(|((_, o), &i)| o.scores[i].move_and_settle_s)
            .sum();
        if pick.as_ref().is_none_or(|p| total < p.1) {
            pick = Some((a, total, winners));
        }
    }
    let (a, _, winners) = pick?;
    let mut text = format!(
        "One acceleration for every axis (the firmware has one): {a} mm/s^2, the least move-and-settle summed over the axes."
    );
    for ((axis, o), w) in axes.iter_mut().zip(winners) {
        if w != o.winner {
            let own = &o.scores[o.winner];
            let _ = write!(
                text,
                " Alone, axis {axis} would take {} at {} mm/s^2 ({:.1} ms); at {a} mm/s^2 its best is {} ({:.1} ms).",
                own.candidate.label(),
                own.accel_mm_s2,
                own.move_and_settle_s * 1e3,
                o.scores[w].candidate.label(),
                o.scores[w].move_and_settle_s * 1e3
            );
            o.alone = Some(o.winner);
            o.winner = w;
        }
    }
    Some(text)
}
