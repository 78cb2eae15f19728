//! Motion-limit commands as data, in SI-style units (mm/s, mm/s^2, Hz, s) whatever the
//! unit the firmware reads them in. Each variant says which command of which dialect
//! produces it and where its meaning was checked; applying them (what stays in force,
//! what a planner does with them) is the firmware planner's business.

/// Optional values per axis (X, Y, Z, E); `None` where the command did not name the axis.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct AxisValues {
    /// X.
    pub x: Option<f64>,
    /// Y.
    pub y: Option<f64>,
    /// Z.
    pub z: Option<f64>,
    /// E (the first extruder's value where a list `E1:2` is given).
    pub e: Option<f64>,
}

impl AxisValues {
    /// Each axis's value through `f`, in the order X, Y, Z, E.
    pub fn map(&self, mut f: impl FnMut(&Option<f64>) -> Option<f64>) -> AxisValues {
        AxisValues {
            x: f(&self.x),
            y: f(&self.y),
            z: f(&self.z),
            e: f(&self.e),
        }
    }
}

/// Which axes a Marlin `M593`/`M493` applies to (all false = the command's default).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct AxisFlags {
    /// X named.
    pub x: bool,
    /// Y named.
    pub y: bool,
    /// Z named.
    pub z: bool,
    /// E named.
    pub e: bool,
}

/// Marlin FT_MOTION's input shaper choice (`M493 C`, MarlinDocumentation
/// `_gcode/M493.md`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FtShaper {
    /// C0: no shaper.
    None,
    /// C1: ZV.
    Zv,
    /// C2: ZVD.
    Zvd,
    /// C3: ZVDD.
    Zvdd,
    /// C4: ZVDDD.
    Zvddd,
    /// C5: EI.
    Ei,
    /// C6: 2-hump EI.
    Ei2,
    /// C7: 3-hump EI.
    Ei3,
    /// C8: MZV.
    Mzv,
}

impl FtShaper {
    /// The shaper for code `c` of `M493 C`.
    pub fn from_code(c: u32) -> Option<Self> {
        use FtShaper::*;
        [None, Zv, Zvd, Zvdd, Zvddd, Ei, Ei2, Ei3, Mzv]
            .get(c as usize)
            .copied()
    }

    /// Its code for `M493 C`.
    pub fn code(self) -> u32 {
        self as u32
    }
}

