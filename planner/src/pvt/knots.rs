//! A PVT move: knots `(t, x, v)` joined by linear-acceleration segments, as a [`Profile`].
//!
//! Position and velocity are continuous by construction; the acceleration is continuous
//! at a knot only if the two segments meeting there agree (the turnarounds and step moves
//! of this module are designed so; [`Pvt::accel_jump`] and [`crate::pvt::check()`] report it
//! when not). A jump is written as a zero-duration [`Segment::Accel`] in the profile (a
//! jerk impulse), a segment of constant acceleration as a [`Segment::Accel`] of its
//! duration.

use crate::pvt::segment::accels;
use crate::{PlanError, Profile, Segment, State};

/// A PVT knot.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Knot {
    /// Time (s).
    pub t_s: f64,
    /// Position (u).
    pub x: f64,
    /// Velocity (u/s).
    pub v: f64,
}

impl Knot {
    /// A knot at time `t_s` (s), position `x` (u), velocity `v` (u/s).
    pub fn new(t_s: f64, x: f64, v: f64) -> Self {
        Self { t_s, x, v }
    }
}

/// A PVT move.
#[derive(Debug, Clone, PartialEq)]
pub struct Pvt {
    /// The knots, times strictly increasing.
    pub knots: Vec<Knot>,
    /// `(a_start, a_end)` of each segment (u/s^2), from [`crate::pvt::segment::accels`].
    pub accels: Vec<(f64, f64)>,
    /// Acceleration before the first knot (u/s^2; 0 for a move from rest).
    pub start_accel: f64,
    /// Acceleration after the last knot (u/s^2; 0 for a move that ends at rest).
    pub end_accel: f64,
    /// The move as a profile starting at the first knot's time (t = 0 there).
    pub profile: Profile,
}

impl Pvt {
    /// A move through `knots` (at least two, times strictly increasing, values finite),
    /// with the acceleration `start_accel` before and `end_accel` after it. Each segment's
    /// accelerations come from its knots ([`crate::pvt::segment::accels`]).
    pub fn new(knots: Vec<Knot>, start_accel: f64, end_accel: f64) -> Result<Self, PlanError> {
        validate(&knots, start_accel, end_accel)?;
        let acc = knots
            .windows(2)
            .map(|w| accels(w[0].x, w[0].v, w[1].x, w[1].v, w[1].t_s - w[0].t_s))
            .collect();
        Self::build(knots, acc, start_accel, end_accel)
    }

    /// A move through `knots` whose segment accelerations are known exactly (a planner
    /// that designed them): they must agree with the knots up to the rounding of the knot
    /// data, and the profile uses them rather than the values recomputed from rounded
    /// knots, so it ends on the last knot as exactly as the planner computed it.
    pub fn with_accels(
        knots: Vec<Knot>,
        acc: Vec<(f64, f64)>,
        start_accel: f64,
        end_accel: f64,
    ) -> Result<Self, PlanError> {
        validate(&knots, start_accel, end_accel)?;
        if acc.len() + 1 != knots.len() {
            return Err(PlanError::InvalidInput {
                reason: "one (start, end) acceleration pair per PVT segment",
            });
        }
        let xs = knots.iter().fold(0.0f64, |s, k| s.max(k.x.abs()));
        let vs = knots.iter().fold(0.0f64, |s, k| s.max(k.v.abs()));
        let a_scale = acc
            .iter()
            .fold(0.0f64, |s, a| s.max(a.0.abs()).max(a.1.abs()));
        for (i, (w, a)) in knots.windows(2).zip(&acc).enumerate() {
            let dt = w[1].t_s - w[0].t_s;
            let (b0, b1) = accels(w[0].x, w[0].v, w[1].x, w[1].v, dt);
            let tol = 1e-9 * a_scale + 16.0 * f64::EPSILON * (6.0 * xs / (dt * dt) + 6.0 * vs / dt);
            if (a.0 - b0).abs() > tol || (a.1 - b1).abs() > tol {
                return Err(PlanError::InvalidSegment {
                    index: i,
                    reason: "the given accelerations disagree with the PVT knots",
                });
            }
        }
        Self::build(knots, acc, start_accel, end_accel)
    }

