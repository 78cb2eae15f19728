//! What an impulse train does, by Klipper's measures (klippy/extras/shaper_calibrate.py):
//! the vibration it leaves on a mode and the smoothing it causes at corners. Free
//! functions on amplitudes and times so that Klipper's shaper choice evaluates trains
//! without building a [`super::Shaper`] for each.

use std::f64::consts::SQRT_2;

/// Fraction of a mode's residual vibration that the train `(amplitudes, times_s)` leaves
/// (`_estimate_shaper`): for the mode `(frequency_hz, damping_ratio)`,
/// `|sum_i A_i e^{-zeta w (T_n - T_i)} e^{i wd T_i}| / sum A`, `w = 2 pi f`,
/// `wd = w sqrt(1 - zeta^2)`. 1 = no reduction.
pub fn remaining_vibration(
    amplitudes: &[f64],
    times_s: &[f64],
    frequency_hz: f64,
    damping_ratio: f64,
) -> f64 {
    let inv_d = 1.0 / amplitudes.iter().sum::<f64>();
    let omega = 2.0 * std::f64::consts::PI * frequency_hz;
    let damping = damping_ratio * omega;
    let omega_d = omega * (1.0 - damping_ratio * damping_ratio).sqrt();
    let t_n = times_s.last().copied().unwrap_or(0.0);
    let (mut s, mut c) = (0.0, 0.0);
    for (a, t) in amplitudes.iter().zip(times_s) {
        let w = a * (-damping * (t_n - t)).exp();
        s += w * (omega_d * t).sin();
        c += w * (omega_d * t).cos();
    }
    (s * s + c * c).sqrt() * inv_d
}

/// Klipper's smoothing figure of a train (`_get_shaper_smoothing`, mm): with
/// `t_s = sum A_i T_i / sum A`, the larger of the 90-degree offset
/// `sqrt2 / sum A * sum_{T_i >= t_s} A_i (scv + a/2 (T_i - t_s)) (T_i - t_s)` and the
/// 180-degree offset `1 / sum A * sum A_i a/2 (T_i - t_s)^2`, at acceleration
/// `accel_mm_s2` and square-corner velocity `scv_mm_s` (Klipper uses 5000 and 5).
pub fn smoothing_mm(amplitudes: &[f64], times_s: &[f64], accel_mm_s2: f64, scv_mm_s: f64) -> f64 {
    let half_accel = accel_mm_s2 * 0.5;
    let inv_d = 1.0 / amplitudes.iter().sum::<f64>();
    let mut ts = 0.0;
    for (a, t) in amplitudes.iter().zip(times_s) {
        ts += a * t;
    }
    ts *= inv_d;
    let (mut off90, mut off180) = (0.0, 0.0);
    for (a, t) in amplitudes.iter().zip(times_s) {
        let dt = t - ts;
        if *t >= ts {
            off90 += a * (scv_mm_s + half_accel * dt) * dt;
        }
        off180 += a * half_accel * (dt * dt);
    }
    off90 *= inv_d * SQRT_2;
    off180 *= inv_d;
    off90.max(off180)
}
