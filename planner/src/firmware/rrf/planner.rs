//! RepRapFirmware's move ring (`DDARing`): adding, preparing and retiring moves.

use std::collections::VecDeque;

use super::config::RrfConfig;
use super::dda::{Dda, DdaState, Retired, do_lookahead};
use crate::PlanError;
use crate::firmware::timeline::Timeline;
use crate::firmware::{FirmwarePlanner, LinearMove, PlannedMove};

/// Prepare moves this long before they are due (`UsualMinimumPreparedTime`).
const USUAL_MIN_PREPARED_S: f64 = 0.1;
/// Prepare even a still-decelerating move this long before (`AbsoluteMinimumPreparedTime`).
const ABSOLUTE_MIN_PREPARED_S: f64 = 0.05;
/// `CanAddMove`: unprepared moves other than the oldest must last less than this...
const UNPREPARED_BUT_FIRST_S: f64 = 0.5;
/// ...or all unprepared moves less than this.
const UNPREPARED_ALL_S: f64 = 2.0;

/// RepRapFirmware's planner and move ring: push moves, pull them as they are prepared.
#[derive(Debug)]
pub struct RrfPlanner {
    cfg: RrfConfig,
    /// Frozen moves not yet finished (oldest first), then provisional ones.
    ring: VecDeque<Dda>,
    /// The last finished move, as the next look-ahead sees it.
    retired: Retired,
    /// How many moves at the front of `ring` are frozen.
    n_frozen: usize,
    /// The simulated time at which the ring is looked at (s).
    now_s: f64,
    /// End of the last frozen move (s).
    prepared_end_s: f64,
    timeline: Timeline,
    seq: u64,
    e_pos: f64,
}

impl RrfPlanner {
    /// A planner with `cfg` (checked), idle at the origin.
    pub fn new(cfg: RrfConfig) -> Result<Self, PlanError> {
        cfg.validate()?;
        Ok(Self {
            cfg,
            ring: VecDeque::new(),
            retired: Retired::default(),
            n_frozen: 0,
            now_s: 0.0,
            prepared_end_s: 0.0,
            timeline: Timeline::default(),
            seq: 0,
            e_pos: 0.0,
        })
    }

    /// The settings in force.
    pub fn config(&self) -> &RrfConfig {
        &self.cfg
    }

    /// Replace the settings (M201, M203, M204, M566) for the moves added from now on.
    pub fn set_config(&mut self, cfg: RrfConfig) -> Result<(), PlanError> {
        cfg.validate()?;
        self.cfg = cfg;
        Ok(())
    }

    /// Moves in the ring (frozen and provisional).
    pub fn queued(&self) -> usize {
        self.ring.len()
    }

    fn frozen(&self) -> usize {
        self.n_frozen
    }

    fn running(&self) -> bool {
        self.prepared_end_s > self.now_s
    }

    /// `CanAddMove`.
    fn can_add(&self) -> bool {
        let n = self.ring.len();
        let size = self.cfg.ring_length;
        let slot_free = n + 1 < size
            || (n + 1 == size
                && self
                    .ring
                    .front()
                    .is_some_and(|d| d.state == DdaState::Frozen));
        if !slot_free {
            return false;
        }
        let mut provisional = self.ring.iter().skip(self.frozen()).map(|d| d.clocks_s);
        let oldest = provisional.next().unwrap_or(0.0);
        let rest: f64 = provisional.sum();
        rest < UNPREPARED_BUT_FIRST_S || rest + oldest < UNPREPARED_ALL_S
    }

    /// Forget the moves that have finished by now (`RecycleDDAs`).
    fn recycle(&mut self) {
        while let Some(d) = self.ring.front() {
            if d.state != DdaState::Frozen || d.end_time_s > self.now_s {
                break;
            }
            self.retired = Retired {
                decel_field: d.decel_field(),
            };
            self.ring.pop_front();
            self.n_frozen -= 1;
        }
    }

    /// Freeze the oldest provisional move (`Prepare`) to start when the frozen ones end.
    fn freeze_next(&mut self, nf: usize) {
        let start = self.prepared_end_s.max(self.now_s);
        self.timeline.idle_until(start);
        let planned: PlannedMove = self.ring[nf].freeze(start);
        self.n_frozen += 1;
        self.prepared_end_s = self.ring[nf].end_time_s;
        self.timeline.emit(planned);
    }

