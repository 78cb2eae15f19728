//! Modes from a resonance sweep: the Welch PSD fitted with the modal model.
//!
//! The measured PSD `P` is compared with the expected PSD `M(theta)`
//! ([`super::sweep_model`]) on a log scale: residual `ln P_f - ln M_f(theta)` per bin. A
//! Welch estimate is a scaled chi-square variable whose logarithm has the same variance at
//! every level, so equal weights on the log scale are the right ones; the fit is
//! Levenberg-Marquardt over `theta = (ln G, ln N, (ln f_k, ln zeta_k, ln w_k)...)`.
//!
//! Why the damping comes out unbiased: the half-power method reads zeta from the width
//! of the peak, `2 zeta f` between the points where the *power* `|T|^2` falls to half its
//! peak. Taking a power spectrum's width at `1/sqrt 2` of its peak (the amplitude rule)
//! measures `|T|^2 = max / sqrt 2`, a width of `2 * 0.644 zeta f` for a lightly damped
//! mode: 36 % low. The window's smoothing then widens a peak narrower than a few bins, and
//! a second mode or the sweep's rising input tilts it. No width is read here: the model's
//! `|T|^2` is the exact power response of the modal model, smoothed by the same kernel as
//! the data and multiplied by the sweep's own spectrum, so the fitted parameters are those
//! of the structure. What remains (see [`MODEL_REL_SIGMA`]) is measured on simulated
//! recordings and carried in the reported sigma.
//!
//! Model size: 1 to `max_modes` modes; a mode is added while the Bayesian information
//! criterion (with the residuals' correlation counted: `n_eff = n / c`) drops by at least
//! [`super::BIC_MARGIN`] and every mode stays significant (weight and damping at least
//! [`super::SIGNIFICANCE`] standard deviations from 0, frequencies a bin apart). The
//! uncertainties are the Gauss-Newton covariance `s^2 (J^T J)^-1` inflated by `c`.

use super::lm::{self, LmFit};
use super::sweep_model::{ModeParams, SweepModel};
use super::{BIC_MARGIN, SIGNIFICANCE, bic, correlation_inflation};
use crate::IdentifyError;
use crate::excitation::SweepTest;
use crate::result::{Diagnostics, Estimate, IdentifiedMode, WeightBasis};
use crate::welch::Welch;

/// Largest PSD in the band over the noise floor (its 5th percentile) must reach this.
pub const MIN_PEAK_TO_FLOOR: f64 = 10.0;

/// The response (PSD over the excitation) must peak at least this far over its median.
pub const MIN_PROMINENCE: f64 = 2.0;

/// Relative model error of (frequency, damping ratio, weight), added in quadrature to the
/// statistical sigma. The expected-PSD model approximates the sweep's spectrum by
/// stationary phase and leaves out the cross terms that Welch's 50 % overlap leaves for a
/// chirp; on the simulated sweeps of `tests/identify/sweep.rs` (one and two modes, zeta
/// 0.02 to 0.18, raw and processed files) the estimates stay within 0.1 % (frequency),
/// 3.5 % (damping, always low) and 1 % (weight) of the truth, while the statistical sigma
/// alone is a few tenths of that. These figures bound that bias.
pub const MODEL_REL_SIGMA: [f64; 3] = [0.0005, 0.03, 0.01];

/// Largest participation weight the fit may reach (a real structure's sum to 1).
const MAX_WEIGHT: f64 = 5.0;

/// Bins left out at each end of the sweep band (the sweep's start and end ripple).
const EDGE_BINS: f64 = 3.0;

/// A weak prior on the noise floor (natural-log units), so that a floor the data cannot
/// see does not leave the normal equations singular.
const NOISE_PRIOR_SIGMA: f64 = 5.0;

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
    /// Fitted gain `G` and noise floor `N` ((mm/s^2)^2/Hz).
    pub gain_and_noise: (f64, f64),
}

