//! Klipper's look-ahead queue (toolhead.py `LookAheadQueue`) and the planner object.

use std::collections::VecDeque;

use super::config::KlipperConfig;
use super::kmove::KMove;
use crate::PlanError;
use crate::firmware::timeline::Timeline;
use crate::firmware::{FirmwarePlanner, LinearMove, Phase, PlannedMove};

/// Flush time after a lazy flush (s): `LOOKAHEAD_FLUSH_TIME`.
const LOOKAHEAD_FLUSH_TIME_S: f64 = 0.150;
/// Flush time after a start or a full flush (s): `BUFFER_TIME_HIGH`.
const BUFFER_TIME_HIGH_S: f64 = 1.0;

/// Klipper's planner: push moves, pull planned trapezoids.
///
/// The queue holds the moves whose junction speeds may still change; it flushes lazily
/// (`LookAheadQueue.flush(lazy=True)`) once the queued moves' minimum durations reach the
/// flush time, and fully on [`FirmwarePlanner::dwell`] and [`FirmwarePlanner::finish`].
/// Its length is bounded by that time, not by the job.
#[derive(Debug)]
pub struct KlipperPlanner {
    cfg: KlipperConfig,
    queue: VecDeque<KMove>,
    junction_flush_s: f64,
    /// Per queued move: (start_v2, cruise_v2 if set, next_start_v2), reused by flushes.
    info: Vec<(f64, Option<f64>, f64)>,
    timeline: Timeline,
    seq: u64,
    position: [f64; 4],
}

impl KlipperPlanner {
    /// A planner with `cfg` (checked), idle at the origin.
    pub fn new(cfg: KlipperConfig) -> Result<Self, PlanError> {
        cfg.validate()?;
        Ok(Self {
            cfg,
            queue: VecDeque::new(),
            junction_flush_s: BUFFER_TIME_HIGH_S,
            info: Vec::new(),
            timeline: Timeline::default(),
            seq: 0,
            position: [0.0; 4],
        })
    }

    /// The settings in force.
    pub fn config(&self) -> &KlipperConfig {
        &self.cfg
    }

    /// Replace the settings for the moves queued from now on (the `SET_VELOCITY_LIMIT`
    /// settings and those Klipper reads only from printer.cfg).
    pub fn set_config(&mut self, cfg: KlipperConfig) -> Result<(), PlanError> {
        cfg.validate()?;
        self.cfg = cfg;
        Ok(())
    }

    /// `SET_VELOCITY_LIMIT` (and `M204`, which sets `accel`): change the given settings for
    /// the moves queued from now on. Moves already queued keep theirs, as in Klipper.
    pub fn set_velocity_limit(
        &mut self,
        velocity_m_s: Option<f64>,
        accel_m_s2: Option<f64>,
        square_corner_velocity_m_s: Option<f64>,
        minimum_cruise_ratio: Option<f64>,
    ) -> Result<(), PlanError> {
        let mut cfg = self.cfg;
        if let Some(v) = velocity_m_s {
            cfg.max_velocity_m_s = v;
        }
        if let Some(a) = accel_m_s2 {
            cfg.max_accel_m_s2 = a;
        }
        if let Some(s) = square_corner_velocity_m_s {
            cfg.square_corner_velocity_m_s = s;
        }
        if let Some(r) = minimum_cruise_ratio {
            cfg.minimum_cruise_ratio = r;
        }
        cfg.validate()?;
        self.cfg = cfg;
        Ok(())
    }

    /// Moves waiting in the look-ahead queue.
    pub fn queued(&self) -> usize {
        self.queue.len()
    }

    /// `LookAheadQueue.add_move`: queue `m`, returning whether a lazy flush is due.
    fn add_move(&mut self, mut m: KMove) -> bool {
        let Some(prev) = self.queue.back() else {
            self.queue.push_back(m);
            return false;
        };
        m.calc_junction(prev, self.cfg.extruder.as_ref());
        self.junction_flush_s -= m.min_move_t;
        self.queue.push_back(m);
        self.junction_flush_s <= 0.0
    }

