//! Paths through space: polylines whose points are *waypoints* (every axis stops there) or
//! *control points* (passed with non-zero speed), planned together with look-ahead.
//!
//! - [`Path`]: the validated polyline (2-D or 3-D).
//! - [`junction`]: corner speeds of GRBL's junction deviation and Klipper's square corner
//!   velocity (sharp corners).
//! - [`blend`]: seed 001's jerk-limited corner blend (the corner is rounded).
//! - [`law`]: how a segment changes speed between corners (attack, sustain, release of
//!   seed 002): trapezoid, S-curve, four-jerk, or any [`law::SpeedLaw`].
//! - [`lookahead`]: backward and forward passes over the corners, producing a multi-axis
//!   [`crate::Trajectory`] with its [`PathGeometry`] attached.
//! - [`PathGeometry`], [`CornerRounding`]: contour error and corner rounding for metrics.
//!
//! **Angle convention** (used everywhere here, as in seed 001, GRBL and Klipper): the corner
//! angle `theta` at a point is the *interior* angle between the two segments as drawn, the
//! angle between `p0 - p1` and `p2 - p1`: `cos(theta) = -u_in . u_out` for the unit travel
//! directions. `theta = pi` is a straight line (no corner), `theta = pi/2` a square corner,
//! `theta = 0` a full reversal. The *turn* (deflection) angle is `pi - theta`.
//!
//! Limits of a path plan are *vector* limits on the toolhead: speed `|v| <= vmax`,
//! `|a| <= amax`, `|j| <= jmax` (Euclidean norms), so every axis also stays within them.

pub mod blend;
mod bvh;
mod geometry;
pub mod junction;
pub mod law;
pub mod lookahead;
mod pieces;
mod poly;
mod rounding;
pub mod vector;
pub mod window;

pub use geometry::{CornerPlan, CornerTransition, PathGeometry, Primitive};
pub use lookahead::{CornerStrategy, Lookahead, PathOptions, plan_path};
pub use rounding::CornerRounding;

use crate::PlanError;
use vector::{V3, dist, norm, scale, sub};

/// What a path point asks of the motion.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PointKind {
    /// Every axis comes to rest exactly on this point.
    Waypoint,
    /// The path aims for this point and passes it with non-zero speed where the corner
    /// strategy allows (within the strategy's tolerance of the point). The first and the
    /// last point of a path are always stops.
    Control,
}

/// One point of a path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathPoint {
    /// Position (m); `z = 0` on 2-D paths.
    pub position: V3,
    /// Waypoint or control point.
    pub kind: PointKind,
}

impl PathPoint {
    /// A waypoint at `position` (m).
    pub fn waypoint(position: V3) -> Self {
        Self {
            position,
            kind: PointKind::Waypoint,
        }
    }

    /// A control point at `position` (m).
    pub fn control(position: V3) -> Self {
        Self {
            position,
            kind: PointKind::Control,
        }
    }
}

/// What is wrong with a path (carried by [`PlanError::InvalidPath`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PathFault {
    /// A path needs at least two points.
    TooFewPoints {
        /// How many points were given.
        count: usize,
    },
    /// Paths are 2-D or 3-D.
    Dimension {
        /// The dimension given.
        dim: usize,
    },
    /// A coordinate is NaN or infinite.
    NonFinite {
        /// 0-based point index.
        index: usize,
        /// 0-based axis (0 = x, 1 = y, 2 = z).
        axis: usize,
        /// The offending value.
        value: f64,
    },
    /// A 2-D path point has a non-zero z.
    OffPlane {
        /// 0-based point index.
        index: usize,
        /// Its z.
        z: f64,
    },
    /// A point coincides with the one before it (zero-length segment, no direction).
    Coincident {
        /// 0-based index of the second of the two points.
        index: usize,
    },
}

impl std::fmt::Display for PathFault {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            PathFault::TooFewPoints { count } => {
                write!(f, "a path needs at least 2 points, got {count}")
            }
            PathFault::Dimension { dim } => {
                write!(f, "a path is 2-D or 3-D, got dimension {dim}")
            }
            PathFault::NonFinite { index, axis, value } => write!(
                f,
                "point {index}: coordinate {} must be finite, got {value}",
                ["x", "y", "z"][axis.min(2)]
            ),
            PathFault::OffPlane { index, z } => {
                write!(f, "point {index}: a 2-D path needs z = 0, got z = {z}")
            }
            PathFault::Coincident { index } => write!(
                f,
                "point {index} coincides with point {} (zero-length segment)",
                index.saturating_sub(1)
            ),
        }
    }
}

fn invalid(fault: PathFault) -> PlanError {
    PlanError::InvalidPath { fault }
}

/// A validated polyline: at least two points, finite, no two consecutive points equal.
#[derive(Debug, Clone, PartialEq)]
pub struct Path {
    dim: usize,
    points: Vec<PathPoint>,
}

/// Two consecutive points closer than this (relative to their magnitude, plus 1e-12
/// absolute) count as coincident: the segment has no meaningful direction.
const COINCIDENT_REL: f64 = 1e-12;

impl Path {
    /// A path of dimension `dim` (2 or 3) through `points`.
    pub fn new(dim: usize, points: Vec<PathPoint>) -> Result<Self, PlanError> {
        if dim != 2 && dim != 3 {
            return Err(invalid(PathFault::Dimension { dim }));
        }
        if points.len() < 2 {
            return Err(invalid(PathFault::TooFewPoints {
                count: points.len(),
            }));
        }
        let mut path = Path {
            dim,
            points: Vec::with_capacity(points.len()),
        };
        for p in points {
            path.push(p)?;
        }
        Ok(path)
    }

