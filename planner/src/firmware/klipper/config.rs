//! Klipper's `[printer]` and `[extruder]` limits the toolhead planner reads.

use crate::PlanError;
use crate::firmware::Kinematics;

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
        crate::firmware::positive("max_velocity", self.max_velocity_m_s)?;
        crate::firmware::positive("max_accel", self.max_accel_m_s2)?;
        crate::firmware::positive("max_z_velocity", self.max_z_velocity_m_s)?;
        crate::firmware::positive("max_z_accel", self.max_z_accel_m_s2)?;
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
            crate::firmware::positive(
                "max_extrude_only_velocity",
                e.max_extrude_only_velocity_m_s,
            )?;
            crate::firmware::positive("max_extrude_only_accel", e.max_extrude_only_accel_m_s2)?;
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
