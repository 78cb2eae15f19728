//! GRBL's block buffer, junction speeds and look-ahead (grbl/planner.c) and the
//! trapezoid each block runs (grbl/stepper.c).

use std::collections::VecDeque;

use super::config::{GrblConfig, MINIMUM_FEED_RATE_M_S};
use crate::PlanError;
use crate::firmware::timeline::Timeline;
use crate::firmware::{FirmwarePlanner, LinearMove, Phase, PlannedMove};

/// `SOME_LARGE_VALUE` (grbl/nuts_bolts.h): a junction speed squared without limit.
const NO_LIMIT_V2: f64 = 1.0e38;
/// `MINIMUM_JUNCTION_SPEED` (grbl/config.h: 0 mm/min).
const MINIMUM_JUNCTION_SPEED_M_S: f64 = 0.0;

/// A block (`plan_block_t`), speeds squared in m^2/s^2.
#[derive(Debug, Clone, Copy)]
struct Block {
    id: u64,
    seq: u64,
    /// X, Y, Z at the start (m, on the step grid).
    start_m: [f64; 3],
    /// Unit direction.
    unit: [f64; 3],
    /// `millimeters` (m).
    length_m: f64,
    /// m/s^2.
    acceleration: f64,
    /// m/s.
    nominal_speed: f64,
    max_entry_speed_sqr: f64,
    entry_speed_sqr: f64,
}

/// `limit_value_by_axis_maximum`: the largest value along `unit` inside the per-axis box
/// `max`.
fn limit_by_axis_maximum(max: &[f64; 3], unit: &[f64; 3]) -> f64 {
    max.iter()
        .zip(unit)
        .filter(|(_, u)| **u != 0.0)
        .fold(f64::INFINITY, |m, (v, u)| m.min(v / u.abs()))
}

/// `convert_delta_vector_to_unit_vector`: normalises `v` in place, returns its length.
fn normalise(v: &mut [f64; 3]) -> f64 {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    for x in v.iter_mut() {
        *x /= n;
    }
    n
}

/// GRBL's planner and block buffer: push moves, pull blocks as the machine runs them.
#[derive(Debug)]
pub struct GrblPlanner {
    cfg: GrblConfig,
    /// `pl.position` (steps).
    position_steps: [i64; 3],
    /// `pl.previous_unit_vec`.
    previous_unit: [f64; 3],
    /// `pl.previous_nominal_speed` (m/s).
    previous_nominal: f64,
    blocks: VecDeque<Block>,
    /// Id of `block_buffer_planned`.
    planned: u64,
    next_id: u64,
    timeline: Timeline,
    seq: u64,
}

impl GrblPlanner {
    /// A planner with `cfg` (checked), idle at the origin.
    pub fn new(cfg: GrblConfig) -> Result<Self, PlanError> {
        cfg.validate()?;
        Ok(Self {
            cfg,
            position_steps: [0; 3],
            previous_unit: [0.0; 3],
            previous_nominal: 0.0,
            blocks: VecDeque::new(),
            planned: 0,
            next_id: 0,
            timeline: Timeline::default(),
            seq: 0,
        })
    }

    /// The settings in force.
    pub fn config(&self) -> &GrblConfig {
        &self.cfg
    }

    /// Replace the settings for the blocks added from now on (GRBL changes `$`-settings
    /// only when idle, so a caller applies them after [`FirmwarePlanner::dwell`]).
    pub fn set_config(&mut self, cfg: GrblConfig) -> Result<(), PlanError> {
        cfg.validate()?;
        if cfg.steps_per_m != self.cfg.steps_per_m {
            for i in 0..3 {
                let m = self.position_steps[i] as f64 / self.cfg.steps_per_m[i];
                self.position_steps[i] = (m * cfg.steps_per_m[i]).round() as i64;
            }
        }
        self.cfg = cfg;
        Ok(())
    }

    /// Blocks in the buffer (the running one included).
    pub fn queued(&self) -> usize {
        self.blocks.len()
    }

    fn block(&self, id: u64) -> &Block {
        &self.blocks[(id - self.blocks[0].id) as usize]
    }

