//! A planned move: what a firmware's planner hands to its step generator, as plain data.
//!
//! The toolhead travels a straight line; its *path speed* (m/s along the line) is a short
//! sequence of [`Phase`]s: a ramp up, a steady part, a ramp down, and for Marlin the short
//! holds its step-counted phase boundaries add. Each axis follows the path speed scaled by
//! its share of the move ([`PlannedMove::axes_r`]).

/// How the path speed changes over a [`Phase`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RampShape {
    /// Constant acceleration: `v = v0 + dv x`, `x = t / ramp_s`.
    Linear,
    /// Marlin's `S_CURVE_ACCELERATION` (stepper.cpp): the quintic Bezier
    /// `v = v0 + dv (10 x^3 - 15 x^4 + 6 x^5)`, `x = t / ramp_s`. It covers the same
    /// distance in the same time as the linear ramp, with peak acceleration `1.875 dv / T`.
    Bezier,
}

/// One piece of a move's path speed: a (possibly cut-short) ramp or a constant speed.
///
/// Over `0 <= t <= duration_s` the speed is `v0 + dv f(t / ramp_s)` with `f` of
/// [`RampShape`]; `duration_s <= ramp_s` (a ramp the firmware cuts short at a step count
/// has `duration_s < ramp_s`). A constant speed has `dv = 0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Phase {
    /// Time spent in the phase (s).
    pub duration_s: f64,
    /// Path speed at the phase start (m/s).
    pub v0_m_s: f64,
    /// Speed change of the whole ramp (m/s); 0 for a constant speed.
    pub dv_m_s: f64,
    /// Duration of the whole ramp (s); the phase may end before it.
    pub ramp_s: f64,
    /// Shape of the ramp.
    pub shape: RampShape,
}

/// Path kinematics at an instant of a phase or move.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PathState {
    /// Distance travelled along the path from the move start (m).
    pub s_m: f64,
    /// Path speed (m/s).
    pub v_m_s: f64,
    /// Path acceleration (m/s^2).
    pub a_m_s2: f64,
}

impl Phase {
    /// A constant speed `v_m_s` for `duration_s`.
    pub fn constant(duration_s: f64, v_m_s: f64) -> Self {
        Self {
            duration_s,
            v0_m_s: v_m_s,
            dv_m_s: 0.0,
            ramp_s: duration_s,
            shape: RampShape::Linear,
        }
    }

    /// Constant acceleration `accel_m_s2` (signed) from `v0_m_s` for `duration_s`.
    pub fn linear(duration_s: f64, v0_m_s: f64, accel_m_s2: f64) -> Self {
        Self {
            duration_s,
            v0_m_s,
            dv_m_s: accel_m_s2 * duration_s,
            ramp_s: duration_s,
            shape: RampShape::Linear,
        }
    }

    /// Path distance, speed and acceleration `tau` seconds into the phase.
    #[inline]
    pub fn state_at(&self, tau: f64) -> PathState {
        if self.dv_m_s == 0.0 || !(self.ramp_s > 0.0) {
            return PathState {
                s_m: self.v0_m_s * tau,
                v_m_s: self.v0_m_s,
                a_m_s2: 0.0,
            };
        }
        let t = self.ramp_s;
        let x = tau / t;
        let (f, df, big_f) = match self.shape {
            RampShape::Linear => (x, 1.0, 0.5 * x * x),
            RampShape::Bezier => {
                let x2 = x * x;
                let x3 = x2 * x;
                (
                    x3 * (10.0 + x * (-15.0 + 6.0 * x)),
                    30.0 * x2 * (1.0 + x * (-2.0 + x)),
                    x2 * x2 * (2.5 + x * (-3.0 + x)),
                )
            }
        };
        PathState {
            s_m: self.v0_m_s * tau + self.dv_m_s * t * big_f,
            v_m_s: self.v0_m_s + self.dv_m_s * f,
            a_m_s2: self.dv_m_s * df / t,
        }
    }

    /// Distance covered over the whole phase (m).
    pub fn distance_m(&self) -> f64 {
        self.state_at(self.duration_s).s_m
    }

    /// Path speed at the phase end (m/s).
    pub fn end_speed_m_s(&self) -> f64 {
        self.state_at(self.duration_s).v_m_s
    }
}

/// Most phases a planned move has (Marlin: ramp, hold, cruise, ramp, hold).
pub const MAX_PHASES: usize = 5;

