//! settle-planner: pure kinematics.
//!
//! Every planner returns a [`Profile`]: a start state plus a list of segments of constant
//! jerk (or, for jerk-unlimited profiles such as trapezoids, constant acceleration). One
//! evaluator, [`Profile::state_at`], serves sampling, plotting, simulation and output.
//!
//! No I/O, no clocks, no simulation types. Units are whatever the caller uses consistently
//! (settle's harness uses metres and seconds).

// `!(x >= 0.0)` is how the planner rejects NaN together with the out-of-range values it
// guards against; the "clearer" `x < 0.0` would let NaN through.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod brake;
mod case_poly;
pub mod duration;
mod error;
mod fastest;
mod fixed;
pub mod fourjerk;
mod jerk_arcs;
mod kind;
mod limits;
mod mixture;
#[cfg(test)]
mod oracle;
pub mod path;
pub mod position;
mod profile;
pub mod pvt;
mod ramp;
pub mod raster;
pub mod scurve;
mod second_order;
mod segs;
pub mod shaper;
pub mod sync;
pub mod tmc;
mod trajectory;
pub mod trapezoid;
mod udu;
mod udud;
mod unit;
pub mod velocity;

pub use error::PlanError;
pub use kind::{KindParams, ProfileKind};
pub use limits::Limits;
pub use profile::{Profile, Sample, Segment, State};
pub use trajectory::Trajectory;
