//! Marlin FT_MOTION's shapers as Marlin/src/module/ft_motion/shaping.cpp computes them
//! (`AxisShaping::set_axis_shaping_A` for the amplitudes, `set_axis_shaping_N` for the
//! impulse times).
//!
//! With `K = exp(-zeta pi / sqrt(1 - zeta^2))` and the amplitudes normalised to sum 1:
//! - ZV `[1, K]`, ZVD `[1, 2K, K^2]`, ZVDD `[1, 3K, 3K^2, K^3]`,
//!   ZVDDD `[1, 4K, 6K^2, 4K^3, K^4]`;
//! - EI `[(1+v)/4, (1-v)K/2, (1+v)K^2/4]` (the closed form Klipper used before its
//!   damping polynomials); 2HEI with `X = (v^2 (sqrt(1-v^2) + 1))^(1/3)`,
//!   `a1 = (3X^2 + 2X + 3v^2) / (16X)`: `[a1, (1/2 - a1)K, (1/2 - a1)K^2, a1 K^3]`;
//!   3HEI with `a1 = (1 + 3v + 2 sqrt(2(v+1)v)) / 16`:
//!   `[a1, (1-v)K/4, ((1+v)/2 - 2a1)K^2, (1-v)K^3/4, a1 K^4]`;
//! - MZV `[1, sqrt2 K, K^2]` with ZV's `K` (Klipper's classic MZV decays by
//!   `exp(-0.75 zeta pi / df)` instead).
//!
//! Impulse `i` comes `i N1` trajectory periods after the first, with
//! `N1 = lroundf(base / f / df * FTM_FS)`, `base` 0.5 (0.375 for MZV), `df = sqrt(1 -
//! zeta^2)`: the times are whole periods of `FTM_FS` (1 kHz by default, so a 40 Hz ZV's
//! half period of 12.5 ms becomes 13 ms). Marlin computes in single precision; so does
//! this file (its `K` goes through `exp` in double precision as the firmware's
//! `exp(double)` call does), so `N1` rounds exactly as on the printer.

use std::f64::consts::PI;

use super::shaper_type::Impulses;
use super::shaper_type::MarlinShaper;

pub(super) fn impulses(
    shaper: MarlinShaper,
    f_hz: f64,
    zeta: f64,
    v_tol: f64,
    ftm_fs_hz: u32,
) -> Impulses {
    let z = zeta as f32;
    let v = v_tol as f32;
    let df = (1.0f32 - z * z).sqrt();
    // `exp(-zeta * M_PI / sqrt(1.f - sq(zeta)))`: a double expression, stored as float.
    let k = (-f64::from(z) * PI / f64::from(df)).exp() as f32;
    let (k2, k3) = (k * k, k * k * k);
    let k4 = k3 * k;
    let normalise = |a: Vec<f32>| -> Vec<f32> {
        let adj = 1.0 / a.iter().sum::<f32>();
        a.into_iter().map(|x| x * adj).collect()
    };
    let a: Vec<f32> = match shaper {
        MarlinShaper::Zv => {
            let a0 = 1.0 / (1.0 + k);
            vec![a0, a0 * k]
        }
        MarlinShaper::Zvd => {
            let a0 = 1.0 / (1.0 + 2.0 * k + k2);
            vec![a0, a0 * 2.0 * k, a0 * k2]
        }
        MarlinShaper::Zvdd => {
            let a0 = 1.0 / (1.0 + 3.0 * k + 3.0 * k2 + k3);
            vec![a0, a0 * 3.0 * k, a0 * 3.0 * k2, a0 * k3]
        }
        MarlinShaper::Zvddd => {
            let a0 = 1.0 / (1.0 + 4.0 * k + 6.0 * k2 + 4.0 * k3 + k4);
            vec![a0, a0 * 4.0 * k, a0 * 6.0 * k2, a0 * 4.0 * k3, a0 * k4]
        }
        MarlinShaper::Ei => {
            let a0 = 0.25 * (1.0 + v);
            normalise(vec![a0, 0.50 * (1.0 - v) * k, a0 * k2])
        }
        MarlinShaper::TwoHei => {
            let v2 = v * v;
            let x = (v2 * ((1.0 - v2).sqrt() + 1.0)).powf(1.0 / 3.0);
            let a0 = (3.0 * x * x + 2.0 * x + 3.0 * v2) / (16.0 * x);
            let a1 = (0.5 - a0) * k;
            normalise(vec![a0, a1, a1 * k, a0 * k3])
        }
        MarlinShaper::ThreeHei => {
            let a0 = 0.0625 * (1.0 + 3.0 * v + 2.0 * (2.0 * (v + 1.0) * v).sqrt());
            let a1 = 0.25 * (1.0 - v) * k;
            normalise(vec![
                a0,
                a1,
                (0.5 * (1.0 + v) - 2.0 * a0) * k2,
                a1 * k2,
                a0 * k4,
            ])
        }
        MarlinShaper::Mzv => {
            let bx = std::f32::consts::SQRT_2 * k;
            let a0 = 1.0 / (1.0 + bx + k2);
            vec![a0, a0 * bx, a0 * k2]
        }
    };
    let base: f32 = if shaper == MarlinShaper::Mzv {
        0.375
    } else {
        0.5
    };
    let fs = ftm_fs_hz as f32;
    let n1 = ((base / f_hz as f32 / df) * fs).round();
    let times = (0..a.len())
        .map(|i| i as f64 * f64::from(n1) / f64::from(ftm_fs_hz))
        .collect();
    (a.into_iter().map(f64::from).collect(), times)
}
