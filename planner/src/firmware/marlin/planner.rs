//! Marlin's block buffer and look-ahead (`Planner::reverse_pass`, `forward_pass`).

use std::collections::VecDeque;

use super::block::{Block, JunctionState};
use super::config::MarlinConfig;
use super::trapezoid::plan_block;
use crate::PlanError;
use crate::firmware::timeline::Timeline;
use crate::firmware::{FirmwarePlanner, LinearMove, PlannedMove};

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
        let delay_s = crate::firmware::check_dwell(delay_s)?;
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
