//! Firmware configuration files in and out: Klipper's `printer.cfg` (with its includes and
//! SAVE_CONFIG block), RepRapFirmware's `config.g` (with the macros it runs), GRBL's
//! `$$` settings and Marlin's `M503` reply read into plain data ([`KlipperConfig`],
//! [`RrfConfig`], [`GrblSettings`], [`MarlinSettings`]) with the values the firmware
//! would use,
//! and input shaper settings written back in each firmware's own syntax, ready to paste
//! ([`KlipperExport`], [`RrfExport`], and Marlin's Fixed-Time Motion `M493` lines,
//! [`MarlinExport`], or its built-in ZV shaper's `M593` lines, [`MarlinZvExport`];
//! Prusa-Firmware-Buddy's `M593 T F D` lines, [`PrusaExport`]).
//!
//! Both readers return per-axis [`AxisDrive`]s (microsteps per mm, microstepping, current,
//! travel) and [`ShaperSetting`]s (shaper name, frequency, damping ratio; Klipper per axis,
//! RepRapFirmware one for all), and [`ConfigNote`]s for what was read in a way worth
//! knowing. Options and commands settle does not need are not read; a value settle reads
//! that the firmware would refuse is an error naming the file, line, option and what is
//! allowed. Each reader's module documentation says which firmware source each rule comes
//! from; two that surprise:
//!
//! - Klipper drops an option from the SAVE_CONFIG block when the rest of the
//!   configuration sets it (`klippy/configfile.py` `_strip_duplicates`): the block
//!   overrides nothing; `SAVE_CONFIG` comments out the main file's lines when it saves.
//! - RepRapFirmware's `M350` rescales the steps per mm already set, and `M593` has one
//!   shaper for all axes.
//!
//! ```
//! use settle_gcode::Dialect;
//! use settle_gcode::config::{KlipperConfig, KlipperExport, RrfExport};
//!
//! let text = "[printer]\nkinematics: corexy\nmax_velocity: 300\nmax_accel: 5000\n\
//!             [input_shaper]\nshaper_type_x: mzv\nshaper_freq_x: 52.4\n\
//!             shaper_type_y: ei\nshaper_freq_y: 41.5\n";
//! let c = KlipperConfig::parse(text, "printer.cfg")?;
//! let shaper = c.input_shaper.expect("an [input_shaper] section");
//! assert_eq!(shaper.x.type_name(Dialect::Klipper).as_deref(), Some("mzv"));
//! assert_eq!((shaper.x.frequency_hz, shaper.x.damping_ratio), (52.4, 0.1)); // default zeta
//! assert_eq!(c.printer.minimum_cruise_ratio, 0.5); // Klipper's default
//!
//! let klipper = KlipperExport {
//!     produced_by: "an example".into(),
//!     x: shaper.x.clone(),
//!     y: shaper.y.clone(),
//!     max_accel_mm_s2: Some(6000.0),
//!     minimum_cruise_ratio: None,
//!     square_corner_velocity_mm_s: None,
//! };
//! assert!(klipper.to_config()?.contains("[input_shaper]\nshaper_type_x: mzv\n"));
//! let mut one = shaper.y.clone();
//! one.name = "ei2".into(); // RepRapFirmware's name for a two-hump EI
//! let rrf = RrfExport { produced_by: "an example".into(), shaper: one, max_accel_xy_mm_s2: [None; 2], print_accel_mm_s2: None, travel_accel_mm_s2: None };
//! assert!(rrf.to_config()?.ends_with("M593 P\"ei2\" F41.5 S0.1\n"));
//! # Ok::<(), settle_gcode::GcodeError>(())
//! ```

mod budget;
mod export_klipper;
mod export_marlin;
mod export_prusa;
mod export_rrf;
mod export_text;
mod glob;
mod grbl;
mod ini;
mod klipper;
mod klipper_files;
pub(crate) mod klipper_shaper;
mod klipper_values;
mod machine;
mod marlin;
mod rrf;
mod rrf_script;

pub use budget::{MAX_BYTES as MAX_CONFIG_BYTES, MAX_FILES as MAX_CONFIG_FILES};
pub use export_klipper::KlipperExport;
pub use export_marlin::{FtAxisShaper, MarlinExport, MarlinZvExport, ZvAxisShaper};
pub use export_prusa::{PrusaAxisShaper, PrusaExport};

pub use export_rrf::RrfExport;
pub use export_text::Note;
pub use grbl::GrblSettings;
pub use klipper::{
    DEFAULT_DAMPING_RATIO, DEFAULT_FULL_STEPS_PER_ROTATION, DEFAULT_MINIMUM_CRUISE_RATIO,
    DEFAULT_SHAPER_TYPE, DEFAULT_SQUARE_CORNER_VELOCITY_MM_S, KlipperConfig, KlipperPrinter,
    KlipperStepper, MAX_SHAPER_FREQUENCY_HZ,
};
pub use machine::{AxisDrive, ConfigNote, MICROSTEPS_PER_MM, ShaperSetting, Xyz};
pub use marlin::MarlinSettings;
pub(crate) use rrf::rrf_shaper_name;
pub use rrf::{
    RRF_DEFAULT_M204_MM_S2, RRF_DEFAULT_SHAPER, RRF_MINIMUM_ACCEL_MM_S2, RRF_MINIMUM_JERK_MM_S,
    RrfAxis, RrfConfig,
};

use std::sync::Arc;

use crate::error::{GcodeError, Location};
use crate::read::dialect::Dialect;
use crate::read::event::EventKind;
use crate::read::reader::{Reader, ReaderOptions};

/// A word a job's command refuses ([`GcodeError::OutOfRange`]) named as the
/// configuration's setting: the command its section, the word its key, the line without a
/// column; any other error as it is.
pub(crate) fn out_of_range_as_setting(e: GcodeError) -> GcodeError {
    match e {
        GcodeError::OutOfRange {
            at,
            command,
            param,
            value,
            allowed,
        } => GcodeError::ConfigValue {
            at: Location { column: None, ..at },
            section: command,
            key: param,
            value: value.to_string().into(),
            allowed: allowed.into(),
        },
        e => e,
    }
}

/// The events of a configuration file's `text` read in `dialect`, each with its line in
/// `source` (what config.g's and GRBL's settings readers walk).
pub(crate) fn located_events<'a>(
    text: &'a str,
    dialect: Dialect,
    source: &Arc<str>,
) -> impl Iterator<Item = Result<(Location, EventKind), GcodeError>> + 'a {
    let source = source.clone();
    Reader::new(text.as_bytes(), ReaderOptions::new(dialect))
        .with_name(source.clone())
        .map(move |e| {
            e.map(|e| {
                let at = Location {
                    source_name: source.clone(),
                    line: e.line,
                    column: None,
                };
                (at, e.kind)
            })
        })
}
