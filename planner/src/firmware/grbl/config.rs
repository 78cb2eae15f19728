//! GRBL's motion settings (`$100`-`$132`, `$11`; grbl/settings.c
//! `settings_store_global_setting`).

use crate::PlanError;

/// GRBL's motion settings in SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GrblConfig {
    /// Steps per metre of X, Y, Z (`$100`-`$102`, steps/mm).
    pub steps_per_m: [f64; 3],
    /// Maximum rate of X, Y, Z (m/s; `$110`-`$112` in mm/min).
    pub max_rate_m_s: [f64; 3],
    /// Acceleration of X, Y, Z (m/s^2; `$120`-`$122` in mm/s^2).
    pub accel_m_s2: [f64; 3],
    /// Junction deviation (m; `$11` in mm).
    pub junction_deviation_m: f64,
    /// `BLOCK_BUFFER_SIZE` (16 in grbl/planner.h; grblHAL's `$398`, 100 by default);
    /// the buffer holds one block less.
    pub block_buffer_size: usize,
}

/// `MINIMUM_FEED_RATE` (grbl/config.h: 1 mm/min), m/s.
pub(super) const MINIMUM_FEED_RATE_M_S: f64 = 1e-3 / 60.0;

impl GrblConfig {
    /// GRBL's `DEFAULTS_GENERIC` (grbl/defaults.h): 250 steps/mm, 500 mm/min, 10 mm/s^2 on
    /// every axis, junction deviation 0.01 mm, a 16-block buffer.
    pub fn new() -> Self {
        Self {
            steps_per_m: [250e3; 3],
            max_rate_m_s: [0.5 / 60.0; 3],
            accel_m_s2: [0.01; 3],
            junction_deviation_m: 0.01e-3,
            block_buffer_size: 16,
        }
    }

    /// Check every setting: steps, rates and accelerations finite and > 0, the junction
    /// deviation finite and >= 0 (GRBL refuses negative settings), at least 3 blocks.
    pub fn validate(&self) -> Result<(), PlanError> {
        for (name, v) in [
            ("steps per mm ($100-$102)", &self.steps_per_m),
            ("max rate ($110-$112)", &self.max_rate_m_s),
            ("acceleration ($120-$122)", &self.accel_m_s2),
        ] {
            for &x in v {
                crate::firmware::positive(name, x)?;
            }
        }
        let jd = self.junction_deviation_m;
        if !(jd.is_finite() && jd >= 0.0) {
            return Err(PlanError::InvalidLimit {
                name: "junction deviation ($11)",
                value: jd,
            });
        }
        if self.block_buffer_size < 3 {
            return Err(PlanError::InvalidLimit {
                name: "block buffer size (>= 3)",
                value: self.block_buffer_size as f64,
            });
        }
        Ok(())
    }

    /// Blocks the buffer holds: `BLOCK_BUFFER_SIZE - 1`.
    pub fn capacity(&self) -> usize {
        self.block_buffer_size - 1
    }
}

impl Default for GrblConfig {
    fn default() -> Self {
        Self::new()
    }
}
