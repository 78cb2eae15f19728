//! The limits of the four-jerk planner: a symmetric velocity limit, two acceleration
//! limits and the four jerks `j1..j4` (the TMC4361A's BOW1..BOW4, see the module
//! documentation of [`crate::fourjerk`]).

use crate::{Limits, PlanError};

/// Limits of the four-jerk planner (symmetric velocity limit; magnitudes, all > 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FourJerkLimits {
    /// Speed limit (u/s).
    pub vmax: f64,
    /// Upper acceleration limit (u/s^2): `a <= amax`.
    pub amax: f64,
    /// Lower acceleration limit magnitude (u/s^2): `a >= -dmax`.
    pub dmax: f64,
    /// `[j1, j2, j3, j4]` (u/s^3): raise `a >= 0`, lower `a > 0`, lower `a <= 0`,
    /// raise `a < 0`.
    pub jerk: [f64; 4],
}

impl FourJerkLimits {
    /// Validated limits (every value finite and > 0, named in the error).
    pub fn new(vmax: f64, amax: f64, dmax: f64, jerk: [f64; 4]) -> Result<Self, PlanError> {
        let named = [
            ("vmax", vmax),
            ("amax", amax),
            ("dmax", dmax),
            ("j1", jerk[0]),
            ("j2", jerk[1]),
            ("j3", jerk[2]),
            ("j4", jerk[3]),
        ];
        for (name, value) in named {
            if !(value.is_finite() && value > 0.0) {
                return Err(PlanError::InvalidLimit { name, value });
            }
        }
        Ok(Self {
            vmax,
            amax,
            dmax,
            jerk,
        })
    }

    /// The symmetric special case of `lim` (needs a jerk limit; uses `vmax`, `amax`).
    pub fn symmetric(lim: &Limits) -> Result<Self, PlanError> {
        let j = lim
            .jmax()
            .ok_or(PlanError::MissingJerkLimit { kind: "fourjerk" })?;
        Self::new(lim.vmax(), lim.amax(), lim.amax(), [j; 4])
    }
}
