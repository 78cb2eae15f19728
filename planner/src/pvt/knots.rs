//! A PVT move: knots `(t, x, v)` joined by linear-acceleration segments, as a [`Profile`].
//!
//! Position and velocity are continuous by construction; the acceleration is continuous
//! at a knot only if the two segments meeting there agree (the seed's moves are designed
//! so; [`Pvt::accel_jump`] and [`crate::pvt::check`] report it when not). A jump is written
//! as a zero-duration [`Segment::Accel`] in the profile (a jerk impulse).

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
    /// `(a_start, a_end)` of each segment (u/s^2), from the seed's formulas.
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
    /// with the acceleration `start_accel` before and `end_accel` after it.
    pub fn new(knots: Vec<Knot>, start_accel: f64, end_accel: f64) -> Result<Self, PlanError> {
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
        for (name, value) in [("start_accel", start_accel), ("end_accel", end_accel)] {
            if !value.is_finite() {
                return Err(PlanError::NonFinite { name, value });
            }
        }
        let mut acc = Vec::with_capacity(knots.len() - 1);
        let mut segs = Vec::with_capacity(2 * knots.len());
        let mut a = start_accel;
        for (i, w) in knots.windows(2).enumerate() {
            let dt = w[1].t_s - w[0].t_s;
            if dt.is_nan() || dt <= 0.0 {
                return Err(PlanError::InvalidSegment {
                    index: i,
                    reason: "knot times must increase strictly",
                });
            }
            let (a0, a1) = accels(w[0].x, w[0].v, w[1].x, w[1].v, dt);
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
            acc.push((a0, a1));
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

    /// Duration (s).
    pub fn duration_s(&self) -> f64 {
        self.profile.duration_s()
    }
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
