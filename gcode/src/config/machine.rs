//! The plain data both configuration readers return: per-axis drive resolution, current
//! and travel, input shaper settings, and notes about what was not read.

use std::fmt;

use crate::error::Location;
use crate::read::dialect::Dialect;

/// One value per axis X, Y, Z.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Xyz<T> {
    /// X.
    pub x: T,
    /// Y.
    pub y: T,
    /// Z.
    pub z: T,
}

impl<T> Xyz<T> {
    /// The three values in order X, Y, Z, with their axis letter.
    pub fn iter(&self) -> impl Iterator<Item = (char, &T)> {
        [('X', &self.x), ('Y', &self.y), ('Z', &self.z)].into_iter()
    }

    /// Each value mapped.
    pub fn map<U>(self, mut f: impl FnMut(T) -> U) -> Xyz<U> {
        Xyz {
            x: f(self.x),
            y: f(self.y),
            z: f(self.z),
        }
    }
}

/// Fewest and most microsteps per mm of an axis a configuration may give (Klipper's
/// `[stepper_x]` resolution, Marlin's `M92`, config.g's `M92` and `M350`): 1 (a microstep of 1 mm; a 1.8 degree
/// motor's full step on a 40 mm belt pulley is 0.2 mm) to 1e9 (a femtometre-scale step,
/// the bound `M92` always had here). Outside it a configuration is a typing or unit
/// mistake (`rotation_distance: 1e-12` gives 3.2e15), and `settle tune` refuses a
/// scenario's `usteps_per_mm` outside it.
pub const MICROSTEPS_PER_MM: (f64, f64) = (1.0, 1e9);

/// How one axis's motor turns into millimetres, with what current, over which travel.
#[derive(Debug, Clone, PartialEq)]
pub struct AxisDrive {
    /// Microsteps per mm of axis travel: the resolution the firmware's step generator
    /// quantises positions to. Klipper: `full_steps_per_rotation * microsteps * gear_ratio
    /// / rotation_distance` (`klippy/stepper.py` `parse_step_distance`); RepRapFirmware:
    /// `M92` after `M350` rescaling.
    pub microsteps_per_mm: f64,
    /// Microsteps per full step.
    pub microsteps: u32,
    /// Whether the driver interpolates each microstep to 1/256 of a step (Trinamic
    /// MicroPlyer): Klipper's `interpolate` in the `[tmc...]` section (default true,
    /// `klippy/extras/tmc.py`), RepRapFirmware's `M350 I`. `None`: no smart driver is
    /// configured for the axis.
    pub interpolate: Option<bool>,
    /// Motor run current, A RMS (Klipper `run_current`; RepRapFirmware `M906` mA peak
    /// divided by `1000 sqrt(2)`). `None` where the configuration does not set it.
    pub run_current_a_rms: Option<f64>,
    /// Lowest position the firmware allows, mm.
    pub position_min_mm: f64,
    /// Highest position the firmware allows, mm (`None`: not configured, as for a Klipper
    /// stepper section without `position_max`).
    pub position_max_mm: Option<f64>,
}

/// One axis's input shaper as a firmware configures it; also the input of the exporters.
#[derive(Debug, Clone, PartialEq)]
pub struct ShaperSetting {
    /// The shaper as the firmware names it: Klipper's `shaper_type` text (`mzv`, `ei`,
    /// `mzv(n=4,t=0.8)`), RepRapFirmware's `M593 P` type (`zvd`, `mzv`, `ei2`, `none`).
    pub name: String,
    /// Shaper frequency, Hz. Klipper: 0 disables the axis's shaper.
    pub frequency_hz: f64,
    /// Damping ratio zeta the shaper is designed for.
    pub damping_ratio: f64,
}

impl ShaperSetting {
    /// Whether the firmware shapes with it: Klipper shapes when the frequency is above 0
    /// (`klippy/extras/input_shaper.py` `get_shaper`), RepRapFirmware unless the type is
    /// `none`.
    pub fn is_enabled(&self, firmware: Dialect) -> bool {
        match firmware {
            Dialect::Rrf => self.name != "none",
            // GRBL has no input shaper.
            Dialect::Grbl => false,
            _ => self.frequency_hz > 0.0,
        }
    }

    /// The name in the syntax of `settle_planner::shaper::ShaperType`: Klipper's text as is,
    /// `rrf:<type>` for RepRapFirmware, `marlin:<name>` for Marlin. `None` when the
    /// firmware does not shape with it ([`ShaperSetting::is_enabled`]) or it is
    /// RepRapFirmware's `custom` shaper, known only by its impulses, or the firmware is one
    /// whose configuration settle does not read (Prusa's, GRBL).
    pub fn type_name(&self, firmware: Dialect) -> Option<String> {
        if !self.is_enabled(firmware) {
            return None;
        }
        match firmware {
            Dialect::Klipper => Some(self.name.clone()),
            Dialect::Rrf if self.name == "custom" => None,
            Dialect::Rrf => Some(format!("rrf:{}", self.name)),
            Dialect::Marlin => Some(format!("marlin:{}", self.name)),
            Dialect::Prusa | Dialect::Grbl => None,
        }
    }
}

/// Something in a configuration file the reader did not apply, or applied in a way the
/// user should know about (a conditional block skipped, a SAVE_CONFIG value overridden).
#[derive(Debug, Clone, PartialEq)]
pub struct ConfigNote {
    /// Where, when it concerns one place.
    pub at: Option<Location>,
    /// What happened.
    pub text: String,
}

impl ConfigNote {
    pub(crate) fn at(at: Location, text: impl Into<String>) -> Self {
        ConfigNote {
            at: Some(at),
            text: text.into(),
        }
    }
}

impl fmt::Display for ConfigNote {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.at {
            Some(at) => write!(f, "{at}: {}", self.text),
            None => f.write_str(&self.text),
        }
    }
}
