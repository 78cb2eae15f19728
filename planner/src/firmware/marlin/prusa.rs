//! The Prusa printers Prusa-Firmware-Buddy is built for, and the motion settings each
//! ships with.
//!
//! Read at github.com/prusa3d/Prusa-Firmware-Buddy, commit 818d812f. Buddy is built once
//! per printer family: include/marlin/Configuration.h picks Configuration_MINI.h,
//! Configuration_MK3.5.h, Configuration_MK4.h, Configuration_XL.h or
//! Configuration_COREONE.h (and Configuration_iX.h, not modelled here). One MK4 build runs
//! the MK4, MK4S, MK3.9 and MK3.9S (include/common/extended_printer_type.hpp: the MK3.9s
//! have 200-step motors at 16 microsteps where the MK4s have 400-step motors at 8, the
//! same steps per mm), one MK3.5 build the MK3.5 and MK3.5S. A G-code file names its
//! printer with `M862.3 P "<name>"`, the names of include/common/printer_model_data.hpp
//! (`id_str`, and the MMU variants' `MK4MMU3` and the like).
//!
//! Every family plans with classic jerk 8/8/2 mm/s on X/Y/Z, `MINIMUM_PLANNER_SPEED`
//! 0.05 mm/s, `DEFAULT_MINSEGMENTTIME` 20 ms, `MIN_STEPS_PER_SEGMENT` 6, a 32-block
//! buffer, positions in quarter steps (`PLANNER_STEPS_MULTIPLIER` 4,
//! lib/Marlin/Marlin/src/module/planner.h) and no S-curve; the rest differs per family
//! (see [`PrusaModel::config`]). The speed limits are the `DEFAULT_MAX_FEEDRATE` capped
//! by `HWLIMIT_NORMAL_MAX_FEEDRATE` (`Planner::apply_settings`,
//! lib/Marlin/Marlin/src/module/planner.cpp); the accelerations are below their caps.

use super::config::{MarlinConfig, MarlinJerk, MarlinStepper};
use crate::firmware::Kinematics;

/// A printer family Prusa-Firmware-Buddy is built for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PrusaModel {
    /// The MINI and MINI+ (Configuration_MINI.h).
    Mini,
    /// The MK3.5 and MK3.5S (Configuration_MK3.5.h).
    Mk3_5,
    /// The MK4, MK4S, MK3.9 and MK3.9S (Configuration_MK4.h).
    Mk4,
    /// The XL (Configuration_XL.h), CoreXY.
    Xl,
    /// The CORE One (Configuration_COREONE.h), CoreXY.
    CoreOne,
}

/// The names `M862.3 P` takes (include/common/printer_model_data.hpp), with the family
/// each runs.
const NAMES: [(&str, PrusaModel); 15] = [
    ("MINI", PrusaModel::Mini),
    ("MK3.5", PrusaModel::Mk3_5),
    ("MK3.5S", PrusaModel::Mk3_5),
    ("MK3.5MMU3", PrusaModel::Mk3_5),
    ("MK3.5SMMU3", PrusaModel::Mk3_5),
    ("MK3.9", PrusaModel::Mk4),
    ("MK3.9S", PrusaModel::Mk4),
    ("MK3.9MMU3", PrusaModel::Mk4),
    ("MK3.9SMMU3", PrusaModel::Mk4),
    ("MK4", PrusaModel::Mk4),
    ("MK4S", PrusaModel::Mk4),
    ("MK4MMU3", PrusaModel::Mk4),
    ("MK4SMMU3", PrusaModel::Mk4),
    ("XL", PrusaModel::Xl),
    ("COREONE", PrusaModel::CoreOne),
];

impl PrusaModel {
    /// Every family settle models.
    pub const ALL: [PrusaModel; 5] = [
        PrusaModel::Mini,
        PrusaModel::Mk3_5,
        PrusaModel::Mk4,
        PrusaModel::Xl,
        PrusaModel::CoreOne,
    ];

    /// The family of the printer `M862.3 P` names (Buddy compares the name exactly,
    /// `PrinterModelInfo::from_id_str`, src/common/printer_model.cpp); `None` for a name
    /// settle does not model (`MK3S`, whose firmware is not Buddy; `iX`; names of later
    /// printers).
    pub fn from_printer_name(name: &str) -> Option<PrusaModel> {
        NAMES.iter().find(|(n, _)| *n == name).map(|(_, m)| *m)
    }

    /// The names `M862.3 P` takes that settle models, comma-separated.
    pub fn printer_names() -> String {
        NAMES.map(|(n, _)| n).join(", ")
    }

