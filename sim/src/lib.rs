//! settle-sim: plant models driven by a commanded trajectory.
//!
//! The reference backend is [`ModalPlant`]: one axis whose toolhead follows the command
//! through lightly damped base-excited modes, integrated exactly for piecewise
//! constant-jerk input. [`closed_form`] gives the residual vibration analytically, so the
//! plant can be checked against an independent formula.

pub mod closed_form;
mod error;
pub mod lumped;
mod modal;
mod mode;
#[cfg(feature = "mujoco")]
pub mod mujoco;
pub mod mujoco_status;
mod plant;

pub use error::SimError;
pub use modal::{ModalPlant, ModalState};
pub use mode::Mode;
pub use plant::{Observation, Plant};
