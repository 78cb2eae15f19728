//! PVT moves: segments with linear acceleration between knots given by time,
//! position and velocity, their feasibility against limits, the raster turnarounds and the
//! symmetric and asymmetric step moves. Every move is also a [`crate::Profile`] (one
//! constant-jerk segment per PVT segment, plus a zero-length acceleration step where the
//! acceleration is discontinuous at a knot).

pub mod check;
mod knots;
pub mod segment;
pub mod step;
pub mod turnaround;

pub use check::{PvtLimit, PvtLimits, Violation, check, violations};
pub use knots::{Knot, Pvt};
