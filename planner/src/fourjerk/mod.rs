//! Time-optimal profiles under four jerks, from any start state (beyond the TMC4361A).
//!
//! The Trinamic ramp has four independent bows; this planner brings that to the
//! any-state problem: from `(p0, v0, a0)` to `(pf, vf, 0)` in minimum time under
//! `|v| <= vmax`, `-dmax <= a <= amax` and a jerk bound that depends on what the jerk does
//! to the acceleration (axis frame, positive direction):
//!
//! | jerk | raises `a >= 0` | lowers `a > 0` | lowers `a <= 0` | raises `a < 0` |
//! |---|---|---|---|---|
//! | limit | `j1` (TMC BOW1) | `j2` (BOW2) | `j3` (BOW3) | `j4` (BOW4) |
//!
//! so that a positive rest-to-rest move is exactly the chip's B1..B4. [`rest_to_rest`]
//! orients the limits along the move (AMAX and BOW1/BOW2 always speed the axis up, as on
//! the chip); [`plan`] uses them in the axis frame as given.
//!
//! A start outside the limits is handled as by the one-jerk planner (`crate::brake`): an
//! acceleration beyond AMAX/DMAX is first brought back at full jerk; a velocity that is (or
//! must become) beyond VMAX is braked along the brake law (see `brake`), stopping at the
//! best time in its range. From there the candidates (see `families`) are the three-arc
//! family in both senses (which contains the peak-velocity profiles without cruise) and the
//! cruise at `+-vmax`; the velocity limit binds from the moment the state is safe (velocity
//! inside, and the velocity after ramping the acceleration to zero at once inside too). The
//! fastest valid profile is returned, after checking that it ends on the target.
//!
//! No other tool plans this (Ruckig has one jerk limit); `planner/tests/all/fourjerk.rs` checks
//! optimality against an independent search over arc durations and the symmetric case
//! against [`crate::position::to_state`].

mod arc_algebra;
mod brake;
mod families;
mod limits;

pub use limits::FourJerkLimits;

use crate::{PlanError, Profile, Segment, State};

/// Does the profile after the brake keep the limits? The acceleration must stay inside
/// (the caller starts inside). A velocity outside the band (left over from braking) must
/// move strictly monotonically back towards it (no cruise out there); once inside, it must
/// stay inside (checked on the monotone pieces of each segment, so it cannot slip through
/// the band between segment ends).
fn valid(start: State, segs: &[Segment], l: &FourJerkLimits) -> bool {
    let tol = 1e-9;
    let (amax, amin) = (l.amax * (1.0 + tol), -l.dmax * (1.0 + tol));
    let vl = l.vmax * (1.0 + tol);
    let mut s = start;
    let mut inside = s.v.abs() <= vl;
    for seg in segs {
        let (a0, j) = seg.accel_and_jerk(&s);
        let e = seg.end_state(&s);
        if a0 > amax || a0 < amin || e.a > amax || e.a < amin {
            return false;
        }
        // The velocity's monotone pieces: split where the acceleration crosses zero.
        let mut ends = [s.v, e.v, e.v];
        let mut n = 2;
        if j != 0.0 {
            let tau = -a0 / j;
            if tau > 0.0 && tau < seg.duration_s() {
                ends[1] = seg.sample(&s, tau).v;
                n = 3;
            }
        }
        for w in ends[..n].windows(2) {
            let (va, vb) = (w[0], w[1]);
            if inside {
                if vb.abs() > vl {
                    return false;
                }
            } else if (va > vl && (vb >= va || vb < -vl)) || (va < -vl && (vb <= va || vb > vl)) {
                return false;
            } else if vb.abs() <= vl {
                inside = true;
            }
        }
        s = e;
    }
    true
}

