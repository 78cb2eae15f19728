//! Modes from a resonance sweep: the Welch PSD fitted with the modal model.
//!
//! The measured PSD `P` is compared with the expected PSD `M(theta)`
//! ([`super::sweep_model`]) on a log scale, weighted by the inverse of each bin's variance
//! ([`super::sweep_residual`]); the fit is Levenberg-Marquardt.
//!
//! Why the damping comes out unbiased: the half-power method reads zeta from the width
//! of the peak, `2 zeta f` between the points where the *power* `|T|^2` falls to half its
//! peak. Taking a power spectrum's width at `1/sqrt 2` of its peak (the amplitude rule)
//! measures `|T|^2 = max / sqrt 2`, a width of `2 * 0.644 zeta f` for a lightly damped
//! mode: 36 % low. The window's smoothing then widens a peak narrower than a few bins, and
//! a second mode or the sweep's rising input tilts it. No width is read here: the model's
//! `|T|^2` is the exact power response of the modal model, times the exact energy
//! spectrum of the test's own command, smoothed by the same kernel as the data, so the
//! fitted parameters are those of the structure. On the simulated random sweeps of
//! `tests/identify/sweep.rs` (`IDENTIFY_SWEEP_CASES=32`: zeta 0.02-0.2, modes 25-128 Hz,
//! one or two modes) the relative errors average `-1e-5` (frequency), `+5e-5` (damping)
//! and `+1.8e-4` (weight) with spreads of `8e-5`, `7.5e-4` and `7.7e-4`.
//!
//! Uncertainties. The residuals are neither independent nor of one variance: the window
//! correlates neighbouring bins (0.47 between adjacent bins at Klipper's Kaiser window and
//! a quarter-segment hop), overlapping segments correlate the estimate in time, and where
//! the spectrum is peaked within the window's kernel (a lightly damped mode) the cross
//! term of the response with the noise adds coherently across overlapping segments.
//! [`super::sweep_model::SweepModel::psd_covariance`] derives the covariance of the PSD
//! between bins from the window and the hop (checked against 200 noise draws in
//! `tests/identify/statistics.rs`: the whitened deviations have a chi-square of 77.0 for 77
//! bins); the parameters' covariance is the sandwich of the least-squares fit with it,
//! scaled by its generalised chi-square (the private `covariance` below). On the random sweeps above,
//! `(estimate - truth) / sigma` then has a spread of 1.05 (frequency), 1.11 (damping) and
//! 1.23 (weight), and the 2-sigma intervals cover the truth for 47, 45 and 45 of the 48
//! modes (a normal error would give 45.8 +- 1.4). The former covariance, `s^2 (J^T J)^-1`
//! inflated by the residuals' own correlation `c`, gave spreads of 1.23, 1.22 and 1.41
//! (44, 43 and 39 of 48 covered): `c` measured from residuals the fit has already
//! smoothed undercounts the bins' correlation, and a common inflation is exact only for
//! parameters whose derivative is smooth over the correlation length, which a mode's
//! frequency and damping at a narrow peak are not.
//!
//! Procedure. The bins are first weighted by the measured PSD itself (the weights' limit
//! where the sweep dominates the noise); the first mode starts at the largest response
//! (PSD over the excitation) with three damping guesses. Each further mode starts from
//! the previous fit plus a mode at the largest excess of the data over it, from the
//! previous fit plus a mode at each of the highest local maxima of the response it does
//! not yet hold, and from the largest peaks of the response (each with its own width and
//! height), and the best start wins: broad overlapping modes mislead a one-mode fit,
//! whose solution is then no starting point for two, and a broad mode fitted across a
//! peak and its shoulder stands over the shoulder, leaving no excess there
//! (`identify/tests/corpus/metis_resonances_20240206_200335_Y.csv`, peaks at 43 and 55
//! Hz: one mode at 57.4 Hz, zeta 0.20, without these starts; 43.9 and 53.8 Hz with
//! them). A mode is kept while the Bayesian information criterion (with the residuals'
//! correlation counted: `n_eff = n / c`) drops by at least
//! [`super::BIC_MARGIN`] and every mode stays significant (weight and damping at least
//! [`super::SIGNIFICANCE`] standard deviations from 0, frequencies a bin apart). The
//! chosen model is refitted with the weights of its own expected PSD and noise floor; the
//! uncertainties are that fit's sandwich covariance (see the notes on uncertainties).

