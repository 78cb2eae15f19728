//! Oracle (test only): a bracketing implementation of step 2, to check the closed forms of
//! `fixed`.
//!
//! Longer than the fastest profile, the peak-velocity family stretches: with peak `vp` and
//! cruise `(dp - D(vp))/vp >= 0` the total time `T(vp) + (dp - D(vp))/vp` falls
//! monotonically as `|vp|` grows (its derivative is `-cruise/vp`), so on each side of zero
//! every duration from the branch's fastest one to infinity is met by exactly one `vp`,
//! found by bracketing and bisection. Durations between the fastest profile and the start
//! of a branch that reaches them cannot be met: Ruckig's *blocked intervals*. A move that
//! starts and ends at rest on the spot is a hold.

use super::peak::{PeakFamily, candidates};
use super::roots::roots;
use crate::brake::BrakeLaw;
use crate::position::{Shape, assemble, bounds, check_target, finite_state, pre, verify};
use crate::velocity::Bounds;
use crate::{Limits, PlanError, Profile, Segment, State};

/// Every duration at which some branch of achievable durations starts (sorted): the
/// fastest profile's and the other local optima's, for every brake stopping time tried.
/// Every achievable duration is one of these or lies above one of them.
pub fn branch_starts(
    start: State,
    target: State,
    lim: &Limits,
    shape: Shape,
) -> Result<Vec<f64>, PlanError> {
    let b = prepare(target, start, lim, shape)?;
    let mut out = Vec::new();
    for (pre_segs, s) in brakes(start, lim, &b) {
        let pre_t: f64 = pre_segs.iter().map(Segment::duration_s).sum();
        out.extend(
            candidates(&s, &target, lim, &b)
                .into_iter()
                .map(|(t, _)| pre_t + t),
        );
    }
    out.sort_by(f64::total_cmp);
    Ok(out)
}

fn prepare(target: State, start: State, lim: &Limits, shape: Shape) -> Result<Bounds, PlanError> {
    finite_state("start", &start)?;
    finite_state("target", &target)?;
    let b = bounds(lim, shape)?;
    check_target(&target, lim, &b)?;
    Ok(b)
}

/// The brake pre-trajectories to try (see `position::to_state`), each with its end state.
fn brakes(start: State, lim: &Limits, b: &Bounds) -> Vec<(Vec<Segment>, State)> {
    let snap = |(segs, mut s): (crate::segs::Segs<4>, State)| {
        s.a = s.a.clamp(lim.amin(), lim.amax());
        (segs.as_slice().to_vec(), s)
    };
    if b.jmax.is_infinite() {
        return vec![snap(pre(start, lim, b))];
    }
    let law = BrakeLaw::new(start, lim, b.jmax);
    law.candidate_times()
        .map(|tau| snap(law.until(tau)))
        .collect()
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
    let b = prepare(target, start, lim, shape)?;
    for (pre_segs, s) in brakes(start, lim, &b) {
        if let Some(p) = from_brake(start, pre_segs, s, target, lim, b, duration_s)? {
            return verify(p, &target, lim, true).map(Some);
        }
    }
    Ok(None)
}

/// `with_duration` after a given brake.
fn from_brake(
    start: State,
    pre_segs: Vec<Segment>,
    s: State,
    target: State,
    lim: &Limits,
    b: Bounds,
    duration_s: f64,
) -> Result<Option<Profile>, PlanError> {
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
        return assemble(start, &[&pre_segs, &segs]).map(Some);
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
            return assemble(start, &[&pre_segs, &segs]).map(Some);
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
    // Three arcs with a plateau at a free level.
    if b.jmax.is_finite() {
        let mut shapes = super::stretch::held_three_arc(&s, &target, lim, &b, rest);
        shapes.extend(super::stretch::four_arc(&s, &target, lim, &b, rest));
        for segs in shapes {
            let prof = assemble(start, &[&pre_segs, &segs])?;
            let e = prof.end();
            let ok_p = (e.p - target.p).abs() <= 1e-9 * target.p.abs().max(dp.abs()).max(1.0);
            if ok_p && (prof.duration_s() - duration_s).abs() <= 1e-9 * duration_s.max(1e-9) {
                return Ok(Some(prof));
            }
        }
    }
    // Prefer the fastest peak (least cruise) in the direction of the move.
    found.sort_by(|x, y| y.abs().total_cmp(&x.abs()));
    for vp in found {
        let Some((_, _, d, _)) = fam.phases(vp) else {
            continue;
        };
        let cruise = (dp - d) / vp;
        if let Some(segs) = fam.segments(vp, cruise.max(0.0)) {
            let prof = assemble(start, &[&pre_segs, &segs])?;
            if (prof.duration_s() - duration_s).abs() <= 1e-9 * duration_s.max(1e-9) {
                return Ok(Some(prof));
            }
        }
    }
    Ok(None)
}

