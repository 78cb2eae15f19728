//! Feasibility of a PVT move against kinematic limits: which limit is violated, where, by
//! how much.
//!
//! Within a segment the acceleration is linear, so its extremes are at the knots; the
//! velocity is quadratic, so its extremes are at the knots or where the acceleration
//! crosses zero inside the segment; the jerk is constant per segment. An acceleration jump
//! at a knot is an infinite jerk: reported separately (tolerance `accel_jump_tol`).
//!
//! Tolerances: limits are compared with a relative slack of 1e-9, plus the rounding of
//! the knot data itself. A segment's accelerations follow from its knots as
//! `6 (x1 - x0)/t^2 - ...`, so rounding of positions of magnitude `|x|` leaves them
//! uncertain by about `eps (6 |x|/t^2 + 6 |v|/t)` (taken 8 times, `eps` = f64 epsilon,
//! `|x|` and `|v|` the largest of the move): a small step far from the origin over a short
//! segment cannot be more precise than that.

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
            PvtLimit::Acceleration => "PVT knot with this index exceeds amax",
            PvtLimit::Jerk => "PVT segment exceeds jmax",
            PvtLimit::AccelerationJump => "PVT acceleration jumps at the knot with this index",
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

/// Uncertainty of segment `k`'s accelerations from the rounding of the knot data (u/s^2).
/// Knot positions are usually computed as offsets from somewhere in the move, so their
/// rounding is that of the largest position magnitude of the move, not of their own.
fn rounding(m: &Pvt, k: usize, xs: f64, vs: f64) -> f64 {
    let dt = m.knots[k + 1].t_s - m.knots[k].t_s;
    8.0 * f64::EPSILON * (6.0 * xs / (dt * dt) + 6.0 * vs / dt)
}

/// Every violation, in the order knots/segments appear.
pub fn violations(m: &Pvt, lim: &PvtLimits) -> Vec<Violation> {
    let tol = 1e-9;
    let mut out = Vec::new();
    let n_seg = m.accels.len();
    let xs = m.knots.iter().fold(0.0f64, |s, k| s.max(k.x.abs()));
    let vs = m.knots.iter().fold(0.0f64, |s, k| s.max(k.v.abs()));
    for k in 0..m.knots.len() {
        let round = (if k > 0 {
            rounding(m, k - 1, xs, vs)
        } else {
            0.0
        }) + (if k < n_seg {
            rounding(m, k, xs, vs)
        } else {
            0.0
        });
        let jump_tol = lim.accel_jump_tol.max(tol * lim.amax) + round;
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
        if a_max > lim.amax * (1.0 + tol) + round {
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
            && jerk.abs() > jmax * (1.0 + tol) + 2.0 * rounding(m, k, xs, vs) / dt
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