use nalgebra::{DMatrix, DVector};

use super::lm::{self, LmFit};
use super::sweep_model::SweepModel;
use super::sweep_residual::SweepResidual;
use super::{FittedSpectrum, main_peak, rejected};
use super::{SIGNIFICANCE, bic, bic_prefers};
use crate::IdentifyError;
use crate::excitation::SweepTest;
use crate::result::{Diagnostics, Estimate, IdentifiedMode, WeightBasis, response_peak_hz};
use crate::welch::Welch;

/// Largest PSD in the band over the noise floor (its 5th percentile) must reach this.
pub const MIN_PEAK_TO_FLOOR: f64 = 10.0;

/// The response (PSD over the excitation) must peak at least this far over its median.
pub const MIN_PROMINENCE: f64 = 2.0;

/// Bins left out at each end of the sweep band: the kernel's main lobe is +-2.2 bins, so
/// from 3 bins in every fitted bin sees only frequencies the test swept.
const EDGE_BINS: f64 = 3.0;

/// A second peak of the response counts as a peak of its own when the response dips
/// below this fraction of its height between it and every higher one.
const PEAK_DIP: f64 = 0.7;

/// Places of the largest excess of the data over the smaller model that a further mode
/// starts from.
const EXCESS_STARTS: usize = 3;

/// Iterations per Levenberg-Marquardt run.
const MAX_ITERATIONS: usize = 200;

/// What a sweep fit returns.
#[derive(Debug, Clone)]
pub struct SweepFit {
    /// The modes, lowest frequency first.
    pub modes: Vec<IdentifiedMode>,
    /// Fit quality.
    pub diagnostics: Diagnostics,
    /// The fitted bins (indices into the spectrum).
    pub bins: Vec<usize>,
    /// The model per fitted bin, in the units of the recording's PSD (before any stored
    /// normalisation).
    pub model: Vec<f64>,
    /// Each mode's share, in the order of [`SweepFit::modes`]: the model with that mode
    /// alone (the same gain and noise floor), per fitted bin.
    pub components: Vec<Vec<f64>>,
    /// Fitted gain `G` and noise floor `N` ((mm/s^2)^2/Hz).
    pub gain_and_noise: (f64, f64),
}

