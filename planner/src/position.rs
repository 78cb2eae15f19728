//! Time-optimal profiles from any state `(p0, v0, a0)` to any target `(pf, vf, af)`
//! (the position interface), and to a velocity and acceleration (the velocity interface).
//!
//! Step 0 brakes a start state that violates, or must violate, the limits (see `brake`).
//! From the safe state the candidates are the cases of Haschke, Weitnauer, Ritter, "On-Line
//! Planning of Time-Optimal, Jerk-Limited Trajectories" (IROS 2008) in the form Ruckig
//! gives them (Berscheid, Kröger, "Jerk-limited Real-time Trajectory Generation with
//! Arbitrary Target States", RSS 2021; see `fastest` and `udu`): the cruise at `vmax` or
//! `vmin` between two time-optimal velocity changes, or three jerk arcs (UDU or DUD) with
//! holds at the acceleration limits, each case a closed-form polynomial whose valid root is
//! picked among spurious ones by checking the profile. The fastest candidate is the
//! time-optimal profile.
//!
//! An independent bracketing implementation is kept as a test-only oracle
//! (`oracle::peak`), and a property test checks that both give the same durations.

use crate::brake::{BrakeLaw, brake};
use crate::fastest::Cruises;
use crate::segs::Segs;
use crate::unit::{Scale, Unit};
use crate::velocity::{Bounds, change};
use crate::{Limits, PlanError, Profile, Segment, State};

/// Jerk-limited (7-phase) or jerk-unlimited (trapezoid) profiles.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shape {
    /// Jerk limited by `jmax` (needs it in the limits).
    JerkLimited,
    /// Jerk unlimited: acceleration jumps, velocity is a trapezoid.
    Trapezoid,
}

pub(crate) fn bounds(lim: &Limits, shape: Shape) -> Result<Bounds, PlanError> {
    let jmax = match shape {
        Shape::JerkLimited => lim.jmax().ok_or(PlanError::MissingJerkLimit {
            kind: "jerk-limited",
        })?,
        Shape::Trapezoid => f64::INFINITY,
    };
    Ok(Bounds {
        amax: lim.amax(),
        amin: lim.amin(),
        jmax,
    })
}

pub(crate) fn finite_state(name: &'static str, s: &State) -> Result<(), PlanError> {
    for value in [s.p, s.v, s.a] {
        if !value.is_finite() {
            return Err(PlanError::NonFinite { name, value });
        }
    }
    Ok(())
}

/// Check that a target can be held within the limits: `af` within the acceleration
/// limits and the velocity reached when `af` is ramped from zero within the velocity
/// limits.
pub(crate) fn check_target(t: &State, lim: &Limits, b: &Bounds) -> Result<(), PlanError> {
    let ramp = if b.jmax.is_finite() {
        t.a * t.a.abs() / (2.0 * b.jmax)
    } else {
        0.0
    };
    let tol = 1e-12;
    if t.a > lim.amax() * (1.0 + tol) || t.a < lim.amin() * (1.0 + tol) {
        return Err(PlanError::InfeasibleTarget {
            reason: "target acceleration outside [amin, amax]",
        });
    }
    let v_before = t.v - ramp;
    if t.v > lim.vmax() * (1.0 + tol)
        || t.v < lim.vmin() * (1.0 + tol)
        || v_before > lim.vmax() * (1.0 + tol)
        || v_before < lim.vmin() * (1.0 + tol)
    {
        return Err(PlanError::InfeasibleTarget {
            reason: "target velocity (or the velocity before ramping to the target acceleration) outside [vmin, vmax]",
        });
    }
    Ok(())
}

/// Brake (jerk-limited) or clamp the velocity (trapezoid) into the limits.
pub(crate) fn pre(start: State, lim: &Limits, b: &Bounds) -> (Segs<4>, State) {
    if b.jmax.is_finite() {
        return brake(start, lim, b.jmax);
    }
    // Trapezoid: the acceleration may jump; only a velocity beyond its limit needs a
    // deceleration phase.
    let mut s = start;
    let mut segs = Segs::<4>::default();
    let (excess, a) = if s.v > lim.vmax() {
        (s.v - lim.vmax(), lim.amin())
    } else if s.v < lim.vmin() {
        (s.v - lim.vmin(), lim.amax())
    } else {
        (0.0, 0.0)
    };
    if excess != 0.0 {
        let seg = Segment::Accel {
            duration_s: -excess / a,
            accel: a,
        };
        s = seg.end_state(&s);
        segs.push(seg);
    }
    (segs, s)
}

