//! The MuJoCo backend (cargo feature `mujoco`): a [`crate::lumped::Lumped`] axis as an MJCF
//! model, stepped by the real MuJoCo 3.17 library through mujoco-rs.
//!
//! - [`MujocoModel`] compiles the lumped model (see `mjcf.rs` for how bodies, couplings,
//!   the command and the driver map onto MuJoCo) and steps a [`MujocoSim`] state: set the
//!   command sample, set the driver force, step, read `q`, `q'` and the toolhead.
//! - [`MujocoPlant`] is the [`crate::Plant`] adapter over it.
//!
//! The library comes from `scripts/setup-mujoco.sh` (into `.deps/mujoco/`); the build finds
//! it through `.cargo/config.toml` and the binaries through an rpath.

mod lean;
mod mjcf;
mod model;
mod per_sample;
mod plant;

pub use mjcf::{COMMAND_MASS_FACTOR, Integrator};
pub use model::{LONG_EXPLICIT_W_H, LONG_LAMBDA_H, MujocoConfig, MujocoModel, MujocoSim};
pub use plant::MujocoPlant;
