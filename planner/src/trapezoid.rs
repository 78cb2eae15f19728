//! Time-optimal rest-to-rest velocity trapezoid (jerk unlimited).

use crate::{Limits, PlanError, Profile, Segment, State};

/// Plan the time-optimal trapezoid for a rest-to-rest move of signed `distance` from `p0`:
/// accelerate at `amax` to `vmax`, cruise, decelerate at `amax`. When the move is too short
/// to reach `vmax` (|d| < vmax^2/amax) the profile is triangular with peak speed
/// `sqrt(|d| amax)`. A zero-length move is an empty profile.
///
/// The acceleration steps are written as [`Segment::Accel`]; a final zero-duration segment
/// returns the acceleration to zero so the end state is at rest.
pub fn rest_to_rest(p0: f64, distance: f64, limits: &Limits) -> Result<Profile, PlanError> {
    finite("p0", p0)?;
    finite("distance", distance)?;
    let start = State {
        p: p0,
        v: 0.0,
        a: 0.0,
    };
    if distance == 0.0 {
        return Ok(Profile::empty(start));
    }
    let s = distance.signum();
    let d = distance.abs();
    let (vmax, amax) = (limits.vmax(), limits.amax());
    let (t_acc, t_cruise) = if d >= vmax * vmax / amax {
        (vmax / amax, d / vmax - vmax / amax)
    } else {
        ((d / amax).sqrt(), 0.0)
    };
    let mut segs = Vec::with_capacity(4);
    segs.push(Segment::Accel {
        duration_s: t_acc,
        accel: s * amax,
    });
    if t_cruise > 0.0 {
        segs.push(Segment::Accel {
            duration_s: t_cruise,
            accel: 0.0,
        });
    }
    segs.push(Segment::Accel {
        duration_s: t_acc,
        accel: -s * amax,
    });
    segs.push(Segment::Accel {
        duration_s: 0.0,
        accel: 0.0,
    });
    Profile::new(start, segs)
}

pub(crate) fn finite(name: &'static str, value: f64) -> Result<(), PlanError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(PlanError::NonFinite { name, value })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_values_cruise_and_triangle() {
        let lim = Limits::new(2.0, 4.0, None).expect("limits");
        // Cruise: d = 10, vmax^2/amax = 1 -> t_acc = 0.5, t_cruise = 10/2 - 0.5 = 4.5, T = 5.5.
        let p = rest_to_rest(1.0, 10.0, &lim).expect("plan");
        assert!((p.duration_s() - 5.5).abs() < 1e-12);
        assert!((p.end().p - 11.0).abs() < 1e-12);
        // Triangle: d = 0.25 < 1 -> t_acc = sqrt(0.25/4) = 0.25, peak speed 1.0.
        let p = rest_to_rest(0.0, -0.25, &lim).expect("plan");
        assert!((p.duration_s() - 0.5).abs() < 1e-12);
        assert!((p.state_at(0.25).v + 1.0).abs() < 1e-12);
        assert!((p.end().p + 0.25).abs() < 1e-15);
        assert_eq!(p.end().a, 0.0);
    }

    #[test]
    fn zero_move_is_empty() {
        let lim = Limits::new(1.0, 1.0, None).expect("limits");
        let p = rest_to_rest(3.0, 0.0, &lim).expect("plan");
        assert!(p.segments().is_empty());
        assert_eq!(p.duration_s(), 0.0);
        assert_eq!(p.state_at(1.0).p, 3.0);
    }
}
