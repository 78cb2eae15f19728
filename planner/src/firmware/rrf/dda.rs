//! One RepRapFirmware move (`DDA`, src/Movement/DDA.cpp) and its look-ahead.

use super::config::RrfConfig;
use crate::firmware::{Kinematics, Phase, PlannedMove};

/// Where a move is in RepRapFirmware's ring.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum DdaState {
    /// Queued, still changed by look-ahead.
    Provisional,
    /// Prepared for the step generator: final.
    Frozen,
}

/// `DDA`: a move with its speeds (m/s), accelerations (m/s^2) and distances (m).
#[derive(Debug, Clone, Copy)]
pub(super) struct Dda {
    pub(super) seq: u64,
    pub(super) state: DdaState,
    start: [f64; 4],
    /// `directionVector`: X, Y, Z, E per metre of `total`.
    dir: [f64; 4],
    total: f64,
    requested: f64,
    accel: f64,
    decel: f64,
    pub(super) start_speed: f64,
    pub(super) end_speed: f64,
    top_speed: f64,
    accel_d: f64,
    decel_d: f64,
    pub(super) target_next: f64,
    /// `clocksNeeded` (s).
    pub(super) clocks_s: f64,
    xy_moving: bool,
    printing: bool,
    nonprinting_extruder: bool,
    /// End time once frozen (s).
    pub(super) end_time_s: f64,
    /// `afterPrepare.averageExtrusionSpeed` (m/s) once frozen. It shares memory with
    /// `beforePrepare.decelDistance`, which `DoLookahead` still reads on a frozen move.
    avg_extrusion_speed: f64,
}

/// `MinimumAccelOrDecelClocks`: 10 step clocks at 750 kHz (Duet 3).
const MIN_ACCEL_OR_DECEL_S: f64 = 10.0 / 750_000.0;

/// `VectorBoxIntersection`: how far along the unit vector `v` (components >= 0) one can
/// go before leaving the box `box_`.
fn vector_box_intersection(v: [f64; 4], box_: [f64; 4]) -> f64 {
    let mut magnitude: f64 = box_.iter().sum();
    for (vd, bd) in v.iter().zip(box_) {
        if magnitude * vd > bd {
            magnitude = bd / vd;
        }
    }
    magnitude
}

impl Dda {
    /// `InitStandardMove` up to the look-ahead: direction, distance, acceleration and
    /// requested speed. `None` for a move that goes nowhere.
    pub(super) fn new(
        cfg: &RrfConfig,
        seq: u64,
        start: [f64; 4],
        delta: [f64; 4],
        speed: f64,
    ) -> Option<Self> {
        let linear = delta[..3].iter().any(|&d| d != 0.0);
        let xy_moving = delta[0] != 0.0 || delta[1] != 0.0;
        let extruding = delta[3] != 0.0;
        if !linear && !extruding {
            return None;
        }
        let printing = xy_moving && delta[3] > 0.0;
        let total = if linear {
            (delta[0] * delta[0] + delta[1] * delta[1] + delta[2] * delta[2]).sqrt()
        } else {
            delta[3].abs()
        };
        let dir = delta.map(|d| d / total);
        let abs_dir = dir.map(f64::abs);
        let mut accel = vector_box_intersection(abs_dir, cfg.max_accel_m_s2);
        if xy_moving {
            accel = accel.min(if printing {
                cfg.print_accel_m_s2
            } else {
                cfg.travel_accel_m_s2
            });
        }
        let mut requested = speed
            .max(cfg.min_movement_speed_m_s)
            .min(vector_box_intersection(abs_dir, cfg.max_feedrate_m_s));
        if cfg.kinematics == Kinematics::CoreXy {
            // CoreKinematics::LimitSpeedAndAcceleration: each shared motor's share.
            for (motor, share) in [(0, (dir[0] + dir[1]).abs()), (1, (dir[0] - dir[1]).abs())] {
                if share != 0.0 {
                    requested = requested.min(cfg.max_feedrate_m_s[motor] / share);
                    accel = accel.min(cfg.max_accel_m_s2[motor] / share);
                }
            }
        }
        Some(Self {
            seq,
            state: DdaState::Provisional,
            start,
            dir,
            total,
            requested,
            accel,
            decel: accel,
            start_speed: 0.0,
            end_speed: 0.0,
            top_speed: 0.0,
            accel_d: 0.0,
            decel_d: 0.0,
            target_next: 0.0,
            clocks_s: 0.0,
            xy_moving,
            printing,
            nonprinting_extruder: extruding && !printing,
            end_time_s: 0.0,
            avg_extrusion_speed: 0.0,
        })
    }

