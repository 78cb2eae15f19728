//! The sweep fit's residual function and the weights of its bins.
//!
//! Parameters `theta = (ln G, N / N_unit, (ln f_k, ln zeta_k, ln w_k)...)`: the gain and
//! the modes on a log scale (positive, and steps relative to their size), the noise floor
//! `N` linear (a floor far below the signal is then simply a small number with its
//! uncertainty, instead of a logarithm running off to minus infinity). Residual per bin:
//! `sqrt(weight_f) (ln P_f - ln M_f(theta))`.
//!
//! Weights. A sweep's PSD is a deterministic spectrum `S` plus sensor noise of PSD `N`:
//! per segment `|S_s + n_s|^2`, whose mean is `|S_s|^2 + N` and whose variance is
//! `2 |S_s|^2 N + N^2` (the cross term and the noise's own chi-square). Averaged over the
//! segments, `var(ln P_f) = N (2 M_f - N) / (S_eff M_f^2)` with `M_f` the expected PSD and
//! `S_eff` the effective number of segments: `2 / S_eff` times `N / M_f` where the sweep
//! dominates, `1 / S_eff` where noise does. A recording's bins therefore differ in
//! variance by the whole dynamic range of the spectrum, and equal weights would let the
//! noisiest bins decide (and make `s^2 (J^T J)^-1` wrong). The weight is the inverse of
//! that variance, normalised to a mean of 1 (the common factor `S_eff` is estimated by the
//! residual variance `s^2`).

use super::sweep_model::{ModeParams, SweepModel};

/// Largest participation weight the fit may reach (a real structure's weights sum to 1).
pub const MAX_WEIGHT: f64 = 5.0;

/// Largest damping ratio the fit may reach.
pub const MAX_ZETA: f64 = 0.95;

/// The residual function's data.
#[derive(Debug)]
pub struct SweepResidual<'a> {
    model: &'a SweepModel,
    ln_y: Vec<f64>,
    /// The unit of `theta[1]` ((mm/s^2)^2/Hz).
    noise_unit: f64,
    /// Frequencies (Hz) a mode may take: from half the first bin to 1.5 times the last.
    f_range: (f64, f64),
    /// Square roots of the bins' weights.
    sqrt_w: Vec<f64>,
}

impl<'a> SweepResidual<'a> {
    /// Residuals of the measured PSD `y` (per bin of `model`, positive) against `model`,
    /// equally weighted; `f_range` the fitted band (Hz).
    pub fn new(model: &'a SweepModel, y: &[f64], noise_unit: f64, f_range: (f64, f64)) -> Self {
        Self {
            model,
            ln_y: y.iter().map(|v| v.ln()).collect(),
            noise_unit,
            f_range,
            sqrt_w: vec![1.0; y.len()],
        }
    }

    /// Weight the bins for an expected PSD `m` and noise floor `noise` (see the notes): the
    /// inverse of `(N / M)(2 - N / M)`, with `N` at least `1e-9` of the smallest `M` (a
    /// floor the data do not resolve then gives weights in proportion to `M`).
    pub fn set_weights(&mut self, m: &[f64], noise: f64) {
        let smallest = m.iter().copied().fold(f64::INFINITY, f64::min);
        let n = noise.max(1e-9 * smallest);
        let w: Vec<f64> = m
            .iter()
            .map(|&mf| {
                let q = (n / mf).min(1.0);
                1.0 / (q * (2.0 - q))
            })
            .collect();
        let mean = w.iter().sum::<f64>() / w.len().max(1) as f64;
        self.sqrt_w = w.iter().map(|v| (v / mean).sqrt()).collect();
    }

    /// The square roots of the bins' weights (mean weight 1).
    pub fn sqrt_weights(&self) -> &[f64] {
        &self.sqrt_w
    }

    /// The gain `G` and noise floor `N` ((mm/s^2)^2/Hz) of `theta`.
    pub fn gain_and_noise(&self, theta: &[f64]) -> (f64, f64) {
        (theta[0].exp(), theta[1] * self.noise_unit)
    }

    /// The modes of `theta`.
    pub fn modes(theta: &[f64]) -> Vec<ModeParams> {
        theta[2..]
            .chunks_exact(3)
            .map(|c| ModeParams {
                f_hz: c[0].exp(),
                zeta: c[1].exp(),
                weight: c[2].exp(),
            })
            .collect()
    }

    /// The expected PSD per bin for `theta`.
    pub fn expected(&self, theta: &[f64]) -> Vec<f64> {
        let (gain, noise) = self.gain_and_noise(theta);
        let mut out = vec![0.0; self.ln_y.len()];
        self.model
            .evaluate(gain, noise, &Self::modes(theta), &mut Vec::new(), &mut out);
        out
    }

    /// The weighted residuals; `None` outside the parameters' domain (a damping ratio of
    /// [`MAX_ZETA`] or more, a weight of [`MAX_WEIGHT`] or more, a frequency outside the
    /// allowed range, a non-positive expected PSD).
    pub fn residuals(&self, theta: &[f64]) -> Option<Vec<f64>> {
        let (lo, hi) = self.f_range;
        let inside = Self::modes(theta).iter().all(|m| {
            m.zeta < MAX_ZETA && m.f_hz > 0.5 * lo && m.f_hz < 1.5 * hi && m.weight < MAX_WEIGHT
        });
        if !inside {
            return None;
        }
        let r: Vec<f64> = self
            .ln_y
            .iter()
            .zip(self.expected(theta))
            .zip(&self.sqrt_w)
            .map(|((y, m), w)| (y - m.ln()) * w)
            .collect();
        r.iter().all(|v| v.is_finite()).then_some(r)
    }
}
