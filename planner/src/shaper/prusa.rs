//! Prusa-Firmware-Buddy's EI shapers as lib/Marlin/Marlin/src/feature/input_shaper/input_shaper.cpp
//! computes them (`input_shaper::get`), in single precision as the firmware does.
//!
//! With `df = sqrt(1 - zeta^2)`, `K = exp(-zeta pi / df)`, the damped period
//! `t_d = 1 / (f df)` and `v = 1 / R` (`M593 R`, the vibration reduction, default 20):
//! - EI: `[(1+v)/4, (1-v)K/2, (1+v)K^2/4]` at `[0, t_d/2, t_d]`;
//! - 2-hump EI: `X = (v^2 (sqrt(1-v^2) + 1))^(1/3)`, `a1 = (3X^2 + 2X + 3v^2) / (16X)`:
//!   `[a1, (1/2 - a1)K, (1/2 - a1)K^2, a1 K^3]` at `[0, 1/2, 1, 3/2] t_d`;
//! - 3-hump EI: `a1 = (1 + 3v + 2 sqrt(2(v+1)v)) / 16`:
//!   `[a1, (1-v)K/4, ((1+v)/2 - 2a1)K^2, (1-v)K^3/4, a1 K^4]` at `[0, 1/2, 1, 3/2, 2] t_d`.
//!
//! These are the closed forms Klipper used before its damping polynomials (and Marlin
//! FT_MOTION's amplitudes, [`super::marlin`]), at times not rounded to any clock. Buddy's
//! ZV, ZVD and MZV are Klipper's (`zv`, `zvd`, the classic `mzv`) formula for formula.

use std::f32::consts::PI;

use super::shaper_type::{Impulses, PrusaShaper};

pub(super) fn impulses(shaper: PrusaShaper, f_hz: f64, zeta: f64, v_tol: f64) -> Impulses {
    let (f, z, v) = (f_hz as f32, zeta as f32, v_tol as f32);
    let df = (1.0f32 - z * z).sqrt();
    let k = (-z * PI / df).exp();
    let t_d = 1.0f32 / (f * df);
    let (a, t): (Vec<f32>, Vec<f32>) = match shaper {
        PrusaShaper::Ei => {
            let a1 = 0.25 * (1.0 + v);
            let a2 = 0.5 * (1.0 - v) * k;
            (vec![a1, a2, a1 * k * k], vec![0.0, 0.5 * t_d, t_d])
        }
        PrusaShaper::TwoHumpEi => {
            let v2 = v * v;
            let x = (v2 * ((1.0 - v2).sqrt() + 1.0)).powf(1.0 / 3.0);
            let a1 = (3.0 * x * x + 2.0 * x + 3.0 * v2) / (16.0 * x);
            let a2 = (0.5 - a1) * k;
            (
                vec![a1, a2, a2 * k, a1 * k * k * k],
                vec![0.0, 0.5 * t_d, t_d, 1.5 * t_d],
            )
        }
        PrusaShaper::ThreeHumpEi => {
            let k2 = k * k;
            let a1 = 0.0625 * (1.0 + 3.0 * v + 2.0 * (2.0 * (v + 1.0) * v).sqrt());
            let a2 = 0.25 * (1.0 - v) * k;
            (
                vec![
                    a1,
                    a2,
                    (0.5 * (1.0 + v) - 2.0 * a1) * k2,
                    a2 * k2,
                    a1 * k2 * k2,
                ],
                vec![0.0, 0.5 * t_d, t_d, 1.5 * t_d, 2.0 * t_d],
            )
        }
    };
    (
        a.into_iter().map(f64::from).collect(),
        t.into_iter().map(f64::from).collect(),
    )
}
