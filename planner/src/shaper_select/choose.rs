//! Klipper's recommendation across shapers (`find_best_shaper`).

use super::data::CalibrationData;
use super::fit::fit_shaper;
use super::options::{Fit, SelectOptions, Selection};
use crate::PlanError;
use crate::shaper::ShaperType;

/// Klipper's shaper choice on `data` (one or more data sets, e.g. several test points):
/// every shaper of `opts.shapers` fitted, and the one Klipper recommends.
pub fn find_best_shaper(
    data: &[CalibrationData],
    opts: &SelectOptions,
) -> Result<Selection, PlanError> {
    let mut best: Option<Fit> = None;
    let mut per_shaper = Vec::with_capacity(opts.shapers.len());
    for &kind in &opts.shapers {
        let (mut shaper, results) = fit_shaper(kind, data, opts)?;
        let b = match best {
            Some(b)
                if !(shaper.score * 1.2 < b.score
                    || (shaper.score * 1.05 < b.score
                        && shaper.smoothing_mm * 1.1 < b.smoothing_mm)
                    || opts
                        .max_vibrations
                        .is_some_and(|m| b.vibrations > m && shaper.vibrations < b.vibrations)) =>
            {
                b
            }
            // Either the shaper improves the score by 20%, or the score by 5% and the
            // smoothing by 10%, or the previous pick vibrated too much and this one less.
            _ => shaper,
        };
        let mut b = b;
        for s in results.iter().rev() {
            if s.vibrations < b.vibrations && s.smoothing_mm < b.smoothing_mm {
                b = *s;
                shaper = *s;
            }
        }
        best = Some(b);
        per_shaper.push(shaper);
    }
    let Some(mut recommended) = best else {
        return Err(PlanError::InvalidInput {
            reason: "Klipper's shaper choice needs at least one shaper to try",
        });
    };
    if recommended.shaper_type == ShaperType::Zv
        && let Some(other) = per_shaper.iter().find(|s| {
            s.shaper_type != ShaperType::Zv && s.vibrations * 1.1 < recommended.vibrations
        })
    {
        recommended = *other;
    }
    Ok(Selection {
        recommended,
        per_shaper,
    })
}
