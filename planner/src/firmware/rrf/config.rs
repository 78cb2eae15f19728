//! RepRapFirmware's motion settings (M201, M203, M204, M566).

use crate::PlanError;
use crate::firmware::Kinematics;

/// RepRapFirmware's motion settings (config.g: M201, M203, M204, M566).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RrfConfig {
    /// Cartesian, or CoreXY (motor limits from the X and Y settings).
    pub kinematics: Kinematics,
    /// `M203` speed limits of X, Y, Z, E (m/s; M203 takes mm/min).
    pub max_feedrate_m_s: [f64; 4],
    /// `M201` acceleration limits of X, Y, Z, E (m/s^2).
    pub max_accel_m_s2: [f64; 4],
    /// `M204 P`: acceleration of printing moves (m/s^2).
    pub print_accel_m_s2: f64,
    /// `M204 T`: acceleration of other XY moves (m/s^2).
    pub travel_accel_m_s2: f64,
    /// `M566` instantaneous speed change of X, Y, Z, E (m/s; M566 takes mm/min; RRF
    /// keeps at least 0.1 mm/s).
    pub instant_dv_m_s: [f64; 4],
    /// `M566 P`: 0 joins only moves of the same kind, 1 joins all.
    pub jerk_policy: u32,
    /// `M203 I`: minimum movement speed (m/s).
    pub min_movement_speed_m_s: f64,
    /// Moves in the ring (`InitialDdaRingLength`, 60 on Duet 3, 40 on Duet 2).
    pub ring_length: usize,
}

impl RrfConfig {
    /// RepRapFirmware's defaults (Configuration.h): 100/100/20/100 mm/s,
    /// 1000/1000/200/500 mm/s^2, `M204` 50000 mm/s^2 (no limit), jerk 15/15/10/5 mm/s,
    /// policy 0, minimum speed 0.5 mm/s, a ring of 60.
    pub fn new() -> Self {
        Self {
            kinematics: Kinematics::Cartesian,
            max_feedrate_m_s: [0.1, 0.1, 0.02, 0.1],
            max_accel_m_s2: [1.0, 1.0, 0.2, 0.5],
            print_accel_m_s2: 50.0,
            travel_accel_m_s2: 50.0,
            instant_dv_m_s: [0.015, 0.015, 0.010, 0.005],
            jerk_policy: 0,
            min_movement_speed_m_s: 0.5e-3,
            ring_length: 60,
        }
    }

    /// Check every setting (jerks of at least 0.1 mm/s, as RRF enforces).
    pub fn validate(&self) -> Result<(), PlanError> {
        for &x in self.max_feedrate_m_s.iter().chain(&self.max_accel_m_s2) {
            crate::firmware::positive("M203/M201 limit", x)?;
        }
        crate::firmware::positive("M204 P", self.print_accel_m_s2)?;
        crate::firmware::positive("M204 T", self.travel_accel_m_s2)?;
        crate::firmware::positive("minimum movement speed", self.min_movement_speed_m_s)?;
        for &j in &self.instant_dv_m_s {
            if !(j.is_finite() && j >= 0.1e-3) {
                return Err(PlanError::InvalidLimit {
                    name: "M566 jerk (>= 0.1 mm/s)",
                    value: j,
                });
            }
        }
        if self.ring_length < 4 {
            return Err(PlanError::InvalidLimit {
                name: "ring length (>= 4)",
                value: self.ring_length as f64,
            });
        }
        Ok(())
    }
}

impl Default for RrfConfig {
    fn default() -> Self {
        Self::new()
    }
}
