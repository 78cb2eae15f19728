//! A queued move and its look-ahead limits (toolhead.py `Move`).

use super::config::{KlipperConfig, KlipperExtruder};
use crate::PlanError;

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