    fn block_mut(&mut self, id: u64) -> &mut Block {
        let front = self.blocks[0].id;
        &mut self.blocks[(id - front) as usize]
    }

    /// `planner_recalculate`.
    fn recalculate(&mut self) {
        let head = self.next_id;
        let last = head - 1;
        if last == self.planned {
            return;
        }
        // Reverse pass: the newest block ends at rest.
        let cur = self.block_mut(last);
        cur.entry_speed_sqr = cur
            .max_entry_speed_sqr
            .min(2.0 * cur.acceleration * cur.length_m);
        let mut next_entry = cur.entry_speed_sqr;
        let mut index = last - 1;
        while index != self.planned {
            let cur = self.block_mut(index);
            if cur.entry_speed_sqr != cur.max_entry_speed_sqr {
                let e = next_entry + 2.0 * cur.acceleration * cur.length_m;
                cur.entry_speed_sqr = e.min(cur.max_entry_speed_sqr);
            }
            next_entry = cur.entry_speed_sqr;
            index -= 1;
        }
        // Forward pass from the planned pointer.
        let mut index = self.planned + 1;
        while index != head {
            let cur = *self.block(index - 1);
            let next = self.block_mut(index);
            if cur.entry_speed_sqr < next.entry_speed_sqr {
                let e = cur.entry_speed_sqr + 2.0 * cur.acceleration * cur.length_m;
                if e < next.entry_speed_sqr {
                    next.entry_speed_sqr = e;
                    self.planned = index;
                }
            }
            if self.block(index).entry_speed_sqr == self.block(index).max_entry_speed_sqr {
                self.planned = index;
            }
            index += 1;
        }
    }

    /// The machine runs the oldest block to its end (its exit is the next block's
    /// entry), and the segment generator discards it (`plan_discard_current_block`).
    fn run_oldest(&mut self) {
        let Some(b) = self.blocks.pop_front() else {
            return;
        };
        let exit_sqr = self.blocks.front().map_or(0.0, |n| n.entry_speed_sqr);
        if self.planned == b.id {
            self.planned = b.id + 1;
        }
        self.timeline.emit(trapezoid(&b, exit_sqr));
    }
}

/// The block's profile as `st_prep_buffer` computes it (normal operation, overrides at
/// 100 %): acceleration-only, deceleration-only, trapezoid (or cruise) or triangle.
fn trapezoid(b: &Block, exit_sqr: f64) -> PlannedMove {
    let (l, a, entry_sqr) = (b.length_m, b.acceleration, b.entry_speed_sqr);
    let nominal_sqr = b.nominal_speed * b.nominal_speed;
    let inv_2a = 0.5 / a;
    // Distances measured back from the end of the block, as the firmware does.
    let intersect = 0.5 * (l + inv_2a * (entry_sqr - exit_sqr));
    let (peak_sqr, accel_d, decel_d) = if intersect > 0.0 {
        if intersect < l {
            let decel_after = inv_2a * (nominal_sqr - exit_sqr);
            if decel_after < intersect {
                (nominal_sqr, inv_2a * (nominal_sqr - entry_sqr), decel_after)
            } else {
                (2.0 * a * intersect + exit_sqr, l - intersect, intersect)
            }
        } else {
            (entry_sqr, 0.0, l)
        }
    } else {
        (entry_sqr + 2.0 * a * l, l, 0.0)
    };
    let (v0, vp) = (entry_sqr.sqrt(), peak_sqr.sqrt());
    let cruise_d = (l - accel_d - decel_d).max(0.0);
    let v_end = (peak_sqr - 2.0 * a * decel_d).max(0.0).sqrt();
    let accel_t = (vp - v0) / a;
    let cruise_t = if cruise_d > 0.0 { cruise_d / vp } else { 0.0 };
    let decel_t = (vp - v_end) / a;
    let phases = [
        Phase::linear(accel_t, v0, a),
        Phase::constant(cruise_t, vp),
        Phase::linear(decel_t, vp, -a),
    ];
    let start = [b.start_m[0], b.start_m[1], b.start_m[2], 0.0];
    let axes_r = [b.unit[0], b.unit[1], b.unit[2], 0.0];
    let mut p = PlannedMove::new(b.seq, start, axes_r, l, &phases);
    p.start_speed_m_s = v0;
    p.cruise_speed_m_s = vp;
    p.end_speed_m_s = v_end;
    p.accel_m_s2 = a;
    p.decel_m_s2 = a;
    p.accel_t_s = accel_t;
    p.cruise_t_s = cruise_t;
    p.decel_t_s = decel_t;
    p
}

