//! Modes from a free decay: a sum of damped sinusoids fitted in the time domain.
//!
//! After the last change of the commanded acceleration the toolhead's acceleration along
//! the motion is `y(t) = c + sum_k e^{-zeta_k w_k t} (a_k cos w_dk t + b_k sin w_dk t)`
//! (`w_dk = w_k sqrt(1 - zeta_k^2)`; `c` absorbs what is left of gravity and offsets).
//! The fit is unbiased because it is this exact model fitted to the samples by least
//! squares (white sensor noise): no width or envelope is read. Start values come from the
//! matrix pencil ([`super::pencil`]) on the decay, with the linear amplitudes solved
//! by least squares for each start; Levenberg-Marquardt then refines
//! `(ln f_k, ln zeta_k, a_k, b_k, c)`. Model size by BIC as for the sweep fit.
//!
//! Where the free decay starts: the one-period moving average of the signal follows the
//! commanded acceleration (the oscillation averages out), so the decay starts one period
//! after the average last leaves [`MOVE_THRESHOLD`] of its largest magnitude; a record
//! whose average never stands out of the oscillation is taken to be a decay from its
//! largest sample on.

use nalgebra::{DMatrix, DVector};

use super::lm::{self, LmFit};
use super::{SIGNIFICANCE, bic, bic_prefers, correlation_inflation};
use crate::IdentifyError;
use crate::result::{Diagnostics, Estimate, IdentifiedMode, WeightBasis};
use crate::welch::Welch;

/// Fraction of the largest moving-average magnitude that counts as "the move is on".
pub const MOVE_THRESHOLD: f64 = 0.3;

/// Samples handed to the matrix pencil at most (decimated above this).
const PENCIL_SAMPLES: usize = 600;

/// Poles beyond `2 m + 1` given to the matrix pencil.
const PENCIL_EXTRA_POLES: usize = 6;

/// The least share of the window's variance the fitted decay must explain: a free decay
/// over sensor noise leaves a few per cent unexplained; a record that holds no decay (a
/// resonance sweep read without its test's options, whose forced oscillation goes on
/// after the "decay" the fit finds) leaves most of it.
pub const MIN_EXPLAINED: f64 = 0.5;

/// Samples fitted at most.
const MAX_FIT_SAMPLES: usize = 20_000;

/// What a ring-down fit returns.
#[derive(Debug, Clone)]
pub struct RingDownFit {
    /// The modes, lowest frequency first.
    pub modes: Vec<IdentifiedMode>,
    /// Fit quality.
    pub diagnostics: Diagnostics,
    /// First and one-past-last sample fitted.
    pub window: (usize, usize),
    /// The fitted curve over the window (mm/s^2).
    pub curve: Vec<f64>,
}

