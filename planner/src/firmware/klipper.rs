//! Klipper's toolhead planner (klippy/toolhead.py), move by move.
//!
//! A move gets its limits when it is queued: speed `min(F, max_velocity)`, acceleration
//! `max_accel`, lowered for Z (cartesian.py / corexy.py `check_move`: `max_z_velocity` and
//! `max_z_accel` scaled by `move_d / |dz|`) and for extruder-only or retracting moves
//! (extruder.py: `max_extrude_only_velocity/accel` over the extruder's share). Junction
//! speeds follow `Move.calc_junction` ([`crate::path::junction`] has the geometry):
//! `jd = scv^2 (sqrt 2 - 1) / max_accel`, `v^2 = R jd a` with `R = sin(t/2)/(1 - sin(t/2))`,
//! the centripetal caps `0.5 L a tan(t/2)` of both moves, both cruise speeds, what the
//! previous move can reach, and the extruder's `instantaneous_corner_velocity` over the
//! change of its share. `minimum_cruise_ratio` plans peaks with the pseudo-acceleration
//! `max_accel (1 - ratio)` (the older `max_accel_to_decel` `d` maps to
//! `ratio = 1 - min(1, d / max_accel)`: [`min_cruise_ratio_from_accel_to_decel`]).
//!
//! The look-ahead ([`KlipperPlanner`]) flushes lazily as Klipper does: once the queued
//! moves' minimum times exceed the flush time (1 s after a start or a full flush, 0.15 s
//! after a lazy one), the moves whose plan can no longer change leave the queue.
//!
//! Approximations: the host's real-time behaviour (a flush when the MCU's step buffer runs
//! low, `BUFFER_TIME_START` after an idle host) is not modelled: printing from a file the
//! host stays ahead. Moves are checked for nothing but speed (no endstop range, no
//! `max_extrude_cross_section` error).

use super::Kinematics;
use crate::PlanError;

/// Klipper's extruder settings (`[extruder]` in printer.cfg, kinematics/extruder.py).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KlipperExtruder {
    /// `instantaneous_corner_velocity` (m/s): the extruder speed change allowed at a
    /// corner. Klipper's default is 1 mm/s.
    pub instantaneous_corner_velocity_m_s: f64,
    /// `max_extrude_only_velocity` (m/s): extruder speed of extrude-only and retract moves.
    pub max_extrude_only_velocity_m_s: f64,
    /// `max_extrude_only_accel` (m/s^2).
    pub max_extrude_only_accel_m_s2: f64,
}

impl KlipperExtruder {
    /// Klipper's defaults for a toolhead limited to `max_velocity_m_s` and
    /// `max_accel_m_s2`: the extrude-only limits are those times
    /// `4 nozzle^2 / (pi (filament/2)^2)`, the default maximum extrusion ratio.
    pub fn with_defaults(
        max_velocity_m_s: f64,
        max_accel_m_s2: f64,
        nozzle_diameter_m: f64,
        filament_diameter_m: f64,
    ) -> Self {
        let area = std::f64::consts::PI * (0.5 * filament_diameter_m).powi(2);
        let ratio = 4.0 * nozzle_diameter_m * nozzle_diameter_m / area;
        Self {
            instantaneous_corner_velocity_m_s: 1e-3,
            max_extrude_only_velocity_m_s: max_velocity_m_s * ratio,
            max_extrude_only_accel_m_s2: max_accel_m_s2 * ratio,
        }
    }
}

/// Klipper's `[printer]` motion settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KlipperConfig {
    /// `max_velocity` (m/s).
    pub max_velocity_m_s: f64,
    /// `max_accel` (m/s^2).
    pub max_accel_m_s2: f64,
    /// `minimum_cruise_ratio` in `[0, 1)`; Klipper's default 0.5.
    pub minimum_cruise_ratio: f64,
    /// `square_corner_velocity` (m/s, >= 0); Klipper's default 5 mm/s.
    pub square_corner_velocity_m_s: f64,
    /// Cartesian and CoreXY limit Z the same way in Klipper.
    pub kinematics: Kinematics,
    /// `max_z_velocity` (m/s); Klipper's default is `max_velocity`.
    pub max_z_velocity_m_s: f64,
    /// `max_z_accel` (m/s^2); Klipper's default is `max_accel`.
    pub max_z_accel_m_s2: f64,
    /// The extruder; `None` makes any extrusion an error, as in Klipper.
    pub extruder: Option<KlipperExtruder>,
}