/// Fit the PSD `psd` (per bin of `welch`, stored units) whose stored values are
/// `factor` x the recording's PSD (1 for raw data; 0 where the file holds nothing),
/// measured under `test`, with up to `max_modes` modes; `digits`: the significant digits
/// a file kept of each value (its rounding is part of the uncertainty), `None` for a PSD
/// computed here.
pub fn fit(
    source: &str,
    welch: &Welch,
    psd: &[f64],
    factor: &[f64],
    test: &SweepTest,
    max_modes: usize,
    digits: Option<i32>,
) -> Result<SweepFit, IdentifyError> {
    let bin = welch.bin_hz();
    let lo_hz = test.freq_start_hz.max(5.0) + EDGE_BINS * bin;
    let hi_hz = (test.freq_end_hz - EDGE_BINS * bin).min(0.45 * welch.sample_rate_hz());
    let bins: Vec<usize> = (0..psd.len().min(factor.len()))
        .filter(|&k| {
            let f = k as f64 * bin;
            f >= lo_hz && f <= hi_hz && psd[k] > 0.0 && factor[k] > 0.0
        })
        .collect();
    let needed = 8 + 3 * max_modes.max(1) + 2;
    if bins.len() < needed {
        return Err(IdentifyError::TooFewSamples {
            file: source.to_string(),
            line: 0,
            what: "frequency bins inside the sweep band",
            found: bins.len(),
            needed,
        });
    }
    let n = bins.len();
    let y: Vec<f64> = bins.iter().map(|&k| psd[k] / factor[k]).collect();
    let freq: Vec<f64> = bins.iter().map(|&k| k as f64 * bin).collect();
    let model = SweepModel::new(welch, &bins, test);
    let exc = model.excitation();
    let no_peak = |measure, ratio, needed| IdentifyError::NoPeak {
        file: source.to_string(),
        band_lo_hz: lo_hz,
        band_hi_hz: hi_hz,
        measure,
        ratio,
        needed,
    };
    let floor = percentile(&y, 0.05);
    let peak_to_floor = y.iter().copied().fold(0.0, f64::max) / floor;
    if peak_to_floor.is_nan() || peak_to_floor < MIN_PEAK_TO_FLOOR {
        return Err(no_peak(
            "largest PSD / noise floor",
            peak_to_floor,
            MIN_PEAK_TO_FLOOR,
        ));
    }
    let response: Vec<f64> = y.iter().zip(&exc).map(|(a, e)| a / e).collect();
    let peaks = response_peaks(&response, &freq);
    let maxima = response_maxima(&response);
    let median = percentile(&response, 0.5);
    let top = peaks.first().map_or(0.0, |p| response[p.index]);
    if top.is_nan() || top < MIN_PROMINENCE * median {
        return Err(no_peak(
            "largest response / median response",
            top / median,
            MIN_PROMINENCE,
        ));
    }
    // Gain from the response well below the first peak, where |T| is close to 1.
    let first = peaks.first().map_or(0, |p| p.index);
    let below: Vec<f64> = (0..first)
        .filter(|&j| freq[j] < 0.5 * freq[first])
        .map(|j| response[j])
        .collect();
    let gain0 = if below.len() >= 3 {
        percentile(&below, 0.5)
    } else {
        percentile(&response, 0.25)
    };
    let start_mode = |p: &Peak, zeta: f64| {
        let height = (response[p.index] / gain0).max(1.0);
        let weight = (2.0 * zeta * height.sqrt()).clamp(0.01, 2.0);
        [freq[p.index].ln(), zeta.ln(), weight.ln()]
    };
    let mut residual = SweepResidual::new(&model, &y, floor, (freq[0], freq[n - 1]));
    // Search weights: the measured PSD's own (see the module notes).
    residual.set_weights(&y, 0.0);
    let run = |residual: &SweepResidual, starts: &[Vec<f64>]| {
        starts
            .iter()
            .filter_map(|t| lm::minimise(|t| residual.residuals(t), t, MAX_ITERATIONS))
            .min_by(|a, b| a.rss.total_cmp(&b.rss))
    };
    let bin_correlation = welch.bin_correlation();
    let mut best: Option<(LmFit, f64)> = None;
    let mut candidates = Vec::new();
    let mut refused = Vec::new();
    for m in 1..=max_modes.max(1) {
        let mut starts = Vec::new();
        match &best {
            None => {
                let p = &peaks[0];
                for zeta in [p.zeta, 0.05, 0.15] {
                    let mut t = vec![gain0.ln(), 0.0];
                    t.extend(start_mode(p, zeta));
                    starts.push(t);
                }
            }
            Some((prev, _)) => {
                let excesses = largest_excesses(prev, &freq, bin, EXCESS_STARTS);
                let shoulders = unfitted_maxima(&maxima, prev, &freq, bin, EXCESS_STARTS);
                for (rank, j) in excesses.into_iter().chain(shoulders).enumerate() {
                    let mut t = prev.theta.clone();
                    t.extend([freq[j].ln(), 0.05f64.ln(), 0.2f64.ln()]);
                    if rank == 0 {
                        // A broad mode fitted across two peaks is no start for two sharp
                        // ones: the same start with the fitted modes' damping halved.
                        let mut sharp = t.clone();
                        for k in 0..m - 1 {
                            sharp[2 + 3 * k + 1] -= std::f64::consts::LN_2;
                        }
                        starts.push(sharp);
                    }
                    starts.push(t);
                }
                if peaks.len() >= m {
                    let mut t = vec![gain0.ln(), 0.0];
                    for p in &peaks[..m] {
                        t.extend(start_mode(p, p.zeta));
                    }
                    starts.push(t);
                }
            }
        }
        let Some(fit) = run(&residual, &starts) else {
            break;
        };
        let c = bin_correlation;
        let score = bic(fit.rss, n, fit.theta.len(), c);
        candidates.push((m, score));
        let accept = match &best {
            None => true,
            Some((prev, prev_score)) => {
                let preferred = bic_prefers(&fit, prev, n, c);
                let accept = preferred && significant(&fit, c, bin);
                if !accept {
                    refused.push(rejected::refused_candidate(
                        &fit,
                        prev,
                        score,
                        *prev_score,
                        preferred,
                    ));
                }
                accept
            }
        };
        if !accept {
            break;
        }
        best = Some((fit, score));
    }
    let Some((searched, _)) = best else {
        return Err(no_peak("fitted modes", 0.0, 1.0));
    };
    // Refit with the chosen model's own weights.
    let (_, noise) = residual.gain_and_noise(&searched.theta);
    residual.set_weights(&residual.expected(&searched.theta), noise);
    let fit = run(&residual, std::slice::from_ref(&searched.theta)).unwrap_or(searched);
    let c = bin_correlation;
    // A file's rounding: uniform over one unit of the last digit kept, a variance of
    // `unit^2 / 12`, independent from bin to bin, relative to the value for `ln P`.
    let rounding: Vec<f64> = match digits {
        None => vec![0.0; n],
        Some(d) => bins
            .iter()
            .map(|&k| {
                let v = psd[k].abs();
                let unit = 10f64.powi(v.log10().floor() as i32 - (d - 1));
                (unit / v).powi(2) / 12.0
            })
            .collect(),
    };
    let sig = covariance(&fit, &residual, &model, &rounding)
        .map(|v| (0..v.nrows()).map(|i| v[(i, i)].max(0.0).sqrt()).collect())
        .unwrap_or_else(|| vec![f64::NAN; fit.theta.len()]);
    let mut modes: Vec<IdentifiedMode> = (0..(fit.theta.len() - 2) / 3)
        .map(|k| {
            let at = |i: usize| {
                let value = fit.theta[2 + 3 * k + i].exp();
                Estimate {
                    value,
                    sigma: value * sig[2 + 3 * k + i],
                }
            };
            let (f, z, w) = (at(0), at(1), at(2));
            IdentifiedMode {
                frequency_hz: f,
                damping_ratio: z,
                weight: Some(w),
                weight_basis: WeightBasis::Fitted,
                peak_hz: response_peak_hz(f.value, z.value, w.value),
            }
        })
        .collect();
    let mut components: Vec<(f64, Vec<f64>)> = (0..modes.len())
        .map(|k| {
            let mut theta = fit.theta[..2].to_vec();
            theta.extend_from_slice(&fit.theta[2 + 3 * k..5 + 3 * k]);
            (modes[k].frequency_hz.value, residual.expected(&theta))
        })
        .collect();
    components.sort_by(|a, b| a.0.total_cmp(&b.0));
    let components = components.into_iter().map(|c| c.1).collect();
    modes.sort_by(|a, b| a.frequency_hz.value.total_cmp(&b.frequency_hz.value));
    let curve = residual.expected(&fit.theta);
    let (gain, noise) = residual.gain_and_noise(&fit.theta);
    let fitted = FittedSpectrum {
        data: &y,
        model: &curve,
        noise,
        freq: &freq,
        bin,
    };
    main_peak::check(source, fitted)?;
    let taken: Vec<f64> = modes
        .iter()
        .flat_map(|m| [m.frequency_hz.value, m.peak_hz])
        .collect();
    let limit = (refused.is_empty() && modes.len() == max_modes).then_some(max_modes);
    let refused = rejected::bumps(fitted, &taken, &refused, limit);
    let rms = (y
        .iter()
        .zip(&curve)
        .map(|(a, b)| (a / b).ln().powi(2))
        .sum::<f64>()
        / n as f64)
        .sqrt();
    Ok(SweepFit {
        modes,
        diagnostics: Diagnostics {
            noise_floor: noise,
            residual_rms: rms,
            residual_correlation: c,
            points: n,
            candidates,
            span: (freq[0], freq[n - 1]),
            rejected: refused,
            converged: fit.converged,
        },
        bins,
        model: curve,
        components,
        gain_and_noise: (gain, noise),
    })
}

