//! Time-optimal rest-to-rest 7-phase jerk-limited S-curve.
//!
//! Phases: jerk up (+j), constant acceleration, jerk down (-j), cruise, jerk (-j), constant
//! deceleration, jerk (+j). Reduced cases, by the limits the move reaches:
//! - `acc_vel`: amax and vmax reached (full seven phases);
//! - `acc_no_vel`: amax reached, no cruise;
//! - `no_acc_vel`: vmax reached without reaching amax (no constant-acceleration phases);
//! - `no_acc_no_vel`: neither (four jerk phases only).

use crate::trapezoid::finite;
use crate::{Limits, PlanError, Profile, Segment, State};

/// Timing of a symmetric rest-to-rest S-curve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Timing {
    /// Duration of each of the four jerk phases (s).
    pub t_jerk: f64,
    /// Duration of each of the two constant-acceleration phases (s).
    pub t_const_acc: f64,
    /// Duration of the cruise phase (s).
    pub t_cruise: f64,
    /// Peak speed reached (units/s).
    pub v_peak: f64,
    /// Peak acceleration reached (units/s^2).
    pub a_peak: f64,
}

impl Timing {
    /// Total duration (s).
    pub fn duration_s(&self) -> f64 {
        4.0 * self.t_jerk + 2.0 * self.t_const_acc + self.t_cruise
    }
}

/// Time-optimal timing for a rest-to-rest move of length `d >= 0` under `vmax`, `amax`, `jmax`.
pub fn timing(d: f64, vmax: f64, amax: f64, jmax: f64) -> Timing {
    // Speed at which amax is just reached by an accel phase with no constant part.
    let v_amax = amax * amax / jmax;
    // Distance of accelerating to vmax and back to rest (no cruise).
    let d_vmax = if vmax >= v_amax {
        vmax * (vmax / amax + amax / jmax)
    } else {
        2.0 * vmax * (vmax / jmax).sqrt()
    };
    if d >= d_vmax {
        return acc_phase(vmax, amax, jmax, (d - d_vmax) / vmax);
    }
    // No cruise. Does the peak speed still reach amax? At v = v_amax the distance is 2 amax^3/j^2.
    if d >= 2.0 * amax * v_amax / jmax {
        // d = v^2/amax + v amax/jmax, solved in a cancellation-free form.
        let b = amax / jmax;
        let v = 2.0 * d / (b + (b * b + 4.0 * d / amax).sqrt());
        acc_phase(v, amax, jmax, 0.0)
    } else {
        let t_jerk = (d / (2.0 * jmax)).cbrt();
        Timing {
            t_jerk,
            t_const_acc: 0.0,
            t_cruise: 0.0,
            v_peak: jmax * t_jerk * t_jerk,
            a_peak: jmax * t_jerk,
        }
    }
}

/// The acceleration phase reaching speed `v` (rest to `v`) plus a given cruise time.
fn acc_phase(v: f64, amax: f64, jmax: f64, t_cruise: f64) -> Timing {
    if v * jmax >= amax * amax {
        Timing {
            t_jerk: amax / jmax,
            t_const_acc: v / amax - amax / jmax,
            t_cruise,
            v_peak: v,
            a_peak: amax,
        }
    } else {
        let t_jerk = (v / jmax).sqrt();
        Timing {
            t_jerk,
            t_const_acc: 0.0,
            t_cruise,
            v_peak: v,
            a_peak: jmax * t_jerk,
        }
    }
}

/// Plan the time-optimal S-curve for a rest-to-rest move of signed `distance` from `p0`.
/// Needs a jerk limit. A zero-length move is an empty profile.
pub fn rest_to_rest(p0: f64, distance: f64, limits: &Limits) -> Result<Profile, PlanError> {
    finite("p0", p0)?;
    finite("distance", distance)?;
    let jmax = limits
        .jmax()
        .ok_or(PlanError::MissingJerkLimit { kind: "scurve" })?;
    let start = State {
        p: p0,
        v: 0.0,
        a: 0.0,
    };
    if distance == 0.0 {
        return Ok(Profile::empty(start));
    }
    let tm = timing(distance.abs(), limits.vmax(), limits.amax(), jmax);
    let j = distance.signum() * jmax;
    let phases = [
        (tm.t_jerk, j),
        (tm.t_const_acc, 0.0),
        (tm.t_jerk, -j),
        (tm.t_cruise, 0.0),
        (tm.t_jerk, -j),
        (tm.t_const_acc, 0.0),
        (tm.t_jerk, j),
    ];
    let segs = phases
        .into_iter()
        .filter(|&(t, _)| t > 0.0)
        .map(|(duration_s, jerk)| Segment::Jerk { duration_s, jerk })
        .collect();
    Profile::new(start, segs)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lim() -> Limits {
        Limits::new(1.0, 2.0, Some(10.0)).expect("limits")
    }

    #[test]
    fn full_seven_phases_known_value() {
        // vmax 1, amax 2, jmax 10: t_jerk 0.2, t_const_acc 1/2 - 0.2 = 0.3,
        // d_vmax = 1*(0.5+0.2) = 0.7; d = 1.7 -> cruise 1.0; T = 0.8 + 0.6 + 1.0 = 2.4.
        let p = rest_to_rest(0.0, 1.7, &lim()).expect("plan");
        assert!((p.duration_s() - 2.4).abs() < 1e-12, "{}", p.duration_s());
        assert!((p.end().p - 1.7).abs() < 1e-12);
        assert_eq!(p.segments().len(), 7);
    }

    #[test]
    fn reduced_cases_have_the_right_phases() {
        // amax reached, no cruise: 2 amax^3/j^2 = 0.16 <= d < 0.7.
        let t = timing(0.5, 1.0, 2.0, 10.0);
        assert!(t.t_const_acc > 0.0 && t.t_cruise == 0.0 && t.a_peak == 2.0);
        // Neither: d < 0.16.
        let t = timing(0.1, 1.0, 2.0, 10.0);
        assert!(t.t_const_acc == 0.0 && t.t_cruise == 0.0 && t.a_peak < 2.0);
        assert!((2.0 * t.v_peak * 2.0 * t.t_jerk / 2.0 - 0.1).abs() < 1e-15);
        // vmax reached without amax: vmax 0.1 < amax^2/j = 0.4.
        let t = timing(1.0, 0.1, 2.0, 10.0);
        assert!(t.t_const_acc == 0.0 && t.t_cruise > 0.0 && t.a_peak < 2.0);
        assert!((t.v_peak - 0.1).abs() < 1e-15);
    }
}
