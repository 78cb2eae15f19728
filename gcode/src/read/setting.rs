//! Machine settings as data: the commands of a RepRapFirmware configuration file
//! (`config.g`) that say how motors turn into millimetres, with what current, over which
//! travel and under which kinematics. Each variant names its command and where its meaning
//! was checked (RepRapFirmware 3.6, `src/GCodes/GCodes2.cpp` unless said otherwise);
//! applying them in order (what a later `M350` does to an earlier `M92`) is
//! [`crate::config::RrfConfig`]'s business.

use crate::read::limits::AxisValues;

/// A machine setting read from the file. The RepRapFirmware dialect produces the
/// configuration commands, the GRBL dialect its `$N=V` lines; the other dialects count
/// the commands as ignored.
#[derive(Debug, Clone, PartialEq)]
pub enum Setting {
    /// `M92`: steps per mm per axis. With `S` the values are for that microstepping, and the
    /// firmware converts them to the microstepping in force (`Move::SetDriveStepsPerMm`,
    /// `src/Movement/Move.cpp`).
    StepsPerMm {
        /// Per axis, (micro)steps per mm.
        per_axis: AxisValues,
        /// `S`: the microstepping the values are given at (none: the one in force).
        at_microstepping: Option<u32>,
    },
    /// `M350`: microsteps per full step per axis, a power of two from 1 to 256 (the smart
    /// drivers' limit, `SmartDrivers::SetMicrostepping` in
    /// `src/Movement/StepperDrivers/TMC22xx.cpp`). The firmware rescales steps per mm so
    /// that a millimetre stays a millimetre (`GCodes::ChangeMicrostepping`).
    Microstepping {
        /// Per axis, microsteps per full step.
        per_axis: AxisValues,
        /// Interpolation to 256 microsteps: on with `I1`, off with `I0` or without `I`
        /// (case 350 reads `Seen('I') && value > 0`).
        interpolation: bool,
    },
    /// `M906`: motor current per axis, mA. The smart drivers turn it into their current
    /// scale as a peak value (`TmcDriverState::UpdateCurrent`: `CS = 32 I / (VRef /
    /// RSense)`, the TMC2209 datasheet's full-scale formula without its `1/sqrt(2)`), so
    /// the RMS current is this divided by `sqrt(2)`.
    MotorCurrent {
        /// Per axis, mA (peak).
        per_axis_ma: AxisValues,
        /// `I`: idle current, percent of the running current.
        idle_percent: Option<f64>,
    },
    /// `M208`: axis travel, mm. `X0:250` sets minimum and maximum; a single value sets the
    /// maximum, or the minimum with `S1`.
    AxisLimits {
        /// Minimums set, per axis, mm.
        minimum_mm: AxisValues,
        /// Maximums set, per axis, mm.
        maximum_mm: AxisValues,
    },
    /// `M669 K`: the kinematics by its code (`KinematicsType`,
    /// `src/Movement/Kinematics/Kinematics.h`: 0 Cartesian, 1 CoreXY, 2 CoreXZ, 3 linear
    /// delta, ...); `M665` with `L` or `D` selects linear delta (3).
    Kinematics {
        /// The `KinematicsType` code.
        code: u32,
    },
    /// GRBL's `$N=V` (grbl/settings.c `settings_store_global_setting`; what each number
    /// means: [`crate::config::GrblSettings`]).
    Grbl {
        /// The setting's number (`110` for `$110`).
        number: u16,
        /// Its value, in GRBL's units (mm/min, mm/s^2, mm).
        value: f64,
    },
}

impl Setting {
    /// The command that produces this setting.
    pub fn command_name(&self) -> &'static str {
        match self {
            Setting::StepsPerMm { .. } => "M92",
            Setting::Microstepping { .. } => "M350",
            Setting::MotorCurrent { .. } => "M906",
            Setting::AxisLimits { .. } => "M208",
            Setting::Kinematics { .. } => "M669",
            Setting::Grbl { .. } => "$",
        }
    }
}
