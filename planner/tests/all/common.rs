//! Shared helpers of the planner's integration tests.

use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Gamma, Normal};
use rsruckig::prelude::*;
use settle_planner::sync::Axis;
use settle_planner::{Limits, Profile, State};

/// One axis drawn like the Ruckig paper: p ~ N(0, 4), v and a ~ N(0, 0.8), limits ~
/// Gamma(2, 2) + 0.05.
#[allow(dead_code)]
pub fn draw_axis(rng: &mut ChaCha8Rng) -> Axis {
    let p = Normal::new(0.0, 4.0).expect("normal");
    let va = Normal::new(0.0, 0.8).expect("normal");
    let g = Gamma::new(2.0, 2.0).expect("gamma");
    let mut limit = || g.sample(rng) + 0.05;
    let limits = Limits::new(limit(), limit(), Some(limit())).expect("limits");
    let mut state = || State {
        p: p.sample(rng),
        v: va.sample(rng),
        a: va.sample(rng),
    };
    let (start, target) = (state(), state());
    Axis {
        limits,
        start,
        target,
    }
}

/// Does this axis start outside its limits, or bound to overshoot them (so it is braked)?
#[allow(dead_code)]
pub fn braked(a: &Axis) -> bool {
    let l = &a.limits;
    let j = l.jmax().unwrap_or(f64::INFINITY);
    let vz = a.start.v + a.start.a * a.start.a.abs() / (2.0 * j);
    a.start.a > l.amax()
        || a.start.a < l.amin()
        || a.start.v > l.vmax()
        || a.start.v < l.vmin()
        || vz > l.vmax()
        || vz < l.vmin()
}

