//! Time-optimal profiles from any state `(p0, v0, a0)` to any target `(pf, vf, af)`
//! (the position interface), and to a velocity and acceleration (the velocity interface).
//!
//! Step 0 brakes a start state that violates, or must violate, the limits (see `brake`).
//! Then the profile is an acceleration phase to a peak velocity `vp` (ending with `a = 0`),
//! a cruise at `vp`, and a phase from `(vp, 0)` to `(vf, af)`; both phases are the
//! time-optimal velocity changes of `velocity`. Writing `D(vp)` and `T(vp)` for the distance
//! and duration of the two phases, a cruise of `(dp - D(vp))/vp >= 0` completes the move,
//! and `d/dvp` of the total time is `-cruise/vp`: the optimum is either the cruise at
//! `vmax` (or `vmin`) or a peak velocity with no cruise, `D(vp) = dp`. These are seed 004's
//! cases: the no-cruise roots are its DD, DT, TD and TT profiles (D/T: the acceleration
//! phase does/does not reach the acceleration limit), found here by bracketing every sign
//! change of `D(vp) - dp` between the structural breakpoints and bisecting to full
//! precision, then keeping the fastest valid root (the others are the spurious solutions
//! the seed warns about).
//!
//! Not yet covered: profiles whose acceleration does not pass through zero between the two
//! phases (Ruckig's UDUD family, which can be optimal when both `a0` and `af` are far from
//! zero). The random suite against rsruckig measures how often that matters.

