//! Several axes: each axis's fastest profile (step 1), then all fitted to the slowest
//! (step 2), as Ruckig synchronises axes.
//!
//! - `None`: every axis on its own, fastest.
//! - `Time`: every axis finishes together, at the earliest duration every axis can meet
//!   (the longest fastest duration, unless it falls in another axis's blocked interval).
//! - `Phase`: straight-line motion with aligned breaks, when the problem is collinear
//!   (start and target velocities and accelerations parallel to the displacement): the
//!   limiting axis's profile scaled onto the others, if it keeps them within their limits;
//!   otherwise time synchronisation.

use crate::duration::branch_starts;
use crate::position::{self, Planned, Shape};
use crate::{Limits, PlanError, Profile, Segment, State};

/// How axes are synchronised.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sync {
    /// Independent axes.
    None,
    /// Common finish time.
    Time,
    /// Straight line where possible, else time.
    Phase,
}

/// One axis of a multi-axis problem.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Axis {
    /// Start state.
    pub start: State,
    /// Target state.
    pub target: State,
    /// Limits.
    pub limits: Limits,
}

/// Plan all axes.
pub fn plan(axes: &[Axis], shape: Shape, sync: Sync) -> Result<Vec<Profile>, PlanError> {
    let on_axis = |axis: usize| {
        move |e: PlanError| PlanError::OnAxis {
            axis,
            source: Box::new(e),
        }
    };
    // Plans are large: built in place (an iterator collecting results would copy each
    // several times).
    let mut fastest: Vec<Planned> = Vec::with_capacity(axes.len());
    for (i, a) in axes.iter().enumerate() {
        position::plan_into(a.start, a.target, &a.limits, shape, &mut fastest)
            .map_err(on_axis(i))?;
    }
    let all = || -> Result<Vec<Profile>, PlanError> {
        fastest
            .iter()
            .enumerate()
            .map(|(i, p)| p.profile().map_err(on_axis(i)))
            .collect()
    };
    if sync == Sync::None || axes.len() <= 1 {
        return all();
    }
    if sync == Sync::Phase
        && let Some(profiles) = phase(axes, &all()?)
    {
        return Ok(profiles);
    }
    time(axes, shape, &fastest)
}

fn time(axes: &[Axis], shape: Shape, fastest: &[Planned]) -> Result<Vec<Profile>, PlanError> {
    let t_min = fastest.iter().map(Planned::duration_s).fold(0.0, f64::max);
    if let Some(out) = all_at(fastest, t_min)? {
        return Ok(out);
    }
    // Some axis cannot last t_min (a blocked interval): try the later durations at which
    // some axis's achievable range starts, in order.
    let mut candidates = Vec::new();
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
        if let Some(out) = all_at(fastest, t)? {
            return Ok(out);
        }
    }
    Err(PlanError::NoSolution {
        reason: "no common duration found for time synchronisation",
    })
}

/// Every axis lasting `t` (its fastest profile where that lasts `t`), or `None`.
fn all_at(fastest: &[Planned], t: f64) -> Result<Option<Vec<Profile>>, PlanError> {
    let mut out = Vec::with_capacity(fastest.len());
    for (i, f) in fastest.iter().enumerate() {
        if (f.duration_s() - t).abs() <= 1e-12 * t.max(1e-9) {
            out.push(f.profile().map_err(|e| PlanError::OnAxis {
                axis: i,
                source: Box::new(e),
            })?);
        } else if let Some(p) = crate::duration::lasting(f, t).map_err(|e| PlanError::OnAxis {
            axis: i,
            source: Box::new(e),
        })? {
            out.push(p);
        } else {
            return Ok(None);
        }
    }
    Ok(Some(out))
}

