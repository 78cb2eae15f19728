//! Marlin's motion settings (Configuration.h, Configuration_adv.h and the M201-M205 commands).

use crate::PlanError;
use crate::firmware::Kinematics;

/// How Marlin limits the speed at a corner.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MarlinJerk {
    /// Junction deviation (`M205 J`, m; Marlin's default 0.013 mm).
    JunctionDeviation {
        /// The deviation (m).
        deviation_m: f64,
        /// The arc limit for short segments (`JD_HANDLE_SMALL_SEGMENTS`).
        small_segments: JdSmallSegments,
    },
    /// Classic jerk (`CLASSIC_JERK`, `M205 X Y Z E`): the largest speed change per axis
    /// (m/s), X, Y, Z, E; Marlin's defaults 10, 10, 0.3, 5 mm/s.
    Classic {
        /// Speed change allowed per axis (m/s).
        max_jerk_m_s: [f64; 4],
        /// `TRAVEL_EXTRA_XYJERK` (m/s) added to X and Y on moves that do not extrude.
        travel_extra_xy_jerk_m_s: f64,
    },
}

/// How `JD_HANDLE_SMALL_SEGMENTS` gets the angle of a junction between short segments.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JdSmallSegments {
    /// Disabled: junction deviation alone.
    Off,
    /// The exact `acos`.
    Acos,
    /// Marlin's default, `JD_USE_LOOKUP_TABLE`: 16 linear pieces of `acos` (max. error
    /// about 0.01 rad).
    LookupTable,
}

/// What runs a planned block: how its entry, cruise and exit speeds become motion.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MarlinStepper {
    /// Marlin's stepper (stepper.cpp): step rates fixed by `calculate_trapezoid_for_block`
    /// (rounded, raised to `MINIMAL_STEP_RATE`), phases ended at step counts.
    Stepper,
    /// Prusa-Firmware-Buddy's precise stepping
    /// (lib/Marlin/Marlin/src/feature/precise_stepping/precise_stepping.cpp,
    /// `append_move_segments_to_queue`): the block's entry, nominal and exit speeds and
    /// acceleration in mm, a trapezoid in continuous time, no step-rate rounding and no
    /// minimal step rate.
    PreciseStepping,
}

/// Marlin's motion settings (Configuration.h, changed by M92, M201, M203, M204, M205).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MarlinConfig {
    /// Cartesian, or CoreXY (motors A = X + Y, B = X - Y take the X, Y limits).
    pub kinematics: Kinematics,
    /// Steps per metre of X (A), Y (B), Z and E (`M92`).
    pub steps_per_m: [f64; 4],
    /// Speed limit per axis (m/s, `M203`).
    pub max_feedrate_m_s: [f64; 4],
    /// Acceleration limit per axis (m/s^2, `M201`).
    pub max_accel_m_s2: [f64; 4],
    /// Acceleration of moves that extrude (m/s^2, `M204 P`; `M204 S` sets it and travel).
    pub print_accel_m_s2: f64,
    /// Acceleration of extruder-only moves (m/s^2, `M204 R`).
    pub retract_accel_m_s2: f64,
    /// Acceleration of moves that do not extrude (m/s^2, `M204 T`).
    pub travel_accel_m_s2: f64,
    /// Lowest feed rate of extruding moves (m/s, `M205 S`).
    pub min_feedrate_m_s: f64,
    /// Lowest feed rate of other moves (m/s, `M205 T`).
    pub min_travel_feedrate_m_s: f64,
    /// `M205 B` (s): with `slowdown`, short blocks are slowed while the queue is short.
    pub min_segment_time_s: f64,
    /// `SLOWDOWN` (on in Marlin's example configuration), divisor 2.
    pub slowdown: bool,
    /// Corner rule.
    pub jerk: MarlinJerk,
    /// `S_CURVE_ACCELERATION`: ramps follow the quintic Bezier.
    pub s_curve: bool,
    /// `BLOCK_BUFFER_SIZE` (16); the queue holds one block less.
    pub block_buffer_size: usize,
    /// `MIN_STEPS_PER_SEGMENT` (6).
    pub min_steps_per_segment: u32,
    /// `MINIMUM_PLANNER_SPEED` (m/s; 0.05 mm/s): the exit speed of the last block.
    pub minimum_planner_speed_m_s: f64,
    /// `MINIMAL_STEP_RATE` (120 steps/s): no block starts or ends slower.
    pub minimal_step_rate_hz: f64,
    /// Blocks queued before the stepper takes the first one after an empty queue (3).
    pub first_block_after: usize,
    /// What runs the planned blocks (Marlin's stepper).
    pub stepper: MarlinStepper,
}