/// The profile from `start` through the segments of every part in order. Zero-duration
/// segments are dropped, except a constant-acceleration one that changes the acceleration.
pub(crate) fn assemble(start: State, parts: &[&[Segment]]) -> Result<Profile, PlanError> {
    let n = parts.iter().map(|p| p.len()).sum();
    let mut out: Vec<Segment> = Vec::with_capacity(n);
    let mut st = start;
    for seg in parts.iter().flat_map(|p| p.iter()) {
        let keep =
            seg.duration_s() > 0.0 || matches!(*seg, Segment::Accel { accel, .. } if accel != st.a);
        st = seg.end_state(&st);
        if keep {
            out.push(*seg);
        }
    }
    Profile::new(start, out)
}

/// Velocity interface: the fastest profile from `start` to velocity `vf` and acceleration
/// `af` (position free). As in Ruckig, the velocity limits do not apply here (the target
/// velocity is the command); the target acceleration must lie within the acceleration
/// limits, and a start acceleration beyond them is first brought back at full jerk.
pub fn to_velocity(
    start: State,
    vf: f64,
    af: f64,
    lim: &Limits,
    shape: Shape,
) -> Result<Profile, PlanError> {
    finite_state("start", &start)?;
    let target = State {
        p: 0.0,
        v: vf,
        a: af,
    };
    finite_state("target", &target)?;
    let b = bounds(lim, shape)?;
    if af > lim.amax() * (1.0 + 1e-12) || af < lim.amin() * (1.0 + 1e-12) {
        return Err(PlanError::InfeasibleTarget {
            reason: "target acceleration outside [amin, amax]",
        });
    }
    let mut pre_segs = Segs::<4>::default();
    let mut s = start;
    if b.jmax.is_finite() && (s.a > lim.amax() || s.a < lim.amin()) {
        let to = s.a.clamp(lim.amin(), lim.amax());
        let seg = Segment::Jerk {
            duration_s: (s.a - to).abs() / b.jmax,
            jerk: if s.a > to { -b.jmax } else { b.jmax },
        };
        s = seg.end_state(&s);
        s.a = to;
        pre_segs.push(seg);
    }
    let c = change(s.v, s.a, vf, af, &b).ok_or(PlanError::NoSolution {
        reason: "velocity change",
    })?;
    verify(
        assemble(start, &[pre_segs.as_slice(), &c.segments])?,
        &target,
        lim,
        false,
    )
}

/// Position interface: the fastest profile from `start` to `target`.
///
/// A start that must violate the limits is braked first. Braking just long enough
/// (`brake::brake`) is not always fastest overall; braking on along the same control law
/// until the velocity itself is back inside the limits (where Ruckig stops braking) can
/// be faster. Both ends and points between them are tried and the fastest total is kept.
pub fn to_state(
    start: State,
    target: State,
    lim: &Limits,
    shape: Shape,
) -> Result<Profile, PlanError> {
    let b = validate(&start, &target, lim, shape)?;
    if at_rest_on(&start, &target) {
        return Profile::new(start, Vec::new());
    }
    if b.jmax.is_finite() && !crate::brake::needed(&start, lim, b.jmax) {
        // The common case, written out straight from the candidate: no `Planned` (its
        // step-2 data is not needed here), which saves copying it.
        let sc = Scale::new(lim, b.jmax);
        let u = Unit::new(&start, &target, lim, &sc);
        let cand =
            crate::fastest::fastest(&u, f64::INFINITY, &mut Cruises::default()).ok_or(NO_PEAK)?;
        let mut segs = Vec::with_capacity(12);
        cand.segments(&sc, &mut segs);
        return verify(finish(start, segs)?, &target, lim, true);
    }
    plan_then(start, target, lim, shape, |p| p.profile())?
}

