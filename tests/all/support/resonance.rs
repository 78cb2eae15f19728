//! Synthetic Klipper resonance recordings from known modes (for the identify tests and
//! `examples/resonance_data.rs`, which writes the files under `examples/data/`).
//!
//! The toolhead of a modes-form axis (toolhead = command + sum w_k e_k with
//! `e_k'' + 2 zeta_k w_k e_k' + w_k^2 e_k = -a_cmd`) under Klipper's resonance test (the
//! commanded acceleration of settle-identify's `SweepTest::pieces`, piecewise constant),
//! integrated exactly: over an interval of constant `a` the deviation `x = e + a / w^2`
//! is a free damped oscillation, `x(h) = e^{-s h} (x0 cos(wd h) + (v0 + s x0) / wd sin(wd h))`,
//! `x'(h) = e^{-s h} (v0 cos(wd h) - (w^2 x0 + s v0) / wd sin(wd h))` with `s = zeta w`,
//! `wd = w sqrt(1 - zeta^2)`. The toolhead acceleration is `a + sum w_k e_k''`.
//!
//! The sensor: an ADXL345 turned `yaw_deg` about the vertical, seeing gravity (+1 g on its
//! z) and white noise of 0.41 mg/sqrt(Hz) (ADXL345 datasheet, Analog Devices Rev. G,
//! Table 1: 0.75 LSB rms at 3.9 mg/LSB in a 50 Hz bandwidth), quantised to Klipper's
//! scale of 0.003774 g/LSB (`SCALE_XY` in klippy/extras/adxl345.py).

#![allow(dead_code)]

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::TAU;

/// Standard gravity (mm/s^2).
pub const G_MM_S2: f64 = 9_806.65;

/// A mode: `(frequency Hz, damping ratio, weight)`.
pub type Truth = (f64, f64, f64);

/// Toolhead acceleration (mm/s^2) sampled at `fs` from `t = 0` for `n` samples, the command
/// `pieces` (`(end_time_s, accel)`, as `SweepTest::pieces`) starting at `t_start`.
pub fn toolhead_accel(
    modes: &[Truth],
    pieces: &[(f64, f64)],
    t_start: f64,
    fs: f64,
    n: usize,
) -> Vec<f64> {
    // Breakpoints (absolute) and the acceleration from each on; zero after the last.
    let mut breaks: Vec<(f64, f64)> = Vec::with_capacity(pieces.len() + 1);
    let mut from = t_start;
    for &(end, a) in pieces {
        breaks.push((from, a));
        from = t_start + end;
    }
    breaks.push((from, 0.0));
    let mut state = vec![(0.0f64, 0.0f64); modes.len()];
    let advance = |state: &mut [(f64, f64)], a: f64, h: f64| {
        for ((e, v), &(f, z, _)) in state.iter_mut().zip(modes) {
            let w = TAU * f;
            let s = z * w;
            let wd = w * (1.0 - z * z).sqrt();
            let x0 = *e + a / (w * w);
            let (c, sn, d) = ((wd * h).cos(), (wd * h).sin(), (-s * h).exp());
            let x = d * (x0 * c + (*v + s * x0) / wd * sn);
            *v = d * (*v * c - (w * w * x0 + s * *v) / wd * sn);
            *e = x - a / (w * w);
        }
    };
    let (mut t, mut a, mut next) = (0.0, 0.0, 0);
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let t_i = i as f64 / fs;
        while next < breaks.len() && breaks[next].0 <= t_i {
            advance(&mut state, a, breaks[next].0 - t);
            t = breaks[next].0;
            a = breaks[next].1;
            next += 1;
        }
        advance(&mut state, a, t_i - t);
        t = t_i;
        let mut acc = a;
        for (&(e, v), &(f, z, weight)) in state.iter().zip(modes) {
            let w = TAU * f;
            acc += weight * (-a - 2.0 * z * w * v - w * w * e);
        }
        out.push(acc);
    }
    out
}

/// What a yawed ADXL345 reports (mm/s^2 per chip axis, quantised) for the toolhead
/// acceleration `accel` along printer axis `axis` (0 = x, 1 = y), noise seeded by `seed`.
pub fn adxl345(accel: &[f64], axis: usize, yaw_deg: f64, fs: f64, seed: u64) -> [Vec<f64>; 3] {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let sigma = 0.75 * 3.9e-3 / 50f64.sqrt() * G_MM_S2 * (fs / 2.0).sqrt();
    let lsb = 0.003774 * G_MM_S2;
    let (c, s) = (yaw_deg.to_radians().cos(), yaw_deg.to_radians().sin());
    let mut gauss = || {
        // Box-Muller.
        let u1: f64 = 1.0 - rng.random::<f64>();
        let u2: f64 = rng.random::<f64>();
        (-2.0 * u1.ln()).sqrt() * (TAU * u2).cos()
    };
    let mut out: [Vec<f64>; 3] = std::array::from_fn(|_| Vec::with_capacity(accel.len()));
    for &acc in accel {
        let p = if axis == 0 { [acc, 0.0] } else { [0.0, acc] };
        let chip = [c * p[0] + s * p[1], -s * p[0] + c * p[1], G_MM_S2];
        for k in 0..3 {
            out[k].push(((chip[k] + sigma * gauss()) / lsb).round() * lsb);
        }
    }
    out
}

/// Klipper raw CSV text (`#time,accel_x,accel_y,accel_z`) of the samples, at `fs` from 0
/// (accelerations with two decimals: the samples are multiples of 37 mm/s^2 anyway).
pub fn klipper_raw_csv(axes: &[Vec<f64>; 3], fs: f64) -> String {
    let mut s = String::from("#time,accel_x,accel_y,accel_z\n");
    for (i, ((x, y), z)) in axes[0].iter().zip(&axes[1]).zip(&axes[2]).enumerate() {
        s.push_str(&format!("{:.6},{x:.2},{y:.2},{z:.2}\n", i as f64 / fs));
    }
    s
}

/// A Klipper raw recording of the resonance test `test` on one axis with `modes`:
/// `rest_s` of rest either side, sampled at `fs`.
pub fn recording(
    modes: &[Truth],
    test: &settle_identify::SweepTest,
    axis: usize,
    fs: f64,
    rest_s: f64,
    seed: u64,
) -> String {
    let n = ((test.duration_s() + 2.0 * rest_s) * fs) as usize;
    let accel = toolhead_accel(modes, &test.pieces(), rest_s, fs, n);
    klipper_raw_csv(&adxl345(&accel, axis, 30.0, fs, seed), fs)
}
