//! settle-sim: plant models driven by a commanded trajectory.
//!
//! A machine ([`machine::Machine`]: masses, belt or screw, mount, frame, motor, driver) is
//! compiled per axis into an [`AxisModel`]: a [`lumped::Lumped`] model of bodies and
//! spring-dampers plus how the command enters it (a linear driver spring, a spring to the
//! microstep-quantised command, or the full [`stepper`] driver). Every backend simulates
//! that same model behind the [`Plant`] trait:
//! - [`ModalPlant`]: the exact discretisation of the linear model (the reference);
//! - [`RapierPlant`]: rigid bodies in rapier3d (f64), couplings and driver as forces;
//! - `mujoco::MujocoPlant` (cargo feature `mujoco`): the model as MJCF, stepped by the
//!   MuJoCo library ([`mujoco_status`] says whether it is built).
//!
//! Backends never import each other: what they share (the explicit step bound, the start
//! equilibrium) is in [`numerics`]. [`closed_form`] gives the residual vibration
//! analytically, so the plants can be checked against an independent formula (the
//! measured modes of a free response come from settle-identify's matrix pencil).

mod axis;
pub mod closed_form;
mod error;
pub mod lumped;
pub mod machine;
mod modal;
mod modal_jump;
mod mode;
#[cfg(feature = "mujoco")]
pub mod mujoco;
pub mod mujoco_status;
pub mod numerics;
mod plant;
pub mod rapier;
mod rapier_driver;
pub mod stepper;

pub use axis::{AxisModel, DriverMode};
pub use error::SimError;
pub use modal::{ModalAxis, ModalPlant, ModalState};
pub use mode::Mode;
pub use plant::{InnerBreak, Observation, Plant, advance_sample, check_step};
pub use rapier::{BeltModel, RapierOptions, RapierPlant, RapierState};
