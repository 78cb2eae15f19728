//! settle-planner's integration tests, one test binary: each module below is one suite;
//! `common` and `fourjerk_check` are shared helpers.

mod any_state;
mod braked;
mod common;
mod corner_blend;
mod fourjerk;
mod fourjerk_check;
mod fourjerk_oracle;
mod interfaces;
mod kinds_scan;
mod module_graph;
mod multi_axis;
mod official_ruckig;
mod paths;
mod pvt;
mod raster;
mod rest_to_rest;
mod tmc_ramp;
mod tmc_registers;
