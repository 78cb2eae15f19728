//! One lightly damped mode of a flexible axis.

use std::f64::consts::TAU;

use crate::SimError;

/// A mode between command and toolhead: natural frequency, damping ratio and participation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mode {
    frequency_hz: f64,
    damping_ratio: f64,
    weight: f64,
}

impl Mode {
    /// `frequency_hz` (> 0, finite), `damping_ratio` in [0, 1) (underdamped: settle is about
    /// lightly damped structures; typical 0.02-0.15), `weight` >= 0: the mode's share of the
    /// toolhead error (toolhead = command + sum weight_i e_i; the weights of a real
    /// structure's modes sum to 1, so a single mode has weight 1).
    pub fn new(frequency_hz: f64, damping_ratio: f64, weight: f64) -> Result<Self, SimError> {
        if !(frequency_hz.is_finite() && frequency_hz > 0.0) {
            return Err(SimError::InvalidMode {
                field: "frequency_hz",
                value: frequency_hz,
                allowed: "a finite number > 0 (Hz)",
            });
        }
        if !(0.0..1.0).contains(&damping_ratio) {
            return Err(SimError::InvalidMode {
                field: "damping_ratio",
                value: damping_ratio,
                allowed: "0 <= damping_ratio < 1",
            });
        }
        if !(weight.is_finite() && weight >= 0.0) {
            return Err(SimError::InvalidMode {
                field: "weight",
                value: weight,
                allowed: "a finite number >= 0",
            });
        }
        Ok(Self {
            frequency_hz,
            damping_ratio,
            weight,
        })
    }

    /// Natural frequency (Hz).
    pub fn frequency_hz(&self) -> f64 {
        self.frequency_hz
    }

    /// Damping ratio zeta.
    pub fn damping_ratio(&self) -> f64 {
        self.damping_ratio
    }

    /// Participation weight in the toolhead error.
    pub fn weight(&self) -> f64 {
        self.weight
    }

    /// Natural angular frequency w (rad/s).
    pub fn omega(&self) -> f64 {
        TAU * self.frequency_hz
    }

    /// Damped angular frequency wd = w sqrt(1 - zeta^2) (rad/s).
    pub fn omega_d(&self) -> f64 {
        self.omega() * (1.0 - self.damping_ratio * self.damping_ratio).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn invalid_modes_are_rejected_with_the_field() {
        let field = |r: Result<Mode, SimError>| match r {
            Err(SimError::InvalidMode { field, .. }) => field,
            other => panic!("expected InvalidMode, got {other:?}"),
        };
        assert_eq!(field(Mode::new(0.0, 0.1, 1.0)), "frequency_hz");
        assert_eq!(field(Mode::new(f64::NAN, 0.1, 1.0)), "frequency_hz");
        assert_eq!(field(Mode::new(40.0, 1.0, 1.0)), "damping_ratio");
        assert_eq!(field(Mode::new(40.0, -0.01, 1.0)), "damping_ratio");
        assert_eq!(field(Mode::new(40.0, 0.05, -1.0)), "weight");
        assert!(Mode::new(40.0, 0.0, 0.0).is_ok());
    }
}
