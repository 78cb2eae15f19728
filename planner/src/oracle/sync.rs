//! Oracle (test only): time synchronisation without the closed-form step 2 (all branch
//! starts computed up front, each duration tried with the bracketing step 2).

use super::duration::{branch_starts, with_duration};
use super::peak::to_state;
use crate::position::Shape;
use crate::sync::Axis;
use crate::{PlanError, Profile};

/// Every axis's fastest profile, then all fitted to the slowest (time synchronisation).
pub fn plan_time(axes: &[Axis], shape: Shape) -> Result<Vec<Profile>, PlanError> {
    let fastest: Vec<Profile> = axes
        .iter()
        .enumerate()
        .map(|(i, a)| {
            to_state(a.start, a.target, &a.limits, shape).map_err(|e| PlanError::OnAxis {
                axis: i,
                source: Box::new(e),
            })
        })
        .collect::<Result<_, _>>()?;
    let t_min = fastest.iter().map(Profile::duration_s).fold(0.0, f64::max);
    let mut candidates = vec![t_min];
    for a in axes {
        candidates.extend(
            branch_starts(a.start, a.target, &a.limits, shape)?
                .into_iter()
                .filter(|t| *t > t_min),
        );
    }
    candidates.sort_by(f64::total_cmp);
    candidates.dedup();
    for t in candidates {
        let mut out = Vec::with_capacity(axes.len());
        for (a, f) in axes.iter().zip(&fastest) {
            if (f.duration_s() - t).abs() <= 1e-12 * t.max(1e-9) {
                out.push(f.clone());
            } else if let Some(p) = with_duration(a.start, a.target, &a.limits, shape, t)? {
                out.push(p);
            } else {
                break;
            }
        }
        if out.len() == axes.len() {
            return Ok(out);
        }
    }
    Err(PlanError::NoSolution {
        reason: "no common duration found for time synchronisation",
    })
}