/// A local maximum of the response and the damping ratio its half-power width gives.
#[derive(Debug, Clone, Copy)]
struct Peak {
    index: usize,
    zeta: f64,
}

/// The response's peaks, highest first: local maxima (over +-2 bins) above the median
/// response, each separated from every higher one by a dip below [`PEAK_DIP`] of its own
/// height, with the damping ratio `(f_hi - f_lo) / (2 f)` from where the response falls to
/// half its height above the median on either side (clamped to 0.01..0.3: a starting
/// value only).
fn response_peaks(response: &[f64], freq: &[f64]) -> Vec<Peak> {
    let n = response.len();
    let base = percentile(response, 0.5);
    let mut peaks: Vec<Peak> = Vec::new();
    for j in response_maxima(response) {
        let separate = peaks.iter().all(|p| {
            let (lo, hi) = (p.index.min(j), p.index.max(j));
            let dip = response[lo..=hi]
                .iter()
                .copied()
                .fold(f64::INFINITY, f64::min);
            dip < PEAK_DIP * response[j]
        });
        if !separate {
            continue;
        }
        let half = base + 0.5 * (response[j] - base);
        let left = (0..j).rev().find(|&i| response[i] < half).unwrap_or(0);
        let right = (j + 1..n).find(|&i| response[i] < half).unwrap_or(n - 1);
        let zeta = ((freq[right] - freq[left]) / (2.0 * freq[j])).clamp(0.01, 0.3);
        peaks.push(Peak { index: j, zeta });
    }
    peaks
}