    /// `PrepareMoves` at the current time.
    fn prepare(&mut self) {
        loop {
            let nf = self.frozen();
            let Some(d) = self.ring.get(nf) else {
                return;
            };
            let time_left = (self.prepared_end_s - self.now_s).max(0.0);
            if time_left < USUAL_MIN_PREPARED_S
                && nf * 2 < self.cfg.ring_length
                && (d.is_good_to_prepare() || time_left < ABSOLUTE_MIN_PREPARED_S)
            {
                self.freeze_next(nf);
            } else {
                return;
            }
        }
    }

    /// Let time run to the next event (a move finishing or a preparation falling due), or
    /// start moving if nothing runs.
    fn advance(&mut self) {
        if !self.running() {
            // Waiting for space with nothing moving: start (`Spin`).
            self.prepare();
            return;
        }
        let nf = self.frozen();
        let completion = self.ring.front().map_or(f64::INFINITY, |d| d.end_time_s);
        let due = match self.ring.get(nf) {
            Some(d) if nf * 2 < self.cfg.ring_length => {
                let margin = if d.is_good_to_prepare() {
                    USUAL_MIN_PREPARED_S
                } else {
                    ABSOLUTE_MIN_PREPARED_S
                };
                self.prepared_end_s - margin
            }
            _ => f64::INFINITY,
        };
        if due <= completion {
            // The next move falls due for preparation before anything finishes.
            self.now_s = due.max(self.now_s);
            self.recycle();
            let nf = self.frozen();
            if nf < self.ring.len() {
                self.freeze_next(nf);
            }
        } else {
            self.now_s = completion.max(self.now_s);
            self.recycle();
        }
        self.prepare();
    }

    /// Run every queued move to the end and idle until it has finished.
    fn drain(&mut self) {
        while self.n_frozen < self.ring.len() {
            let nf = self.frozen();
            self.freeze_next(nf);
        }
        self.now_s = self.now_s.max(self.prepared_end_s);
        self.recycle();
    }
}

impl FirmwarePlanner for RrfPlanner {
    fn push(&mut self, mv: &LinearMove) -> Result<(), PlanError> {
        mv.validate()?;
        let seq = self.seq;
        self.seq += 1;
        let start = [mv.start_m[0], mv.start_m[1], mv.start_m[2], self.e_pos];
        let Some(mut dda) = Dda::new(&self.cfg, seq, start, mv.delta_m(), mv.speed_m_s) else {
            return Ok(());
        };
        self.e_pos += mv.extrude_m;
        self.recycle();
        while !self.can_add() {
            let before = (self.now_s, self.ring.len(), self.frozen());
            self.advance();
            if (self.now_s, self.ring.len(), self.frozen()) == before {
                return Err(PlanError::NoSolution {
                    reason: "the RepRapFirmware ring can neither take a move nor advance",
                });
            }
        }
        let meld = self
            .ring
            .back()
            .is_some_and(|prev| dda.can_meld_after(prev, self.cfg.jerk_policy));
        self.ring.push_back(dda);
        let last = self.ring.len() - 1;
        if meld {
            let target = self.ring[last].max_start_from_rest();
            let ring = self.ring.make_contiguous();
            ring[last - 1].target_next = target;
            do_lookahead(ring, last - 1, self.retired, &self.cfg);
            dda = self.ring[last];
            dda.start_speed = self.ring[last - 1].end_speed;
        } else {
            dda.start_speed = 0.0;
        }
        dda.recalculate();
        self.ring[last] = dda;
        if self.running() {
            self.prepare();
        }
        Ok(())
    }

    fn dwell(&mut self, delay_s: f64) -> Result<(), PlanError> {
        let delay_s = crate::firmware::check_dwell(delay_s)?;
        self.drain();
        self.now_s += delay_s;
        self.prepared_end_s = self.now_s;
        self.timeline.idle(delay_s);
        Ok(())
    }

    fn finish(&mut self) {
        self.drain();
    }

    fn pop(&mut self) -> Option<PlannedMove> {
        self.timeline.pop()
    }

    fn print_time_s(&self) -> f64 {
        self.timeline.time_s()
    }
}
