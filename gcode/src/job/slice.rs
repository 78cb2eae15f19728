//! Cutting a trajectory at an instant (where a shaper change takes effect).

use settle_planner::shaper::stream::cut;
use settle_planner::{PlanError, Trajectory};

/// A part of a cut trajectory with its start time (`None`: empty).
pub(crate) type Part = Option<(f64, Trajectory)>;

/// Cut `tr`, which starts at `start_s`, at `at_s`: the parts before and after.
pub(crate) fn split(start_s: f64, tr: &Trajectory, at_s: f64) -> Result<(Part, Part), PlanError> {
    let d = tr.duration_s();
    let at = at_s - start_s;
    if at <= 0.0 {
        return Ok((None, Some((start_s, tr.clone()))));
    }
    if at >= d {
        return Ok((Some((start_s, tr.clone())), None));
    }
    let part = |a: f64, b: f64| -> Result<Trajectory, PlanError> {
        Trajectory::new(
            tr.axes()
                .iter()
                .map(|p| cut(p, a, b))
                .collect::<Result<Vec<_>, _>>()?,
        )
    };
    Ok((
        Some((start_s, part(0.0, at)?)),
        Some((start_s + at, part(at, d)?)),
    ))
}