/// The response's local maxima (over +-2 bins) above its median, highest first: the
/// peaks [`response_peaks`] keeps and the shoulders it merges into a higher neighbour.
fn response_maxima(response: &[f64]) -> Vec<usize> {
    let n = response.len();
    let base = percentile(response, 0.5);
    let mut maxima: Vec<usize> = (0..n)
        .filter(|&j| {
            let lo = j.saturating_sub(2);
            let hi = (j + 2).min(n - 1);
            (lo..=hi).all(|i| response[i] <= response[j]) && response[j] > base
        })
        .collect();
    maxima.sort_by(|&a, &b| response[b].total_cmp(&response[a]));
    maxima
}

/// The `count` bins with the largest excess of the data over `fit` (summed over 3 bins),
/// largest first, each more than 3 bins from every fitted mode and from each other.
fn largest_excesses(fit: &LmFit, freq: &[f64], bin: f64, count: usize) -> Vec<usize> {
    let r = &fit.residuals;
    let mut taken: Vec<f64> = SweepResidual::modes(&fit.theta)
        .iter()
        .map(|m| m.f_hz)
        .collect();
    let excess = |j: usize| r[j - 1] + r[j] + r[j + 1];
    let mut order: Vec<usize> = (1..r.len().saturating_sub(1)).collect();
    order.sort_by(|&a, &b| excess(b).total_cmp(&excess(a)));
    let mut out = Vec::new();
    for j in order {
        if out.len() == count || excess(j) <= 0.0 {
            break;
        }
        if taken.iter().all(|&f| (f - freq[j]).abs() > 3.0 * bin) {
            out.push(j);
            taken.push(freq[j]);
        }
    }
    out
}

/// The first `count` of `maxima` more than 3 bins from every mode of `fit`: a peak of
/// the data the fit does not yet hold, though the model may already stand over it (a
/// broad mode fitted across a peak and its shoulder leaves no excess there).
fn unfitted_maxima(
    maxima: &[usize],
    fit: &LmFit,
    freq: &[f64],
    bin: f64,
    count: usize,
) -> Vec<usize> {
    let fitted: Vec<f64> = SweepResidual::modes(&fit.theta)
        .iter()
        .map(|m| m.f_hz)
        .collect();
    maxima
        .iter()
        .copied()
        .filter(|&j| fitted.iter().all(|&f| (f - freq[j]).abs() > 3.0 * bin))
        .take(count)
        .collect()
}

/// Every mode of `fit` clearly present: weight and damping at least [`SIGNIFICANCE`]
/// sigmas from zero, frequencies more than a bin apart.
fn significant(fit: &LmFit, c: f64, bin: f64) -> bool {
    let Some(sig) = fit.sigmas(c) else {
        return false;
    };
    let f: Vec<f64> = SweepResidual::modes(&fit.theta)
        .iter()
        .map(|m| m.f_hz)
        .collect();
    let m = f.len();
    (0..m)
        .all(|k| sig[2 + 3 * k + 1] * SIGNIFICANCE < 1.0 && sig[2 + 3 * k + 2] * SIGNIFICANCE < 1.0)
        && (0..m).all(|a| (a + 1..m).all(|b| (f[a] - f[b]).abs() > bin))
}