/// Is `start` at rest on `target` (same position, velocity and acceleration zero at both)?
/// Then the fastest profile has no segments, and one lasting `T` is [`hold`]`(T)`. The case
/// polynomials degenerate there (every coefficient zero), so it is answered before them. A
/// start on the target's position that is moving or accelerating is an ordinary problem.
pub(crate) fn at_rest_on(start: &State, target: &State) -> bool {
    start.p == target.p
        && [start.v, start.a, target.v, target.a]
            .iter()
            .all(|x| *x == 0.0)
}

/// Standing still for `duration_s`: one segment holding the acceleration at exactly zero
/// (as a cruise does), or none for a zero duration.
pub(crate) fn hold(duration_s: f64) -> Vec<Segment> {
    if duration_s > 0.0 {
        vec![Segment::Accel {
            duration_s,
            accel: 0.0,
        }]
    } else {
        Vec::new()
    }
}

const NO_PEAK: PlanError = PlanError::NoSolution {
    reason: "no peak velocity reaches the target",
};

/// Check the inputs of a position-interface problem; the velocity changes' bounds.
pub(crate) fn validate(
    start: &State,
    target: &State,
    lim: &Limits,
    shape: Shape,
) -> Result<Bounds, PlanError> {
    finite_state("start", start)?;
    finite_state("target", target)?;
    let b = bounds(lim, shape)?;
    check_target(target, lim, &b)?;
    Ok(b)
}

/// The fastest profile of one axis, planned but not yet written out as a [`Profile`]
/// (several axes only need the slowest one's).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Planned {
    pub(crate) start: State,
    pub(crate) target: State,
    pub(crate) lim: Limits,
    duration_s: f64,
    pub(crate) how: How,
}

// The variants differ in size; boxing the large one would cost the allocation this plan
// exists to avoid (it lives on the stack or in the caller's vector).
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, Copy)]
pub(crate) enum How {
    /// Jerk limited, no brake: `cand`, found for the problem `u` (normalised by `sc`) whose
    /// cruise changes step 2 can reuse.
    Direct {
        sc: Scale,
        u: Unit,
        cruises: Cruises,
        cand: crate::fastest::Cand,
    },
    /// Jerk limited: brake until `tau`, then `cand` (normalised by `sc`).
    Jerk {
        sc: Scale,
        tau: f64,
        cand: crate::fastest::Cand,
    },
    /// Jerk unlimited: clamp the velocity, then `trap`.
    Trap(crate::second_order::Trap),
    /// At rest on the target ([`at_rest_on`]): no segments.
    Rest,
}

impl Planned {
    /// Duration (s).
    pub(crate) fn duration_s(&self) -> f64 {
        self.duration_s
    }

    /// The profile, checked to reach the target.
    pub(crate) fn profile(&self) -> Result<Profile, PlanError> {
        let mut segs = Vec::with_capacity(12);
        match &self.how {
            How::Direct { sc, cand, .. } => cand.segments(sc, &mut segs),
            &How::Jerk { sc, tau, cand } => {
                if tau > 0.0 {
                    let (pre_segs, _) = BrakeLaw::new(self.start, &self.lim, sc.j).until(tau);
                    segs.extend_from_slice(pre_segs.as_slice());
                }
                cand.segments(&sc, &mut segs);
            }
            How::Trap(trap) => {
                let b = bounds(&self.lim, Shape::Trapezoid)?;
                segs.extend_from_slice(pre(self.start, &self.lim, &b).0.as_slice());
                trap.segments(&mut segs);
            }
            How::Rest => {}
        }
        verify(finish(self.start, segs)?, &self.target, &self.lim, true)
    }
}

/// Step 1 for one axis: validate, brake, find the fastest profile, and append its plan
/// to `out`.
pub(crate) fn plan_into(
    start: State,
    target: State,
    lim: &Limits,
    shape: Shape,
    out: &mut Vec<Planned>,
) -> Result<(), PlanError> {
    plan_then(start, target, lim, shape, |p| out.push(*p))
}