    /// `LookAheadQueue.flush`: plan the queue assuming a stop after its last move, then
    /// emit the moves whose plan is final (all of them unless `lazy`).
    fn flush(&mut self, lazy: bool) {
        self.junction_flush_s = LOOKAHEAD_FLUSH_TIME_S;
        let mut update_flush_count = lazy;
        let n = self.queue.len();
        let mut flush_count = n;
        self.info.clear();
        self.info.resize(n, (0.0, None, 0.0));
        // Backward pass: the highest junction speeds that still allow the final stop.
        let (mut next_start_v2, mut next_mcr_start_v2, mut peak_cruise_v2) = (0.0, 0.0, 0.0);
        let mut pending_cv2_assign = 0usize;
        for i in (0..n).rev() {
            let m = &self.queue[i];
            let reachable_start_v2 = next_start_v2 + m.delta_v2;
            let start_v2 = m.max_start_v2.min(reachable_start_v2);
            let mut cruise_v2 = None;
            pending_cv2_assign += 1;
            let reach_mcr_start_v2 = next_mcr_start_v2 + m.mcr_delta_v2;
            let mcr_start_v2 = m.max_mcr_start_v2.min(reach_mcr_start_v2);
            if mcr_start_v2 < reach_mcr_start_v2 {
                // This move can accelerate.
                if mcr_start_v2 + m.mcr_delta_v2 > next_mcr_start_v2 || pending_cv2_assign > 1 {
                    // It can accelerate and decelerate, or it is a full acceleration
                    // followed by a full deceleration: a new peak.
                    if update_flush_count && peak_cruise_v2 != 0.0 {
                        flush_count = i + pending_cv2_assign;
                        update_flush_count = false;
                    }
                    peak_cruise_v2 = (mcr_start_v2 + reach_mcr_start_v2) * 0.5;
                }
                cruise_v2 = Some(
                    ((start_v2 + reachable_start_v2) * 0.5)
                        .min(m.max_cruise_v2)
                        .min(peak_cruise_v2),
                );
                pending_cv2_assign = 0;
            }
            self.info[i] = (start_v2, cruise_v2, next_start_v2);
            next_start_v2 = start_v2;
            next_mcr_start_v2 = mcr_start_v2;
        }
        if update_flush_count || flush_count == 0 {
            return;
        }
        // Forward pass: moves that cannot accelerate keep the previous cruise speed.
        let mut prev_cruise_v2: f64 = 0.0;
        for i in 0..flush_count {
            let Some(m) = self.queue.pop_front() else {
                break;
            };
            let (start_v2, cruise, next_start_v2) = self.info[i];
            let cruise_v2 = cruise.unwrap_or_else(|| prev_cruise_v2.min(start_v2));
            let planned = set_junction(
                &m,
                start_v2.min(cruise_v2),
                cruise_v2,
                next_start_v2.min(cruise_v2),
            );
            self.timeline.emit(planned);
            prev_cruise_v2 = cruise_v2;
        }
    }

    /// Flush everything and restart the flush timer at `BUFFER_TIME_HIGH`
    /// (`ToolHead._flush_lookahead`).
    fn flush_all(&mut self) {
        self.flush(false);
        self.junction_flush_s = BUFFER_TIME_HIGH_S;
    }
}

/// `Move.set_junction`: the trapezoid of `m` for the given speeds squared.
fn set_junction(m: &KMove, start_v2: f64, cruise_v2: f64, end_v2: f64) -> PlannedMove {
    let half_inv_accel = 0.5 / m.accel;
    let accel_d = (cruise_v2 - start_v2) * half_inv_accel;
    let decel_d = (cruise_v2 - end_v2) * half_inv_accel;
    let cruise_d = m.move_d - accel_d - decel_d;
    let start_v = start_v2.sqrt();
    let cruise_v = cruise_v2.sqrt();
    let end_v = end_v2.sqrt();
    // Time is distance over average speed, as Klipper computes it.
    let accel_t = accel_d / ((start_v + cruise_v) * 0.5);
    let cruise_t = cruise_d / cruise_v;
    let decel_t = decel_d / ((end_v + cruise_v) * 0.5);
    let phases = [
        Phase::linear(accel_t, start_v, m.accel),
        Phase::constant(cruise_t, cruise_v),
        Phase::linear(decel_t, cruise_v, -m.accel),
    ];
    let mut p = PlannedMove::new(m.seq, m.start, m.axes_r, m.move_d, &phases);
    p.start_speed_m_s = start_v;
    p.cruise_speed_m_s = cruise_v;
    p.end_speed_m_s = end_v;
    p.accel_m_s2 = m.accel;
    p.decel_m_s2 = m.accel;
    p.accel_t_s = accel_t;
    p.cruise_t_s = cruise_t;
    p.decel_t_s = decel_t;
    p
}

impl FirmwarePlanner for KlipperPlanner {
    fn push(&mut self, mv: &LinearMove) -> Result<(), PlanError> {
        mv.validate()?;
        let seq = self.seq;
        self.seq += 1;
        let start = [
            mv.start_m[0],
            mv.start_m[1],
            mv.start_m[2],
            self.position[3],
        ];
        let delta = mv.delta_m();
        let Some(m) = KMove::new(&self.cfg, seq, start, delta, mv.speed_m_s)? else {
            return Ok(());
        };
        self.position[3] += mv.extrude_m;
        if self.add_move(m) {
            self.flush(true);
        }
        Ok(())
    }

    fn dwell(&mut self, delay_s: f64) -> Result<(), PlanError> {
        let delay_s = crate::firmware::check_dwell(delay_s)?;
        self.flush_all();
        self.timeline.idle(delay_s);
        Ok(())
    }

    fn finish(&mut self) {
        self.flush_all();
    }

    fn pop(&mut self) -> Option<PlannedMove> {
        self.timeline.pop()
    }

    fn print_time_s(&self) -> f64 {
        self.timeline.time_s()
    }
}
