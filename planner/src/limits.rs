//! Validated kinematic limits.

use crate::PlanError;

/// Kinematic limits of one axis. Construct with [`Limits::new`] (symmetric) or
/// [`Limits::asymmetric`], which reject zero, negative, NaN and infinite values, so every
/// planner can trust them. `vmin`/`amin` are the (negative) lower limits; by default
/// `-vmax`/`-amax`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    vmax: f64,
    amax: f64,
    jmax: Option<f64>,
    vmin: f64,
    amin: f64,
}

fn check(name: &'static str, value: f64) -> Result<f64, PlanError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(PlanError::InvalidLimit { name, value })
    }
}

impl Limits {
    /// Velocity limit `vmax` (units/s), acceleration limit `amax` (units/s^2) and an optional
    /// jerk limit `jmax` (units/s^3; `None` for jerk-unlimited planners such as trapezoids).
    pub fn new(vmax: f64, amax: f64, jmax: Option<f64>) -> Result<Self, PlanError> {
        let (vmax, amax) = (check("vmax", vmax)?, check("amax", amax)?);
        Ok(Self {
            vmax,
            amax,
            jmax: jmax.map(|j| check("jmax", j)).transpose()?,
            vmin: -vmax,
            amin: -amax,
        })
    }

    /// Asymmetric limits: `vmin` and `amin` are given as (negative) lower limits, i.e. the
    /// axis may move between `vmin < 0` and `vmax > 0` and accelerate between `amin < 0` and
    /// `amax > 0`. `None` means the mirror of the upper limit.
    pub fn asymmetric(
        vmax: f64,
        vmin: Option<f64>,
        amax: f64,
        amin: Option<f64>,
        jmax: Option<f64>,
    ) -> Result<Self, PlanError> {
        let mut l = Self::new(vmax, amax, jmax)?;
        let negative = |name, value: f64| {
            if value.is_finite() && value < 0.0 {
                Ok(value)
            } else {
                Err(PlanError::InvalidLimit { name, value })
            }
        };
        if let Some(v) = vmin {
            l.vmin = negative("vmin", v)?;
        }
        if let Some(a) = amin {
            l.amin = negative("amin", a)?;
        }
        Ok(l)
    }

    /// Lower velocity limit (< 0).
    pub fn vmin(&self) -> f64 {
        self.vmin
    }

    /// Lower acceleration limit (< 0).
    pub fn amin(&self) -> f64 {
        self.amin
    }

    /// Maximum speed (units/s).
    pub fn vmax(&self) -> f64 {
        self.vmax
    }

    /// Maximum acceleration magnitude (units/s^2).
    pub fn amax(&self) -> f64 {
        self.amax
    }

    /// Maximum jerk magnitude (units/s^3), if the limits carry one.
    pub fn jmax(&self) -> Option<f64> {
        self.jmax
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_bad_limits_with_typed_errors() {
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            assert!(matches!(
                Limits::new(bad, 1.0, None),
                Err(PlanError::InvalidLimit { name: "vmax", .. })
            ));
            assert!(matches!(
                Limits::new(1.0, bad, None),
                Err(PlanError::InvalidLimit { name: "amax", .. })
            ));
            assert!(matches!(
                Limits::new(1.0, 1.0, Some(bad)),
                Err(PlanError::InvalidLimit { name: "jmax", .. })
            ));
        }
        let ok = Limits::new(2.0, 3.0, Some(4.0)).expect("valid limits");
        assert_eq!((ok.vmax(), ok.amax(), ok.jmax()), (2.0, 3.0, Some(4.0)));
    }
}
