//! settle-planner's integration tests, one test binary: each module below is one suite;
//! `common`, `fourjerk_check` and `firmware_common` are shared helpers.

mod any_state;
mod at_target;
mod braked;
mod common;
mod corner_blend;
mod firmware_common;
mod firmware_grbl;
mod firmware_klipper;
mod firmware_marlin;
mod firmware_profiles;
mod firmware_prusa;
mod firmware_rrf;
mod fourjerk;
mod fourjerk_check;
mod fourjerk_oracle;
mod interfaces;
mod kinds_scan;
mod multi_axis;
mod official_ruckig;
mod path_window;
mod paths;
mod pvt;
mod raster;
mod rest_to_rest;
mod shaper_extremes;
mod shaper_klipper;
mod shaper_marlin_m593;
mod shaper_marlin_rrf;
mod shaper_names;
mod shaper_select;
mod shaper_stream;
mod tmc_5160;
mod tmc_ramp;
mod tmc_registers;

/// The package's directory: the `CARGO_MANIFEST_DIR` cargo sets when it runs this
/// binary, else the one it was compiled with. The run-time value is the one that is right
/// when a target directory is shared between clones at different paths: cargo reuses a
/// test binary whose sources are unchanged, with the other clone's path compiled in.
fn manifest_dir() -> &'static str {
    static DIR: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    DIR.get_or_init(|| {
        std::env::var("CARGO_MANIFEST_DIR")
            .unwrap_or_else(|_| env!("CARGO_MANIFEST_DIR").to_owned())
    })
}
