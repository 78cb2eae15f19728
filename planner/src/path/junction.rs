//! Corner (junction) speeds for *sharp* corners: GRBL's junction deviation and Klipper's
//! square corner velocity, which is the same formula with the deviation derived from a
//! chosen speed at 90 degrees, plus Klipper's mid-move cap.
//!
//! Both firmwares pass a sharp corner with an *instantaneous* change of the velocity vector
//! (each axis's velocity jumps). The speed is that of a virtual circular arc of radius `R`
//! tangent to both segments whose closest point is the deviation `delta` from the corner:
//! with the interior angle `theta` (module doc of [`crate::path`]),
//!
//! `R = delta sin(theta/2) / (1 - sin(theta/2))`, `v^2 = a R`.
//!
//! So `theta = pi` (straight) gives no limit, `theta = 0` (reversal) gives zero. Klipper
//! configures `scv`, the speed at 90 degrees: `delta = scv^2 (sqrt(2) - 1) / a`, which makes
//! `v(pi/2) = scv` exactly (`sin(pi/4)/(1 - sin(pi/4)) = 1/(sqrt 2 - 1)`). Klipper also keeps
//! the virtual arc from touching the segments beyond their midpoints: the arc touches a
//! segment at `R / tan(theta/2)` from the corner, so `R <= (L/2) tan(theta/2)`, i.e.
//! `v^2 <= 0.5 L a tan(theta/2)` for both the incoming and outgoing segment lengths `L`.

use crate::PlanError;

/// `sin(theta/2)` and `cos(theta/2)` for an interior angle in `[0, pi]` (clamped; exactly
/// `(1, 0)` for a straight line, where `cos(pi/2)` would round to 6e-17).
fn half(theta: f64) -> (f64, f64) {
    if theta >= std::f64::consts::PI {
        return (1.0, 0.0);
    }
    let h = 0.5 * theta.max(0.0);
    (h.sin(), h.cos())
}

/// GRBL junction speed (m/s) at interior angle `theta` (rad) for junction deviation
/// `deviation_m` (m) and acceleration `accel` (m/s^2): `sqrt(a delta s/(1-s))`,
/// `s = sin(theta/2)`. Infinite for a straight line, zero for a reversal.
pub fn grbl_speed(theta: f64, deviation_m: f64, accel: f64) -> f64 {
    let (s, _) = half(theta);
    if s >= 1.0 {
        return f64::INFINITY;
    }
    (accel * deviation_m * s / (1.0 - s)).sqrt()
}

/// Klipper's junction deviation (m) from the square corner velocity `scv` (m/s) and the
/// acceleration `accel` (m/s^2): `scv^2 (sqrt(2) - 1) / a`.
pub fn klipper_deviation(scv: f64, accel: f64) -> f64 {
    scv * scv * (std::f64::consts::SQRT_2 - 1.0) / accel
}

/// Klipper's mid-move cap (m/s) for a segment of length `len_m`: the virtual arc must touch
/// the segment no farther than its middle, `v^2 <= 0.5 L a tan(theta/2)`.
pub fn mid_move_cap(theta: f64, accel: f64, len_m: f64) -> f64 {
    let (s, c) = half(theta);
    if c <= 0.0 {
        return f64::INFINITY;
    }
    (0.5 * len_m * accel * s / c).sqrt()
}

/// Klipper junction speed (m/s): the GRBL formula with `delta = klipper_deviation(scv, a)`,
/// capped by [`mid_move_cap`] of both segments.
pub fn klipper_speed(theta: f64, scv: f64, accel: f64, len_in_m: f64, len_out_m: f64) -> f64 {
    grbl_speed(theta, klipper_deviation(scv, accel), accel)
        .min(mid_move_cap(theta, accel, len_in_m))
        .min(mid_move_cap(theta, accel, len_out_m))
}

/// Which sharp-corner speed rule to use.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Junction {
    /// GRBL: junction deviation `deviation_m` (m); GRBL's default is 0.01 mm.
    Grbl {
        /// Junction deviation (m), > 0.
        deviation_m: f64,
    },
    /// Klipper: square corner velocity (m/s; Klipper's default is 5 mm/s), with the
    /// mid-move cap.
    Klipper {
        /// Speed through a 90-degree corner (m/s), > 0.
        square_corner_velocity: f64,
    },
}

impl Junction {
    /// The corner speed (m/s) at interior angle `theta` between segments of lengths
    /// `len_in_m` and `len_out_m`, at acceleration `accel`.
    pub fn speed(&self, theta: f64, accel: f64, len_in_m: f64, len_out_m: f64) -> f64 {
        match *self {
            Junction::Grbl { deviation_m } => grbl_speed(theta, deviation_m, accel),
            Junction::Klipper {
                square_corner_velocity,
            } => klipper_speed(theta, square_corner_velocity, accel, len_in_m, len_out_m),
        }
    }