/// A change of motion limits or shaping requested in the file.
#[derive(Debug, Clone, PartialEq)]
pub enum LimitChange {
    /// `M201` (Marlin, RepRapFirmware): maximum acceleration per axis, mm/s^2. Marlin's
    /// `F`/`S` set its XY frequency limit (`XY_FREQUENCY_LIMIT`, MarlinDocumentation
    /// `_gcode/M201.md`).
    MaxAccel {
        /// Per axis, mm/s^2.
        per_axis_mm_s2: AxisValues,
        /// Marlin `F`: the highest rate of XY direction changes, Hz.
        xy_frequency_limit_hz: Option<f64>,
        /// Marlin `S`: the least speed, percent, the frequency limit may slow to.
        xy_frequency_min_speed_pct: Option<f64>,
    },
    /// `M203`: maximum feed rate per axis, mm/s (Marlin reads mm/s; RepRapFirmware mm/min,
    /// or mm/s after `S1`: `src/GCodes/GCodes2.cpp` case 203).
    MaxFeedrate {
        /// Per axis, mm/s.
        per_axis_mm_s: AxisValues,
        /// RepRapFirmware `I`: the minimum movement speed, mm/s.
        min_speed_mm_s: Option<f64>,
    },
    /// `M204` (Marlin, RepRapFirmware): accelerations by move type, mm/s^2. `S` sets print
    /// and travel both (Marlin `M200-M205.cpp`, RepRapFirmware
    /// `GCodes::ConfigureAccelerations` in `src/GCodes/GCodes5.cpp`); `R` (retract) is
    /// Marlin only.
    Accel {
        /// `P` (or `S`): moves that extrude, mm/s^2.
        print_mm_s2: Option<f64>,
        /// `T` (or `S`): moves that do not, mm/s^2.
        travel_mm_s2: Option<f64>,
        /// Marlin `R`: E-only moves, mm/s^2.
        retract_mm_s2: Option<f64>,
    },
    /// Marlin `M205` (`Marlin/src/gcode/config/M200-M205.cpp`).
    MarlinAdvanced {
        /// `J`: junction deviation, mm (builds without `CLASSIC_JERK`).
        junction_deviation_mm: Option<f64>,
        /// `X Y Z E`: classic jerk, mm/s.
        jerk_mm_s: AxisValues,
        /// `S`: minimum feed rate of print moves, mm/s.
        min_feedrate_mm_s: Option<f64>,
        /// `T`: minimum feed rate of travel moves, mm/s.
        min_travel_feedrate_mm_s: Option<f64>,
        /// `B`: minimum segment time, s (the command takes microseconds).
        min_segment_time_s: Option<f64>,
    },
    /// RepRapFirmware `M566` (mm/min) and `M205` (mm/s): the largest instantaneous speed
    /// change per axis, mm/s, and `M566 P` the jerk policy (`src/GCodes/GCodes2.cpp`
    /// cases 205/566). `M566` sets the machine's limit; `M205` only the value printing
    /// moves use, capped by that limit (`Move::SetInstantDv`).
    RrfJerk {
        /// Per axis, mm/s.
        per_axis_mm_s: AxisValues,
        /// `P`: 0 = jerk only between printing moves, 1 = between any moves.
        policy: Option<u32>,
        /// `M566` (true) or `M205` (false).
        sets_maximum: bool,
    },
    /// Marlin `M593`: its built-in ZV input shaper (MarlinDocumentation `_gcode/M593.md`).
    /// No axis flag means every shaped axis.
    MarlinInputShaping {
        /// Axes named (X, Y, Z; E unused).
        axes: AxisFlags,
        /// `F`: frequency, Hz (0 disables).
        frequency_hz: Option<f64>,
        /// `D`: damping ratio zeta.
        damping_ratio: Option<f64>,
    },
    /// Prusa-Firmware-Buddy `M593` (lib/Marlin/Marlin/src/gcode/feature/input_shaper/M593.cpp):
    /// per axis (X, Y and Z when none is named) the shaper type, frequency, damping ratio
    /// and vibration reduction; the weight adjustment `M74` applies to Y; saving to EEPROM.
    PrusaInputShaping {
        /// Axes named (X, Y, Z; E unused).
        axes: AxisFlags,
        /// `T`: 0 ZV, 1 ZVD, 2 MZV, 3 EI, 4 2HUMP_EI, 5 3HUMP_EI, 6 none.
        shaper_type: Option<u32>,
        /// `F`: frequency, Hz (0 turns the axis's shaper off).
        frequency_hz: Option<f64>,
        /// `D`: damping ratio zeta (0 ..= 1).
        damping_ratio: Option<f64>,
        /// `R`: vibration reduction of the EI family (> 0; its tolerance is `1 / R`).
        vibration_reduction: Option<f64>,
        /// `A`: the weight adjustment's frequency change at the mass limit, Hz (< 0).
        weight_frequency_delta_hz: Option<f64>,
        /// `M`: the weight adjustment's mass limit, g (0 turns it off).
        weight_mass_limit_g: Option<f64>,
        /// `W`: save the settings to EEPROM.
        save: bool,
    },
    /// RepRapFirmware `M593` (`AxisShaper::Configure`, `src/Movement/AxisShaper.cpp`).
    RrfInputShaping {
        /// `P"type"`: none, zvd, zvdd, zvddd, mzv, ei2, ei3, custom (lower case).
        shaper: Option<String>,
        /// `F`: frequency, Hz.
        frequency_hz: Option<f64>,
        /// `S`: damping ratio zeta (0 ..= 0.99).
        damping_ratio: Option<f64>,
        /// `L`: minimum acceleration reduction factor (0.01 ..= 1).
        reduction_limit: Option<f64>,
        /// `H`: custom shaper amplitudes.
        amplitudes: Vec<f64>,
        /// `T`: custom shaper durations, s.
        durations_s: Vec<f64>,
    },
    /// Marlin `M493`: Fixed-Time Motion and its shaper, as documented for Marlin 2.1.3+
    /// (MarlinDocumentation `_gcode/M493.md`). No axis flag means X and Y.
    FtMotion {
        /// `S`: FT_MOTION on or off.
        enabled: Option<bool>,
        /// `H`: axis synchronisation on or off.
        axis_sync: Option<bool>,
        /// Axes the shaper parameters apply to.
        axes: AxisFlags,
        /// `C`: the shaper.
        shaper: Option<FtShaper>,
        /// `D`: dynamic frequency mode (0 off, 1 Z-based, 2 mass-based).
        dynamic_mode: Option<u32>,
        /// `A`: base frequency, Hz.
        frequency_hz: Option<f64>,
        /// `F`: dynamic frequency scaling.
        frequency_scaling: Option<f64>,
        /// `I`: damping ratio zeta.
        damping_ratio: Option<f64>,
        /// `Q`: vibration tolerance (0 ..= 1).
        vibration_tolerance: Option<f64>,
    },
    /// Marlin `M494`: FT_MOTION trajectory generator and smoothing (MarlinDocumentation
    /// `_gcode/M494.md`).
    FtSmoothing {
        /// `T`: 0 trapezoidal, 1 POLY5, 2 POLY6.
        trajectory: Option<u32>,
        /// `O`: POLY6 acceleration overshoot (1.25 ..= 1.875).
        overshoot: Option<f64>,
        /// `X Y Z E`: smoothing time per axis, s.
        smoothing_s: AxisValues,
    },
    /// Klipper `SET_VELOCITY_LIMIT` (`klippy/toolhead.py`); Klipper's `M204` arrives here
    /// too, as `accel_mm_s2` (`S`, else the smaller of `P` and `T`).
    VelocityLimit {
        /// `VELOCITY`, mm/s.
        velocity_mm_s: Option<f64>,
        /// `ACCEL`, mm/s^2.
        accel_mm_s2: Option<f64>,
        /// `ACCEL_TO_DECEL`, mm/s^2: removed from Klipper on 2025-08-11
        /// (`docs/Config_Changes.md`), ignored by current Klipper; from 2024-03-13 until
        /// then it set `minimum_cruise_ratio = 1 - min(1, accel_to_decel / accel)`.
        accel_to_decel_mm_s2: Option<f64>,
        /// `SQUARE_CORNER_VELOCITY`, mm/s.
        square_corner_velocity_mm_s: Option<f64>,
        /// `MINIMUM_CRUISE_RATIO` (0 ..< 1).
        minimum_cruise_ratio: Option<f64>,
    },
    /// Klipper `SET_INPUT_SHAPER` (`klippy/extras/input_shaper.py`). `SHAPER_TYPE` sets
    /// every axis; it cannot be combined with the per-axis types.
    InputShaper {
        /// `SHAPER_TYPE` (lower case; may carry parameters such as `mzv(n=4,t=0.8)`).
        shaper_type: Option<String>,
        /// `SHAPER_TYPE_X`, `_Y`, `_Z`.
        shaper_type_xyz: [Option<String>; 3],
        /// `SHAPER_FREQ_X`, `_Y`, `_Z`, Hz (0 disables the axis).
        frequency_hz_xyz: [Option<f64>; 3],
        /// `DAMPING_RATIO_X`, `_Y`, `_Z`.
        damping_ratio_xyz: [Option<f64>; 3],
    },
}

impl LimitChange {
    /// The command that produces this change in `dialect` terms (for messages).
    pub fn command_name(&self) -> &'static str {
        match self {
            LimitChange::MaxAccel { .. } => "M201",
            LimitChange::MaxFeedrate { .. } => "M203",
            LimitChange::Accel { .. } => "M204",
            LimitChange::MarlinAdvanced { .. } => "M205",
            LimitChange::RrfJerk {
                sets_maximum: false,
                ..
            } => "M205",
            LimitChange::RrfJerk { .. } => "M566",
            LimitChange::MarlinInputShaping { .. }
            | LimitChange::PrusaInputShaping { .. }
            | LimitChange::RrfInputShaping { .. } => "M593",
            LimitChange::FtMotion { .. } => "M493",
            LimitChange::FtSmoothing { .. } => "M494",
            LimitChange::VelocityLimit { .. } => "SET_VELOCITY_LIMIT",
            LimitChange::InputShaper { .. } => "SET_INPUT_SHAPER",
        }
    }
}
