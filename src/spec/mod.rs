//! What one run is: [`run_spec::RunSpec`] (one point of a sweep, resolved) with the values
//! it was swept to ([`value::Value`]), the backend it runs on ([`backend::Backend`]) and
//! the states of its studies ([`run_spec::StudyState`], filled in by `crate::studies`).

pub mod backend;
pub mod groups;
pub mod machine;
pub mod run_spec;
pub mod runs;
pub mod value;

/// The largest |position| a move, a corner path or a scan may reach (mm): 100 m, as the G-code reader
/// takes coordinates. Positions are simulated in metres as f64, whose resolution at 100 m
/// (1.4e-14 m) is far below the 1e-10 m (1e-4 um) the metrics print; at 1e15 mm a 1 mm
/// move is not resolved at all.
pub const MAX_POSITION_MM: f64 = 1e5;

/// The shortest length a move (other than a zero one), a corner path's leg or a scan's width
/// may have (mm): 1 nm, the smallest step a wafer stage makes. A corner path's points are
/// told apart to 1e-12 of their distance from the origin (settle-planner's `Path`), 1e-7 mm
/// at [`MAX_POSITION_MM`]; a move's profile misses its target below about 1e-35 mm.
pub const MIN_LENGTH_MM: f64 = 1e-6;

/// The speeds a move's and a scan's limits may take (mm/s): a galvo's 1e4 with a hundred
/// times to spare above, 1 um/s below. A scan's lines break below 1e-6 mm/s (their knot
/// times no longer increase) and above 1e9 mm/s.
pub const SPEED_RANGE_MM_S: (f64, f64) = (1e-3, 1e6);

/// The accelerations a move's and a scan's limits may take (mm/s^2): a galvo's or a wafer
/// stage's 1e7 with a hundred times to spare. A scan's turnarounds break above 1e17 mm/s^2
/// and a move's profile above 1e100.
pub const ACCELERATION_RANGE_MM_S2: (f64, f64) = (1e-3, 1e9);

/// The jerks a move's and a scan's limits may take (mm/s^3): a galvo's 1e12 with a thousand
/// times to spare. A move's profile breaks above 1e100 mm/s^3; at 1e-9 a 10 mm move lasts
/// two hours.
pub const JERK_RANGE_MM_S3: (f64, f64) = (1e-3, 1e15);

/// The deviations a corner may take from its sharp point (mm): `corner.junction_deviation_mm`
/// (GRBL's junction deviation) and `corner.blend_deviation_mm` (the blend's tolerance), from
/// [`MIN_LENGTH_MM`] (1 nm, the smallest step a wafer stage makes) to [`MAX_POSITION_MM`]
/// (100 m, beyond any machine). Firmware that owns such a key takes less or does not bound
/// it: Marlin's `M205 J` takes 0.01 to 0.3 mm (`GcodeSuite::M205`,
/// Marlin/src/gcode/config/M200-M205.cpp), GRBL's `$11` any number
/// (`settings_store_global_setting`, grbl/settings.c). Beyond 100 m a deviation no longer
/// describes a corner of a machine: `corner.junction_deviation_mm = 1e300` planned the
/// corner at full speed and lost steps.
pub const DEVIATION_RANGE_MM: (f64, f64) = (MIN_LENGTH_MM, MAX_POSITION_MM);

/// The longest a scan may wait at a line's end (`scan.settle_margin_s`, s): a hundred
/// seconds, against a real margin's milliseconds. A scan's trace is kept in memory
/// (`crate::expand::validate::MAX_RECORDED_VALUES`): a 100 s margin at 10 kHz is 8e6 of a
/// one-axis scan's values, half the limit; 1e4 s broke the 1e8 samples of a run.
pub const MAX_MARGIN_S: f64 = 1e2;

/// A quantity whose values a scenario bounds ([`check_limit`]): its range and its unit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quantity {
    /// A corner's deviation from its sharp point ([`DEVIATION_RANGE_MM`], mm).
    Deviation,
    /// A speed ([`SPEED_RANGE_MM_S`], mm/s).
    Speed,
    /// An acceleration ([`ACCELERATION_RANGE_MM_S2`], mm/s^2).
    Acceleration,
    /// A jerk ([`JERK_RANGE_MM_S3`], mm/s^3).
    Jerk,
}

impl Quantity {
    /// The values taken (both ends included).
    pub fn range(self) -> (f64, f64) {
        match self {
            Self::Deviation => DEVIATION_RANGE_MM,
            Self::Speed => SPEED_RANGE_MM_S,
            Self::Acceleration => ACCELERATION_RANGE_MM_S2,
            Self::Jerk => JERK_RANGE_MM_S3,
        }
    }

    /// The unit the values are in.
    pub fn unit(self) -> &'static str {
        match self {
            Self::Deviation => "mm",
            Self::Speed => "mm/s",
            Self::Acceleration => "mm/s^2",
            Self::Jerk => "mm/s^3",
        }
    }
}

/// Check a motion limit against the range of its quantity: the message for a value
/// outside it.
pub fn check_limit(value: f64, quantity: Quantity) -> Result<(), String> {
    let ((lo, hi), unit) = (quantity.range(), quantity.unit());
    if value.is_finite() && (lo..=hi).contains(&value) {
        Ok(())
    } else {
        Err(format!(
            "must be a finite number from {lo:e} to {hi:e} ({unit}), got {value}"
        ))
    }
}

/// Check a length (a leg, a width) or, with `zero_ok`, a move's distance (either sign)
/// against [`MIN_LENGTH_MM`]: the message for a value outside it. The largest is bounded
/// by the positions it reaches ([`MAX_POSITION_MM`]).
pub fn check_length(value: f64, zero_ok: bool) -> Result<(), String> {
    let ok = if zero_ok {
        value == 0.0 || value.abs() >= MIN_LENGTH_MM
    } else {
        value >= MIN_LENGTH_MM
    };
    if value.is_finite() && ok {
        return Ok(());
    }
    Err(if zero_ok {
        format!(
            "must be 0 or a finite number at least {MIN_LENGTH_MM:e} in magnitude (mm), got {value}"
        )
    } else {
        format!("must be a finite number of at least {MIN_LENGTH_MM:e} (mm), got {value}")
    })
}

/// Why a position past [`MAX_POSITION_MM`] is refused: `what` (`the move starts`) at `x` mm.
pub fn beyond_positions(what: &str, x: f64) -> String {
    format!(
        "{what} at {x} mm; positions are limited to +-{MAX_POSITION_MM:e} mm (100 m: no machine is larger, and far out the simulation's numbers cannot resolve a move)"
    )
}
