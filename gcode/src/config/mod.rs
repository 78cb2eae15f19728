//! Firmware configuration files in and out: Klipper's `printer.cfg` (with its includes and
//! SAVE_CONFIG block) and RepRapFirmware's `config.g` read into plain data
//! ([`KlipperConfig`], [`RrfConfig`]) with the values the firmware would use, and input
//! shaper settings written back in each firmware's own syntax, ready to paste.

mod export_klipper;
mod export_rrf;
mod glob;
mod ini;
mod klipper;
mod klipper_files;
mod klipper_shaper;
mod klipper_values;
mod machine;
mod rrf;
mod rrf_script;

pub use export_klipper::KlipperExport;
pub use export_rrf::RrfExport;
pub use klipper::{
    DEFAULT_DAMPING_RATIO, DEFAULT_FULL_STEPS_PER_ROTATION, DEFAULT_MINIMUM_CRUISE_RATIO,
    DEFAULT_SHAPER_TYPE, DEFAULT_SQUARE_CORNER_VELOCITY_MM_S, KlipperConfig, KlipperPrinter,
    KlipperStepper,
};
pub use machine::{AxisDrive, ConfigNote, ShaperSetting, Xyz};
pub use rrf::{RRF_DEFAULT_M204_MM_S2, RRF_DEFAULT_SHAPER, RrfAxis, RrfConfig};
