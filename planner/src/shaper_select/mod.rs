//! Klipper's shaper choice (klippy/extras/shaper_calibrate.py `find_best_shaper`,
//! `fit_shaper`; scripts/calibrate_shaper.py) as a pure function: calibration data in, per
//! shaper the best frequency, remaining vibration, smoothing, score and maximum
//! acceleration out, and the shaper Klipper recommends.
//!
//! How Klipper chooses (and so how [`find_best_shaper`] does):
//! 1. For each shaper (by default `zv`, `mzv`, `ei`, `2hump_ei`, `3hump_ei`; `zvd` is not
//!    tried) and each test frequency from 150 Hz down to the shaper's minimum (21, 23, 29,
//!    29, 39, 48 Hz) in 0.2 Hz steps (numpy's `arange`), the shaper is built at the configured
//!    damping ratio (0.1) and scored on the PSD (`psd_xyz`, bins up to `max_freq`, 200 Hz):
//!    remaining vibration `sum(max(V(f) PSD - thr, 0)) / sum(max(PSD - thr, 0))`,
//!    `thr = max(PSD)/20`, worst over the test damping ratios 0.075, 0.1, 0.15 and over the
//!    data sets; smoothing at 5000 mm/s^2 and the square-corner velocity (5 mm/s);
//!    `score = smoothing (v^1.5 + 0.2 v + 0.01)`; `max_accel` the largest acceleration
//!    whose smoothing stays <= 0.12 mm. With `max_smoothing`, the scan stops
//!    at the first frequency that smooths more (once a result exists).
//! 2. Per shaper, the least-vibrating frequency is the "best"; going up in frequency from
//!    the lowest, any frequency within `1.1 best + 0.0005` of its vibration and with a
//!    lower score (or, with `max_vibrations`, when the best exceeds it) replaces the pick.
//! 3. Across shapers, a shaper replaces the recommendation if its score is 20%
//!    lower, or 5% lower with 10% less smoothing, or (with `max_vibrations`) if the
//!    recommendation vibrates more than allowed and it vibrates less; then any of the
//!    shaper's frequencies that both vibrates and smooths less than the recommendation
//!    takes over. A recommended `zv` gives way to the first other shaper that vibrates 10%
//!    less.
//!
//! The arithmetic follows the Python closely (the same sums in the same order where the
//! Python sums in order; numpy's pairwise sums over PSD bins differ in the last bits), so
//! settle's numbers agree with Klipper's to about 1e-12 and the recommendation is the same.

mod accel;
mod choose;
mod data;
mod fit;
mod grid;
mod options;

pub use accel::max_accel_mm_s2;
pub use choose::find_best_shaper;
pub use data::CalibrationData;
pub use fit::fit_shaper;
pub use options::{
    Fit, MAX_FREQ_HZ, MAX_SHAPER_FREQ_HZ, SelectOptions, Selection, ShaperFreqs,
    TARGET_SMOOTHING_MM, TEST_DAMPING_RATIOS,
};