/// Fit the free decay in `s` (acceleration along the motion, mm/s^2, sampled at
/// `sample_rate_hz`) with up to `max_modes` modes.
pub fn fit(
    source: &str,
    s: &[f64],
    sample_rate_hz: f64,
    max_modes: usize,
) -> Result<RingDownFit, IdentifyError> {
    let fail = |reason: String| IdentifyError::NoRingDown {
        file: source.to_string(),
        reason,
    };
    let no_oscillation = || fail("no oscillation above 5 Hz in the recording".into());
    // The move's own spectrum falls with frequency: weigh by f to find the ringing, then
    // look again at the decay alone.
    let mut f_dom = dominant_frequency(s, sample_rate_hz, 1).ok_or_else(no_oscillation)?;
    let mut period = ((sample_rate_hz / f_dom).round() as usize).max(2);
    let mut start = decay_start(s, period);
    if let Some(f) = dominant_frequency(&s[start.min(s.len())..], sample_rate_hz, 0) {
        f_dom = f;
        period = ((sample_rate_hz / f_dom).round() as usize).max(2);
        start = decay_start(s, period);
    }
    let end = s.len().min(start + MAX_FIT_SAMPLES);
    if end - start < 4 * period || end - start < 40 {
        return Err(fail(format!(
            "the free decay after the move holds {} samples; at least {} (four periods of the {f_dom:.1} Hz oscillation) are needed",
            end - start,
            (4 * period).max(40)
        )));
    }
    let y = &s[start..end];
    let dt = 1.0 / sample_rate_hz;
    let q = (y.len() / PENCIL_SAMPLES)
        .max(1)
        .min(((sample_rate_hz / (8.0 * f_dom)).floor() as usize).max(1));
    // The start of the decay, where it stands out of the noise most: the pencil's SVD
    // costs the cube of its length (the whole of a 5,200-sample record at 800 Hz, where
    // the oscillation allows no decimation, took 20 s).
    let decimated: Vec<f64> = y.iter().step_by(q).take(PENCIL_SAMPLES).copied().collect();
    let nyquist = 0.45 * sample_rate_hz / q as f64;
    let mut best: Option<(LmFit, f64)> = None;
    let mut candidates = Vec::new();
    for m in 1..=max_modes.max(1) {
        // Extra poles take up the noise, so the m strongest oscillations are the modes.
        let order = 2 * m + 1 + PENCIL_EXTRA_POLES;
        let Some(found) = super::pencil::fit(&decimated, dt * q as f64, order) else {
            break;
        };
        let mut nonlinear: Vec<(f64, f64)> = found
            .iter()
            .filter(|p| {
                p.frequency_hz > 2.0
                    && p.frequency_hz < nyquist
                    && p.damping_ratio > 0.0
                    && p.damping_ratio < 0.9
            })
            .take(m)
            .map(|p| (p.frequency_hz, p.damping_ratio))
            .collect();
        if nonlinear.len() < m {
            break;
        }
        nonlinear.sort_by(|a, b| a.0.total_cmp(&b.0));
        let Some(linear) = solve_linear(y, dt, &nonlinear) else {
            break;
        };
        let mut theta = Vec::with_capacity(4 * m + 1);
        for (k, &(f, z)) in nonlinear.iter().enumerate() {
            theta.extend([f.ln(), z.ln(), linear[2 * k], linear[2 * k + 1]]);
        }
        theta.push(linear[2 * m]);
        let Some(fit) = lm::minimise(|t| residuals(y, dt, t), &theta, 200) else {
            break;
        };
        let c = correlation_inflation(&fit.residuals);
        let score = bic(fit.rss, y.len(), fit.theta.len(), c);
        candidates.push((m, score));
        let accept = match &best {
            None => true,
            Some((prev, _)) => bic_prefers(&fit, prev, y.len(), c) && significant(&fit, c),
        };
        if !accept {
            break;
        }
        best = Some((fit, score));
    }
    let Some((fit, _)) = best else {
        return Err(fail(format!(
            "no damped oscillation could be fitted to the decay after sample {start}"
        )));
    };
    let c = correlation_inflation(&fit.residuals);
    // Without finite uncertainties the fit has not converged to a decay: no answer.
    let Some(sig) = fit
        .sigmas(c)
        .filter(|s| s.iter().chain(&fit.theta).all(|v| v.is_finite()))
    else {
        return Err(fail(format!(
            "the fit of a free decay after sample {start} did not converge (its uncertainties are not finite): the recording holds no clean decay; a resonance test's recording needs the test's --freq-start, --freq-end and --hz-per-sec"
        )));
    };
    let m = fit.theta.len() / 4;
    let mut modes: Vec<IdentifiedMode> = (0..m)
        .map(|k| {
            let at = |i: usize| {
                let v = fit.theta[4 * k + i].exp();
                Estimate {
                    value: v,
                    sigma: v * sig[4 * k + i],
                }
            };
            let (weight, weight_basis) = if m == 1 {
                (
                    Some(Estimate {
                        value: 1.0,
                        sigma: 0.0,
                    }),
                    WeightBasis::AssumedSingleMode,
                )
            } else {
                (None, WeightBasis::NotIdentified)
            };
            let (f, z) = (at(0), at(1));
            IdentifiedMode {
                frequency_hz: f,
                damping_ratio: z,
                weight,
                weight_basis,
                peak_hz: f.value * (1.0 - z.value * z.value).max(0.0).sqrt(),
            }
        })
        .collect();
    modes.sort_by(|a, b| a.frequency_hz.value.total_cmp(&b.frequency_hz.value));
    let n = y.len();
    let mean = y.iter().sum::<f64>() / n as f64;
    let total: f64 = y.iter().map(|v| (v - mean).powi(2)).sum();
    let explained = 1.0 - fit.rss / total;
    if explained.is_nan() || explained < MIN_EXPLAINED {
        return Err(fail(format!(
            "the damped oscillations fitted after sample {start} explain {:.0} % of the signal there (at least {:.0} % for a free decay): the recording holds no clean decay; a resonance test's recording needs the test's --freq-start, --freq-end and --hz-per-sec",
            100.0 * explained.max(0.0),
            100.0 * MIN_EXPLAINED
        )));
    }
    let curve: Vec<f64> = y.iter().zip(&fit.residuals).map(|(v, r)| v - r).collect();
    let rms = (fit.rss / n as f64).sqrt();
    Ok(RingDownFit {
        modes,
        diagnostics: Diagnostics {
            noise_floor: fit.residual_variance().sqrt(),
            residual_rms: rms,
            residual_correlation: c,
            points: n,
            candidates,
            span: (start as f64 * dt, end as f64 * dt),
            rejected: Vec::new(),
            converged: fit.converged,
        },
        window: (start, end),
        curve,
    })
}