    /// Check the parameter (finite, > 0).
    pub fn validate(&self) -> Result<(), PlanError> {
        let (name, value) = match *self {
            Junction::Grbl { deviation_m } => ("junction deviation", deviation_m),
            Junction::Klipper {
                square_corner_velocity,
            } => ("square corner velocity", square_corner_velocity),
        };
        if value.is_finite() && value > 0.0 {
            Ok(())
        } else {
            Err(PlanError::InvalidLimit { name, value })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_PI_2, PI, SQRT_2};

    #[test]
    fn limits_of_the_angle_convention() {
        assert_eq!(grbl_speed(PI, 1e-5, 3.0), f64::INFINITY);
        assert_eq!(grbl_speed(0.0, 1e-5, 3.0), 0.0);
        assert_eq!(klipper_speed(PI, 0.005, 3.0, 1.0, 1.0), f64::INFINITY);
        assert_eq!(klipper_speed(0.0, 0.005, 3.0, 1.0, 1.0), 0.0);
        // 90 degrees: exactly the square corner velocity (segments long enough).
        for (scv, a) in [(0.005, 3.0), (0.25, 20.0), (1.0, 0.1)] {
            let v = klipper_speed(FRAC_PI_2, scv, a, 1e3, 1e3);
            assert!((v - scv).abs() <= 1e-14 * scv, "{v} vs {scv}");
        }
    }

    #[test]
    fn known_values() {
        // GRBL, a = 1000 mm/s^2, delta = 0.01 mm (units mm here; the formula is unit-free):
        // 60 deg: sin 30 = 1/2, R = delta, v^2 = 10.
        // 90 deg: R = delta (sqrt 2 + 1), v^2 = 10 (1 + sqrt 2).
        // 120 deg: sin 60 = sqrt3/2, R/delta = sqrt3/(2 - sqrt3) = 3 + 2 sqrt3, v^2 = 10 (3 + 2 sqrt3).
        let s3 = 3.0_f64.sqrt();
        for (deg, v2) in [
            (60.0_f64, 10.0),
            (90.0, 10.0 * (1.0 + SQRT_2)),
            (120.0, 10.0 * (3.0 + 2.0 * s3)),
        ] {
            let v = grbl_speed(deg.to_radians(), 0.01, 1000.0);
            assert!((v * v - v2).abs() < 1e-12 * v2, "{deg}: {}", v * v);
        }
        // Klipper scv = 5 mm/s, a = 1000: delta = 25 (sqrt2 - 1)/1000 mm.
        // 60 deg: v^2 = 25 (sqrt2 - 1); 120 deg: v^2 = 25 (sqrt2 - 1)(3 + 2 sqrt3).
        for (deg, v2) in [
            (60.0_f64, 25.0 * (SQRT_2 - 1.0)),
            (120.0, 25.0 * (SQRT_2 - 1.0) * (3.0 + 2.0 * s3)),
        ] {
            let v = klipper_speed(deg.to_radians(), 5.0, 1000.0, 100.0, 100.0);
            assert!((v * v - v2).abs() < 1e-12 * v2, "{deg}: {}", v * v);
        }
        // Mid-move cap at 90 deg (tan 45 = 1): v^2 <= 0.5 L a. L = 2 mm: 1000 (not binding);
        // L = 0.01 mm: 5 < 25, binding on either side.
        assert!((mid_move_cap(FRAC_PI_2, 1000.0, 2.0).powi(2) - 1000.0).abs() < 1e-9);
        let v = klipper_speed(FRAC_PI_2, 5.0, 1000.0, 100.0, 0.01);
        assert!((v * v - 5.0).abs() < 1e-12, "{v}");
        let v = klipper_speed(FRAC_PI_2, 5.0, 1000.0, 0.01, 100.0);
        assert!((v * v - 5.0).abs() < 1e-12, "{v}");
        // 60 deg: tan 30 = 1/sqrt3; L = 0.02 mm: v^2 = 0.5*0.02*1000/sqrt3 = 10/sqrt3 = 5.7735
        // < 25 (sqrt2 - 1) = 10.355: binding.
        let v = klipper_speed(60.0_f64.to_radians(), 5.0, 1000.0, 0.02, 100.0);
        assert!((v * v - 10.0 / s3).abs() < 1e-12, "{v}");
    }

    #[test]
    fn monotone_in_the_angle() {
        let mut last = 0.0;
        for i in 1..=180 {
            let v = grbl_speed((i as f64).to_radians(), 1e-5, 5.0);
            assert!(v > last);
            last = v;
        }
        assert!(
            Junction::Grbl { deviation_m: 0.0 }.validate().is_err()
                && Junction::Klipper {
                    square_corner_velocity: f64::NAN
                }
                .validate()
                .is_err()
        );
    }
}