/// Step 1, handing the plan to `then` where it is built (no copy of the plan).
#[inline(always)]
fn plan_then<R>(
    start: State,
    target: State,
    lim: &Limits,
    shape: Shape,
    then: impl FnOnce(&Planned) -> R,
) -> Result<R, PlanError> {
    let b = validate(&start, &target, lim, shape)?;
    let none = NO_PEAK;
    let planned = |duration_s, how| Planned {
        start,
        target,
        lim: *lim,
        duration_s,
        how,
    };
    let then = |p: Planned| then(&p);
    if at_rest_on(&start, &target) {
        return Ok(then(planned(0.0, How::Rest)));
    }
    if b.jmax.is_infinite() {
        let (pre_segs, s) = pre(start, lim, &b);
        let trap = crate::second_order::fastest(&s, &target, lim).ok_or(none)?;
        return Ok(then(planned(
            pre_segs.duration_s() + trap.duration(),
            How::Trap(trap),
        )));
    }
    let sc = Scale::new(lim, b.jmax);
    if !crate::brake::needed(&start, lim, b.jmax) {
        let u = Unit::new(&start, &target, lim, &sc);
        let mut cruises = Cruises::default();
        let cand = crate::fastest::fastest(&u, f64::INFINITY, &mut cruises).ok_or(none)?;
        return Ok(then(planned(
            cand.duration() * sc.t,
            How::Direct {
                sc,
                u,
                cruises,
                cand,
            },
        )));
    }
    let law = BrakeLaw::new(start, lim, b.jmax);
    // (total duration, brake stopping time, profile after the brake)
    let mut best: Option<(f64, f64, crate::fastest::Cand)> = None;
    for tau in law.candidate_times() {
        let s = law.state_at(tau, lim);
        let t_max = best.map_or(f64::INFINITY, |(total, _, _)| (total - tau) / sc.t);
        let u = Unit::new(&s, &target, lim, &sc);
        if let Some(c) = crate::fastest::fastest(&u, t_max, &mut Cruises::default()) {
            let total = tau + c.duration() * sc.t;
            if best.is_none_or(|(bt, _, _)| total < bt) {
                best = Some((total, tau, c));
            }
        }
    }
    let (total, tau, cand) = best.ok_or(none)?;
    Ok(then(planned(total, How::Jerk { sc, tau, cand })))
}

/// The profile from `start` through `segs`, dropping zero-duration segments except a
/// constant-acceleration one that changes the acceleration (as [`assemble`], in place).
pub(crate) fn finish(start: State, mut segs: Vec<Segment>) -> Result<Profile, PlanError> {
    let mut a = start.a;
    segs.retain(|seg| {
        let keep =
            seg.duration_s() > 0.0 || matches!(*seg, Segment::Accel { accel, .. } if accel != a);
        a = match *seg {
            Segment::Jerk { duration_s, jerk } => a + jerk * duration_s,
            Segment::Accel { accel, .. } => accel,
        };
        keep
    });
    Profile::new(start, segs)
}

/// Last line of defence: a profile is only returned if it really ends on the target (and
/// is finite). Extreme inputs (positions near the f64 range, limits near underflow) can
/// defeat the arithmetic; they get an error, never a wrong profile. Position is checked
/// relative to the largest position magnitude of the move.
pub(crate) fn verify(
    prof: Profile,
    target: &State,
    lim: &Limits,
    position: bool,
) -> Result<Profile, PlanError> {
    let e = prof.end();
    let tol = 1e-8;
    let finite =
        prof.duration_s().is_finite() && e.p.is_finite() && e.v.is_finite() && e.a.is_finite();
    let ok_p = !position || {
        let err = (e.p - target.p).abs();
        let ends = prof.start().p.abs().max(target.p.abs());
        // The scale is the largest position along the move; the ends usually suffice.
        err <= tol * ends
            || err <= tol * prof.iter().map(|(_, s, _)| s.p.abs()).fold(ends, f64::max)
    };
    let ok_v = (e.v - target.v).abs() <= tol * target.v.abs().max(lim.vmax());
    let ok_a = (e.a - target.a).abs() <= tol * target.a.abs().max(lim.amax());
    if finite && ok_p && ok_v && ok_a {
        Ok(prof)
    } else {
        Err(PlanError::NoSolution {
            reason: "the computed profile misses the target (inputs beyond what f64 arithmetic resolves)",
        })
    }
}
