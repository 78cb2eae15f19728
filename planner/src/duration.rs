//! Step 2: a profile of a *given* duration for one axis (for time synchronisation).
//!
//! Jerk limited: after the brake (each stopping time tried in turn, as in
//! `position::to_state`), `fixed` finds the members of each profile case that last the
//! given duration, in closed form, and mixes the highest- and lowest-reaching ones to land
//! on the target (the reachable positions at a fixed duration form an interval, the
//! feasible profiles a convex set). Durations whose interval misses the target cannot be
//! met: Ruckig's *blocked intervals*; every achievable duration is one of the
//! `branch_starts` or lies above one of them. Jerk unlimited: the same with `second_order`.

use crate::brake::BrakeLaw;
use crate::position::{
    How, Planned, Shape, assemble, at_rest_on, finish, hold, pre, validate, verify,
};
use crate::segs::Segs;
use crate::unit::{Scale, Unit};
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
    let b = validate(&start, &target, lim, shape)?;
    if at_rest_on(&start, &target) {
        // Standing still lasts any duration.
        return Ok(vec![0.0]);
    }
    let mut out = Vec::new();
    if b.jmax.is_infinite() {
        let (pre_segs, s) = pre(start, lim, &b);
        let pre_t = pre_segs.duration_s();
        crate::second_order::each_duration(&s, &target, lim, |t| out.push(pre_t + t));
    } else {
        let sc = Scale::new(lim, b.jmax);
        let law = BrakeLaw::new(start, lim, b.jmax);
        for tau in law.candidate_times() {
            let u = Unit::new(&law.state_at(tau, lim), &target, lim, &sc);
            crate::fastest::each_duration(&u, |t| out.push(tau + t * sc.t));
        }
    }
    out.sort_by(f64::total_cmp);
    Ok(out)
}

/// A profile of the problem `plan` solved in step 1 lasting `duration_s` (step 2), or
/// `None` if that duration cannot be met. Without a brake this reuses step 1's normalised
/// problem and cruise changes.
pub(crate) fn lasting(plan: &Planned, duration_s: f64) -> Result<Option<Profile>, PlanError> {
    match &plan.how {
        How::Direct { sc, u, cruises, .. } => {
            let mut segs = Vec::with_capacity(16);
            let mut cruises = *cruises;
            if !crate::fixed::lasting(u, duration_s / sc.t, sc, &mut cruises, &mut segs) {
                return Ok(None);
            }
            verify(finish(plan.start, segs)?, &plan.target, &plan.lim, true).map(Some)
        }
        How::Jerk { .. } => with_duration(
            plan.start,
            plan.target,
            &plan.lim,
            Shape::JerkLimited,
            duration_s,
        ),
        How::Trap(_) => with_duration(
            plan.start,
            plan.target,
            &plan.lim,
            Shape::Trapezoid,
            duration_s,
        ),
        How::Rest => rest_lasting(plan.start, duration_s),
    }
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
    let b = validate(&start, &target, lim, shape)?;
    if at_rest_on(&start, &target) {
        return rest_lasting(start, duration_s);
    }
    let mut segs = Vec::with_capacity(16);
    if b.jmax.is_infinite() {
        let (pre_segs, s) = pre(start, lim, &b);
        let rest = duration_s - pre_segs.duration_s();
        segs.extend_from_slice(pre_segs.as_slice());
        if rest.is_nan()
            || rest < 0.0
            || !crate::second_order::lasting(&s, &target, lim, rest, &mut segs)
        {
            return Ok(None);
        }
        return verify(finish(start, segs)?, &target, lim, true).map(Some);
    }
    let sc = Scale::new(lim, b.jmax);
    if !crate::brake::needed(&start, lim, b.jmax) {
        let u = Unit::new(&start, &target, lim, &sc);
        let mut cruises = crate::fastest::Cruises::default();
        if !crate::fixed::lasting(&u, duration_s / sc.t, &sc, &mut cruises, &mut segs) {
            return Ok(None);
        }
        return verify(finish(start, segs)?, &target, lim, true).map(Some);
    }
    let law = BrakeLaw::new(start, lim, b.jmax);
    for tau in law.candidate_times() {
        let rest = duration_s - tau;
        if rest.is_nan() || rest < 0.0 {
            continue;
        }
        let u = Unit::new(&law.state_at(tau, lim), &target, lim, &sc);
        let (pre_segs, _) = law.until(tau);
        segs.clear();
        segs.extend_from_slice(pre_segs.as_slice());
        let mut cruises = crate::fastest::Cruises::default();
        if crate::fixed::lasting(&u, rest / sc.t, &sc, &mut cruises, &mut segs) {
            return verify(finish(start, segs)?, &target, lim, true).map(Some);
        }
    }
    Ok(None)
}

/// An axis at rest on its target standing still for `duration_s` (`None` for a negative or
/// non-finite duration).
fn rest_lasting(start: State, duration_s: f64) -> Result<Option<Profile>, PlanError> {
    if !(duration_s >= 0.0 && duration_s.is_finite()) {
        return Ok(None);
    }
    Profile::new(start, hold(duration_s)).map(Some)
}

