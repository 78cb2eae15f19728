//! Input shapers, applicable to any profile, each computed as its firmware computes it.
//!
//! A shaper is a train of impulses `A_i` at times `T_i` (`T_0 = 0`). Shaping a profile
//! convolves it with the normalised train: `q(t) = sum_i w_i p(t - T_i)`, `w_i = A_i / sum A`.
//! For a lightly damped mode `(f, zeta)` the residual vibration is multiplied by
//! [`Shaper::remaining_vibration`], so a shaper tuned to the mode cancels most of it, at the
//! price of a longer, smoother move (duration `T_last`, [`Shaper::smoothing_mm`]).
//!
//! Users paste shaper settings between settle and their firmware, and the firmwares do not
//! agree on what a name means, so a [`ShaperType`] names the firmware too:
//! - bare names are Klipper's current definitions (klippy/extras/shaper_defs.py): `zv`, `mzv(n,t)`, `zvd`, `ei(v_tol)`, `2hump_ei`,
//!   `3hump_ei`;
//! - `marlin:...` are Marlin FT_MOTION's (Marlin/src/module/ft_motion/shaping.cpp), with
//!   impulse times rounded to its trajectory rate `FTM_FS`; `marlin:m593` is the stepper's
//!   ZV of `M593` (Marlin/src/module/stepper.cpp), amplitudes in 128ths from a cubic in the
//!   damping ratio, the echo half the undamped period late;
//! - `rrf:...` are RepRapFirmware M593's (src/Movement/AxisShaper.cpp), with delays rounded
//!   to the step clock;
//! - `prusa:...` are Prusa-Firmware-Buddy's EI family
//!   (lib/Marlin/Marlin/src/feature/input_shaper/input_shaper.cpp), Klipper's earlier
//!   closed forms; Buddy's ZV, ZVD and MZV are Klipper's own.
//!
//! The shaped profile is again a [`crate::Profile`]: between consecutive shifted breakpoints every
//! copy has constant jerk, so the sum does too; acceleration jumps (trapezoids) stay jumps.

mod apply;
mod klipper;
mod marlin;
mod marlin_m593;
mod mzv_solve;
mod name;
mod prusa;
mod response;
mod rrf;
mod shaper_type;
pub mod stream;
#[cfg(test)]
mod tests;

pub use response::{remaining_vibration, smoothing_mm};
pub use shaper_type::{
    KLIPPER_DEFAULT_DAMPING_RATIO, KLIPPER_V_TOL, MARLIN_FTM_FS_HZ, MARLIN_V_TOL, MarlinShaper,
    PRUSA_V_TOL, PrusaShaper, RRF_STEP_CLOCK_HZ, RrfShaper, ShaperType,
};

use crate::PlanError;

/// The lowest shaper frequency settle runs (Hz), whatever a firmware accepts: a shaper
/// lasts about one period (0.5/f for ZV to 2/f for 3-hump EI), so below 1 Hz it lasts
/// seconds per move (and at 1e-6 Hz days), shaping nothing a machine has. [`Shaper::new`]
/// keeps each firmware's own range; the callers that take a user's setting check this.
pub const MIN_FREQUENCY_HZ: f64 = 1.0;
/// The largest start or end acceleration [`Shaper::apply`] takes as zero, as a fraction of
/// the profile's peak acceleration: a million times f64's round-off (2.2e-16), a million
/// times below any acceleration a move is planned with.
pub const END_ACCEL_ROUND_OFF: f64 = 1e-9;

/// Klipper's vibration tolerance of the EI family: 5% (a 20x reduction).
pub const VIBRATION_TOLERANCE: f64 = KLIPPER_V_TOL;

/// A shaper: impulse amplitudes (as its firmware computes them; Klipper's do not sum to
/// 1, Marlin's and RepRapFirmware's do; RepRapFirmware's `ei3` above damping 0.3 and `ei2`
/// above 0.41 have negative ones) and times (s), increasing, the first 0.
#[derive(Debug, Clone, PartialEq)]
pub struct Shaper {
    shaper_type: ShaperType,
    frequency_hz: f64,
    damping_ratio: f64,
    amplitudes: Vec<f64>,
    times_s: Vec<f64>,
}

fn invalid(kind: ShaperType, reason: String) -> PlanError {
    PlanError::InvalidShaper {
        name: kind.to_string(),
        reason,
    }
}