    /// The family's name (`MINI`, `MK3.5`, `MK4`, `XL`, `CORE One`).
    pub fn name(self) -> &'static str {
        match self {
            PrusaModel::Mini => "MINI",
            PrusaModel::Mk3_5 => "MK3.5",
            PrusaModel::Mk4 => "MK4",
            PrusaModel::Xl => "XL",
            PrusaModel::CoreOne => "CORE One",
        }
    }

    /// The motion settings the family ships with:
    ///
    /// | | steps/mm X/Y/Z/E | mm/s X/Y/Z/E | mm/s^2 X/Y/Z/E | print/retract/travel mm/s^2 | E jerk mm/s |
    /// |---|---|---|---|---|---|
    /// | MINI | 100/100/400/325 | 180/180/12/80 | 1250/1250/400/4000 | 1250/1250/1250 | 10 |
    /// | MK3.5 | 100/100/400/266 | 200/200/12/45 | 1250/1250/400/4000 | 1250/1250/1250 | 5 |
    /// | MK4 | 100/100/400/380 | 300/300/40/50 | 1250/1250/200/1500 | 1250/800/1250 | 5 |
    /// | XL | 80/80/800/380 | 460/460/12/45 | 5000/5000/200/1500 | 1800/1200/5000 | 5 |
    /// | CORE One | 100/100/400/380 | 350/350/30/50 | 10000/10000/1000/1500 | 1250/1250/1500 | 5 |
    ///
    /// (`DEFAULT_AXIS_STEPS_PER_UNIT`, `DEFAULT_MAX_FEEDRATE` and
    /// `HWLIMIT_NORMAL_MAX_FEEDRATE`, `DEFAULT_MAX_ACCELERATION`, `DEFAULT_ACCELERATION`,
    /// `DEFAULT_RETRACT_ACCELERATION`, `DEFAULT_TRAVEL_ACCELERATION`, `DEFAULT_EJERK` of
    /// each Configuration_*.h; the XL and CORE One are CoreXY, `COREXY`.)
    pub fn config(self) -> MarlinConfig {
        let mk4 = MarlinConfig::prusa_mk4();
        let (kinematics, steps_mm, feed_mm_s, accel_mm_s2, [print, retract, travel], e_jerk) =
            match self {
                PrusaModel::Mk4 => return mk4,
                PrusaModel::Mini => (
                    Kinematics::Cartesian,
                    [100.0, 100.0, 400.0, 325.0],
                    [180.0, 180.0, 12.0, 80.0],
                    [1250.0, 1250.0, 400.0, 4000.0],
                    [1250.0, 1250.0, 1250.0],
                    10.0,
                ),
                PrusaModel::Mk3_5 => (
                    Kinematics::Cartesian,
                    [100.0, 100.0, 400.0, 266.0],
                    [200.0, 200.0, 12.0, 45.0],
                    [1250.0, 1250.0, 400.0, 4000.0],
                    [1250.0, 1250.0, 1250.0],
                    5.0,
                ),
                PrusaModel::Xl => (
                    Kinematics::CoreXy,
                    [80.0, 80.0, 800.0, 380.0],
                    [460.0, 460.0, 12.0, 45.0],
                    [5000.0, 5000.0, 200.0, 1500.0],
                    [1800.0, 1200.0, 5000.0],
                    5.0,
                ),
                PrusaModel::CoreOne => (
                    Kinematics::CoreXy,
                    [100.0, 100.0, 400.0, 380.0],
                    [350.0, 350.0, 30.0, 50.0],
                    [10000.0, 10000.0, 1000.0, 1500.0],
                    [1250.0, 1250.0, 1500.0],
                    5.0,
                ),
            };
        let mm = 1e-3;
        MarlinConfig {
            kinematics,
            steps_per_m: steps_mm.map(|s| s * PLANNER_STEPS_MULTIPLIER * 1e3),
            max_feedrate_m_s: feed_mm_s.map(|v| v * mm),
            max_accel_m_s2: accel_mm_s2.map(|a| a * mm),
            print_accel_m_s2: print * mm,
            retract_accel_m_s2: retract * mm,
            travel_accel_m_s2: travel * mm,
            jerk: MarlinJerk::Classic {
                max_jerk_m_s: [8e-3, 8e-3, 2e-3, e_jerk * mm],
                travel_extra_xy_jerk_m_s: 0.0,
            },
            stepper: MarlinStepper::PreciseStepping,
            ..mk4
        }
    }

    /// The highest frequency `M593 F` takes (Hz; `frequency_safe_max`,
    /// lib/Marlin/Marlin/src/feature/input_shaper/input_shaper_config.hpp: 150 on the
    /// MINI, 100 on the others; the lowest is 10 on all).
    pub fn shaper_max_hz(self) -> f64 {
        match self {
            PrusaModel::Mini => 150.0,
            _ => 100.0,
        }
    }
}

/// Buddy's planner counts quarter steps (`PLANNER_STEPS_MULTIPLIER`,
/// lib/Marlin/Marlin/src/module/planner.h).
pub const PLANNER_STEPS_MULTIPLIER: f64 = 4.0;

impl std::fmt::Display for PrusaModel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_mk4_is_the_preset_settle_had() {
        assert_eq!(PrusaModel::Mk4.config(), MarlinConfig::prusa_mk4());
        for m in PrusaModel::ALL {
            m.config().validate().expect("valid");
        }
    }

    #[test]
    fn names_as_buddy_spells_them() {
        assert_eq!(PrusaModel::from_printer_name("MK4S"), Some(PrusaModel::Mk4));
        assert_eq!(
            PrusaModel::from_printer_name("MK3.5"),
            Some(PrusaModel::Mk3_5)
        );
        assert_eq!(
            PrusaModel::from_printer_name("COREONE"),
            Some(PrusaModel::CoreOne)
        );
        assert_eq!(PrusaModel::from_printer_name("MK3S"), None);
        assert_eq!(PrusaModel::from_printer_name("mini"), None);
        assert!(PrusaModel::printer_names().starts_with("MINI, MK3.5, "));
    }
}