/// The fastest profile from `start` to `target` (`target.a` must be 0, `|target.v| <=
/// vmax`) under the four-jerk limits in the axis frame.
pub fn plan(start: State, target: State, l: &FourJerkLimits) -> Result<Profile, PlanError> {
    FourJerkLimits::new(l.vmax, l.amax, l.dmax, l.jerk)?;
    for (name, s) in [("start", &start), ("target", &target)] {
        for value in [s.p, s.v, s.a] {
            if !value.is_finite() {
                return Err(PlanError::NonFinite { name, value });
            }
        }
    }
    if target.a != 0.0 {
        return Err(PlanError::InvalidInput {
            reason: "the four-jerk planner needs a target acceleration of 0",
        });
    }
    if target.v.abs() > l.vmax {
        return Err(PlanError::InfeasibleTarget {
            reason: "target velocity outside [-vmax, vmax]",
        });
    }
    // An acceleration beyond its limit is brought back at full jerk first.
    let mut pre = Vec::new();
    let mut s = start;
    if s.a > l.amax {
        arc_algebra::push_down(&mut pre, s.a, l.amax, l);
    } else if s.a < -l.dmax {
        arc_algebra::push_up(&mut pre, s.a, -l.dmax, l);
    }
    s = arc_algebra::run(s, &pre);
    s.a = s.a.clamp(-l.dmax, l.amax);
    // Brake where the velocity overshoots, stopping at the best time in the law's range;
    // from the stop, the fastest valid candidate.
    let law = brake::BrakeLaw::new(s, l);
    let from = |tau: f64| -> Option<(f64, Vec<Segment>)> {
        let (mut segs, st) = law.until(tau);
        let (t, rest) = families::candidates(&st, target.p, target.v, l)
            .into_iter()
            .filter(|(_, segs)| valid(st, segs, l))
            .min_by(|x, y| x.0.total_cmp(&y.0))?;
        segs.extend(rest);
        Some((tau + t, segs))
    };
    let taus = law.samples();
    let mut best: Option<(f64, Vec<Segment>)> = None;
    let mut best_k = 0;
    for (k, &tau) in taus.iter().enumerate() {
        if let Some(c) = from(tau)
            && best.as_ref().is_none_or(|b| c.0 < b.0)
        {
            best = Some(c);
            best_k = k;
        }
    }
    if taus.len() > 1 && best.is_some() {
        // The total is not monotone in the stopping time: refine around the best sample.
        let lo = taus[best_k.saturating_sub(1)];
        let hi = taus[(best_k + 1).min(taus.len() - 1)];
        let r = 0.5 * (5f64.sqrt() - 1.0);
        let (mut a, mut b) = (lo, hi);
        let f = |tau: f64| from(tau).map_or(f64::INFINITY, |c| c.0);
        let (mut c, mut d) = (b - r * (b - a), a + r * (b - a));
        let (mut fc, mut fd) = (f(c), f(d));
        for _ in 0..80 {
            if fc < fd {
                b = d;
                d = c;
                fd = fc;
                c = b - r * (b - a);
                fc = f(c);
            } else {
                a = c;
                c = d;
                fc = fd;
                d = a + r * (b - a);
                fd = f(d);
            }
        }
        let tau = if fc < fd { c } else { d };
        if let Some(cand) = from(tau)
            && best.as_ref().is_none_or(|b| cand.0 < b.0)
        {
            best = Some(cand);
        }
    }
    let best = best.ok_or(PlanError::NoSolution {
        reason: "no four-jerk profile reaches the target",
    })?;
    pre.extend(best.1);
    let prof = Profile::new(start, pre)?;
    let e = prof.end();
    let p_scale = prof
        .iter()
        .map(|(_, s, _)| s.p.abs())
        .fold(start.p.abs().max(target.p.abs()), f64::max);
    let tol = 1e-8;
    if (e.p - target.p).abs() <= tol * p_scale.max(f64::MIN_POSITIVE)
        && (e.v - target.v).abs() <= tol * l.vmax
        && e.a.abs() <= tol * l.amax.max(l.dmax)
    {
        Ok(prof)
    } else {
        Err(PlanError::NoSolution {
            reason: "the computed four-jerk profile misses the target (inputs beyond what f64 arithmetic resolves)",
        })
    }
}

/// A rest-to-rest move of signed `distance` from `p0`, with the limits oriented along the
/// move: for a negative move they are mirrored, so AMAX, BOW1 and BOW2 always speed the
/// axis up and DMAX, BOW3 and BOW4 slow it down (the chip's convention).
pub fn rest_to_rest(p0: f64, distance: f64, l: &FourJerkLimits) -> Result<Profile, PlanError> {
    for (name, value) in [("p0", p0), ("distance", distance)] {
        if !value.is_finite() {
            return Err(PlanError::NonFinite { name, value });
        }
    }
    let start = State {
        p: p0,
        v: 0.0,
        a: 0.0,
    };
    if distance == 0.0 {
        return Ok(Profile::empty(start));
    }
    let target = State {
        p: p0 + distance,
        v: 0.0,
        a: 0.0,
    };
    if distance > 0.0 {
        plan(start, target, l)
    } else {
        plan(start, target, &l.mirrored())
    }
}
