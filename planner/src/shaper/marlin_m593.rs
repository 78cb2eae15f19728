//! Marlin's stepper ZV shaper (`INPUT_SHAPING_X`/`INPUT_SHAPING_Y`, set by `M593 F D`), as
//! Marlin/src/module/stepper.cpp computes it; FT_MOTION's ZV (`M493`) is [`super::marlin`].
//!
//! - Amplitudes (`Stepper::set_shaping_damping_ratio`): the echo's share of 128 is the cubic
//!   `64.44056192 - 99.02008832 zeta - 7.58095488 zeta^2 + 43.073216 zeta^3`, floored
//!   (`FLOOR`) into the `uint8_t factor2` (64 at `zeta <= 0`, 0 at `zeta >= 1`); the step
//!   itself keeps `factor1 = 128 - factor2`. The stepper ISR adds `factor1` to an axis's
//!   secondary Bresenham counter at each step and `factor2` at each echo
//!   (`PULSE_PREP_SHAPING` in `Stepper::pulse_phase_isr`, the echoes queued in
//!   `ShapingQueue`, stepper.h), so the axis moves `(factor1 x(t) + factor2 x(t - T)) / 128`.
//!   The cubic approximates the ZV split `K / (1 + K)` of 128 (`K = exp(-zeta pi / sqrt(1 -
//!   zeta^2))`); it falls below 1 at a damping of 0.8646 (its least value is 0.44, near
//!   0.93), so from there to 1 `factor2` is 0: only the first impulse is left and nothing
//!   is shaped.
//! - Delay (`Stepper::set_shaping_frequency`): `T = float(STEPPER_TIMER_RATE / 2) / F`
//!   stepper-timer ticks, half the *undamped* period `1 / (2F)` whatever the damping
//!   (Klipper's `zv` waits half the damped period `1 / (2F sqrt(1 - zeta^2))`). Marlin
//!   truncates it to whole ticks; this file takes the exact half period: a tick is 0.5 us
//!   on the many boards whose stepper timer runs at 2 MHz (1 us at 1 MHz), and each
//!   echo step is timed by the stepper ISR's own tick anyway, so the truncation moves the
//!   echo by at most 2.5e-5 of a period at 50 Hz (a phase of 1.6e-4 rad, a residual of
//!   about 1e-4 of the unshaped one).
//!
//! The cubic is evaluated as the firmware does: `zeta` is a `float` (M593 reads `D` with
//! `value_float`), each step multiplies a double constant by a float power of it, adds in
//! double precision and stores the sum in the float `factor2`.

use super::shaper_type::Impulses;

/// `factor2`, the echo's share of 128 (`Stepper::set_shaping_damping_ratio`).
pub(super) fn echo_share(zeta: f64) -> u8 {
    let z = zeta as f32;
    if z <= 0.0 {
        return 64;
    }
    if z >= 1.0 {
        return 0;
    }
    let mut f2 = (64.440_561_92 + -99.020_088_32 * f64::from(z)) as f32;
    let z2 = z * z;
    f2 = (f64::from(f2) + -7.580_954_88 * f64::from(z2)) as f32;
    let z3 = z2 * z;
    f2 = (f64::from(f2) + 43.073_216 * f64::from(z3)) as f32;
    // `FLOOR` then the store into `uint8_t`: the cubic stays within 0..=64.44 on 0..1.
    f2.floor().max(0.0) as u8
}

pub(super) fn impulses(f_hz: f64, zeta: f64) -> Impulses {
    let f2 = echo_share(zeta);
    let f1 = 128 - f2;
    if f2 == 0 {
        // The echo adds nothing: the move runs unshaped.
        return (vec![1.0], vec![0.0]);
    }
    (
        vec![f64::from(f1) / 128.0, f64::from(f2) / 128.0],
        vec![0.0, 0.5 / f_hz],
    )
}
