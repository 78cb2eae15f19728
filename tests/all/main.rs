//! The root crate's end-to-end tests, one test binary: `cargo test --test all` (with
//! `--features mujoco` for the MuJoCo cases, `--features rerun` for the rerun sink).

mod support;

mod cli;
mod corners;
mod faults;
mod gcode_job;
mod layers;
mod machines;
mod outputs_check;
mod outputs_mcap;
mod outputs_plots;
mod outputs_shard;
mod pipeline_reference;
mod plan_cli;
#[cfg(feature = "rerun")]
mod rerun;
mod scan_asym;
mod scan_reference;
mod scenarios;
mod shaping_sweep;
mod step_samples;
mod tune;
mod tune_scan;
mod validate;
mod workflows;