    /// Whether look-ahead may join this move to `prev` (jerk policy 0 joins only moves
    /// of the same kind: printing, XY, extruder-only).
    pub(super) fn can_meld_after(&self, prev: &Dda, jerk_policy: u32) -> bool {
        prev.state == DdaState::Provisional
            && (jerk_policy != 0
                || (self.printing == prev.printing
                    && self.xy_moving == prev.xy_moving
                    && self.nonprinting_extruder == prev.nonprinting_extruder))
    }

    /// The top speed this move could start at if it ended at rest:
    /// `min(sqrt(2 d L), requested)`.
    pub(super) fn max_start_from_rest(&self) -> f64 {
        (2.0 * self.decel * self.total).sqrt().min(self.requested)
    }

    /// `IsDecelerationMove`.
    fn is_deceleration_move(&self) -> bool {
        self.decel_d == self.total
            || (self.top_speed < self.requested && self.decel_d > 0.98 * self.total)
    }

    /// `IsGoodToPrepare`: a move that never decelerates cannot improve.
    pub(super) fn is_good_to_prepare(&self) -> bool {
        self.end_speed >= self.top_speed
    }

    /// What `DoLookahead` reads as `prev->beforePrepare.decelDistance`.
    pub(super) fn decel_field(&self) -> f64 {
        match self.state {
            DdaState::Provisional => self.decel_d,
            DdaState::Frozen => self.avg_extrusion_speed,
        }
    }

    /// `RecalculateMove`: top speed and the acceleration and deceleration distances.
    pub(super) fn recalculate(&mut self) {
        let two_a = 2.0 * self.accel;
        let two_d = 2.0 * self.decel;
        let (u, v, req) = (self.start_speed, self.end_speed, self.requested);
        self.accel_d = (req * req - u * u) / two_a;
        self.decel_d = (req * req - v * v) / two_d;
        if self.accel_d + self.decel_d < self.total {
            // Reaches its top speed; drop a very short ramp next to it.
            self.top_speed = req;
            if u >= v {
                if u + self.accel * MIN_ACCEL_OR_DECEL_S > req && u >= 0.9 * req {
                    self.top_speed = u;
                    self.accel_d = 0.0;
                    self.decel_d = (u * u - v * v) / two_d;
                }
            } else if v + self.decel * MIN_ACCEL_OR_DECEL_S > req && v >= 0.9 * req {
                self.top_speed = v;
                self.decel_d = 0.0;
                self.accel_d = (v * v - u * u) / two_a;
            }
        } else {
            let vsq =
                (two_a * two_d * self.total + two_a * v * v + two_d * u * u) / (two_a + two_d);
            if vsq > u * u && vsq > v * v {
                self.accel_d = (vsq - u * u) / two_a;
                self.decel_d = (vsq - v * v) / two_d;
                self.top_speed = vsq.sqrt();
            } else if u < v {
                // Accelerate-only: the acceleration absorbs rounding.
                self.accel_d = self.total;
                self.decel_d = 0.0;
                self.top_speed = v;
                self.accel = (v * v - u * u) / (2.0 * self.total);
            } else {
                self.accel_d = 0.0;
                self.decel_d = self.total;
                self.top_speed = u;
                self.decel = (u * u - v * v) / (2.0 * self.total);
            }
        }
        let (accel_t, steady_t, decel_t) = self.phase_times();
        self.clocks_s = accel_t + steady_t + decel_t;
    }

    /// `PrepParams::SetFromDDA` and `Finalise`: accelerate, steady and decelerate times.
    fn phase_times(&self) -> (f64, f64, f64) {
        let decel_start = self.total - self.decel_d;
        let accel_d = self.accel_d.min(decel_start);
        let steady_d = decel_start - accel_d;
        (
            (self.top_speed - self.start_speed) / self.accel,
            if steady_d <= 0.0 {
                0.0
            } else {
                steady_d / self.top_speed
            },
            (self.top_speed - self.end_speed) / self.decel,
        )
    }

