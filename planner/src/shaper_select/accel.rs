//! Klipper's suggested maximum acceleration (`find_shaper_max_accel`, `_bisect`): the
//! largest acceleration whose smoothing stays within 0.12 mm, by doubling and bisection to
//! 1e-8 mm/s^2, in the same steps as the Python.

use super::options::TARGET_SMOOTHING_MM;
use crate::shaper::smoothing_mm;

/// The largest acceleration (mm/s^2) at which the shaper with `amplitudes` at `times_s`
/// smooths a corner taken at `scv_mm_s` by at most [`TARGET_SMOOTHING_MM`]: the
/// `max_accel` `calibrate_shaper.py` prints beside each shaper.
pub fn max_accel_mm_s2(amplitudes: &[f64], times_s: &[f64], scv_mm_s: f64) -> f64 {
    let ok = |accel: f64| smoothing_mm(amplitudes, times_s, accel, scv_mm_s) <= TARGET_SMOOTHING_MM;
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
        if ok(middle) {
            left = middle;
        } else {
            right = middle;
        }
    }
    left
}