/// Phase synchronisation: scale the limiting axis's profile onto the others.
fn phase(axes: &[Axis], fastest: &[Profile]) -> Option<Vec<Profile>> {
    let (lead, lead_prof) = fastest
        .iter()
        .enumerate()
        .max_by(|x, y| x.1.duration_s().total_cmp(&y.1.duration_s()))?;
    let d_lead = axes[lead].target.p - axes[lead].start.p;
    if d_lead == 0.0 {
        return None;
    }
    let mut out = Vec::with_capacity(axes.len());
    for a in axes {
        if crate::position::at_rest_on(&a.start, &a.target) {
            // On the line whatever it is: stands still for the lead's duration.
            out.push(Profile::new(a.start, crate::position::hold(lead_prof.duration_s())).ok()?);
            continue;
        }
        let d = a.target.p - a.start.p;
        let k = d / d_lead;
        // Collinear: every state component scales with the displacement.
        let close =
            |x: f64, y: f64| (x - k * y).abs() <= 1e-9 * (x.abs() + (k * y).abs()).max(1e-12);
        let (ls, lt) = (axes[lead].start, axes[lead].target);
        if !(close(a.start.v, ls.v)
            && close(a.start.a, ls.a)
            && close(a.target.v, lt.v)
            && close(a.target.a, lt.a))
        {
            return None;
        }
        let segs: Vec<Segment> = lead_prof
            .segments()
            .iter()
            .map(|s| match *s {
                Segment::Jerk { duration_s, jerk } => Segment::Jerk {
                    duration_s,
                    jerk: k * jerk,
                },
                Segment::Accel { duration_s, accel } => Segment::Accel {
                    duration_s,
                    accel: k * accel,
                },
            })
            .collect();
        let prof = Profile::new(a.start, segs).ok()?;
        if !within(&prof, &a.limits) {
            return None;
        }
        out.push(prof);
    }
    Some(out)
}

/// The profile stays within `lim` (velocity at segment ends and interior extrema,
/// acceleration, jerk), with a relative tolerance of 1e-9.
fn within(prof: &Profile, lim: &Limits) -> bool {
    let tol = 1.0 + 1e-9;
    let (vmax, vmin, amax, amin) = (
        lim.vmax() * tol,
        lim.vmin() * tol,
        lim.amax() * tol,
        lim.amin() * tol,
    );
    let jmax = lim.jmax().map_or(f64::INFINITY, |j| j * tol);
    prof.iter().all(|(_, s, seg)| {
        let (a0, j) = seg.accel_and_jerk(&s);
        let e = seg.end_state(&s);
        let mut vs = vec![s.v, e.v];
        if j != 0.0 {
            let tau = -a0 / j;
            if tau > 0.0 && tau < seg.duration_s() {
                vs.push(seg.sample(&s, tau).v);
            }
        }
        j.abs() <= jmax
            && [a0, e.a].iter().all(|a| *a <= amax && *a >= amin)
            && vs.iter().all(|v| *v <= vmax && *v >= vmin)
    })
}

/// Velocity interface for several axes: each axis reaches its target velocity and
/// acceleration; with `Time` (or `Phase`, treated as `Time` here) all at the slowest axis's
/// duration, each other axis stretched by lowering its acceleration plateau (jerk limited)
/// or its constant acceleration (trapezoid).
pub fn plan_velocity(axes: &[Axis], shape: Shape, sync: Sync) -> Result<Vec<Profile>, PlanError> {
    let on_axis = |axis: usize| {
        move |e: PlanError| PlanError::OnAxis {
            axis,
            source: Box::new(e),
        }
    };
    let fastest: Vec<Profile> = axes
        .iter()
        .enumerate()
        .map(|(i, a)| {
            crate::position::to_velocity(a.start, a.target.v, a.target.a, &a.limits, shape)
                .map_err(on_axis(i))
        })
        .collect::<Result<_, _>>()?;
    if sync == Sync::None || axes.len() <= 1 {
        return Ok(fastest);
    }
    let t_min = fastest.iter().map(Profile::duration_s).fold(0.0, f64::max);
    if shape == Shape::Trapezoid {
        // A constant acceleration dv/T meets any duration from the fastest on.
        return axes
            .iter()
            .enumerate()
            .map(|(i, a)| {
                crate::duration::trapezoid_velocity_with_duration(
                    a.start, a.target.v, a.target.a, &a.limits, t_min,
                )
                .map_err(on_axis(i))?
                .ok_or(PlanError::NoSolution {
                    reason: "velocity-interface synchronisation of a trapezoid",
                })
            })
            .collect();
    }
    // Earliest common duration: the slowest axis's, unless another axis cannot meet it
    // (a blocked interval); then the next local-optimum duration of any axis.
    let mut candidates = vec![t_min];
    for a in axes {
        candidates.extend(
            crate::duration::velocity_branch_starts(a.start, a.target.v, a.target.a, &a.limits)
                .into_iter()
                .filter(|t| *t > t_min),
        );
    }
    candidates.sort_by(f64::total_cmp);
    candidates.dedup();
    for t in candidates {
        let profiles: Option<Vec<Profile>> = axes
            .iter()
            .map(|a| {
                crate::duration::velocity_with_duration(
                    a.start, a.target.v, a.target.a, &a.limits, t,
                )
                .ok()
                .flatten()
            })
            .collect();
        if let Some(p) = profiles {
            return Ok(p);
        }
    }
    Err(PlanError::NoSolution {
        reason: "no common duration found for velocity-interface synchronisation",
    })
}