/// Limits hold from the moment they first hold (a start outside them is braked back in).
/// Returns a description of the first violation. Rules (tolerance 1e-9 relative):
/// - jerk within `jmax` always;
/// - acceleration: once inside `[amin, amax]` it stays inside (it is linear in each segment,
///   so both ends of every segment are checked); outside it only at the start and moving
///   towards the limits;
/// - velocity, checked on the monotone pieces of every segment (split where the
///   acceleration crosses zero, so it cannot slip through the band inside a segment):
///   once the state is safe (v inside, and the velocity reached by ramping the acceleration
///   to zero at full jerk, vz, inside too) it stays inside. Before that the start may
///   overshoot (the side where vz, else v, is beyond the band): on that side it may rise no
///   higher than the start's own v or vz and, once it falls, never rise beyond the limit
///   again; beyond the other side only at the start and returning monotonically.
#[allow(dead_code)]
pub fn check_limits(prof: &Profile, lim: &Limits) -> Result<(), String> {
    let tol = 1e-9;
    let j = lim.jmax().unwrap_or(f64::INFINITY);
    let (vmax, vmin) = (lim.vmax() * (1.0 + tol), lim.vmin() * (1.0 + tol));
    let (amax, amin) = (lim.amax() * (1.0 + tol), lim.amin() * (1.0 + tol));
    let vtol = tol * lim.vmax().max(-lim.vmin());
    let vz_of = |st: &State| {
        if j.is_finite() {
            st.v + st.a * st.a.abs() / (2.0 * j)
        } else {
            st.v
        }
    };
    let s0 = prof.start();
    let mut a_in = s0.a <= amax && s0.a >= amin;
    let safe = |st: &State| {
        let vz = vz_of(st);
        st.v <= vmax && st.v >= vmin && vz <= vmax && vz >= vmin
    };
    let mut v_in = safe(&s0);
    // The overshoot direction of an unsafe start (+1 above vmax, -1 below vmin), in the
    // frame `d * v` where it is upwards; the band is then [lo, hi].
    let vz0 = vz_of(&s0);
    let d = if vz0 > vmax {
        1.0
    } else if vz0 < vmin {
        -1.0
    } else if s0.v > vmax {
        1.0
    } else {
        -1.0
    };
    let (lo, hi) = if d > 0.0 {
        (vmin, vmax)
    } else {
        (-vmax, -vmin)
    };
    // The highest velocity the overshoot may reach (mirrored frame).
    let peak = (d * s0.v).max(d * vz0) + vtol;
    // Still below the band from the start (allowed while it returns monotonically).
    let mut below = d * s0.v < lo;
    let mut fallen = false;
    for (t, s, seg) in prof.iter() {
        let (a0, jerk) = seg.accel_and_jerk(&s);
        if jerk.abs() > j * (1.0 + tol) {
            return Err(format!("jerk {jerk} at t={t}"));
        }
        let e = seg.end_state(&s);
        if seg.duration_s() == 0.0 {
            continue;
        }
        // Acceleration (linear in the segment: its ends bound it).
        if a_in {
            if a0 > amax || a0 < amin || e.a > amax || e.a < amin {
                return Err(format!("a = {a0} -> {} leaves the limits at t={t}", e.a));
            }
        } else {
            let towards = (a0 > amax && jerk < 0.0) || (a0 < amin && jerk > 0.0);
            if !towards {
                return Err(format!("a = {a0} outside the limits, not returning, t={t}"));
            }
            if e.a <= amax && e.a >= amin {
                a_in = true;
            }
        }
        // Velocity on monotone pieces.
        let mut ends = [s.v, e.v, e.v];
        let mut n = 2;
        if jerk != 0.0 {
            let tau = -a0 / jerk;
            if tau > 0.0 && tau < seg.duration_s() {
                ends[1] = seg.sample(&s, tau).v;
                n = 3;
            }
        }
        for w in ends[..n].windows(2) {
            let (va, vb) = (w[0], w[1]);
            if v_in {
                if vb > vmax || vb < vmin {
                    return Err(format!("v = {vb} leaves the limits near t={t}"));
                }
                continue;
            }
            // Mirrored frame: the overshoot is upwards.
            let (ma, mb) = (d * va, d * vb);
            if mb < lo {
                if !(below && mb > ma) {
                    return Err(format!(
                        "v = {va} -> {vb} beyond the side opposite the overshoot near t={t}"
                    ));
                }
            } else {
                below = false;
            }
            if mb > peak {
                return Err(format!(
                    "v = {vb} beyond the start's overshoot ({}) near t={t}",
                    d * peak
                ));
            }
            if mb < ma - vtol {
                fallen = true;
            } else if fallen && mb > hi && mb > ma + vtol {
                return Err(format!(
                    "v = {va} -> {vb} rises beyond the limit again near t={t}"
                ));
            }
        }
        if safe(&e) {
            v_in = true;
        }
    }
    Ok(())
}

/// One 1-DoF problem for rsruckig: duration, or `None` if rsruckig rejects it.
#[allow(dead_code)]
pub fn ruckig_1dof(
    start: &State,
    target: &State,
    lim: &Limits,
    velocity_interface: bool,
) -> Option<f64> {
    let mut otg = Ruckig::<1, ThrowErrorHandler>::new(None, 0.001);
    let mut input = InputParameter::new(None);
    if velocity_interface {
        input.control_interface = ControlInterface::Velocity;
    }
    input.current_position[0] = start.p;
    input.current_velocity[0] = start.v;
    input.current_acceleration[0] = start.a;
    input.target_position[0] = target.p;
    input.target_velocity[0] = target.v;
    input.target_acceleration[0] = target.a;
    input.max_velocity[0] = lim.vmax();
    input.max_acceleration[0] = lim.amax();
    input.max_jerk[0] = lim.jmax().unwrap_or(f64::INFINITY);
    if lim.vmin() != -lim.vmax() {
        input.min_velocity = Some(DataArrayOrVec::new(None, lim.vmin()));
    }
    if lim.amin() != -lim.amax() {
        input.min_acceleration = Some(DataArrayOrVec::new(None, lim.amin()));
    }
    let mut traj = Trajectory::new(None);
    otg.calculate(&input, &mut traj).ok()?;
    Some(traj.get_duration())
}
