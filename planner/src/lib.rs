//! settle-planner: pure kinematics.
//!
//! Every planner returns a [`Profile`]: a start state plus a list of segments of constant
//! jerk (or, for jerk-unlimited profiles such as trapezoids, constant acceleration). One
//! evaluator, [`Profile::state_at`], serves sampling, plotting, simulation and output.
//! Several axes in time are a [`Trajectory`].
//!
//! What is where:
//! - one axis, rest to rest: [`scurve`] (7-phase S-curve), [`trapezoid`];
//! - one axis from any state to any target, time-optimal: [`position`] (step 1: brake, then
//!   the fastest of the cruise and the three-arc cases), [`duration`] (step 2: a profile
//!   of a given duration), [`velocity`] (velocity changes); derivations of the case
//!   polynomials in `planner/derivations/`;
//! - several axes: [`sync`] (each axis's fastest profile, all fitted to the slowest);
//! - four independent jerks: [`fourjerk`] (any state) and [`tmc`] (the TMC4361A ramp and
//!   its registers);
//! - [`pvt`] (PVT segments, turnarounds, step moves), [`raster`] (raster scans),
//!   [`path`] (polylines with corners, look-ahead);
//! - [`shaper`] (input shapers as Klipper, Marlin and RepRapFirmware compute them),
//!   [`shaper_select`] (Klipper's choice of a shaper from a resonance measurement);
//! - [`firmware`]: the firmwares by name ([`firmware::Firmware`]) and the planners of
//!   Klipper, Marlin and RepRapFirmware (a G-code job's moves as the printer runs them);
//! - [`ProfileKind`]: every profile kind by name, one entry point; [`ProfileParams`] the
//!   parameters of those that take any.
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
pub mod firmware;
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
mod runs;
pub mod scurve;
mod second_order;
mod segs;
pub mod shaper;
pub mod shaper_select;
pub mod sync;
pub mod tmc;
mod trajectory;
pub mod trapezoid;
mod udu;
mod udud;
mod unit;
pub mod velocity;

pub use error::PlanError;
pub use kind::{ProfileKind, ProfileParams};
pub use limits::Limits;
pub use profile::{Profile, Sample, Segment, State};
pub use trajectory::Trajectory;
