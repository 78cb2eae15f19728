//! Klipper's suggested maximum acceleration (`find_shaper_max_accel`, `_bisect`): the
//! largest acceleration whose smoothing stays within a target (Klipper's 0.12 mm,
//! [`super::TARGET_SMOOTHING_MM`]), by doubling and bisection to 1e-8 mm/s^2, in the same
//! steps as the Python (and no further than two neighbouring doubles, where the Python
//! would loop forever).

use crate::shaper::smoothing_mm;

/// The largest acceleration (mm/s^2) whose smoothing at `scv_mm_s` stays within
/// `target_mm`; 0 when even a vanishing acceleration smooths more.
pub fn max_accel_mm_s2(amplitudes: &[f64], times_s: &[f64], scv_mm_s: f64, target_mm: f64) -> f64 {
    let ok = |accel: f64| smoothing_mm(amplitudes, times_s, accel, scv_mm_s) <= target_mm;
    let (mut left, mut right) = (1.0f64, 1.0f64);
    if !ok(1e-9) {
        return 0.0;
    }
    while !ok(left) {
        right = left;
        left *= 0.5;
    }
    if right == left {
        while ok(right) {
            right *= 2.0;
        }
    }
    while right - left > 1e-8 {
        let middle = (left + right) * 0.5;
        // Past about 6e7 mm/s^2 (a shaper of a few kHz) no double lies between two
        // neighbours 1e-8 apart: the interval cannot shrink further, and Klipper's
        // tolerance would loop forever.
        if middle <= left || middle >= right {
            break;
        }
        if ok(middle) {
            left = middle;
        } else {
            right = middle;
        }
    }
    left
}
