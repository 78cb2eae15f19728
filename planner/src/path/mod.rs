//! Paths through space: polylines whose points are *waypoints* (every axis stops there) or
//! *control points* (passed with non-zero speed), planned together with look-ahead.
//!
//! - [`Path`]: the validated polyline (2-D or 3-D).
//! - [`junction`]: corner speeds of GRBL's junction deviation and Klipper's square corner
//!   velocity (sharp corners).
//! - [`blend`]: the jerk-limited corner blend (the corner is rounded).
//! - [`law`]: how a segment changes speed between corners (attack, sustain, release):
//!   trapezoid, S-curve, four-jerk, or any [`law::SpeedLaw`].
//! - [`lookahead`]: backward and forward passes over the corners, producing a multi-axis
//!   [`crate::Trajectory`] with its [`PathGeometry`] attached.
//! - [`PathGeometry`], [`CornerRounding`]: contour error and corner rounding for metrics.
//!
//! **Angle convention** (used everywhere here, as in GRBL and Klipper): the corner
//! angle `theta` at a point is the *interior* angle between the two segments as drawn, the
//! angle between `p0 - p1` and `p2 - p1`: `cos(theta) = -u_in . u_out` for the unit travel
//! directions. `theta = pi` is a straight line (no corner), `theta = pi/2` a square corner,
//! `theta = 0` a full reversal. The *turn* (deflection) angle is `pi - theta`.
//!
//! Limits of a path plan are *vector* limits on the toolhead: speed `|v| <= vmax`,
//! `|a| <= amax`, `|j| <= jmax` (Euclidean norms), so every axis also stays within them.

pub mod blend;
mod bvh;
mod distance_poly;
mod fault;
mod geometry;
pub mod junction;
pub mod law;
pub mod lookahead;
mod pieces;
mod polyline;
mod rounding;
pub mod vector;
pub mod window;

pub use fault::PathFault;
pub use geometry::{CornerPlan, CornerTransition, PathGeometry, Primitive};
pub use lookahead::{CornerStrategy, Lookahead, PathOptions, plan_path};
pub use polyline::{Path, PathPoint, PointKind, interior_angle};
pub use rounding::CornerRounding;