impl Shaper {
    /// The shaper of `kind` tuned to `frequency_hz` and `damping_ratio`, refused where its
    /// firmware refuses the setting:
    /// - Klipper: `frequency_hz > 0`; `damping_ratio` in `0..=0.99` (`ei` 0.4, `2hump_ei`
    ///   0.3, `3hump_ei` 0.2: `max_damping_ratio` in shaper_defs.py). Default damping 0.1.
    /// - Marlin: `frequency_hz` in `(0, FTM_FS/2]` (M493 `A`), `damping_ratio` in
    ///   `0.01..1` (M493 `I` allows 1.0, where the firmware divides by zero), `v_tol` in
    ///   `0..=1` (M493 `Q`), above 0 for 2HEI (whose first amplitude is 0 / 0 at 0).
    ///   Default 0.1.
    /// - Marlin's stepper ZV (`marlin:m593`): `damping_ratio` in `0..=1` (M593 `D`; from
    ///   0.8646 its echo is 0 and nothing is shaped). M593 `F` takes any frequency above 0.
    /// - RepRapFirmware: `frequency_hz` in `step_clock / 131070 ..= 1000` (M593 `F`; 5.72
    ///   Hz on Duet 3), `damping_ratio` in `0..=0.99` (M593 `S`). Default 0.05 (3.6 line).
    /// - Prusa (its EI family): `damping_ratio` below 1 (`input_shaper::get` halts the
    ///   printer otherwise), `v_tol` above 0 (M593 `R` > 0), at most 1 for 2HUMP_EI
    ///   (`sqrt(1 - v^2)`). Default damping 0.1. Its
    ///   `M593 F` clamp to 10..=100 Hz (150 on the MINI) is the caller's.
    ///
    /// Whatever the firmware, amplitudes that are not all numbers, or whose sum is not
    /// above 0, are refused: every firmware divides by their sum.
    pub fn new(kind: ShaperType, frequency_hz: f64, damping_ratio: f64) -> Result<Self, PlanError> {
        if !(frequency_hz.is_finite() && frequency_hz > 0.0) {
            return Err(PlanError::NonFinite {
                name: "shaper frequency_hz (must be finite and > 0)",
                value: frequency_hz,
            });
        }
        if !(damping_ratio.is_finite() && damping_ratio >= 0.0) {
            return Err(PlanError::NonFinite {
                name: "shaper damping_ratio (must be finite and >= 0)",
                value: damping_ratio,
            });
        }
        let out_of = |what: &str, lo: f64, hi: f64, v: f64| {
            invalid(kind, format!("{what} must be in {lo}..={hi}, got {v}"))
        };
        let (amplitudes, times_s) = match kind {
            ShaperType::Marlin {
                shaper,
                v_tol,
                ftm_fs_hz,
            } => {
                let f_max = f64::from(ftm_fs_hz) / 2.0;
                if frequency_hz > f_max {
                    return Err(out_of("frequency_hz (M493 A)", 0.0, f_max, frequency_hz));
                }
                if !(0.01..1.0).contains(&damping_ratio) {
                    return Err(invalid(
                        kind,
                        format!("damping_ratio (M493 I) must be in 0.01..1, got {damping_ratio}"),
                    ));
                }
                if !(0.0..=1.0).contains(&v_tol) {
                    return Err(out_of("v_tol (M493 Q)", 0.0, 1.0, v_tol));
                }
                if shaper == MarlinShaper::TwoHei && v_tol as f32 == 0.0 {
                    return Err(invalid(
                        kind,
                        "v_tol (M493 Q) 0: Marlin's 2HEI amplitude (3X^2 + 2X + 3v^2) / (16X) has X = (v^2 (sqrt(1 - v^2) + 1))^(1/3) = 0 and divides 0 by 0 (AxisShaping::set_axis_shaping_A, Marlin/src/module/ft_motion/shaping.cpp); M493 takes Q0 and shapes with NaN: give Q above 0".into(),
                    ));
                }
                marlin::impulses(shaper, frequency_hz, damping_ratio, v_tol, ftm_fs_hz)
            }
            ShaperType::MarlinM593 => {
                if damping_ratio > 1.0 {
                    return Err(out_of("damping_ratio (M593 D)", 0.0, 1.0, damping_ratio));
                }
                marlin_m593::impulses(frequency_hz, damping_ratio)
            }
            ShaperType::Prusa { shaper, v_tol } => {
                if damping_ratio >= 1.0 {
                    return Err(invalid(
                        kind,
                        format!("damping_ratio must be below 1, got {damping_ratio}"),
                    ));
                }
                if !(v_tol.is_finite() && v_tol > 0.0) {
                    return Err(out_of("v_tol", 0.0, f64::INFINITY, v_tol));
                }
                if shaper == PrusaShaper::TwoHumpEi && v_tol as f32 > 1.0 {
                    return Err(invalid(
                        kind,
                        format!(
                            "v_tol {v_tol} (1 / M593 R) above 1: Buddy's 2HUMP_EI takes sqrt(1 - v^2) of it (input_shaper::get, lib/Marlin/Marlin/src/feature/input_shaper/input_shaper.cpp), which is no number; M593 takes any R above 0 and shapes with NaN: give R of 1 or more"
                        ),
                    ));
                }
                prusa::impulses(shaper, frequency_hz, damping_ratio, v_tol)
            }
            ShaperType::Rrf {
                shaper,
                step_clock_hz,
            } => {
                let f_min = f64::from(step_clock_hz as f32 / (2.0 * 65535.0));
                if !(f_min..=1000.0).contains(&frequency_hz) {
                    return Err(out_of("frequency_hz (M593 F)", f_min, 1000.0, frequency_hz));
                }
                if damping_ratio > 0.99 {
                    return Err(out_of("damping_ratio (M593 S)", 0.0, 0.99, damping_ratio));
                }
                rrf::impulses(shaper, frequency_hz, damping_ratio, step_clock_hz)
            }
            _ => {
                let max = klipper::max_damping_ratio(kind.family());
                if damping_ratio > max {
                    return Err(out_of("damping_ratio", 0.0, max, damping_ratio));
                }
                match kind {
                    ShaperType::Zv => klipper::zv(frequency_hz, damping_ratio),
                    ShaperType::Zvd => klipper::zvd(frequency_hz, damping_ratio),
                    ShaperType::Mzv { n, t } => klipper::mzv(frequency_hz, damping_ratio, n, t)
                        .map_err(|reason| invalid(kind, reason))?,
                    ShaperType::Ei { v_tol } => {
                        if !(v_tol.is_finite() && v_tol >= 0.0) {
                            return Err(out_of("v_tol", 0.0, f64::INFINITY, v_tol));
                        }
                        klipper::ei(frequency_hz, damping_ratio, v_tol)
                    }
                    ShaperType::TwoHumpEi => klipper::two_hump_ei(frequency_hz, damping_ratio),
                    _ => klipper::three_hump_ei(frequency_hz, damping_ratio),
                }
            }
        };
        // Every amplitude a number and their sum positive: the firmwares divide by the sum
        // (Klipper's C side, Marlin's `adj`, Buddy's `inv_sum_a`), so a train that is not
        // is no motion any of them runs.
        let sum: f64 = amplitudes.iter().sum();
        if amplitudes.iter().any(|a| !a.is_finite()) || !(sum.is_finite() && sum > 0.0) {
            return Err(invalid(
                kind,
                format!(
                    "the firmware's impulse amplitudes at {frequency_hz} Hz and damping {damping_ratio} are not numbers summing above 0: {amplitudes:?}"
                ),
            ));
        }
        // Klipper's step generation refuses impulses out of time order (kin_shaper.c);
        // RepRapFirmware runs its ei2/ei3 delays in any order and `rrf::impulses` puts
        // them in time order; the others cannot produce them.
        if times_s.windows(2).any(|w| w[0] >= w[1]) {
            return Err(invalid(
                kind,
                format!("impulse times are not increasing at {frequency_hz} Hz: {times_s:?}"),
            ));
        }
        Ok(Self {
            shaper_type: kind,
            frequency_hz,
            damping_ratio,
            amplitudes,
            times_s,
        })
    }

