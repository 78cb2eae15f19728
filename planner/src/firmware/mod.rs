//! Motion planning as firmwares do it: Klipper, Marlin and RepRapFirmware for printers,
//! GRBL for CNC mills and lasers.
//!
//! Each firmware turns a stream of straight moves into trapezoids (Marlin optionally into
//! S-curves) with its own corner rule, look-ahead and queue. The planners here follow the
//! firmwares' sources step by step, so that the print time, the speed at each corner and
//! the acceleration phases are the ones the printer runs:
//!
//! - [`klipper`]: klippy/toolhead.py (`Move`, `calc_junction`, `LookAheadQueue.flush`),
//!   kinematics/cartesian.py and corexy.py (Z limits), kinematics/extruder.py.
//! - [`marlin`]: Marlin/src/module/planner.cpp (`_populate_block`, junction deviation or
//!   classic jerk, `reverse_pass`, `forward_pass`, `calculate_trapezoid_for_block`) and
//!   stepper.cpp (how the stepper runs a block, `S_CURVE_ACCELERATION`).
//! - [`rrf`]: RepRapFirmware src/Movement/DDA.cpp (`InitStandardMove`, `DoLookahead`,
//!   `MatchSpeeds`, `RecalculateMove`) and DDARing.cpp (`CanAddMove`, `PrepareMoves`).
//! - [`grbl`]: GRBL 1.1 grbl/planner.c (`plan_buffer_line`, `planner_recalculate`) and
//!   grbl/stepper.c (the block's trapezoid in `st_prep_buffer`); grblHAL plans the same
//!   way.
//!
//! [`Firmware`] names every firmware settle knows (and settle's own planner), with the one
//! parser of their names that every command uses.
//!
//! Every planner is a bounded queue like the firmware's own: push [`LinearMove`]s in, pull
//! final [`PlannedMove`]s out; memory does not grow with the length of the job.
//! [`profiles::ProfileStream`] turns planned moves into per-axis [`crate::Profile`]
//! chunks for simulation.
//!
//! Units are SI throughout (m, s); firmware settings given in mm or mm/min are converted
//! by the caller.
//!
//! The firmwares run in real time; these planners assume the G-code arrives faster than
//! the printer moves (printing from a file), so every queue is as full as the firmware
//! allows whenever it decides something. What each model approximates is said in its
//! module.
//!
//! ```
//! use settle_planner::firmware::klipper::{KlipperConfig, KlipperPlanner};
//! use settle_planner::firmware::profiles::{ProfileOptions, ProfileStream};
//! use settle_planner::firmware::{FirmwarePlanner, LinearMove};
//!
//! // max_velocity 300 mm/s, max_accel 3000 mm/s^2, Klipper's other defaults.
//! let mut planner = KlipperPlanner::new(KlipperConfig::new(0.3, 3.0))?;
//! let mut stream = ProfileStream::new(ProfileOptions::default())?;
//! let corner = [
//!     LinearMove::new([0.0, 0.0, 0.0], [0.05, 0.0, 0.0], 0.0, 0.1),
//!     LinearMove::new([0.05, 0.0, 0.0], [0.05, 0.05, 0.0], 0.0, 0.1),
//! ];
//! for mv in &corner {
//!     planner.push(mv)?;
//!     while let Some(planned) = planner.pop() {
//!         stream.push(&planned)?;
//!     }
//! }
//! planner.finish();
//! while let Some(planned) = planner.pop() {
//!     // 5 mm/s at the corner: Klipper's square_corner_velocity.
//!     assert!(planned.end_speed_m_s < 0.0051);
//!     stream.push(&planned)?;
//! }
//! stream.finish()?;
//! let chunk = stream.pop().expect("one chunk");
//! assert_eq!(chunk.trajectory.dof(), 4); // X, Y, Z, E
//! # Ok::<(), settle_planner::PlanError>(())
//! ```

pub mod grbl;
pub mod klipper;
pub mod marlin;
mod planned;
pub mod profiles;
pub mod rrf;
mod timeline;
mod which;

pub use planned::{MAX_PHASES, PathState, Phase, PlannedMove, RampShape};
pub use which::Firmware;