/// Velocity interface, step 2: a velocity change from `start` to `(vf, af)` lasting exactly
/// `duration_s`, or `None`. Shape: two jerk arcs (each rising or falling) through a free
/// level, with the spare time held as a plateau at the start level, the free level or the
/// end level.
pub fn velocity_with_duration(
    start: State,
    vf: f64,
    af: f64,
    lim: &Limits,
    duration_s: f64,
) -> Result<Option<Profile>, PlanError> {
    let fastest = crate::position::to_velocity(start, vf, af, lim, Shape::JerkLimited)?;
    if (fastest.duration_s() - duration_s).abs() <= 1e-12 * duration_s.max(1e-9) {
        return Ok(Some(fastest));
    }
    let j = lim.jmax().ok_or(PlanError::MissingJerkLimit {
        kind: "jerk-limited",
    })?;
    // Any acceleration brake first (as in `to_velocity`).
    let (pre_segs, s) = match fastest.segments().first() {
        Some(seg) if start.a > lim.amax() || start.a < lim.amin() => {
            (vec![*seg], seg.end_state(&start))
        }
        _ => (Vec::new(), start),
    };
    let rest = duration_s - pre_segs.iter().map(Segment::duration_s).sum::<f64>();
    if rest.is_nan() || rest < 0.0 {
        return Ok(None);
    }
    let a0 = s.a.clamp(lim.amin(), lim.amax());
    // Template: jerk s1 j to a level A, jerk s2 j on to af, and the remaining time held as
    // a plateau at the start level a0, at A, or at the end level af. For each choice the
    // velocity change is a function of A alone; its roots are bracketed and bisected.
    let tol = 1e-12 * rest.max(1e-9);
    let build = |level: f64, s1: f64, s2: f64, at: usize| -> Option<[Segment; 5]> {
        let (t1, t3) = ((level - a0) / (s1 * j), (af - level) / (s2 * j));
        let hold = rest - t1 - t3;
        if t1 < -tol || t3 < -tol || hold < -tol {
            return None;
        }
        let h = |k: usize| if k == at { hold.max(0.0) } else { 0.0 };
        Some([
            Segment::Jerk {
                duration_s: h(0),
                jerk: 0.0,
            },
            Segment::Jerk {
                duration_s: t1.max(0.0),
                jerk: s1 * j,
            },
            Segment::Jerk {
                duration_s: h(1),
                jerk: 0.0,
            },
            Segment::Jerk {
                duration_s: t3.max(0.0),
                jerk: s2 * j,
            },
            Segment::Jerk {
                duration_s: h(2),
                jerk: 0.0,
            },
        ])
    };
    let s0 = State {
        p: 0.0,
        v: s.v,
        a: a0,
    };
    for at in [1, 0, 2] {
        for (s1, s2) in [(1.0, -1.0), (-1.0, 1.0), (1.0, 1.0), (-1.0, -1.0)] {
            let g = |level: f64| {
                let segs = build(level, s1, s2, at)?;
                let mut st = s0;
                for sg in &segs {
                    st = sg.end_state(&st);
                }
                Some(st.v - vf)
            };
            let mut knots = vec![lim.amin(), lim.amax(), a0, af];
            knots.sort_by(f64::total_cmp);
            knots.dedup();
            for level in roots(&g, &knots) {
                let Some(segs) = build(level, s1, s2, at) else {
                    continue;
                };
                let prof = assemble(start, &[&pre_segs, &segs])?;
                let e = prof.end();
                let ok = (e.v - vf).abs() <= 1e-9 * vf.abs().max(1.0)
                    && (e.a - af).abs() <= 1e-9 * lim.amax()
                    && (prof.duration_s() - duration_s).abs() <= 1e-9 * duration_s.max(1e-9);
                if ok {
                    return Ok(Some(prof));
                }
            }
        }
    }
    Ok(None)
}