    /// Append a point (validated against the last one).
    pub fn push(&mut self, point: PathPoint) -> Result<(), PlanError> {
        let index = self.points.len();
        for (axis, &value) in point.position.iter().enumerate() {
            if !value.is_finite() {
                return Err(invalid(PathFault::NonFinite { index, axis, value }));
            }
        }
        if self.dim == 2 && point.position[2] != 0.0 {
            return Err(invalid(PathFault::OffPlane {
                index,
                z: point.position[2],
            }));
        }
        if let Some(last) = self.points.last() {
            let scale_m = 1.0 + norm(last.position).max(norm(point.position));
            if dist(last.position, point.position) <= COINCIDENT_REL * scale_m {
                return Err(invalid(PathFault::Coincident { index }));
            }
        }
        self.points.push(point);
        Ok(())
    }

    /// Two segments of length `leg_m` meeting at the interior angle `theta_rad` (see the
    /// module doc: `pi` straight, `pi/2` square, `0` reversal) at a control point at the
    /// origin. The first segment runs along +x from `(-leg_m, 0)`; the path turns left.
    /// This is the corner-angle sweep's path.
    pub fn corner(theta_rad: f64, leg_m: f64) -> Result<Self, PlanError> {
        let turn = std::f64::consts::PI - theta_rad;
        let out = [turn.cos(), turn.sin(), 0.0];
        Path::new(
            2,
            vec![
                PathPoint::waypoint([-leg_m, 0.0, 0.0]),
                PathPoint::control([0.0, 0.0, 0.0]),
                PathPoint::waypoint(scale(out, leg_m)),
            ],
        )
    }

    /// Dimension (2 or 3): the number of axes of the planned trajectory.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// The points.
    pub fn points(&self) -> &[PathPoint] {
        &self.points
    }

    /// Number of segments (points - 1).
    pub fn segment_count(&self) -> usize {
        self.points.len() - 1
    }

    /// Length of segment `i` (from point `i` to point `i + 1`), m.
    pub fn segment_length(&self, i: usize) -> f64 {
        dist(self.points[i].position, self.points[i + 1].position)
    }

    /// Unit direction of segment `i`.
    pub fn direction(&self, i: usize) -> V3 {
        let d = sub(self.points[i + 1].position, self.points[i].position);
        scale(d, 1.0 / norm(d))
    }

    /// Interior angle (rad) at interior point `k` (1..len-1), see the module doc.
    pub fn interior_angle(&self, k: usize) -> f64 {
        interior_angle(self.direction(k - 1), self.direction(k))
    }
}

/// Interior angle (rad, in `[0, pi]`) between an incoming and an outgoing unit direction:
/// `cos(theta) = -u_in . u_out`. Computed from the half-angle chord lengths (accurate near
/// both 0 and pi, where `acos` loses digits).
pub fn interior_angle(u_in: V3, u_out: V3) -> f64 {
    // |u_in + u_out| = 2 sin(theta/2), |u_out - u_in| = 2 cos(theta/2).
    let s = norm(vector::add(u_in, u_out));
    let c = norm(sub(u_out, u_in));
    2.0 * s.atan2(c)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validation_errors_are_typed() {
        let p = |x: f64, y: f64| PathPoint::waypoint([x, y, 0.0]);
        assert_eq!(
            Path::new(2, vec![p(0.0, 0.0)]),
            Err(PlanError::InvalidPath {
                fault: PathFault::TooFewPoints { count: 1 }
            })
        );
        assert_eq!(
            Path::new(2, vec![p(0.0, 0.0), p(1.0, 0.0), p(1.0, 0.0)]),
            Err(PlanError::InvalidPath {
                fault: PathFault::Coincident { index: 2 }
            })
        );
        let e = Path::new(3, vec![p(0.0, 0.0), p(f64::NAN, 1.0)]).expect_err("NaN");
        assert!(matches!(
            e,
            PlanError::InvalidPath {
                fault: PathFault::NonFinite {
                    index: 1,
                    axis: 0,
                    ..
                }
            }
        ));
        assert_eq!(
            e.to_string(),
            "invalid path: point 1: coordinate x must be finite, got NaN"
        );
        assert!(matches!(
            Path::new(2, vec![p(0.0, 0.0), PathPoint::control([1.0, 0.0, 0.5])]),
            Err(PlanError::InvalidPath {
                fault: PathFault::OffPlane { index: 1, .. }
            })
        ));
        assert!(matches!(
            Path::new(4, vec![p(0.0, 0.0), p(1.0, 0.0)]),
            Err(PlanError::InvalidPath {
                fault: PathFault::Dimension { dim: 4 }
            })
        ));
    }

    #[test]
    fn corner_helper_has_the_requested_interior_angle() {
        for deg in [0.0_f64, 15.0, 45.0, 90.0, 135.0, 180.0] {
            let path = Path::corner(deg.to_radians(), 0.05).expect("path");
            let theta = path.interior_angle(1);
            assert!((theta - deg.to_radians()).abs() < 1e-12, "{deg}: {theta}");
            assert!((path.segment_length(1) - 0.05).abs() < 1e-15);
        }
        // Square corner: out along +y.
        let path = Path::corner(std::f64::consts::FRAC_PI_2, 1.0).expect("path");
        let d = path.direction(1);
        assert!(d[0].abs() < 1e-15 && (d[1] - 1.0).abs() < 1e-15);
    }
}