/// Fit the PSD `psd` (per bin of `welch`, stored units) whose stored values are
/// `factor` x the recording's PSD (1 for raw data; 0 where the file holds nothing),
/// measured under `test`, with up to `max_modes` modes.
pub fn fit(
    source: &str,
    welch: &Welch,
    psd: &[f64],
    factor: &[f64],
    test: &SweepTest,
    max_modes: usize,
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
    let ratio: Vec<f64> = y.iter().zip(&exc).map(|(a, e)| a / e).collect();
    let median_ratio = percentile(&ratio, 0.5);
    let (peak_j, peak) = ratio
        .iter()
        .copied()
        .enumerate()
        .fold((0, 0.0), |b, (j, r)| if r > b.1 { (j, r) } else { b });
    let prominence = peak / median_ratio;
    if prominence.is_nan() || prominence < MIN_PROMINENCE {
        return Err(no_peak(
            "largest response / median response",
            peak / median_ratio,
            MIN_PROMINENCE,
        ));
    }
    // Gain from the response well below the first peak, where |T| is close to 1.
    let below: Vec<f64> = (0..peak_j)
        .filter(|&j| freq[j] < 0.5 * freq[peak_j])
        .map(|j| ratio[j])
        .collect();
    let gain0 = if below.len() >= 3 {
        percentile(&below, 0.5)
    } else {
        percentile(&ratio, 0.25)
    };
    let zeta0 = (0.5 / (peak / gain0).max(1.0).sqrt()).clamp(0.01, 0.3);
    let noise0 = 0.1 * floor;
    let fitter = Fitter {
        model: &model,
        ln_y: y.iter().map(|v| v.ln()).collect(),
        ln_noise0: noise0.ln(),
        f_range: (freq[0], freq[freq.len() - 1]),
    };
    let mut theta = vec![gain0.ln(), noise0.ln(), freq[peak_j].ln(), zeta0.ln(), 0.0];
    let mut best: Option<(LmFit, f64)> = None;
    let mut candidates = Vec::new();
    for m in 1..=max_modes.max(1) {
        // The first mode also starts from a light and a heavy damping guess (broad,
        // overlapping peaks mislead the width-based guess); the lowest RSS wins.
        let mut starts = vec![theta.clone()];
        if m == 1 {
            for z in [0.05f64, 0.15] {
                let mut t = theta.clone();
                t[3] = z.ln();
                starts.push(t);
            }
        }
        let Some(fit) = starts
            .iter()
            .filter_map(|t| lm::minimise(|t| fitter.residuals(t), t, 200))
            .min_by(|a, b| a.rss.total_cmp(&b.rss))
        else {
            break;
        };
        let c = correlation_inflation(&fit.residuals[..bins.len()]);
        let score = bic(fit.rss, bins.len(), fit.theta.len(), c);
        candidates.push((m, score));
        let accept = match &best {
            None => true,
            Some((_, prev)) => score < prev - BIC_MARGIN && significant(&fit, c, bin),
        };
        if !accept {
            break;
        }
        theta = fit.theta.clone();
        // The next mode starts at the largest excess of the data over this model.
        let r = &fit.residuals[..bins.len()];
        let taken: Vec<f64> = (0..m).map(|k| fit.theta[2 + 3 * k].exp()).collect();
        let next = (1..r.len() - 1)
            .filter(|&j| taken.iter().all(|&f| (f - freq[j]).abs() > 3.0 * bin))
            .max_by(|&a, &b| (r[a - 1] + r[a] + r[a + 1]).total_cmp(&(r[b - 1] + r[b] + r[b + 1])));
        best = Some((fit, score));
        let Some(j) = next else { break };
        theta.extend([freq[j].ln(), 0.05f64.ln(), 0.2f64.ln()]);
    }
    let Some((fit, _)) = best else {
        return Err(no_peak("fitted modes", 0.0, 1.0));
    };
    let n = bins.len();
    let c = correlation_inflation(&fit.residuals[..n]);
    let sig = fit
        .sigmas(c)
        .unwrap_or_else(|| vec![f64::NAN; fit.theta.len()]);
    let mut modes: Vec<IdentifiedMode> = (0..(fit.theta.len() - 2) / 3)
        .map(|k| {
            let at = |i: usize| {
                let v = fit.theta[2 + 3 * k + i].exp();
                let statistical = v * sig[2 + 3 * k + i];
                let model = v * MODEL_REL_SIGMA[i];
                Estimate {
                    value: v,
                    sigma: statistical.hypot(model),
                }
            };
            IdentifiedMode {
                frequency_hz: at(0),
                damping_ratio: at(1),
                weight: Some(at(2)),
                weight_basis: WeightBasis::Fitted,
            }
        })
        .collect();
    modes.sort_by(|a, b| a.frequency_hz.value.total_cmp(&b.frequency_hz.value));
    let mut curve = vec![0.0; n];
    let (gain, noise) = (fit.theta[0].exp(), fit.theta[1].exp());
    let params = Fitter::modes(&fit.theta);
    model.evaluate(gain, noise, &params, &mut Vec::new(), &mut curve);
    let rms = (fit.residuals[..n].iter().map(|r| r * r).sum::<f64>() / n as f64).sqrt();
    Ok(SweepFit {
        modes,
        diagnostics: Diagnostics {
            noise_floor: noise,
            residual_rms: rms,
            residual_correlation: c,
            points: n,
            candidates,
            span: (freq[0], freq[n - 1]),
        },
        bins,
        model: curve,
        gain_and_noise: (gain, noise),
    })
}

