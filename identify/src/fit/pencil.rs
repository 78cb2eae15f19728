//! Measuring modes from a free response: the matrix pencil method.
//!
//! A free decay sampled every `dt` is a sum of damped exponentials
//! `y[n] = sum_k a_k z_k^n` with `z_k = e^{lambda_k dt}`. The Hankel matrix of the samples
//! has rank equal to the number of exponentials; the shift between its first and last
//! rows (the "pencil") has the `z_k` as eigenvalues (Hua & Sarkar, 1990). The ring-down
//! fit ([`super::ringdown`]) starts from it; `settle validate` uses it to measure what a
//! simulation backend actually simulated (including its integrator's frequency and
//! damping errors) without knowing the model, against the analytic eigenvalues.

use nalgebra::{Complex, DMatrix, DVector};

type C = Complex<f64>;

/// The largest `|ln |z||` of a pole (its decay or growth per sample, in nepers) the fit
/// reports: e^700 is 1e304, the edge of `f64`; a pole beyond it is an eigenvalue without
/// bound, not a mode.
const MAX_LOG_STEP: f64 = 700.0;

/// One measured mode.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeasuredMode {
    /// Natural frequency `|lambda| / 2 pi` (Hz).
    pub frequency_hz: f64,
    /// Damping ratio `-Re lambda / |lambda|`.
    pub damping_ratio: f64,
    /// Amplitude at the first sample (signal units): `2 |a_k|` for an oscillatory pair.
    pub amplitude: f64,
}

/// Fit `order` damped exponentials to `y` (sampled every `dt_s`) and return the modes,
/// strongest first (conjugate pairs merged). `y` should hold a few hundred samples at
/// least 4 per period of the fastest mode; `order` is the number of poles (2 per
/// oscillatory mode). `None` if the fit fails (too few samples, NaN) or does not converge
/// to a physical answer: a pole at zero or not finite (an unbounded eigenvalue: a decay
/// rate or frequency without limit), or a mode whose frequency, damping ratio or
/// amplitude is not a finite number.
pub fn fit(y: &[f64], dt_s: f64, order: usize) -> Option<Vec<MeasuredMode>> {
    let n = y.len();
    if order == 0 || n < 3 * order + 3 || y.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let l = n / 2;
    let rows = n - l;
    let hankel = DMatrix::from_fn(rows, l + 1, |i, j| y[i + j]);
    let svd = hankel.svd(false, true);
    let vt = svd.v_t?;
    // Right singular vectors of the `order` largest singular values (nalgebra sorts them
    // in decreasing order), as columns: (l + 1) x order.
    let mut idx: Vec<usize> = (0..svd.singular_values.len()).collect();
    idx.sort_by(|&a, &b| svd.singular_values[b].total_cmp(&svd.singular_values[a]));
    let m = order.min(idx.len());
    let v = DMatrix::from_fn(l + 1, m, |i, k| vt[(idx[k], i)]);
    let v1 = v.rows(0, l).into_owned();
    let v2 = v.rows(1, l).into_owned();
    // Least squares: v1 X = v2.
    let x = (v1.transpose() * &v1).lu().solve(&(v1.transpose() * &v2))?;
    let z: Vec<C> = x.complex_eigenvalues().iter().copied().collect();
    // `ln z` is unbounded at zero and undefined off the finite plane, and a pole that
    // decays or grows by more than e^700 (1e304) in one sample has left the range of the
    // arithmetic: no mode to report.
    if z.iter().any(|z| {
        let r = z.norm();
        !(z.re.is_finite() && z.im.is_finite() && r > 0.0 && r.ln().abs() <= MAX_LOG_STEP)
    }) {
        return None;
    }
    // Amplitudes: y[k] = sum a_j z_j^k, complex least squares (QR).
    let vand = DMatrix::from_fn(n, m, |k, j| z[j].powu(k as u32));
    let yc = DVector::from_iterator(n, y.iter().map(|&v| C::new(v, 0.0)));
    let qr = vand.qr();
    let rhs = qr.q().adjoint() * yc;
    let a = qr.r().solve_upper_triangular(&rhs)?;
    let mut out: Vec<MeasuredMode> = z
        .iter()
        .zip(a.iter())
        .filter(|(z, _)| z.im >= 0.0)
        .map(|(z, a)| {
            let lambda = z.ln() / dt_s;
            let w = lambda.norm();
            MeasuredMode {
                frequency_hz: w / std::f64::consts::TAU,
                damping_ratio: -lambda.re / w.max(f64::MIN_POSITIVE),
                amplitude: if z.im > 0.0 { 2.0 * a.norm() } else { a.norm() },
            }
        })
        .collect();
    if out.iter().any(|m| {
        !(m.frequency_hz.is_finite() && m.damping_ratio.is_finite() && m.amplitude.is_finite())
    }) {
        return None;
    }
    out.sort_by(|p, q| q.amplitude.total_cmp(&p.amplitude));
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    #[test]
    fn recovers_two_damped_modes() {
        let dt = 5e-4;
        let modes = [(43.0, 0.05, 1e-4, 0.3), (240.0, 0.02, 2e-5, 1.1)];
        let y: Vec<f64> = (0..400)
            .map(|k| {
                let t = k as f64 * dt;
                modes
                    .iter()
                    .map(|&(f, z, a, ph)| {
                        let w = TAU * f;
                        let wd = w * (1.0f64 - z * z).sqrt();
                        a * (-z * w * t).exp() * (wd * t + ph).cos()
                    })
                    .sum()
            })
            .collect();
        let got = fit(&y, dt, 4).expect("fit");
        for (m, &(f, z, a, _)) in got.iter().zip(&modes) {
            assert!((m.frequency_hz - f).abs() < 1e-8 * f, "{m:?}");
            assert!((m.damping_ratio - z).abs() < 1e-8, "{m:?}");
            assert!((m.amplitude - a).abs() < 1e-7 * a, "{m:?}");
        }
    }

    /// A lone impulse (one sample, then silence) is a decay infinitely fast: the pencil's
    /// eigenvalue is exactly zero, whose logarithm has no bound. The fit is refused rather
    /// than reported as a mode of infinite frequency and undefined damping.
    #[test]
    fn an_unbounded_eigenvalue_is_refused() {
        let mut y = vec![0.0; 64];
        y[0] = 1.0;
        assert_eq!(fit(&y, 1e-3, 1), None);
        // A decay by 1e-305 in one sample: a finite pole, but no mode.
        let mut fast = y.clone();
        fast[1] = 1e-305;
        assert_eq!(fit(&fast, 1e-3, 1), None, "{:?}", fit(&fast, 1e-3, 1));
    }
}
