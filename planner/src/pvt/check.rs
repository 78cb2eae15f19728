//! Feasibility of a PVT move against kinematic limits: which limit is violated, where, by
//! how much.
//!
//! Within a segment the acceleration is linear, so its extremes are at the knots; the
//! velocity is quadratic, so its extremes are at the knots or where the acceleration
//! crosses zero inside the segment; the jerk is constant per segment. An acceleration jump
//! at a knot is an infinite jerk: reported separately (tolerance `accel_jump_tol`).

use crate::pvt::Pvt;
use crate::{PlanError, Segment, State};

/// Limits a PVT move is checked against (symmetric; magnitudes).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PvtLimits {
    /// Speed limit (u/s).
    pub vmax: f64,
    /// Acceleration limit (u/s^2).
    pub amax: f64,
    /// Jerk limit (u/s^3); `None`: unlimited.
    pub jmax: Option<f64>,
    /// Largest acceleration jump tolerated at a knot (u/s^2); 0 requires continuity up
    /// to rounding (relative 1e-9 of `amax`).
    pub accel_jump_tol: f64,
}

/// Which limit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PvtLimit {
    /// |v| > vmax inside segment `at`.
    Velocity,
    /// |a| > amax at knot `at`.
    Acceleration,
    /// |j| > jmax over segment `at`.
    Jerk,
    /// Acceleration discontinuous at knot `at`.
    AccelerationJump,
}

impl PvtLimit {
    /// Short description, also the `reason` of the [`PlanError`].
    pub fn describe(self) -> &'static str {
        match self {
            PvtLimit::Velocity => "PVT segment exceeds vmax",
            PvtLimit::Acceleration => "PVT knot exceeds amax",
            PvtLimit::Jerk => "PVT segment exceeds jmax",
            PvtLimit::AccelerationJump => "PVT acceleration jumps at this knot",
        }
    }
}

/// One violated limit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Violation {
    /// Which limit.
    pub limit: PvtLimit,
    /// Knot index (acceleration, jump) or segment index (velocity, jerk; segment `k` joins
    /// knots `k` and `k + 1`).
    pub at: usize,
    /// The offending value (magnitude).
    pub value: f64,
    /// The limit it exceeds.
    pub bound: f64,
}

impl Violation {
    /// As the crate's error type (`InvalidSegment` with the index and the limit).
    pub fn to_error(self) -> PlanError {
        PlanError::InvalidSegment {
            index: self.at,
            reason: self.limit.describe(),
        }
    }
}

impl std::fmt::Display for Violation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let what = match self.limit {
            PvtLimit::Velocity | PvtLimit::Jerk => "segment",
            _ => "knot",
        };
        write!(
            f,
            "{} ({what} {}): {} > {}",
            self.limit.describe(),
            self.at,
            self.value,
            self.bound
        )
    }
}

/// Every violation, in the order knots/segments appear (relative tolerance 1e-9).
pub fn violations(m: &Pvt, lim: &PvtLimits) -> Vec<Violation> {
    let tol = 1e-9;
    let mut out = Vec::new();
    let jump_tol = lim.accel_jump_tol.max(tol * lim.amax);
    for k in 0..m.knots.len() {
        let jump = m.accel_jump(k).abs();
        if jump > jump_tol {
            out.push(Violation {
                limit: PvtLimit::AccelerationJump,
                at: k,
                value: jump,
                bound: jump_tol,
            });
        }
        let mut a_max = 0.0f64;
        if k > 0 {
            a_max = a_max.max(m.accels[k - 1].1.abs());
        }
        if k < m.accels.len() {
            a_max = a_max.max(m.accels[k].0.abs());
        }
        if a_max > lim.amax * (1.0 + tol) {
            out.push(Violation {
                limit: PvtLimit::Acceleration,
                at: k,
                value: a_max,
                bound: lim.amax,
            });
        }
        if k + 1 == m.knots.len() {
            break;
        }
        let (w0, w1) = (m.knots[k], m.knots[k + 1]);
        let dt = w1.t_s - w0.t_s;
        let (a0, a1) = m.accels[k];
        let jerk = (a1 - a0) / dt;
        if let Some(jmax) = lim.jmax
            && jerk.abs() > jmax * (1.0 + tol)
        {
            out.push(Violation {
                limit: PvtLimit::Jerk,
                at: k,
                value: jerk.abs(),
                bound: jmax,
            });
        }
        let mut v = w0.v.abs().max(w1.v.abs());
        if jerk != 0.0 {
            let tau = -a0 / jerk;
            if tau > 0.0 && tau < dt {
                let seg = Segment::Jerk {
                    duration_s: dt,
                    jerk,
                };
                let from = State {
                    p: w0.x,
                    v: w0.v,
                    a: a0,
                };
                v = v.max(seg.sample(&from, tau).v.abs());
            }
        }
        if v > lim.vmax * (1.0 + tol) {
            out.push(Violation {
                limit: PvtLimit::Velocity,
                at: k,
                value: v,
                bound: lim.vmax,
            });
        }
    }
    out
}

/// The first violation, if any.
pub fn check(m: &Pvt, lim: &PvtLimits) -> Result<(), Violation> {
    match violations(m, lim).first() {
        Some(v) => Err(*v),
        None => Ok(()),
    }
}
