//! settle-sim's integration tests, one test binary: each module below is one suite;
//! `common`, `lean_support` and `mujoco_support` are shared fixtures. The MuJoCo suites
//! need the `mujoco` cargo feature (`cargo test -p settle-sim --features mujoco`).

mod common;
#[cfg(feature = "mujoco")]
mod lean_support;
mod machine;
mod modal_samples;
mod modal_transition;
#[cfg(feature = "mujoco")]
mod mujoco_axis;
#[cfg(feature = "mujoco")]
mod mujoco_lean;
#[cfg(feature = "mujoco")]
mod mujoco_modes;
#[cfg(feature = "mujoco")]
mod mujoco_step_budget;
#[cfg(feature = "mujoco")]
mod mujoco_stepper;
#[cfg(feature = "mujoco")]
mod mujoco_support;
mod rapier;
mod rapier_full_step;
mod reference;
mod shaping;
mod stepper;
