//! settle-planner: pure kinematics.
//!
//! Every planner returns a [`Profile`]: a start state plus a list of segments of constant
//! jerk (or, for jerk-unlimited profiles such as trapezoids, constant acceleration). One
//! evaluator, [`Profile::state_at`], serves sampling, plotting, simulation and output.
//!
//! No I/O, no clocks, no simulation types. Units are whatever the caller uses consistently
//! (settle's harness uses metres and seconds).

mod brake;
pub mod duration;
mod error;
pub mod fourjerk;
mod kind;
mod limits;
pub mod path;
pub mod position;
mod profile;
pub mod pvt;
pub mod raster;
mod roots;
pub mod scurve;
pub mod shaper;
mod stretch;
pub mod sync;
mod three_arc;
pub mod tmc;
mod trajectory;
pub mod trapezoid;
pub mod velocity;

pub use error::PlanError;
pub use kind::{KindParams, ProfileKind};
pub use limits::Limits;
pub use profile::{Profile, Sample, Segment, State};
pub use trajectory::Trajectory;
