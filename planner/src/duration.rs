//! Step 2: a profile of a *given* duration for one axis (for time synchronisation).
//!
//! Longer than the fastest profile, the peak-velocity family stretches: with peak `vp` and
//! cruise `(dp - D(vp))/vp >= 0` the total time `T(vp) + (dp - D(vp))/vp` falls
//! monotonically as `|vp|` grows (its derivative is `-cruise/vp`), so on each side of zero
//! every duration from the branch's fastest one to infinity is met by exactly one `vp`,
//! found by bracketing and bisection. Durations between the fastest profile and the start
//! of a branch that reaches them cannot be met: Ruckig's *blocked intervals*. A move that
//! starts and ends at rest on the spot is a hold.

use crate::position::{
    PeakFamily, Shape, assemble, bounds, candidates, check_target, finite_state, pre,
};
use crate::roots::roots;
use crate::{Limits, PlanError, Profile, Segment, State};

/// Every duration at which some branch of achievable durations starts (sorted): the
/// fastest profile's and the other local optima's. Every achievable duration is one of
/// these or lies above one of them.
pub fn branch_starts(
    start: State,
    target: State,
    lim: &Limits,
    shape: Shape,
) -> Result<Vec<f64>, PlanError> {
    let (pre_t, s, b) = prepare(start, target, lim, shape)?;
    let mut out: Vec<f64> = candidates(&s, &target, lim, &b)
        .into_iter()
        .map(|(t, _)| pre_t + t)
        .collect();
    out.sort_by(f64::total_cmp);
    Ok(out)
}

fn prepare(
    start: State,
    target: State,
    lim: &Limits,
    shape: Shape,
) -> Result<(f64, State, crate::velocity::Bounds), PlanError> {
    finite_state("start", &start)?;
    finite_state("target", &target)?;
    let b = bounds(lim, shape)?;
    check_target(&target, lim, &b)?;
    let (pre_segs, mut s) = pre(start, lim, &b);
    s.a = s.a.clamp(lim.amin(), lim.amax());
    Ok((pre_segs.iter().map(Segment::duration_s).sum(), s, b))
}

/// A profile from `start` to `target` lasting exactly `duration_s`, or `None` if that
/// duration is shorter than the fastest profile or inside a blocked interval.
pub fn with_duration(
    start: State,
    target: State,
    lim: &Limits,
    shape: Shape,
    duration_s: f64,
) -> Result<Option<Profile>, PlanError> {
    let (_, _, b) = prepare(start, target, lim, shape)?;
    let (pre_segs, mut s) = pre(start, lim, &b);
    s.a = s.a.clamp(lim.amin(), lim.amax());
    let rest = duration_s - pre_segs.iter().map(Segment::duration_s).sum::<f64>();
    if rest.is_nan() || rest < 0.0 {
        return Ok(None);
    }
    let tol = 1e-12 * rest.max(1e-9);
    // A local optimum of exactly this duration.
    if let Some((_, segs)) = candidates(&s, &target, lim, &b)
        .into_iter()
        .find(|(t, _)| (t - rest).abs() <= tol)
    {
        return assemble(start, pre_segs, &[&segs]).map(Some);
    }
    let fam = PeakFamily::new(s, target, lim, b);
    let dp = fam.dp();
    // On the spot: both phases at vp = 0 cover dp exactly, so cruise at zero speed.
    if let Some((_, _, d, t)) = fam.phases(0.0) {
        let scale = dp.abs().max(d.abs()).max(1e-300);
        if (d - dp).abs() <= 1e-12 * scale
            && t <= rest
            && let Some(segs) = fam.segments(0.0, rest - t)
        {
            return assemble(start, pre_segs, &[&segs]).map(Some);
        }
    }
    let total = |vp: f64| -> Option<f64> {
        let (_, _, d, t) = fam.phases(vp)?;
        let cruise = (dp - d) / vp;
        (cruise >= 0.0 && cruise.is_finite()).then_some(t + cruise - rest)
    };
    let mut knots = fam.knots();
    let tiny = 1e-12 * lim.vmax().max(-lim.vmin());
    knots.retain(|v| v.abs() > tiny);
    knots.extend([tiny, -tiny]);
    knots.sort_by(f64::total_cmp);
    let mut found: Vec<f64> = Vec::new();
    for side in [1.0, -1.0] {
        let branch: Vec<f64> = knots
            .iter()
            .copied()
            .filter(|v| v.signum() == side)
            .collect();
        found.extend(roots(&total, &branch));
    }
    // Prefer the fastest peak (least cruise) in the direction of the move.
    found.sort_by(|x, y| y.abs().total_cmp(&x.abs()));
    for vp in found {
        let Some((_, _, d, _)) = fam.phases(vp) else {
            continue;
        };
        let cruise = (dp - d) / vp;
        if let Some(segs) = fam.segments(vp, cruise.max(0.0)) {
            let prof = assemble(start, pre_segs.clone(), &[&segs])?;
            if (prof.duration_s() - duration_s).abs() <= 1e-9 * duration_s.max(1e-9) {
                return Ok(Some(prof));
            }
        }
    }
    Ok(None)
}