/// Every mode of `fit` clearly present: weight and damping at least [`SIGNIFICANCE`]
/// sigmas from zero, frequencies more than a bin apart.
fn significant(fit: &LmFit, c: f64, bin: f64) -> bool {
    let Some(sig) = fit.sigmas(c) else {
        return false;
    };
    let m = (fit.theta.len() - 2) / 3;
    let f: Vec<f64> = (0..m).map(|k| fit.theta[2 + 3 * k].exp()).collect();
    (0..m)
        .all(|k| sig[2 + 3 * k + 1] * SIGNIFICANCE < 1.0 && sig[2 + 3 * k + 2] * SIGNIFICANCE < 1.0)
        && (0..m).all(|a| (a + 1..m).all(|b| (f[a] - f[b]).abs() > bin))
}

/// The residual function's data.
struct Fitter<'a> {
    model: &'a SweepModel,
    ln_y: Vec<f64>,
    ln_noise0: f64,
    f_range: (f64, f64),
}

impl Fitter<'_> {
    fn modes(theta: &[f64]) -> Vec<ModeParams> {
        theta[2..]
            .chunks_exact(3)
            .map(|c| ModeParams {
                f_hz: c[0].exp(),
                zeta: c[1].exp(),
                weight: c[2].exp(),
            })
            .collect()
    }

    fn residuals(&self, theta: &[f64]) -> Option<Vec<f64>> {
        let modes = Self::modes(theta);
        if modes.iter().any(|m| {
            !(m.zeta < 0.95
                && m.f_hz > 0.5 * self.f_range.0
                && m.f_hz < 1.5 * self.f_range.1
                && m.weight < MAX_WEIGHT)
        }) {
            return None;
        }
        let mut out = vec![0.0; self.ln_y.len()];
        self.model.evaluate(
            theta[0].exp(),
            theta[1].exp(),
            &modes,
            &mut Vec::new(),
            &mut out,
        );
        let mut r: Vec<f64> = self
            .ln_y
            .iter()
            .zip(&out)
            .map(|(y, m)| y - m.ln())
            .collect();
        r.push((theta[1] - self.ln_noise0) / NOISE_PRIOR_SIGMA);
        r.iter().all(|v| v.is_finite()).then_some(r)
    }
}

/// The `q` quantile of `v` (nearest rank).
fn percentile(v: &[f64], q: f64) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    s[((s.len() - 1) as f64 * q).round() as usize]
}
