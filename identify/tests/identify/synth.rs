//! Synthetic accelerometer recordings from known modes, for the tests and the bench.
//!
//! The toolhead is settle's own plant (settle-sim's `ModalPlant`, the exact discretisation
//! of `e'' + 2 zeta w e' + w^2 e = -a_cmd` per mode), driven by a piecewise-constant
//! commanded acceleration (Klipper's resonance test from `SweepTest::pieces`, or a
//! trapezoid move followed by rest), steps split at every change of the command. The
//! toolhead's acceleration is read from the plant's state: `a_cmd + sum w_k e_k''` with
//! `e_k'' = -a_cmd - 2 zeta_k w_k e_k' - w_k^2 e_k`.
//!
//! The sensor is an ADXL345: mounted rotated (a rotation of the printer frame), it sees the
//! motion plus gravity (+1 g up, the specific force), white noise of the datasheet's
//! figure and the quantisation of Klipper's scale factors. ADXL345 datasheet (Analog
//! Devices, Rev. G), Table 1: noise 0.75 LSB rms on X and Y and 1.1 LSB rms on Z at a 100
//! Hz output data rate (50 Hz bandwidth) with 3.9 mg/LSB, i.e. noise densities of
//! 0.75 * 3.9 / sqrt(50) = 0.41 mg/sqrt(Hz) (X, Y) and 0.61 mg/sqrt(Hz) (Z), spread here
//! white over the band up to fs/2. Scale: 0.003774 g/LSB (X, Y) and 0.003906 g/LSB (Z),
//! Klipper's `SCALE_XY` / `SCALE_Z` in `klippy/extras/adxl345.py`.

#![allow(dead_code)]

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use settle_planner::{Sample, State};
use settle_sim::{AxisModel, ModalPlant, Mode, Plant};

/// Standard gravity (mm/s^2).
pub const G_MM_S2: f64 = 9_806.65;
/// ADXL345 noise density (g/sqrt(Hz)), X/Y and Z (see the module notes).
pub const NOISE_DENSITY_G: [f64; 3] = [
    0.75 * 3.9e-3 / 7.0710678118654755,
    0.75 * 3.9e-3 / 7.0710678118654755,
    1.1 * 3.9e-3 / 7.0710678118654755,
];
/// Klipper's ADXL345 scale (g/LSB), X/Y and Z.
pub const LSB_G: [f64; 3] = [0.003774, 0.003774, 0.003906];

/// A mode: (frequency Hz, damping ratio, weight).
pub type Truth = (f64, f64, f64);

/// Toolhead acceleration (mm/s^2) along the motion, sampled at `fs` from `t = 0` for
/// `n` samples, for the command `pieces` (`(end_time_s, accel)`, starting at `t_start`,
/// zero before and after).
pub fn toolhead_accel(
    modes: &[Truth],
    pieces: &[(f64, f64)],
    t_start: f64,
    fs: f64,
    n: usize,
) -> Vec<f64> {
    let ms: Vec<Mode> = modes
        .iter()
        .map(|&(f, z, w)| Mode::new(f, z, w).expect("mode"))
        .collect();
    let axis = AxisModel::from_modes("x", &ms).expect("axis");
    let dt = 1.0 / fs;
    let plant = ModalPlant::new(vec![axis], dt).expect("plant");
    let mut state = plant.initial_state(&[State::default()]).expect("state");
    // Breakpoints (absolute time) and the acceleration from each on.
    let mut breaks: Vec<(f64, f64)> = vec![(t_start, pieces.first().map_or(0.0, |p| p.1))];
    for w in pieces.windows(2) {
        breaks.push((t_start + w[0].0, w[1].1));
    }
    breaks.push((t_start + pieces.last().map_or(0.0, |p| p.0), 0.0));
    let (mut p, mut v, mut a) = (0.0, 0.0, 0.0);
    let mut next = 0;
    let mut out = Vec::with_capacity(n);
    let read = |state: &settle_sim::ModalState, a: f64| -> f64 {
        let ax = &state.axes[0];
        let (r, rd) = (ax.r(), ax.rd());
        let mut acc = a;
        for (k, &(f, z, w)) in modes.iter().enumerate() {
            let om = std::f64::consts::TAU * f;
            acc += w * (-a - 2.0 * z * om * rd[k] - om * om * r[k]);
        }
        acc
    };
    for i in 0..n {
        let t_i = i as f64 * dt;
        let t_end = (i + 1) as f64 * dt;
        // The command is right-continuous: a change at t_i shows at sample i.
        while next < breaks.len() && breaks[next].0 <= t_i {
            a = breaks[next].1;
            next += 1;
        }
        out.push(read(&state, a));
        let mut tc = t_i;
        let mut step = |h: f64, a: f64, p: &mut f64, v: &mut f64| {
            plant
                .step(
                    &mut state,
                    &[Sample {
                        p: *p,
                        v: *v,
                        a,
                        j: 0.0,
                    }],
                    h,
                )
                .expect("step");
            *p += *v * h + 0.5 * a * h * h;
            *v += a * h;
        };
        while next < breaks.len() && breaks[next].0 < t_end {
            let h = breaks[next].0 - tc;
            if h > 0.0 {
                step(h, a, &mut p, &mut v);
            }
            tc = breaks[next].0;
            a = breaks[next].1;
            next += 1;
        }
        step(if tc == t_i { dt } else { t_end - tc }, a, &mut p, &mut v);
    }
    out
}

/// A trapezoid move: `accel` for `t_acc`, cruise `t_cruise`, `-accel` for `t_acc`.
pub fn trapezoid(accel: f64, t_acc: f64, t_cruise: f64) -> Vec<(f64, f64)> {
    vec![
        (t_acc, accel),
        (t_acc + t_cruise, 0.0),
        (2.0 * t_acc + t_cruise, -accel),
    ]
}