    /// `Prepare` (without input shaping): freeze the move to start at `start_time_s`.
    pub(super) fn freeze(&mut self, start_time_s: f64) -> PlannedMove {
        let (accel_t, steady_t, decel_t) = self.phase_times();
        self.state = DdaState::Frozen;
        self.end_time_s = start_time_s + accel_t + steady_t + decel_t;
        self.avg_extrusion_speed = self.dir[3] * self.total / self.clocks_s;
        let phases = [
            Phase::linear(accel_t, self.start_speed, self.accel),
            Phase::constant(steady_t, self.top_speed),
            Phase::linear(decel_t, self.top_speed, -self.decel),
        ];
        let axes_r = if self.dir[..3].iter().all(|&d| d == 0.0) {
            [0.0, 0.0, 0.0, self.dir[3].signum()]
        } else {
            self.dir
        };
        let mut p = PlannedMove::new(self.seq, self.start, axes_r, self.total, &phases);
        p.start_speed_m_s = self.start_speed;
        p.cruise_speed_m_s = self.top_speed;
        p.end_speed_m_s = self.end_speed;
        p.accel_m_s2 = self.accel;
        p.decel_m_s2 = self.decel;
        p.accel_t_s = accel_t;
        p.cruise_t_s = steady_t;
        p.decel_t_s = decel_t;
        p
    }
}

/// `MatchSpeeds` for `ring[i]` followed by `ring[i + 1]`: lower the wished-for junction
/// speed until no drive changes speed by more than its `M566` jerk.
fn match_speeds(ring: &mut [Dda], i: usize, instant_dv: &[f64; 4]) {
    let next_dir = ring[i + 1].dir;
    let d = &mut ring[i];
    for drive in 0..4 {
        if d.dir[drive] != 0.0 || next_dir[drive] != 0.0 {
            let fraction = (d.dir[drive] - next_dir[drive]).abs();
            if fraction * d.target_next > instant_dv[drive] {
                d.target_next = instant_dv[drive] / fraction;
            }
        }
    }
}

/// What look-ahead needs to know of the move before `ring[0]` (already executed).
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Retired {
    pub(super) decel_field: f64,
}

/// `DoLookahead`: raise the end speed of `ring[la]` towards its `target_next`, walking
/// back through provisional deceleration-only moves that must speed up too.
pub(super) fn do_lookahead(ring: &mut [Dda], mut la: usize, retired: Retired, cfg: &RrfConfig) {
    let mut depth = 0usize;
    let mut going_up = true;
    loop {
        if going_up {
            let requested = ring[la].requested;
            ring[la].target_next = ring[la].target_next.min(requested);
            let prev_decel_field = if la > 0 {
                ring[la - 1].decel_field()
            } else {
                retired.decel_field
            };
            if ring[la].top_speed >= requested {
                match_speeds(ring, la, &cfg.instant_dv_m_s);
                going_up = false;
            } else if ring[la].is_deceleration_move() && prev_decel_field > 0.0 {
                let cur = ring[la];
                let adjust_prev = la > 0 && {
                    let prev = &ring[la - 1];
                    prev.state == DdaState::Provisional
                        && (cfg.jerk_policy != 0
                            || (prev.xy_moving == cur.xy_moving
                                && (prev.printing == cur.printing
                                    || (prev.printing && prev.requested == cur.requested))))
                };
                if adjust_prev {
                    match_speeds(ring, la, &cfg.instant_dv_m_s);
                    let d = &ring[la];
                    let max_start =
                        (d.target_next * d.target_next + 2.0 * d.decel * d.total).sqrt();
                    ring[la - 1].target_next = max_start.min(d.requested);
                } else {
                    let d = &mut ring[la];
                    let reach = (d.start_speed * d.start_speed + 2.0 * d.decel * d.total).sqrt();
                    d.target_next = d.target_next.min(reach);
                    match_speeds(ring, la, &cfg.instant_dv_m_s);
                    going_up = false;
                }
            } else {
                let d = &mut ring[la];
                let reach = (d.start_speed * d.start_speed + 2.0 * d.accel * d.total).sqrt();
                d.target_next = d.target_next.min(reach);
                match_speeds(ring, la, &cfg.instant_dv_m_s);
                going_up = false;
            }
        } else {
            // Coming back down: start where the previous move now ends.
            let prev_end = ring[la - 1].end_speed;
            let d = &mut ring[la];
            d.start_speed = prev_end;
            let max_end = (d.start_speed * d.start_speed + 2.0 * d.accel * d.total).sqrt();
            d.target_next = d.target_next.min(max_end);
        }
        if going_up {
            la -= 1;
            depth += 1;
        } else {
            let d = &mut ring[la];
            // Never lower an end speed (that could make the move infeasible).
            if d.target_next >= d.end_speed {
                d.end_speed = d.target_next;
            }
            d.recalculate();
            if depth == 0 {
                return;
            }
            la += 1;
            depth -= 1;
        }
    }
}