use crate::PlanError;

/// One straight move as the G-code asks for it, in machine coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearMove {
    /// X, Y, Z at the start (m).
    pub start_m: [f64; 3],
    /// X, Y, Z at the end (m).
    pub end_m: [f64; 3],
    /// Filament pushed by the extruder over the move (m; negative retracts).
    pub extrude_m: f64,
    /// Requested speed (m/s): the feed rate along the XYZ path, or of the extruder for an
    /// extruder-only move.
    pub speed_m_s: f64,
    /// A rapid (`G0`) that a CNC firmware runs at its machine's own rate, whatever
    /// `speed_m_s` says (GRBL's `PL_COND_FLAG_RAPID_MOTION`); the printer firmwares plan
    /// `G0` like `G1` and ignore it.
    pub rapid: bool,
}

impl LinearMove {
    /// A move from `start_m` to `end_m` at `speed_m_s`, extruding `extrude_m`.
    pub fn new(start_m: [f64; 3], end_m: [f64; 3], extrude_m: f64, speed_m_s: f64) -> Self {
        Self {
            start_m,
            end_m,
            extrude_m,
            speed_m_s,
            rapid: false,
        }
    }

    /// The same move as a rapid ([`LinearMove::rapid`]).
    pub fn as_rapid(mut self) -> Self {
        self.rapid = true;
        self
    }

    /// X, Y, Z and E displacement (m).
    pub fn delta_m(&self) -> [f64; 4] {
        [
            self.end_m[0] - self.start_m[0],
            self.end_m[1] - self.start_m[1],
            self.end_m[2] - self.start_m[2],
            self.extrude_m,
        ]
    }

    /// Reject NaN or infinite coordinates and a speed that is not finite and > 0.
    pub fn validate(&self) -> Result<(), PlanError> {
        for (name, v) in [
            ("start x", self.start_m[0]),
            ("start y", self.start_m[1]),
            ("start z", self.start_m[2]),
            ("end x", self.end_m[0]),
            ("end y", self.end_m[1]),
            ("end z", self.end_m[2]),
            ("extrude", self.extrude_m),
        ] {
            if !v.is_finite() {
                return Err(PlanError::NonFinite { name, value: v });
            }
        }
        if !(self.speed_m_s.is_finite() && self.speed_m_s > 0.0) {
            return Err(PlanError::InvalidLimit {
                name: "move speed",
                value: self.speed_m_s,
            });
        }
        Ok(())
    }
}

/// How the motors make the toolhead move in X and Y.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Kinematics {
    /// One motor per axis.
    #[default]
    Cartesian,
    /// Motor A moves `X + Y`, motor B `X - Y` (both belts drive the toolhead).
    CoreXy,
}

/// A firmware's planner: moves and waits go in, final planned moves come out in order.
pub trait FirmwarePlanner {
    /// Queue one straight move (zero-length moves are accepted and dropped, as the
    /// firmwares do).
    fn push(&mut self, mv: &LinearMove) -> Result<(), PlanError>;

    /// Wait until every queued move has finished (the machine stops), then idle
    /// `delay_s`: G4 is `dwell(P)`, M400 is `dwell(0)`.
    fn dwell(&mut self, delay_s: f64) -> Result<(), PlanError>;

    /// End of input: plan every queued move to a stop.
    fn finish(&mut self);

    /// Take the next final planned move, in execution order.
    fn pop(&mut self) -> Option<PlannedMove>;

    /// The print clock (s): the end of the last final move or dwell.
    fn print_time_s(&self) -> f64;
}

/// Check a dwell time.
fn check_dwell(delay_s: f64) -> Result<f64, PlanError> {
    if !(delay_s.is_finite() && delay_s >= 0.0) {
        return Err(PlanError::NonFinite {
            name: "dwell time (must be finite and >= 0)",
            value: delay_s,
        });
    }
    Ok(delay_s)
}

/// Check that a firmware setting is finite and > 0.
fn positive(name: &'static str, value: f64) -> Result<(), PlanError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(PlanError::InvalidLimit { name, value })
    }
}
