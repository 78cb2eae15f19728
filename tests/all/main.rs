//! The root crate's end-to-end tests, one test binary: `cargo test --test all` (with
//! `--features mujoco` for the MuJoCo cases, `--features rerun` for the rerun sink).

mod support;

mod across_breakpoints;
#[cfg(target_os = "linux")]
mod adversarial;
mod cli;
mod corners;
mod export_roundtrip;
mod faults;
mod gcode_bgcode;
mod gcode_config;
mod gcode_grbl;
mod gcode_job;
mod gcode_layer_source;
mod gcode_range;
mod gcode_range_random;
mod gcode_split;
mod gcode_stream;
mod hardening_input;
mod html_report;
mod identify_cmd;
mod identify_unfaithful;
mod import;
mod import_marlin;
mod import_roundtrip;
mod klipper_corpus;
mod layers;
mod limits;
mod machine_cmd;
mod machines;
mod modes_axes;
mod module_graph;
mod outputs_check;
mod outputs_mcap;
mod outputs_plots;
mod outputs_ranking;
mod outputs_shard;
mod pipeline_reference;
mod plan_cli;
#[cfg(feature = "rerun")]
mod rerun;
mod scan_asym;
mod scan_reference;
mod scan_views;
mod scenarios;
mod shaping_sweep;
mod shards_kubernetes;
mod step_samples;
mod sweep_repeats;
mod sweep_runs;
mod sweep_safety;
mod tune;
mod tune_firmware;
mod tune_klipper;
mod tune_scan;
mod tune_trust;
mod validate;
mod workflows;
mod wrong_kind;
