//! Marlin's planner (Marlin/src/module/planner.cpp) with its block buffer.
//!
//! Read from planner.cpp of Marlin 2.0.9.x and stepper.cpp of a 2.1.x version; later 2.1
//! releases reworked the rounding in `calculate_trapezoid_for_block`, which this model
//! does not follow.
//!
//! Marlin plans in stepper steps. A move becomes a *block* (`_populate_block`): positions
//! are rounded to whole steps, a block of fewer than `MIN_STEPS_PER_SEGMENT` steps on
//! every axis is dropped (its steps join the next block), the feed rate is raised to the
//! minimum feed rate and lowered to each axis's `M203` limit, the nominal step rate is
//! `ceil(steps / time)`, the acceleration is `M204` print, travel or retract acceleration
//! in steps/s^2 (`ceil`), lowered for each axis to its `M201` limit (`floor`). The corner
//! speed comes from junction deviation (`M205 J`, with the small-segment arc limit of
//! `JD_HANDLE_SMALL_SEGMENTS`) or classic jerk (`M205 X Y Z E`, the "safe speed" logic).
//! Look-ahead runs `reverse_pass` and `forward_pass` over the non-busy blocks each time a
//! block is added, with Marlin's `block_buffer_planned` bookkeeping; the last block ends at
//! `MINIMUM_PLANNER_SPEED`. When the stepper takes a block its trapezoid is fixed
//! (`calculate_trapezoid_for_block`): entry and exit rates `ceil`ed and raised to
//! `MINIMAL_STEP_RATE`, acceleration steps `ceil`ed, deceleration steps `floor`ed.
//! [`crate::firmware::PlannedMove`] then follows the stepper (stepper.cpp): the rate ramps
//! in time (linearly, or along the quintic Bezier with `S_CURVE_ACCELERATION`) and phases
//! end at the planned step counts, holding the ramp's target rate if it is reached early
//! and leaving a deceleration cut short above the exit rate.
//!
//! The queue holds `BLOCK_BUFFER_SIZE - 1` blocks. Printing from a file it is full: the
//! stepper takes block `k` (fixing its trapezoid and the next block's entry speed) before
//! block `k + 14` is added. After an empty queue the first block starts once
//! [`MarlinConfig::first_block_after`] blocks are queued (stepper.cpp delivers it when 3
//! are, `BLOCK_DELAY_FOR_1ST_MOVE`).
//!
//! Approximations: f64 instead of the firmware's f32; the stepper's timer-tick rounding
//! and one-step offsets at phase boundaries are not modelled (each phase is exact in
//! continuous time between the planned step counts: an error of about one step period per
//! phase). Classic jerk can, in Marlin, let a junction exceed the previous block's nominal
//! speed (the "safe speed" branch); here the junction is capped at it, as junction
//! deviation does. Not modelled: `LIN_ADVANCE` limits, `XY_FREQUENCY_LIMIT`, volumetric
//! limits, `FT_MOTION`.

use std::collections::VecDeque;

use super::marlin_block::{Block, JunctionState};
use super::marlin_trapezoid::plan_block;
use super::timeline::Timeline;
use super::{FirmwarePlanner, Kinematics, LinearMove, PlannedMove};
use crate::PlanError;

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
                super::positive(name, x)?;
            }
        }
        super::positive("print acceleration", self.print_accel_m_s2)?;
        super::positive("retract acceleration", self.retract_accel_m_s2)?;
        super::positive("travel acceleration", self.travel_accel_m_s2)?;
        super::positive("minimal step rate", self.minimal_step_rate_hz)?;
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
                super::positive("junction deviation", deviation_m)?;
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

/// Marlin's planner and block buffer: push moves, pull blocks as the stepper takes them.
#[derive(Debug)]
pub struct MarlinPlanner {
    cfg: MarlinConfig,
    junction: JunctionState,
    /// Planner position in steps (X/A head, Y/B head, Z, E).
    position_steps: [i64; 4],
    /// Target position of the last move pushed (m), E accumulated.
    target_m: [f64; 4],
    blocks: VecDeque<Block>,
    /// Whether `blocks[0]` is being executed (its plan is final).
    busy: bool,
    /// Id of `block_buffer_planned`: blocks before it no longer change.
    planned: u64,
    next_id: u64,
    timeline: Timeline,
    seq: u64,
}

impl MarlinPlanner {
    /// A planner with `cfg` (checked), idle at the origin.
    pub fn new(cfg: MarlinConfig) -> Result<Self, PlanError> {
        cfg.validate()?;
        Ok(Self {
            cfg,
            junction: JunctionState::default(),
            position_steps: [0; 4],
            target_m: [0.0; 4],
            blocks: VecDeque::new(),
            busy: false,
            planned: 0,
            next_id: 0,
            timeline: Timeline::default(),
            seq: 0,
        })
    }

    /// The settings in force.
    pub fn config(&self) -> &MarlinConfig {
        &self.cfg
    }

    /// Replace the settings (M92, M201, M203, M204, M205) for the blocks added from now
    /// on; queued blocks keep theirs, as in Marlin. A change of steps per metre re-rounds
    /// the planner position (`refresh_positioning`).
    pub fn set_config(&mut self, cfg: MarlinConfig) -> Result<(), PlanError> {
        cfg.validate()?;
        if cfg.steps_per_m != self.cfg.steps_per_m {
            for i in 0..4 {
                self.position_steps[i] = (self.target_m[i] * cfg.steps_per_m[i]).round() as i64;
            }
        }
        self.cfg = cfg;
        Ok(())
    }

