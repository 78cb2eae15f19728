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

/// Limits hold from the moment they first hold (a start outside them is braked back in):
/// jerk always; acceleration and velocity at every segment end and at interior velocity
/// extrema. Returns a description of the first violation.
#[allow(dead_code)]
pub fn check_limits(prof: &Profile, lim: &Limits) -> Result<(), String> {
    let tol = 1e-9;
    let j = lim.jmax().unwrap_or(f64::INFINITY);
    let (vmax, vmin) = (lim.vmax() * (1.0 + tol), lim.vmin() * (1.0 + tol));
    let (amax, amin) = (lim.amax() * (1.0 + tol), lim.amin() * (1.0 + tol));
    let s0 = prof.start();
    let mut a_in = s0.a <= amax && s0.a >= amin;
    // The velocity limit binds once the state is safe: v inside, and the velocity reached by
    // ramping the acceleration to zero (vz) inside too. Before that, exceeding it may be
    // unavoidable.
    let safe = |st: &State| {
        let vz = st.v + st.a * st.a.abs() / (2.0 * j);
        st.v <= vmax && st.v >= vmin && vz <= vmax && vz >= vmin
    };
    let mut v_in = safe(&s0);
    for (t, s, seg) in prof.iter() {
        let (a0, jerk) = seg.accel_and_jerk(&s);
        if jerk.abs() > j * (1.0 + tol) {
            return Err(format!("jerk {jerk} at t={t}"));
        }
        let e = seg.end_state(&s);
        let mut vs = vec![s.v, e.v];
        if jerk != 0.0 {
            let tau = -a0 / jerk;
            if tau > 0.0 && tau < seg.duration_s() {
                vs.push(seg.sample(&s, tau).v);
            }
        }
        for val in [a0, e.a] {
            if a_in && (val > amax || val < amin) {
                return Err(format!("a = {val} leaves the limits at t={t}"));
            }
            if val <= amax && val >= amin {
                a_in = true;
            }
        }
        for v in vs {
            if v_in && (v > vmax || v < vmin) {
                return Err(format!("v = {v} leaves the limits near t={t}"));
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