/// Velocity interface, step 2: a velocity change from `start` to `(vf, af)` lasting exactly
/// `duration_s`, or `None`. Shape: two jerk arcs (each rising or falling) through a free
/// level `A`, with the spare time held as a plateau at the start level, at `A` or at the
/// end level. With arc jerks `s1 j`, `s2 j` (`p = 1/(s1 j)`, `q = 1/(s2 j)`) the plateau lasts
/// `H(A) = T + a0 p - af q + (q - p) A`, and the velocity gained,
/// `(A^2 - a0^2) p/2 + (af^2 - A^2) q/2 + L H(A)` with `L` the plateau's level, is a
/// quadratic in `A`: closed form.
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
    let mut pre_segs = Segs::<4>::default();
    let mut s = start;
    if let Some(seg) = fastest.segments().first()
        && (start.a > lim.amax() || start.a < lim.amin())
    {
        pre_segs.push(*seg);
        s = seg.end_state(&start);
    }
    let rest = duration_s - pre_segs.duration_s();
    if rest.is_nan() || rest < 0.0 {
        return Ok(None);
    }
    let a0 = s.a.clamp(lim.amin(), lim.amax());
    let dv = vf - s.v;
    let tol = 1e-12 * rest.max(1e-9);
    let pad = 1e-12 * (lim.amax() - lim.amin());
    for at in [1, 0, 2] {
        for (s1, s2) in [(1.0, -1.0), (-1.0, 1.0), (1.0, 1.0), (-1.0, -1.0)] {
            let (p, q) = (1.0 / (s1 * j), 1.0 / (s2 * j));
            let (h0, h1) = (rest + a0 * p - af * q, q - p);
            let base = 0.5 * (q * af * af - p * a0 * a0) - dv;
            let c = match at {
                1 => [base, h0, 0.5 * (q - p)],
                0 => [base + a0 * h0, a0 * h1, 0.5 * (p - q)],
                _ => [base + af * h0, af * h1, 0.5 * (p - q)],
            };
            let roots = crate::case_poly::case_roots(&c, lim.amin() - pad, lim.amax() + pad);
            for &level in roots.as_slice() {
                let level = level.clamp(lim.amin(), lim.amax());
                let (t1, t3) = ((level - a0) * p, (af - level) * q);
                let hold = rest - t1 - t3;
                if t1 < -tol || t3 < -tol || hold < -tol {
                    continue;
                }
                let h = |k: usize| if k == at { hold.max(0.0) } else { 0.0 };
                let mut body = Segs::<8>::default();
                for (d, jerk) in [
                    (h(0), 0.0),
                    (t1.max(0.0), s1 * j),
                    (h(1), 0.0),
                    (t3.max(0.0), s2 * j),
                    (h(2), 0.0),
                ] {
                    body.push(Segment::Jerk {
                        duration_s: d,
                        jerk,
                    });
                }
                let prof = assemble(start, &[pre_segs.as_slice(), body.as_slice()])?;
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

/// Velocity interface without a jerk limit, step 2: a constant acceleration `dv / T` for
/// the whole duration `T`, then a jump to `af`; `None` if that acceleration is beyond the
/// limits (`T` shorter than the fastest change). Every longer duration is achievable.
pub fn trapezoid_velocity_with_duration(
    start: State,
    vf: f64,
    af: f64,
    lim: &Limits,
    duration_s: f64,
) -> Result<Option<Profile>, PlanError> {
    let fastest = crate::position::to_velocity(start, vf, af, lim, Shape::Trapezoid)?;
    if (fastest.duration_s() - duration_s).abs() <= 1e-12 * duration_s.max(1e-9) {
        return Ok(Some(fastest));
    }
    let longer = duration_s > fastest.duration_s();
    if !longer {
        return Ok(None);
    }
    let a = (vf - start.v) / duration_s;
    if a > lim.amax() || a < lim.amin() {
        return Ok(None);
    }
    let segs = [
        Segment::Accel {
            duration_s,
            accel: a,
        },
        Segment::Accel {
            duration_s: 0.0,
            accel: af,
        },
    ];
    let target = State {
        p: 0.0,
        v: vf,
        a: af,
    };
    verify(assemble(start, &[&segs])?, &target, lim, false).map(Some)
}

/// Velocity interface: every duration at which a range of achievable durations starts
/// (the local optima of `velocity::local_changes`, after any acceleration brake).
pub fn velocity_branch_starts(start: State, vf: f64, af: f64, lim: &Limits) -> Vec<f64> {
    let Some(j) = lim.jmax() else {
        return Vec::new();
    };
    let (mut s, mut pre_t) = (start, 0.0);
    if start.a > lim.amax() || start.a < lim.amin() {
        let to = start.a.clamp(lim.amin(), lim.amax());
        pre_t = (start.a - to).abs() / j;
        let seg = Segment::Jerk {
            duration_s: pre_t,
            jerk: if start.a > to { -j } else { j },
        };
        s = seg.end_state(&start);
        s.a = to;
    }
    let b = Bounds {
        amax: lim.amax(),
        amin: lim.amin(),
        jmax: j,
    };
    crate::velocity::local_changes(s.v, s.a, vf, af, &b)
        .iter()
        .map(|c| pre_t + c.duration_s())
        .collect()
}