/// The frequency (Hz) of the largest peak above 5 Hz of the periodogram times
/// `f^power`.
fn dominant_frequency(s: &[f64], fs: f64, power: i32) -> Option<f64> {
    let n = s.len() & !1;
    if n < 16 {
        return None;
    }
    let welch = Welch::new(fs, n);
    let p = welch.psd(&s[..n])?;
    let lo = (5.0 / welch.bin_hz()).ceil() as usize;
    let hi = ((0.45 * fs) / welch.bin_hz()) as usize;
    let weighted = |k: usize| p[k] * (k as f64).powi(power);
    let k = (lo..hi.min(p.len())).max_by(|&a, &b| weighted(a).total_cmp(&weighted(b)))?;
    (p[k] > 0.0).then(|| k as f64 * welch.bin_hz())
}

/// Index where the free decay starts (see the module notes).
fn decay_start(s: &[f64], period: usize) -> usize {
    let n = s.len();
    let mut prefix = Vec::with_capacity(n + 1);
    prefix.push(0.0);
    for v in s {
        prefix.push(prefix[prefix.len() - 1] + v);
    }
    let half = period / 2;
    let avg: Vec<f64> = (0..n)
        .map(|i| {
            let a = i.saturating_sub(half);
            let b = (i + half + 1).min(n);
            (prefix[b] - prefix[a]) / (b - a) as f64
        })
        .collect();
    let peak_avg = avg.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let peak = s.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let largest = s
        .iter()
        .enumerate()
        .fold(0, |b, (i, v)| if v.abs() > s[b].abs() { i } else { b });
    if peak_avg < 0.15 * peak {
        return largest;
    }
    let last_on = (0..n)
        .rev()
        .find(|&i| avg[i].abs() > MOVE_THRESHOLD * peak_avg)
        .unwrap_or(0);
    (last_on + period).min(n)
}

/// Least-squares amplitudes `(a_k, b_k)..., c` for given `(f, zeta)` pairs.
fn solve_linear(y: &[f64], dt: f64, nonlinear: &[(f64, f64)]) -> Option<Vec<f64>> {
    let m = nonlinear.len();
    let basis = DMatrix::from_fn(y.len(), 2 * m + 1, |i, j| {
        if j == 2 * m {
            return 1.0;
        }
        let (f, z) = nonlinear[j / 2];
        let w = std::f64::consts::TAU * f;
        let t = i as f64 * dt;
        let env = (-z * w * t).exp();
        let ph = w * (1.0 - z * z).sqrt() * t;
        env * if j % 2 == 0 { ph.cos() } else { ph.sin() }
    });
    let sol = basis
        .svd(true, true)
        .solve(&DVector::from_column_slice(y), 1e-12)
        .ok()?;
    Some(sol.iter().copied().collect())
}

/// Data minus model for `theta = ((ln f, ln zeta, a, b)..., c)`.
fn residuals(y: &[f64], dt: f64, theta: &[f64]) -> Option<Vec<f64>> {
    let m = theta.len() / 4;
    let c = theta[4 * m];
    let mut r: Vec<f64> = y.iter().map(|v| v - c).collect();
    for k in 0..m {
        let f = theta[4 * k].exp();
        let z = theta[4 * k + 1].exp();
        if !(z < 0.95 && f.is_finite()) {
            return None;
        }
        let (a, b) = (theta[4 * k + 2], theta[4 * k + 3]);
        let w = std::f64::consts::TAU * f;
        let wd = w * (1.0 - z * z).sqrt();
        // Rotate a phasor sample by sample: e^{(-zeta w + i wd) dt}.
        let step = nalgebra::Complex::from_polar((-z * w * dt).exp(), wd * dt);
        let mut p = nalgebra::Complex::new(1.0, 0.0);
        for ri in r.iter_mut() {
            *ri -= a * p.re + b * p.im;
            p *= step;
        }
    }
    r.iter().all(|v| v.is_finite()).then_some(r)
}

/// Every mode clearly present: amplitude and damping at least [`SIGNIFICANCE`] sigmas.
fn significant(fit: &LmFit, c: f64) -> bool {
    let Some(sig) = fit.sigmas(c) else {
        return false;
    };
    (0..fit.theta.len() / 4).all(|k| {
        let (a, b) = (fit.theta[4 * k + 2], fit.theta[4 * k + 3]);
        let amp = a.hypot(b);
        let sig_amp = sig[4 * k + 2].hypot(sig[4 * k + 3]);
        amp > SIGNIFICANCE * sig_amp && sig[4 * k + 1] * SIGNIFICANCE < 1.0
    })
}