impl KlipperConfig {
    /// Klipper's defaults around `max_velocity` and `max_accel`: minimum_cruise_ratio 0.5,
    /// square_corner_velocity 5 mm/s, cartesian, Z limits equal to the XY ones, and an
    /// extruder with Klipper's defaults for a 0.4 mm nozzle and 1.75 mm filament.
    pub fn new(max_velocity_m_s: f64, max_accel_m_s2: f64) -> Self {
        Self {
            max_velocity_m_s,
            max_accel_m_s2,
            minimum_cruise_ratio: 0.5,
            square_corner_velocity_m_s: 5e-3,
            kinematics: Kinematics::Cartesian,
            max_z_velocity_m_s: max_velocity_m_s,
            max_z_accel_m_s2: max_accel_m_s2,
            extruder: Some(KlipperExtruder::with_defaults(
                max_velocity_m_s,
                max_accel_m_s2,
                0.4e-3,
                1.75e-3,
            )),
        }
    }

    /// Check every setting against the ranges Klipper accepts.
    pub fn validate(&self) -> Result<(), PlanError> {
        super::positive("max_velocity", self.max_velocity_m_s)?;
        super::positive("max_accel", self.max_accel_m_s2)?;
        super::positive("max_z_velocity", self.max_z_velocity_m_s)?;
        super::positive("max_z_accel", self.max_z_accel_m_s2)?;
        let r = self.minimum_cruise_ratio;
        if !(0.0..1.0).contains(&r) {
            return Err(PlanError::InvalidLimit {
                name: "minimum_cruise_ratio (0 <= r < 1)",
                value: r,
            });
        }
        let scv = self.square_corner_velocity_m_s;
        if !(scv.is_finite() && scv >= 0.0) {
            return Err(PlanError::InvalidLimit {
                name: "square_corner_velocity (>= 0)",
                value: scv,
            });
        }
        if let Some(e) = &self.extruder {
            super::positive("max_extrude_only_velocity", e.max_extrude_only_velocity_m_s)?;
            super::positive("max_extrude_only_accel", e.max_extrude_only_accel_m_s2)?;
            let icv = e.instantaneous_corner_velocity_m_s;
            if !(icv.is_finite() && icv >= 0.0) {
                return Err(PlanError::InvalidLimit {
                    name: "instantaneous_corner_velocity (>= 0)",
                    value: icv,
                });
            }
        }
        Ok(())
    }

    /// Junction deviation (m): `scv^2 (sqrt 2 - 1) / max_accel`
    /// (toolhead.py `_calc_junction_deviation`).
    pub fn junction_deviation_m(&self) -> f64 {
        let scv = self.square_corner_velocity_m_s;
        scv * scv * (std::f64::consts::SQRT_2 - 1.0) / self.max_accel_m_s2
    }

    /// The pseudo-acceleration `max_accel (1 - minimum_cruise_ratio)` (m/s^2).
    pub fn mcr_pseudo_accel_m_s2(&self) -> f64 {
        self.max_accel_m_s2 * (1.0 - self.minimum_cruise_ratio)
    }
}

/// `minimum_cruise_ratio` equivalent to the older `max_accel_to_decel` setting:
/// `1 - min(1, accel_to_decel / max_accel)` (toolhead.py when it still read both).
pub fn min_cruise_ratio_from_accel_to_decel(accel_to_decel_m_s2: f64, max_accel_m_s2: f64) -> f64 {
    1.0 - (accel_to_decel_m_s2 / max_accel_m_s2).min(1.0)
}

/// Speeds squared in Klipper are compared against this "no limit" value
/// (999999999.9 mm^2/s^2 in toolhead.py).
const NO_JUNCTION_LIMIT_V2: f64 = 999_999_999.9e-6;
/// Acceleration Klipper gives an extruder-only move before the extruder limits it
/// (99999999.9 mm/s^2 in toolhead.py).
const EXTRUDE_ONLY_ACCEL_M_S2: f64 = 99_999_999.9e-3;
/// Below this XYZ length (1e-9 mm) a move is extruder-only.
const MIN_KINEMATIC_LENGTH_M: f64 = 1e-12;

/// A queued move and its look-ahead limits (toolhead.py `Move`), speeds squared in m^2/s^2.
#[derive(Debug, Clone, Copy)]
pub(super) struct KMove {
    pub(super) seq: u64,
    pub(super) start: [f64; 4],
    pub(super) axes_r: [f64; 4],
    pub(super) move_d: f64,
    is_kinematic: bool,
    pub(super) accel: f64,
    junction_deviation: f64,
    pub(super) min_move_t: f64,
    pub(super) max_start_v2: f64,
    pub(super) max_cruise_v2: f64,
    pub(super) delta_v2: f64,
    next_junction_v2: f64,
    pub(super) max_mcr_start_v2: f64,
    pub(super) mcr_delta_v2: f64,
}