/// One move as the firmware executes it: geometry, the summary every firmware reports
/// (start/cruise/end speed, acceleration, phase times) and the exact path speed
/// ([`Self::phases`]).
///
/// Times are on the firmware's print clock: `start_time_s` is the sum, in order, of every
/// earlier move's phase durations and dwells since the planner was created.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlannedMove {
    /// Index of the input move this plans (0-based, counting every move pushed, also those
    /// the firmware dropped or merged).
    pub seq: u64,
    /// Start time on the print clock (s).
    pub start_time_s: f64,
    /// Position of X, Y, Z (m) and the extruder (m of filament) at the move start.
    pub start_m: [f64; 4],
    /// Displacement of X, Y, Z and E per metre of path: the unit direction in XYZ for a
    /// move with XYZ motion (E then per metre of travel), `[0, 0, 0, +-1]` for an
    /// extruder-only move.
    pub axes_r: [f64; 4],
    /// Path length the speeds refer to (m).
    pub length_m: f64,
    /// Path speed at the start (m/s).
    pub start_speed_m_s: f64,
    /// Highest path speed of the move (m/s).
    pub cruise_speed_m_s: f64,
    /// Path speed at the end (m/s).
    pub end_speed_m_s: f64,
    /// Acceleration of the ramp up (m/s^2).
    pub accel_m_s2: f64,
    /// Deceleration of the ramp down (m/s^2, positive).
    pub decel_m_s2: f64,
    /// Time accelerating (s), including a firmware's hold at the top of the ramp.
    pub accel_t_s: f64,
    /// Time cruising (s).
    pub cruise_t_s: f64,
    /// Time decelerating (s), including a firmware's hold at the bottom of the ramp.
    pub decel_t_s: f64,
    /// Whether ramps follow Marlin's quintic Bezier ([`RampShape::Bezier`]).
    pub s_curve: bool,
    phases: [Phase; MAX_PHASES],
    n_phases: u8,
}

impl PlannedMove {
    /// A planned move from its geometry and phases (in time order, at most
    /// [`MAX_PHASES`]); the summary fields start at zero for the firmware to fill in.
    pub(crate) fn new(
        seq: u64,
        start_m: [f64; 4],
        axes_r: [f64; 4],
        length_m: f64,
        phases: &[Phase],
    ) -> Self {
        let mut p = [Phase::constant(0.0, 0.0); MAX_PHASES];
        let n = phases.len().min(MAX_PHASES);
        p[..n].copy_from_slice(&phases[..n]);
        Self {
            seq,
            start_time_s: 0.0,
            start_m,
            axes_r,
            length_m,
            start_speed_m_s: 0.0,
            cruise_speed_m_s: 0.0,
            end_speed_m_s: 0.0,
            accel_m_s2: 0.0,
            decel_m_s2: 0.0,
            accel_t_s: 0.0,
            cruise_t_s: 0.0,
            decel_t_s: 0.0,
            s_curve: false,
            phases: p,
            n_phases: n as u8,
        }
    }

    /// The path-speed phases, in time order.
    pub fn phases(&self) -> &[Phase] {
        &self.phases[..usize::from(self.n_phases)]
    }

    /// Duration (s): the phase durations summed in order.
    pub fn duration_s(&self) -> f64 {
        self.phases().iter().fold(0.0, |t, p| t + p.duration_s)
    }

    /// End time on the print clock (s).
    pub fn end_time_s(&self) -> f64 {
        self.phases()
            .iter()
            .fold(self.start_time_s, |t, p| t + p.duration_s)
    }

    /// Path state `tau` seconds after the move start (clamped to the move).
    pub fn path_at(&self, tau: f64) -> PathState {
        let mut s0 = 0.0;
        let mut t0 = 0.0;
        let phases = self.phases();
        for (i, p) in phases.iter().enumerate() {
            let last = i + 1 == phases.len();
            if tau < t0 + p.duration_s || last {
                let st = p.state_at((tau - t0).clamp(0.0, p.duration_s.max(0.0)));
                return PathState {
                    s_m: s0 + st.s_m,
                    ..st
                };
            }
            s0 += p.distance_m();
            t0 += p.duration_s;
        }
        PathState::default()
    }

    /// Position (m), velocity (m/s) and acceleration (m/s^2) of axis `axis` (0 = X, 1 = Y,
    /// 2 = Z, 3 = E) `tau` seconds after the move start.
    pub fn axis_at(&self, axis: usize, tau: f64) -> (f64, f64, f64) {
        let st = self.path_at(tau);
        let r = self.axes_r[axis];
        (self.start_m[axis] + r * st.s_m, r * st.v_m_s, r * st.a_m_s2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bezier_ramp_matches_the_linear_ramp_in_time_and_distance() {
        let lin = Phase {
            duration_s: 0.2,
            v0_m_s: 0.01,
            dv_m_s: 0.09,
            ramp_s: 0.2,
            shape: RampShape::Linear,
        };
        let bez = Phase {
            shape: RampShape::Bezier,
            ..lin
        };
        assert!((lin.distance_m() - bez.distance_m()).abs() < 1e-15);
        assert!((bez.end_speed_m_s() - 0.1).abs() < 1e-15);
        // Peak acceleration at mid-ramp: 1.875 dv / T.
        let a_mid = bez.state_at(0.1).a_m_s2;
        assert!((a_mid - 1.875 * 0.09 / 0.2).abs() < 1e-12);
        assert_eq!(bez.state_at(0.0).a_m_s2, 0.0);
        assert!(bez.state_at(0.2).a_m_s2.abs() < 1e-12);
    }
}