    fn build(
        knots: Vec<Knot>,
        acc: Vec<(f64, f64)>,
        start_accel: f64,
        end_accel: f64,
    ) -> Result<Self, PlanError> {
        let mut segs = Vec::with_capacity(2 * knots.len());
        let mut a = start_accel;
        for (w, &(a0, a1)) in knots.windows(2).zip(&acc) {
            let dt = w[1].t_s - w[0].t_s;
            if a0 == a1 {
                // Constant acceleration (a hold, a cruise): written as such, so the
                // rounding of the jerk phase before it is not carried over a long time.
                segs.push(Segment::Accel {
                    duration_s: dt,
                    accel: a0,
                });
            } else {
                if a0 != a {
                    segs.push(Segment::Accel {
                        duration_s: 0.0,
                        accel: a0,
                    });
                }
                segs.push(Segment::Jerk {
                    duration_s: dt,
                    jerk: (a1 - a0) / dt,
                });
            }
            a = a1;
        }
        if end_accel != a {
            segs.push(Segment::Accel {
                duration_s: 0.0,
                accel: end_accel,
            });
        }
        let k0 = knots[0];
        let profile = Profile::new(
            State {
                p: k0.x,
                v: k0.v,
                a: start_accel,
            },
            segs,
        )?;
        Ok(Self {
            knots,
            accels: acc,
            start_accel,
            end_accel,
            profile,
        })
    }

    /// Acceleration jump at knot `k` (u/s^2): the acceleration after it minus before it
    /// (the start/end accelerations outside the move).
    pub fn accel_jump(&self, k: usize) -> f64 {
        let before = if k == 0 {
            self.start_accel
        } else {
            self.accels[k - 1].1
        };
        let after = if k == self.accels.len() {
            self.end_accel
        } else {
            self.accels[k].0
        };
        after - before
    }

    /// The same move shifted by `dx` in position. The accelerations (and the profile's
    /// segments) are kept exactly: a move planned near the origin and shifted keeps the
    /// precision its knots had there, which knots far from the origin lose.
    pub fn shifted(mut self, dx: f64) -> Result<Self, PlanError> {
        for k in &mut self.knots {
            k.x += dx;
        }
        let mut start = self.profile.start();
        start.p += dx;
        self.profile = Profile::new(start, self.profile.segments().to_vec())?;
        Ok(self)
    }

    /// Duration (s).
    pub fn duration_s(&self) -> f64 {
        self.profile.duration_s()
    }
}

fn validate(knots: &[Knot], start_accel: f64, end_accel: f64) -> Result<(), PlanError> {
    if knots.len() < 2 {
        return Err(PlanError::InvalidInput {
            reason: "a PVT move needs at least two knots",
        });
    }
    for (i, k) in knots.iter().enumerate() {
        if !(k.t_s.is_finite() && k.x.is_finite() && k.v.is_finite()) {
            return Err(PlanError::InvalidSegment {
                index: i,
                reason: "knot time, position and velocity must be finite",
            });
        }
    }
    for (i, w) in knots.windows(2).enumerate() {
        let dt = w[1].t_s - w[0].t_s;
        if dt.is_nan() || dt <= 0.0 {
            return Err(PlanError::InvalidSegment {
                index: i,
                reason: "knot times must increase strictly",
            });
        }
    }
    for (name, value) in [("start_accel", start_accel), ("end_accel", end_accel)] {
        if !value.is_finite() {
            return Err(PlanError::NonFinite { name, value });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn profile_passes_through_the_knots() {
        let knots = vec![
            Knot::new(0.0, 0.0, 0.0),
            Knot::new(0.5, 0.1, 0.6),
            Knot::new(1.2, 0.7, 0.2),
            Knot::new(2.0, 1.0, 0.0),
        ];
        let m = Pvt::new(knots.clone(), 0.0, 0.0).expect("pvt");
        for k in &knots {
            let s = m.profile.state_at(k.t_s - knots[0].t_s);
            assert!((s.p - k.x).abs() < 1e-12 && (s.v - k.v).abs() < 1e-12);
        }
        assert!(Pvt::new(vec![knots[0], knots[0]], 0.0, 0.0).is_err());
    }
}
