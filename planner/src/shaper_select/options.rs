//! What Klipper's shaper choice takes (its constants and options) and gives back.

use crate::shaper::ShaperType;

/// Klipper's test damping ratios (`TEST_DAMPING_RATIOS`): the printer's damping is
/// unknown, so each shaper is judged by its worst case over these.
pub const TEST_DAMPING_RATIOS: [f64; 3] = [0.075, 0.1, 0.15];
/// The highest PSD frequency Klipper considers by default (`MAX_FREQ`, Hz).
pub const MAX_FREQ_HZ: f64 = 200.0;
/// The highest shaper frequency Klipper tries by default (`MAX_SHAPER_FREQ`, Hz).
pub const MAX_SHAPER_FREQ_HZ: f64 = 150.0;
/// The smoothing (mm) Klipper's suggested `max_accel` keeps to (`TARGET_SMOOTHING`).
pub const TARGET_SMOOTHING_MM: f64 = 0.12;

/// Which shaper frequencies to try (`--shaper_freq` of calibrate_shaper.py).
#[derive(Debug, Clone, PartialEq)]
pub enum ShaperFreqs {
    /// `[start]:end[:step]`: `start` defaults to the shaper's minimum frequency, `end` to
    /// 150 Hz, `step` to 0.2 Hz; the grid is numpy's `arange(start, end, step)`.
    Range {
        /// First frequency (Hz).
        start_hz: Option<f64>,
        /// End, excluded (Hz).
        end_hz: Option<f64>,
        /// Step (Hz).
        step_hz: Option<f64>,
    },
    /// An explicit list (Hz).
    List(Vec<f64>),
}

impl Default for ShaperFreqs {
    fn default() -> Self {
        ShaperFreqs::Range {
            start_hz: None,
            end_hz: None,
            step_hz: None,
        }
    }
}

/// The options of Klipper's choice, with Klipper's defaults from [`SelectOptions::default`].
#[derive(Debug, Clone, PartialEq)]
pub struct SelectOptions {
    /// Shapers to try, in order (order matters for ties): `AUTOTUNE_SHAPERS` = `zv`, `mzv`,
    /// `ei`, `2hump_ei`, `3hump_ei`. Kinds of other firmwares need frequencies with a start
    /// (they have no Klipper minimum frequency).
    pub shapers: Vec<ShaperType>,
    /// Damping ratio the shapers are built with (`DEFAULT_DAMPING_RATIO`, 0.1; Klipper
    /// treats 0 as "unset").
    pub damping_ratio: f64,
    /// Square-corner velocity for smoothing (mm/s; the script's default 5).
    pub scv_mm_s: f64,
    /// Frequencies to try.
    pub shaper_freqs: ShaperFreqs,
    /// Stop a shaper's scan at frequencies that smooth more than this (mm).
    pub max_smoothing_mm: Option<f64>,
    /// Remaining vibration (fraction, not percent) above which a less vibrating choice
    /// wins regardless of score.
    pub max_vibrations: Option<f64>,
    /// Damping ratios of the modes shapers are judged against.
    pub test_damping_ratios: Vec<f64>,
    /// Highest PSD frequency used (Hz); `None` = 200 Hz. Raised to the highest test
    /// frequency when that is above it.
    pub max_freq_hz: Option<f64>,
}

impl Default for SelectOptions {
    fn default() -> Self {
        Self {
            shapers: vec![
                ShaperType::Zv,
                ShaperType::MZV,
                ShaperType::EI,
                ShaperType::TwoHumpEi,
                ShaperType::ThreeHumpEi,
            ],
            damping_ratio: crate::shaper::KLIPPER_DEFAULT_DAMPING_RATIO,
            scv_mm_s: 5.0,
            shaper_freqs: ShaperFreqs::default(),
            max_smoothing_mm: None,
            max_vibrations: None,
            test_damping_ratios: TEST_DAMPING_RATIOS.to_vec(),
            max_freq_hz: None,
        }
    }
}

/// One shaper at one frequency, judged (`CalibrationResult` without the plotting curve).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fit {
    /// The shaper.
    pub shaper_type: ShaperType,
    /// Its frequency (Hz).
    pub frequency_hz: f64,
    /// Remaining vibration, a fraction of the PSD above the threshold (worst case).
    pub vibrations: f64,
    /// Smoothing at 5000 mm/s^2 and the options' square-corner velocity (mm).
    pub smoothing_mm: f64,
    /// Klipper's score (lower is better).
    pub score: f64,
    /// Largest acceleration keeping the smoothing <= 0.12 mm (mm/s^2; Klipper prints it
    /// rounded to 100).
    pub max_accel_mm_s2: f64,
}

/// Klipper's choice: the recommendation and each shaper's pick, in the order tried.
#[derive(Debug, Clone, PartialEq)]
pub struct Selection {
    /// The recommended shaper and frequency.
    pub recommended: Fit,
    /// One pick per shaper tried (`all_shapers`).
    pub per_shaper: Vec<Fit>,
}