/// The covariance of the fitted parameters: the sandwich ([`LmFit::sandwich`]) with the
/// residuals' covariance `C` from the Welch estimate's own ([`SweepModel::psd_covariance`],
/// through `d ln P = d P / M` and the bins' weights), which holds the correlation of
/// neighbouring bins and the excess variance at narrow peaks.
///
/// `C` is known up to one factor: the noise that drives it (the cross term, which
/// dominates wherever the sweep stands above the floor, scales with the noise floor `N`
/// over the number of segments, and `N` is poorly determined exactly there: on the
/// simulated sweeps of `tests/identify/sweep.rs` the fitted floor ranges from 0 to 3 times
/// the sensor's). The factor is estimated from the residuals by generalised least
/// squares: `r^T C^-1 r` over its expectation `tr(C^-1 (I - H) C (I - H)^T)` with the fit's
/// hat matrix `H = J (J^T J)^-1 J^T` (the residuals of a fit are `(I - H)` times the
/// noise). A file's rounding (`rounding`: the variance it adds to each bin's `ln P`) is a
/// known, fixed part added to the scaled one, the factor then solving the same equation. On those sweeps the factor times the fitted floor recovers the sensor's noise
/// density to within the factor's own scatter, and any misfit of the model shows as a
/// larger factor, so it widens the sigmas too.
fn covariance(
    fit: &LmFit,
    residual: &SweepResidual,
    model: &SweepModel,
    rounding: &[f64],
) -> Option<DMatrix<f64>> {
    let expected = residual.expected(&fit.theta);
    let (gain, noise) = residual.gain_and_noise(&fit.theta);
    // The floor the weights assume where the data do not resolve one
    // (`SweepResidual::set_weights`).
    let smallest = expected.iter().copied().fold(f64::INFINITY, f64::min);
    let noise = noise.max(1e-9 * smallest);
    let cov_p = model.psd_covariance(gain, noise, &SweepResidual::modes(&fit.theta));
    let sw = residual.sqrt_weights();
    let n = expected.len();
    let shape = DMatrix::from_fn(n, n, |i, j| {
        sw[i] * sw[j] * cov_p[(i, j)] / (expected[i] * expected[j])
    });
    let fixed = DMatrix::from_diagonal(&DVector::from_iterator(
        n,
        (0..n).map(|i| sw[i] * sw[i] * rounding[i]),
    ));
    let inv = fit.inv_normal.as_ref()?;
    let resid = DMatrix::identity(n, n) - &fit.jacobian * inv * fit.jacobian.transpose();
    let r = DVector::from_column_slice(&fit.residuals);
    // Observed minus expected generalised chi-square for the scale `s`.
    let excess = |s: f64| -> Option<f64> {
        let total = &shape * s + &fixed;
        let chol = total.clone().cholesky()?;
        let chi2 = r.dot(&chol.solve(&r));
        let expectation = chol.solve(&(&resid * &total * resid.transpose())).trace();
        Some(chi2 - expectation)
    };
    // Without a fixed part the equation is linear in `s`; with one, bisect (on a log
    // scale) below that value, which the fixed part can only lower.
    let chol = shape.clone().cholesky()?;
    let chi2 = r.dot(&chol.solve(&r));
    let s0 = chi2 / chol.solve(&(&resid * &shape * resid.transpose())).trace();
    let scale = if rounding.iter().all(|&v| v == 0.0) {
        s0
    } else {
        let (mut lo, mut hi) = (s0 * 1e-6, s0);
        if excess(lo)? <= 0.0 {
            lo
        } else {
            for _ in 0..60 {
                let mid = (lo * hi).sqrt();
                if excess(mid)? > 0.0 {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            (lo * hi).sqrt()
        }
    };
    fit.sandwich(&(&shape * scale + &fixed))
}

/// The `q` quantile of `v` (nearest rank).
fn percentile(v: &[f64], q: f64) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    s[((s.len() - 1) as f64 * q).round() as usize]
}