impl FirmwarePlanner for GrblPlanner {
    fn push(&mut self, mv: &LinearMove) -> Result<(), PlanError> {
        mv.validate()?;
        if mv.extrude_m != 0.0 {
            return Err(PlanError::InvalidInput {
                reason: "GRBL drives no extruder: a move with E cannot be planned",
            });
        }
        let seq = self.seq;
        self.seq += 1;
        let spm = self.cfg.steps_per_m;
        let target: [i64; 3] = std::array::from_fn(|i| (mv.end_m[i] * spm[i]).round() as i64);
        let d: [i64; 3] = std::array::from_fn(|i| target[i] - self.position_steps[i]);
        if d.iter().all(|&x| x == 0) {
            return Ok(());
        }
        // `mc_line`: wait for room; meanwhile the machine runs the oldest block.
        while self.blocks.len() >= self.cfg.capacity() {
            self.run_oldest();
        }
        let start_m: [f64; 3] = std::array::from_fn(|i| self.position_steps[i] as f64 / spm[i]);
        let mut unit: [f64; 3] = std::array::from_fn(|i| d[i] as f64 / spm[i]);
        let length_m = normalise(&mut unit);
        let acceleration = limit_by_axis_maximum(&self.cfg.accel_m_s2, &unit);
        let rapid_rate = limit_by_axis_maximum(&self.cfg.max_rate_m_s, &unit);
        // `plan_compute_profile_nominal_speed`.
        let nominal_speed = if mv.rapid {
            rapid_rate
        } else {
            mv.speed_m_s.min(rapid_rate)
        }
        .max(MINIMUM_FEED_RATE_M_S);
        let max_junction_speed_sqr = if self.blocks.is_empty() {
            0.0
        } else {
            let p = self.previous_unit;
            let cos_theta = -(p[0] * unit[0] + p[1] * unit[1] + p[2] * unit[2]);
            if cos_theta > 0.999999 {
                MINIMUM_JUNCTION_SPEED_M_S * MINIMUM_JUNCTION_SPEED_M_S
            } else if cos_theta < -0.999999 {
                NO_LIMIT_V2
            } else {
                let mut ju: [f64; 3] = std::array::from_fn(|i| unit[i] - p[i]);
                normalise(&mut ju);
                let ja = limit_by_axis_maximum(&self.cfg.accel_m_s2, &ju);
                let sin_half = (0.5 * (1.0 - cos_theta)).sqrt();
                (ja * self.cfg.junction_deviation_m * sin_half / (1.0 - sin_half))
                    .max(MINIMUM_JUNCTION_SPEED_M_S * MINIMUM_JUNCTION_SPEED_M_S)
            }
        };
        // `plan_compute_profile_parameters`.
        let slower = nominal_speed.min(self.previous_nominal);
        let block = Block {
            id: self.next_id,
            seq,
            start_m,
            unit,
            length_m,
            acceleration,
            nominal_speed,
            max_entry_speed_sqr: (slower * slower).min(max_junction_speed_sqr),
            entry_speed_sqr: 0.0,
        };
        if self.blocks.is_empty() {
            self.planned = block.id;
        }
        self.previous_nominal = nominal_speed;
        self.previous_unit = unit;
        self.position_steps = target;
        self.next_id += 1;
        self.blocks.push_back(block);
        self.recalculate();
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
            self.run_oldest();
        }
    }

    fn pop(&mut self) -> Option<PlannedMove> {
        self.timeline.pop()
    }

    fn print_time_s(&self) -> f64 {
        self.timeline.time_s()
    }
}