/// A rotation (sensor from printer frame) by Euler angles (degrees) about z, then y, then x.
pub fn rotation(z_deg: f64, y_deg: f64, x_deg: f64) -> [[f64; 3]; 3] {
    let (a, b, c) = (z_deg.to_radians(), y_deg.to_radians(), x_deg.to_radians());
    let rz = [
        [a.cos(), -a.sin(), 0.0],
        [a.sin(), a.cos(), 0.0],
        [0.0, 0.0, 1.0],
    ];
    let ry = [
        [b.cos(), 0.0, b.sin()],
        [0.0, 1.0, 0.0],
        [-b.sin(), 0.0, b.cos()],
    ];
    let rx = [
        [1.0, 0.0, 0.0],
        [0.0, c.cos(), -c.sin()],
        [0.0, c.sin(), c.cos()],
    ];
    mul(&rx, &mul(&ry, &rz))
}

fn mul(p: &[[f64; 3]; 3], q: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let mut o = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            o[i][j] = (0..3).map(|k| p[i][k] * q[k][j]).sum();
        }
    }
    o
}

/// What the ADXL345 reports (mm/s^2 per chip axis, quantised): the toolhead acceleration
/// `accel` along printer direction `dir` plus gravity (printer +z up), rotated into the
/// sensor by `rot`, with noise (seeded) and quantisation.
pub fn adxl345(
    accel: &[f64],
    dir: [f64; 3],
    rot: &[[f64; 3]; 3],
    fs: f64,
    seed: u64,
) -> [Vec<f64>; 3] {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let noise: Vec<Normal<f64>> = (0..3)
        .map(|k| {
            Normal::new(0.0, NOISE_DENSITY_G[k] * G_MM_S2 * (fs / 2.0).sqrt()).expect("normal")
        })
        .collect();
    let mut out: [Vec<f64>; 3] = std::array::from_fn(|_| Vec::with_capacity(accel.len()));
    for &a in accel {
        let f = [a * dir[0], a * dir[1], a * dir[2] + G_MM_S2];
        for k in 0..3 {
            let s: f64 = (0..3).map(|j| rot[k][j] * f[j]).sum::<f64>() + noise[k].sample(&mut rng);
            let lsb = LSB_G[k] * G_MM_S2;
            out[k].push((s / lsb).round() * lsb);
        }
    }
    out
}

/// The samples as `(index, [x, y, z])`.
fn rows(axes: &[Vec<f64>; 3]) -> impl Iterator<Item = (usize, [f64; 3])> + '_ {
    axes[0]
        .iter()
        .zip(&axes[1])
        .zip(&axes[2])
        .map(|((x, y), z)| [*x, *y, *z])
        .enumerate()
}

/// Klipper raw CSV text (`adxl345.py`'s `write_to_file`): times from `t0` at `fs`.
pub fn klipper_raw_csv(axes: &[Vec<f64>; 3], t0: f64, fs: f64) -> String {
    let mut s = String::with_capacity(axes[0].len() * 48);
    s.push_str("#time,accel_x,accel_y,accel_z\n");
    for (i, [x, y, z]) in rows(axes) {
        let t = t0 + i as f64 / fs;
        s.push_str(&format!("{t:.6},{x:.6},{y:.6},{z:.6}\n"));
    }
    s
}

/// RepRapFirmware M956 CSV text (all three axes, g with 4 decimals, integer rate).
pub fn rrf_csv(axes: &[Vec<f64>; 3], rate_hz: u32) -> String {
    let mut s = String::from("Sample,X,Y,Z\n");
    for (i, [x, y, z]) in rows(axes) {
        let g = [x / G_MM_S2, y / G_MM_S2, z / G_MM_S2];
        s.push_str(&format!("{i},{:.4},{:.4},{:.4}\n", g[0], g[1], g[2]));
    }
    s.push_str(&format!("Rate {rate_hz}, overflows 0\n"));
    s
}

/// Shake&Tune `.stdata` bytes: one measurement, zstd-compressed JSON line.
pub fn stdata(name: &str, axes: &[Vec<f64>; 3], t0: f64, fs: f64) -> Vec<u8> {
    let mut line = format!("{{\"name\": \"{name}\", \"samples\": [");
    for (i, [x, y, z]) in rows(axes) {
        if i > 0 {
            line.push_str(", ");
        }
        line.push_str(&format!("[{}, {x}, {y}, {z}]", t0 + i as f64 / fs));
    }
    line.push_str("]}\n");
    zstd::stream::encode_all(line.as_bytes(), 3).expect("zstd")
}

/// The bench's recording: Klipper's default test (5-135 Hz at 1 Hz/s, 130 s) at 3,200 Hz
/// with 0.5 s of rest either side, two modes (42 Hz zeta 0.04 weight 0.75, 95 Hz zeta
/// 0.08 weight 0.25), sensor rotated: about 419,000 samples.
pub fn default_sweep_axes() -> [Vec<f64>; 3] {
    sweep_axes_at(3200.0)
}

/// The bench's recording sampled at `fs` (Hz) instead.
pub fn sweep_axes_at(fs: f64) -> [Vec<f64>; 3] {
    let test = settle_identify::SweepTest::klipper();
    let n = ((test.duration_s() + 1.0) * fs) as usize;
    let accel = toolhead_accel(
        &[(42.0, 0.04, 0.75), (95.0, 0.08, 0.25)],
        &test.pieces(),
        0.5,
        fs,
        n,
    );
    adxl345(&accel, [1.0, 0.0, 0.0], &rotation(30.0, 12.0, -8.0), fs, 21)
}