use crate::brake::brake;
use crate::roots::roots;
use crate::velocity::{Bounds, Change, change};
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
pub(crate) fn pre(start: State, lim: &Limits, b: &Bounds) -> (Vec<Segment>, State) {
    if b.jmax.is_finite() {
        return brake(start, lim, b.jmax);
    }
    // Trapezoid: the acceleration may jump; only a velocity beyond its limit needs a
    // deceleration phase.
    let mut s = start;
    let mut segs = Vec::new();
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

pub(crate) fn assemble(
    start: State,
    mut segs: Vec<Segment>,
    parts: &[&[Segment]],
) -> Result<Profile, PlanError> {
    for part in parts {
        segs.extend(
            part.iter()
                .copied()
                .filter(|s| s.duration_s() > 0.0 || matches!(s, Segment::Accel { .. })),
        );
    }
    // Zero-duration Accel segments only matter where they change the acceleration.
    let mut out: Vec<Segment> = Vec::with_capacity(segs.len());
    let mut a = start.a;
    let mut st = start;
    for seg in segs {
        let keep =
            seg.duration_s() > 0.0 || matches!(seg, Segment::Accel { accel, .. } if accel != a);
        st = seg.end_state(&st);
        a = st.a;
        if keep {
            out.push(seg);
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
    let mut pre_segs = Vec::new();
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
        assemble(start, pre_segs, &[&c.segments])?,
        &target,
        lim,
        false,
    )
}

/// Position interface: the fastest profile from `start` to `target`.
///
/// A start that must violate the limits is braked first. Braking just long enough
/// (`brake::minimal`) is not always fastest overall; braking on along the same control law
/// until the velocity itself is back inside the limits (where Ruckig stops braking) can
/// be faster. Both ends and points between them are tried and the fastest total is kept.
pub fn to_state(
    start: State,
    target: State,
    lim: &Limits,
    shape: Shape,
) -> Result<Profile, PlanError> {
    finite_state("start", &start)?;
    finite_state("target", &target)?;
    let b = bounds(lim, shape)?;
    check_target(&target, lim, &b)?;
    if b.jmax.is_infinite() {
        let (pre_segs, s) = pre(start, lim, &b);
        let (_, segs) = from_safe(&s, &target, lim, &b).ok_or(PlanError::NoSolution {
            reason: "no peak velocity reaches the target",
        })?;
        return verify(assemble(start, pre_segs, &[&segs])?, &target, lim, true);
    }
    let law = crate::brake::BrakeLaw::new(start, lim, b.jmax);
    let mut best: Option<(f64, Vec<Segment>, Vec<Segment>)> = None;
    for tau in law.candidate_times() {
        let (pre_segs, mut s) = law.until(tau);
        // The brake ends on the acceleration limit up to rounding: snap it there.
        s.a = s.a.clamp(lim.amin(), lim.amax());
        if let Some((t, segs)) = from_safe(&s, &target, lim, &b) {
            let total = tau + t;
            if best.as_ref().is_none_or(|(bt, _, _)| total < *bt) {
                best = Some((total, pre_segs, segs));
            }
        }
    }
    let (_, pre_segs, segs) = best.ok_or(PlanError::NoSolution {
        reason: "no peak velocity reaches the target",
    })?;
    verify(assemble(start, pre_segs, &[&segs])?, &target, lim, true)
}

/// The peak-velocity family from a safe state `s` to `target`: for a peak velocity `vp`,
/// the two phases, their distance and their duration.
pub(crate) struct PeakFamily<'a> {
    s: State,
    target: State,
    lim: &'a Limits,
    b: Bounds,
}

impl<'a> PeakFamily<'a> {
    pub(crate) fn new(s: State, target: State, lim: &'a Limits, b: Bounds) -> Self {
        Self { s, target, lim, b }
    }

    /// The two phases for peak velocity `vp`, their distance and duration.
    pub(crate) fn phases(&self, vp: f64) -> Option<(Change, Change, f64, f64)> {
        let c1 = change(self.s.v, self.s.a, vp, 0.0, &self.b)?;
        let c2 = change(vp, 0.0, self.target.v, self.target.a, &self.b)?;
        let d = c1.end(self.s.v, self.s.a).p + c2.end(vp, 0.0).p;
        Some((c1, c2, d, c1.duration_s() + c2.duration_s()))
    }

    /// Distance still to cover after the two phases.
    pub(crate) fn dp(&self) -> f64 {
        self.target.p - self.s.p
    }

    /// The profile for peak `vp` with `cruise` seconds at `vp`.
    pub(crate) fn segments(&self, vp: f64, cruise: f64) -> Option<Vec<Segment>> {
        let (c1, c2, _, _) = self.phases(vp)?;
        let mut segs = c1.segments.to_vec();
        // The cruise holds the acceleration at exactly zero: the phase before ends there
        // only up to rounding, and a cruise can be long enough for that to matter.
        segs.push(Segment::Accel {
            duration_s: cruise,
            accel: 0.0,
        });
        segs.extend(c2.segments);
        Some(segs)
    }

    /// Structural breakpoints in `vp` (see [`breakpoints`]).
    pub(crate) fn knots(&self) -> Vec<f64> {
        breakpoints(&self.s, &self.target, self.lim, &self.b)
    }
}

/// Every locally fastest profile from a state inside the limits, as `(duration, segments)`:
/// the cruise at `vmax` and at `vmin`, each no-cruise peak velocity, and the three-arc
/// family's solutions. The fastest of them is the time-optimal profile; the others start
/// the ranges of longer durations that step 2 (time synchronisation) can stretch to.
pub(crate) fn candidates(
    s: &State,
    target: &State,
    lim: &Limits,
    b: &Bounds,
) -> Vec<(f64, Vec<Segment>)> {
    let fam = PeakFamily::new(*s, *target, lim, *b);
    let dp = fam.dp();
    let mut out = Vec::new();
    for vlim in [lim.vmax(), lim.vmin()] {
        if let Some((_, _, d, t)) = fam.phases(vlim) {
            let cruise = (dp - d) / vlim;
            if cruise >= 0.0 && (t + cruise).is_finite() {
                out.extend(fam.segments(vlim, cruise).map(|segs| (t + cruise, segs)));
            }
        }
    }
    for vp in roots(
        &|vp| fam.phases(vp).map(|(_, _, d, _)| d - dp),
        &fam.knots(),
    ) {
        if let Some((_, _, _, t)) = fam.phases(vp) {
            out.extend(fam.segments(vp, 0.0).map(|segs| (t, segs)));
        }
    }
    if b.jmax.is_finite() {
        out.extend(crate::three_arc::candidates(s, target, lim, b));
    }
    out
}

/// The fastest profile from a state inside the limits. Returns its duration and segments.
fn from_safe(s: &State, target: &State, lim: &Limits, b: &Bounds) -> Option<(f64, Vec<Segment>)> {
    candidates(s, target, lim, b)
        .into_iter()
        .min_by(|x, y| x.0.total_cmp(&y.0))
}

/// Peak velocities where either phase changes structure, plus the velocity limits.
fn breakpoints(s: &State, t: &State, lim: &Limits, b: &Bounds) -> Vec<f64> {
    let mut v = vec![lim.vmin(), lim.vmax(), 0.0, s.v, t.v];
    if b.jmax.is_finite() {
        let j = b.jmax;
        let (amax2, amin2) = (b.amax * b.amax, b.amin * b.amin);
        v.extend([
            s.v + s.a * s.a.abs() / (2.0 * j),
            s.v + (amax2 - s.a * s.a / 2.0) / j,
            s.v + (s.a * s.a / 2.0 - amin2) / j,
            t.v - t.a * t.a.abs() / (2.0 * j),
            t.v - (amax2 - t.a * t.a / 2.0) / j,
            t.v - (t.a * t.a / 2.0 - amin2) / j,
        ]);
    }
    v.retain(|x| x.is_finite() && *x >= lim.vmin() && *x <= lim.vmax());
    v.sort_by(f64::total_cmp);
    v.dedup();
    v
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
    let p_scale = prof
        .iter()
        .map(|(_, s, _)| s.p.abs())
        .fold(prof.start().p.abs().max(target.p.abs()), f64::max);
    let ok_p = !position || (e.p - target.p).abs() <= tol * p_scale;
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