impl KMove {
    /// Build the move and apply the kinematic and extruder limits (`ToolHead.move`), or
    /// `None` for a move that goes nowhere.
    pub(super) fn new(
        cfg: &KlipperConfig,
        seq: u64,
        start: [f64; 4],
        delta: [f64; 4],
        speed: f64,
    ) -> Result<Option<Self>, PlanError> {
        let mut axes_d = delta;
        let mut velocity = speed.min(cfg.max_velocity_m_s);
        let mut accel = cfg.max_accel_m_s2;
        let mut move_d =
            (axes_d[0] * axes_d[0] + axes_d[1] * axes_d[1] + axes_d[2] * axes_d[2]).sqrt();
        let is_kinematic = move_d >= MIN_KINEMATIC_LENGTH_M;
        if !is_kinematic {
            axes_d[0] = 0.0;
            axes_d[1] = 0.0;
            axes_d[2] = 0.0;
            move_d = axes_d[3].abs();
            accel = EXTRUDE_ONLY_ACCEL_M_S2;
            velocity = speed;
        }
        if move_d == 0.0 {
            return Ok(None);
        }
        let inv = 1.0 / move_d;
        let mut m = Self {
            seq,
            start,
            axes_r: axes_d.map(|d| d * inv),
            move_d,
            is_kinematic,
            accel,
            junction_deviation: cfg.junction_deviation_m(),
            min_move_t: move_d / velocity,
            max_start_v2: 0.0,
            max_cruise_v2: velocity * velocity,
            delta_v2: 2.0 * move_d * accel,
            next_junction_v2: NO_JUNCTION_LIMIT_V2,
            max_mcr_start_v2: 0.0,
            mcr_delta_v2: 2.0 * move_d * cfg.mcr_pseudo_accel_m_s2(),
        };
        if is_kinematic && axes_d[2] != 0.0 {
            // cartesian.py and corexy.py: the slower Z axis.
            let z_ratio = move_d / axes_d[2].abs();
            m.limit_speed(
                cfg.max_z_velocity_m_s * z_ratio,
                cfg.max_z_accel_m_s2 * z_ratio,
            );
        }
        if axes_d[3] != 0.0 {
            let Some(e) = &cfg.extruder else {
                return Err(PlanError::InvalidInput {
                    reason: "the move extrudes but no extruder is configured",
                });
            };
            let axis_r = m.axes_r[3];
            if (axes_d[0] == 0.0 && axes_d[1] == 0.0) || axis_r < 0.0 {
                // Extrude-only or retracting: the extruder's own limits.
                let inv_r = 1.0 / axis_r.abs();
                m.limit_speed(
                    e.max_extrude_only_velocity_m_s * inv_r,
                    e.max_extrude_only_accel_m_s2 * inv_r,
                );
            }
        }
        Ok(Some(m))
    }

    /// `Move.limit_speed`.
    fn limit_speed(&mut self, speed: f64, accel: f64) {
        let speed2 = speed * speed;
        if speed2 < self.max_cruise_v2 {
            self.max_cruise_v2 = speed2;
            self.min_move_t = self.move_d / speed;
        }
        self.accel = self.accel.min(accel);
        self.delta_v2 = 2.0 * self.move_d * self.accel;
        self.mcr_delta_v2 = self.mcr_delta_v2.min(self.delta_v2);
    }

    /// `Move.calc_junction`: the highest start speed after `prev`.
    pub(super) fn calc_junction(&mut self, prev: &KMove, extruder: Option<&KlipperExtruder>) {
        if !self.is_kinematic || !prev.is_kinematic {
            return;
        }
        let diff_r = self.axes_r[3] - prev.axes_r[3];
        let extruder_v2 = match extruder {
            Some(e) if diff_r != 0.0 => {
                let v = e.instantaneous_corner_velocity_m_s / diff_r.abs();
                v * v
            }
            _ => self.max_cruise_v2,
        };
        let mut max_start_v2 = self
            .max_cruise_v2
            .min(prev.max_cruise_v2)
            .min(prev.next_junction_v2)
            .min(prev.max_start_v2 + prev.delta_v2)
            .min(extruder_v2);
        let (r, p) = (&self.axes_r, &prev.axes_r);
        let cos_theta = -(r[0] * p[0] + r[1] * p[1] + r[2] * p[2]);
        let sin_half = (0.5 * (1.0 - cos_theta)).max(0.0).sqrt();
        let cos_half = (0.5 * (1.0 + cos_theta)).max(0.0).sqrt();
        let one_minus_sin = 1.0 - sin_half;
        if one_minus_sin > 0.0 && cos_half > 0.0 {
            let r_jd = sin_half / one_minus_sin;
            let move_jd_v2 = r_jd * self.junction_deviation * self.accel;
            let pmove_jd_v2 = r_jd * prev.junction_deviation * prev.accel;
            // The virtual arc touches each move no farther than its middle.
            let quarter_tan = 0.25 * sin_half / cos_half;
            max_start_v2 = max_start_v2
                .min(move_jd_v2)
                .min(pmove_jd_v2)
                .min(self.delta_v2 * quarter_tan)
                .min(prev.delta_v2 * quarter_tan);
        }
        self.max_start_v2 = max_start_v2;
        self.max_mcr_start_v2 = max_start_v2.min(prev.max_mcr_start_v2 + prev.mcr_delta_v2);
    }
}

pub use super::klipper_queue::KlipperPlanner;