impl MarlinConfig {
    /// Marlin's example-configuration defaults: 80/80/400/500 steps/mm, 300/300/5/25 mm/s,
    /// 3000/3000/100/10000 mm/s^2, 3000 mm/s^2 print/retract/travel acceleration, junction
    /// deviation 0.013 mm with the lookup-table arc limit, minimum feed rates 0,
    /// `M205 B` 20 ms with `SLOWDOWN`, trapezoids, a 16-block buffer.
    pub fn new() -> Self {
        Self {
            kinematics: Kinematics::Cartesian,
            steps_per_m: [80e3, 80e3, 400e3, 500e3],
            max_feedrate_m_s: [0.3, 0.3, 0.005, 0.025],
            max_accel_m_s2: [3.0, 3.0, 0.1, 10.0],
            print_accel_m_s2: 3.0,
            retract_accel_m_s2: 3.0,
            travel_accel_m_s2: 3.0,
            min_feedrate_m_s: 0.0,
            min_travel_feedrate_m_s: 0.0,
            min_segment_time_s: 0.02,
            slowdown: true,
            jerk: MarlinJerk::JunctionDeviation {
                deviation_m: 0.013e-3,
                small_segments: JdSmallSegments::LookupTable,
            },
            s_curve: false,
            block_buffer_size: 16,
            min_steps_per_segment: 6,
            minimum_planner_speed_m_s: 0.05e-3,
            minimal_step_rate_hz: 120.0,
            first_block_after: 3,
            stepper: MarlinStepper::Stepper,
        }
    }

    /// A Prusa MK4 / MK4S as Prusa-Firmware-Buddy ships it (include/marlin/Configuration_MK4.h
    /// and Configuration_MK4_adv.h): 100/100/400/380 steps/mm planned in mini-steps of a
    /// quarter step (`PLANNER_STEPS_MULTIPLIER` 4, lib/Marlin/Marlin/src/module/planner.h;
    /// so 400/400/1600/1520 per mm, and `MIN_STEPS_PER_SEGMENT` 6 steps is 24), 300/300/40/50
    /// mm/s (`DEFAULT_MAX_FEEDRATE` 400/400/40/50 capped by `HWLIMIT_NORMAL_MAX_FEEDRATE`
    /// 300/300/40/100, `Planner::apply_settings`), 1250/1250/200/1500 mm/s^2,
    /// print and travel 1250 mm/s^2, retract 800 mm/s^2, classic jerk 8/8/2/5 mm/s,
    /// minimum feed rates 0, `M205 B` 20 ms, a 32-block buffer, `MINIMUM_PLANNER_SPEED`
    /// 0.05 mm/s, trapezoids run by precise stepping. `SLOWDOWN` is off here: Buddy slows
    /// short blocks only while its command queue holds 3 commands or fewer
    /// (`Planner::_populate_block`), and printing from a file it holds more.
    pub fn prusa_mk4() -> Self {
        Self {
            steps_per_m: [400e3, 400e3, 1600e3, 1520e3],
            max_feedrate_m_s: [0.3, 0.3, 0.04, 0.05],
            max_accel_m_s2: [1.25, 1.25, 0.2, 1.5],
            print_accel_m_s2: 1.25,
            retract_accel_m_s2: 0.8,
            travel_accel_m_s2: 1.25,
            slowdown: false,
            jerk: MarlinJerk::Classic {
                max_jerk_m_s: [8e-3, 8e-3, 2e-3, 5e-3],
                travel_extra_xy_jerk_m_s: 0.0,
            },
            block_buffer_size: 32,
            min_steps_per_segment: 24,
            stepper: MarlinStepper::PreciseStepping,
            ..Self::new()
        }
    }

    /// Check every setting.
    pub fn validate(&self) -> Result<(), PlanError> {
        for (name, v) in [
            ("steps_per_m", &self.steps_per_m),
            ("max_feedrate", &self.max_feedrate_m_s),
            ("max_accel", &self.max_accel_m_s2),
        ] {
            for &x in v {
                crate::firmware::positive(name, x)?;
            }
        }
        crate::firmware::positive("print acceleration", self.print_accel_m_s2)?;
        crate::firmware::positive("retract acceleration", self.retract_accel_m_s2)?;
        crate::firmware::positive("travel acceleration", self.travel_accel_m_s2)?;
        crate::firmware::positive("minimal step rate", self.minimal_step_rate_hz)?;
        for (name, v) in [
            ("min_feedrate", self.min_feedrate_m_s),
            ("min_travel_feedrate", self.min_travel_feedrate_m_s),
            ("min_segment_time", self.min_segment_time_s),
            ("minimum planner speed", self.minimum_planner_speed_m_s),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(PlanError::InvalidLimit { name, value: v });
            }
        }
        match self.jerk {
            MarlinJerk::JunctionDeviation { deviation_m, .. } => {
                crate::firmware::positive("junction deviation", deviation_m)?;
            }
            MarlinJerk::Classic {
                max_jerk_m_s,
                travel_extra_xy_jerk_m_s,
            } => {
                for j in max_jerk_m_s.into_iter().chain([travel_extra_xy_jerk_m_s]) {
                    if !(j.is_finite() && j >= 0.0) {
                        return Err(PlanError::InvalidLimit {
                            name: "classic jerk",
                            value: j,
                        });
                    }
                }
            }
        }
        if self.block_buffer_size < 3 {
            return Err(PlanError::InvalidLimit {
                name: "block buffer size (>= 3)",
                value: self.block_buffer_size as f64,
            });
        }
        if self.first_block_after == 0 {
            return Err(PlanError::InvalidLimit {
                name: "first block after (>= 1)",
                value: 0.0,
            });
        }
        Ok(())
    }

    /// Blocks the queue holds: `BLOCK_BUFFER_SIZE - 1`.
    pub fn capacity(&self) -> usize {
        self.block_buffer_size - 1
    }
}

impl Default for MarlinConfig {
    fn default() -> Self {
        Self::new()
    }
}
