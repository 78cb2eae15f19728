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

fn bounds(lim: &Limits, shape: Shape) -> Result<Bounds, PlanError> {
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

fn finite_state(name: &'static str, s: &State) -> Result<(), PlanError> {
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
fn check_target(t: &State, lim: &Limits, b: &Bounds) -> Result<(), PlanError> {
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
fn pre(start: State, lim: &Limits, b: &Bounds) -> (Vec<Segment>, State) {
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

fn assemble(
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
/// `af` (position free).
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
    check_target(&target, lim, &b)?;
    // Only the acceleration needs braking: the velocity is free to pass the limits' side
    // on the way to vf... but not beyond them; brake handles both.
    let (pre_segs, s) = pre(start, lim, &b);
    let c = change(s.v, s.a, vf, af, &b).ok_or(PlanError::NoSolution {
        reason: "velocity change",
    })?;
    assemble(start, pre_segs, &[&c.segments])
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
        return assemble(start, pre_segs, &[&segs]);
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
    assemble(start, pre_segs, &[&segs])
}

/// The fastest profile from a state inside the limits: the peak-velocity family (with
/// cruise) and the three-arc family. Returns its duration and segments.
fn from_safe(s: &State, target: &State, lim: &Limits, b: &Bounds) -> Option<(f64, Vec<Segment>)> {
    let dp = target.p - s.p;
    let phases = |vp: f64| -> Option<(Change, Change, f64, f64)> {
        let c1 = change(s.v, s.a, vp, 0.0, b)?;
        let c2 = change(vp, 0.0, target.v, target.a, b)?;
        let d = c1.end(s.v, s.a).p + c2.end(vp, 0.0).p;
        Some((c1, c2, d, c1.duration_s() + c2.duration_s()))
    };
    // Candidates: (total time, vp, cruise time).
    let mut best: Option<(f64, f64, f64)> = None;
    let mut consider = |t: f64, vp: f64, cruise: f64| {
        if t.is_finite() && cruise >= 0.0 && best.is_none_or(|(bt, _, _)| t < bt) {
            best = Some((t, vp, cruise));
        }
    };
    for vlim in [lim.vmax(), lim.vmin()] {
        if let Some((_, _, d, t)) = phases(vlim) {
            let cruise = (dp - d) / vlim;
            consider(t + cruise, vlim, cruise);
        }
    }
    for vp in roots(
        &|vp| phases(vp).map(|(_, _, d, _)| d - dp),
        &breakpoints(s, target, lim, b),
    ) {
        if let Some((_, _, _, t)) = phases(vp) {
            consider(t, vp, 0.0);
        }
    }
    let arcs = if b.jmax.is_finite() {
        crate::three_arc::candidates(s, target, lim, b)
    } else {
        Vec::new()
    };
    let best_arc = arcs
        .into_iter()
        .min_by(|x, y| x.0.total_cmp(&y.0))
        .filter(|(t, _)| best.is_none_or(|(bt, _, _)| *t < bt));
    if best_arc.is_some() {
        return best_arc;
    }
    let (t, vp, cruise) = best?;
    let (c1, c2, _, _) = phases(vp)?;
    let mut segs = c1.segments.to_vec();
    segs.push(Segment::Jerk {
        duration_s: cruise,
        jerk: 0.0,
    });
    segs.extend(c2.segments);
    Some((t, segs))
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

/// Every root of `g` on `[first, last]` of the sorted `knots`, bracketed on a grid that
/// refines each knot interval, then bisected to full precision.
pub(crate) fn roots(g: &dyn Fn(f64) -> Option<f64>, knots: &[f64]) -> Vec<f64> {
    const SUB: usize = 16;
    let mut grid = Vec::with_capacity(knots.len() * SUB);
    for w in knots.windows(2) {
        for k in 0..SUB {
            grid.push(w[0] + (w[1] - w[0]) * k as f64 / SUB as f64);
        }
    }
    if let Some(&last) = knots.last() {
        grid.push(last);
    }
    let mut pts: Vec<(f64, Option<f64>)> = Vec::with_capacity(grid.len() + 8);
    for &x in &grid {
        let gx = g(x);
        // Where the domain of g ends between two grid points, add its edge (bisected), so
        // roots next to it are bracketed too.
        if let Some(&(xp, gp)) = pts.last()
            && gp.is_some() != gx.is_some()
        {
            {
                let (mut valid, mut invalid) = if gp.is_some() { (xp, x) } else { (x, xp) };
                for _ in 0..200 {
                    let mid = 0.5 * (valid + invalid);
                    if mid == valid || mid == invalid {
                        break;
                    }
                    if g(mid).is_some() {
                        valid = mid;
                    } else {
                        invalid = mid;
                    }
                }
                if valid != xp && valid != x {
                    pts.push((valid, g(valid)));
                }
            }
        }
        pts.push((x, gx));
    }
    // Where |g| has a local minimum between samples without a sign change, g may dip
    // through zero and back (two close roots): find the extremum by golden-section search
    // and, if it crosses zero, split the interval there.
    let mut i = 1;
    while i + 1 < pts.len() {
        if let ((xa, Some(ga)), (_, Some(gb)), (xc, Some(gc))) = (pts[i - 1], pts[i], pts[i + 1])
            && ga.signum() == gb.signum()
            && gc.signum() == gb.signum()
            && gb.abs() <= ga.abs()
            && gb.abs() <= gc.abs()
            && let Some((xm, gm)) = golden_min(&|x| g(x).map(|v| v * gb.signum()), xa, xc)
            && gm < 0.0
        {
            let at = if xm < pts[i].0 { i } else { i + 1 };
            pts.insert(at, (xm, Some(gm * gb.signum())));
            i += 1;
        }
        i += 1;
    }
    let mut out = Vec::new();
    for i in 0..pts.len() {
        let (xi, Some(gi)) = pts[i] else { continue };
        if gi == 0.0 {
            out.push(xi);
            continue;
        }
        let Some(&(xn, Some(gn))) = pts.get(i + 1) else {
            continue;
        };
        if gi.signum() != gn.signum() && gn != 0.0 {
            out.push(bisect(g, xi, gi, xn));
        }
    }
    out
}

/// Bisect `g` on `[lo, hi]` (g(lo) = glo, opposite sign at hi) to full precision.
fn bisect(g: &dyn Fn(f64) -> Option<f64>, lo: f64, glo: f64, hi: f64) -> f64 {
    let (mut lo, mut hi, mut glo) = (lo, hi, glo);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo.min(hi) || mid >= hi.max(lo) {
            break;
        }
        match g(mid) {
            Some(gm) if gm.signum() == glo.signum() => {
                lo = mid;
                glo = gm;
            }
            Some(_) => hi = mid,
            None => break,
        }
    }
    if glo.abs() <= g(hi).map_or(f64::INFINITY, f64::abs) {
        lo
    } else {
        hi
    }
}

/// Minimum of `f` on `[a, b]` by golden-section search (f assumed unimodal there).
fn golden_min(f: &dyn Fn(f64) -> Option<f64>, a: f64, b: f64) -> Option<(f64, f64)> {
    const R: f64 = 0.618_033_988_749_894_9;
    let (mut a, mut b) = (a, b);
    let mut c = b - R * (b - a);
    let mut d = a + R * (b - a);
    let (mut fc, mut fd) = (f(c)?, f(d)?);
    for _ in 0..100 {
        if fc < 0.0 {
            return Some((c, fc));
        }
        if fd < 0.0 {
            return Some((d, fd));
        }
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - R * (b - a);
            fc = f(c)?;
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + R * (b - a);
            fd = f(d)?;
        }
        if (b - a).abs() <= 1e-15 * (a.abs() + b.abs()) {
            break;
        }
    }
    Some(if fc < fd { (c, fc) } else { (d, fd) })
}