    /// The family and its parameters.
    pub fn shaper_type(&self) -> ShaperType {
        self.shaper_type
    }

    /// The frequency it is tuned to (Hz).
    pub fn frequency_hz(&self) -> f64 {
        self.frequency_hz
    }

    /// The damping ratio it is tuned to.
    pub fn damping_ratio(&self) -> f64 {
        self.damping_ratio
    }

    /// Impulse amplitudes as the firmware computes them (Klipper's do not sum to 1).
    pub fn amplitudes(&self) -> &[f64] {
        &self.amplitudes
    }

    /// Impulse times (s), the first is 0.
    pub fn times_s(&self) -> &[f64] {
        &self.times_s
    }

    /// Duration: the last impulse time (s). A shaped move is this much longer.
    pub fn duration_s(&self) -> f64 {
        self.times_s.last().copied().unwrap_or(0.0)
    }

    /// Normalised weights `A_i / sum A`.
    pub fn weights(&self) -> impl Iterator<Item = f64> + '_ {
        let inv = 1.0 / self.amplitudes.iter().sum::<f64>();
        self.amplitudes.iter().map(move |a| a * inv)
    }

    /// The fraction of a mode's residual vibration the shaper leaves (Klipper's
    /// `_estimate_shaper`): for a mode at `frequency_hz` with `damping_ratio`,
    /// `|sum_i A_i e^{-zeta w (T_n - T_i)} e^{i wd T_i}| / sum A`. 1 = no reduction.
    pub fn remaining_vibration(&self, frequency_hz: f64, damping_ratio: f64) -> f64 {
        remaining_vibration(&self.amplitudes, &self.times_s, frequency_hz, damping_ratio)
    }

    /// Klipper's smoothing figure (`_get_shaper_smoothing`, mm): the larger of the offsets a
    /// 90-degree corner at square-corner velocity `scv_mm_s` and a 180-degree turn see at
    /// acceleration `accel_mm_s2` (Klipper reports it at 5000 mm/s^2 and 5 mm/s).
    pub fn smoothing_mm(&self, accel_mm_s2: f64, scv_mm_s: f64) -> f64 {
        smoothing_mm(&self.amplitudes, &self.times_s, accel_mm_s2, scv_mm_s)
    }
}