    /// Blocks in the buffer (the executing one included).
    pub fn queued(&self) -> usize {
        self.blocks.len()
    }

    /// The stepper takes the oldest block: its trapezoid is fixed with the next block's
    /// entry speed, and `block_buffer_planned` moves past it (`get_current_block`).
    fn take_next(&mut self) {
        let Some(b) = self.blocks.front() else {
            return;
        };
        let exit = self
            .blocks
            .get(1)
            .map_or(self.cfg.minimum_planner_speed_m_s, |n| {
                n.entry_speed_sqr.sqrt()
            });
        let planned: PlannedMove = plan_block(b, b.entry_speed_sqr.sqrt(), exit, &self.cfg);
        if self.planned == b.id {
            self.planned = b.id + 1;
        }
        self.busy = true;
        self.timeline.emit(planned);
    }

    /// The executing block finishes; the stepper takes the next at once.
    fn finish_busy(&mut self) {
        if self.busy {
            self.blocks.pop_front();
            self.busy = false;
        }
        if !self.blocks.is_empty() {
            self.take_next();
        }
    }

    /// `recalculate`: reverse and forward pass over the blocks after
    /// `block_buffer_planned`. Trapezoids are computed when the stepper takes a block.
    fn recalculate(&mut self) {
        let Some(last) = self.blocks.len().checked_sub(1) else {
            return;
        };
        let front_id = self.blocks[0].id;
        let pi = (self.planned.saturating_sub(front_id) as usize).min(last);
        if last != pi {
            let min_v2 = self.cfg.minimum_planner_speed_m_s.powi(2);
            // Reverse pass: the fastest entry that can still slow down to the next one.
            for i in (pi + 1..=last).rev() {
                let next = (i < last).then(|| {
                    (
                        self.blocks[i + 1].entry_speed_sqr,
                        self.blocks[i + 1].recalculate,
                    )
                });
                let b = &mut self.blocks[i];
                let max_entry = b.max_entry_speed_sqr;
                if b.entry_speed_sqr != max_entry || next.is_some_and(|n| n.1) {
                    let new_entry = if b.nominal_length {
                        max_entry
                    } else {
                        let next_v2 = next.map_or(min_v2, |n| n.0);
                        max_entry.min(next_v2 + 2.0 * b.acceleration * b.millimeters)
                    };
                    if b.entry_speed_sqr != new_entry {
                        b.recalculate = true;
                        b.entry_speed_sqr = new_entry;
                    }
                }
            }
            // Forward pass: an entry no faster than the previous block can accelerate to.
            for i in pi + 1..=last {
                let prev = &self.blocks[i - 1];
                let (p_nominal, p_entry, p_reach) = (
                    prev.nominal_length,
                    prev.entry_speed_sqr,
                    prev.entry_speed_sqr + 2.0 * prev.acceleration * prev.millimeters,
                );
                let b = &mut self.blocks[i];
                if !p_nominal && p_entry < b.entry_speed_sqr && p_reach < b.entry_speed_sqr {
                    b.recalculate = true;
                    b.entry_speed_sqr = p_reach;
                    self.planned = b.id;
                }
                if b.entry_speed_sqr == b.max_entry_speed_sqr {
                    self.planned = b.id;
                }
            }
        }
        for b in &mut self.blocks {
            b.recalculate = false;
        }
    }
}

impl FirmwarePlanner for MarlinPlanner {
    fn push(&mut self, mv: &LinearMove) -> Result<(), PlanError> {
        mv.validate()?;
        let seq = self.seq;
        self.seq += 1;
        // `get_next_free_block`: wait for room; meanwhile the stepper moves on.
        while self.blocks.len() >= self.cfg.capacity() {
            if self.busy {
                self.finish_busy();
            } else {
                self.take_next();
            }
        }
        let target = [
            mv.end_m[0],
            mv.end_m[1],
            mv.end_m[2],
            self.target_m[3] + mv.extrude_m,
        ];
        let moves_queued = self.blocks.len() - usize::from(self.busy);
        let block = Block::populate(
            &self.cfg,
            &mut self.junction,
            &mut self.position_steps,
            target,
            mv.speed_m_s,
            moves_queued,
            seq,
            self.next_id,
        );
        self.target_m = target;
        if let Some(b) = block {
            self.next_id += 1;
            self.blocks.push_back(b);
            self.recalculate();
        }
        if !self.busy && self.blocks.len() >= self.cfg.first_block_after {
            self.take_next();
        }
        Ok(())
    }

    fn dwell(&mut self, delay_s: f64) -> Result<(), PlanError> {
        let delay_s = super::check_dwell(delay_s)?;
        self.finish();
        self.timeline.idle(delay_s);
        Ok(())
    }

    fn finish(&mut self) {
        while !self.blocks.is_empty() {
            if self.busy {
                self.finish_busy();
            } else {
                self.take_next();
            }
        }
    }

    fn pop(&mut self) -> Option<PlannedMove> {
        self.timeline.pop()
    }

    fn print_time_s(&self) -> f64 {
        self.timeline.time_s()
    }
}
