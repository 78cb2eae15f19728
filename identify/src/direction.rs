//! Which direction of the sensor carries the excited motion.
//!
//! Sensors are mounted rotated (and Klipper's `axes_map` may or may not be set right), so
//! the motion of a test along the printer's X can show on any sensor axis or a mix of
//! them. Gravity and sensor offsets are constant: they are the recording's mean, removed
//! before anything else (each Welch segment also removes its own mean, as Klipper does).
//! The direction is the principal axis of the in-band cross-spectral matrix
//! `C_ab = sum_{f in band} Re S_ab(f)`: the unit vector `d` that maximises the in-band
//! power `d^T C d` of the projected signal `d . a(t)`. Its share `lambda_1 / trace C` says
//! how much of the in-band motion lies along it (1 = a single straight line).

use nalgebra::{Matrix3, SymmetricEigen};

/// The motion direction found in a recording.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Direction {
    /// Unit vector in the sensor frame (x, y, z); its largest component is positive.
    pub vector: [f64; 3],
    /// Share of the in-band power along `vector` (0 to 1).
    pub share: f64,
    /// The sensor axis nearest to `vector` (0 = x, 1 = y, 2 = z).
    pub nearest_axis: usize,
    /// Angle between `vector` and that axis (degrees).
    pub angle_to_axis_deg: f64,
    /// The mean acceleration removed (mm/s^2): gravity plus offsets, in the sensor frame
    /// (0 for axes the file does not hold).
    pub mean_mm_s2: [f64; 3],
}

impl Direction {
    /// A name such as `x`, `-y` or `0.71x + 0.71y` for messages and reports.
    pub fn describe(&self) -> String {
        let names = ["x", "y", "z"];
        if self.angle_to_axis_deg < 5.0 {
            return names[self.nearest_axis].to_string();
        }
        let mut parts = Vec::new();
        for (k, &c) in self.vector.iter().enumerate() {
            if c.abs() >= 0.05 {
                parts.push(format!("{c:+.2}{}", names[k]));
            }
        }
        parts.join(" ").trim_start_matches('+').to_string()
    }
}

/// The direction from the packed cross spectra of the present sensor axes `axes`
/// (see [`crate::welch::Welch::cross`]) summed over the bins `lo..hi`, and the channel means.
pub fn principal(
    cross: &[Vec<f64>],
    axes: &[usize],
    lo: usize,
    hi: usize,
    means: [f64; 3],
) -> Direction {
    let m = axes.len();
    let mut c = Matrix3::<f64>::zeros();
    let mut p = 0;
    for a in 0..m {
        for b in a..m {
            let s: f64 = cross[p][lo..hi].iter().sum();
            c[(axes[a], axes[b])] = s;
            c[(axes[b], axes[a])] = s;
            p += 1;
        }
    }
    let eig = SymmetricEigen::new(c);
    let mut best = 0;
    for k in 1..3 {
        if eig.eigenvalues[k] > eig.eigenvalues[best] {
            best = k;
        }
    }
    let v = eig.eigenvectors.column(best);
    let mut vector = [v[0], v[1], v[2]];
    let mut nearest_axis = 0;
    for k in 1..3 {
        if vector[k].abs() > vector[nearest_axis].abs() {
            nearest_axis = k;
        }
    }
    if vector[nearest_axis] < 0.0 {
        vector.iter_mut().for_each(|x| *x = -*x);
    }
    let trace = c.trace();
    Direction {
        vector,
        share: if trace > 0.0 {
            eig.eigenvalues[best] / trace
        } else {
            0.0
        },
        nearest_axis,
        angle_to_axis_deg: vector[nearest_axis].clamp(-1.0, 1.0).acos().to_degrees(),
        mean_mm_s2: means,
    }
}

/// Project the packed cross spectra of `axes` onto the direction: the PSD of `d . a(t)`.
pub fn project(cross: &[Vec<f64>], axes: &[usize], d: &[f64; 3]) -> Vec<f64> {
    let m = axes.len();
    let bins = cross[0].len();
    let mut out = vec![0.0; bins];
    let mut p = 0;
    for a in 0..m {
        for b in a..m {
            let w = d[axes[a]] * d[axes[b]] * if a == b { 1.0 } else { 2.0 };
            for (o, s) in out.iter_mut().zip(&cross[p]) {
                *o += w * s;
            }
            p += 1;
        }
    }
    out
}
