//! Fitting the modal model: to a sweep's spectrum ([`sweep`]) or to a free decay
//! ([`ringdown`]), with model selection and uncertainties shared here.

pub mod lm;
pub mod ringdown;
pub mod sweep;
pub mod sweep_model;

/// A larger model must lower the Bayesian information criterion by at least this much
/// (Kass & Raftery's "very strong" evidence: a BIC difference above 10).
pub const BIC_MARGIN: f64 = 10.0;

/// A mode counts as present when its weight (sweep) or amplitude (ring-down) and its
/// damping ratio lie at least this many standard deviations from zero.
pub const SIGNIFICANCE: f64 = 3.0;

/// Lags (points) over which residual correlation is summed.
const CORRELATION_LAGS: usize = 6;

/// `1 + 2 sum_{l=1}^{6} rho_l` of the residuals (at least 1): neighbouring PSD bins share
/// the window's kernel and neighbouring samples share sensor filtering, so `n` residuals
/// carry about `n / c` independent ones. Multiplies the covariance and divides `n` in the
/// BIC.
pub fn correlation_inflation(r: &[f64]) -> f64 {
    let n = r.len();
    let mean = r.iter().sum::<f64>() / n.max(1) as f64;
    let var: f64 = r.iter().map(|x| (x - mean).powi(2)).sum();
    if var.is_nan() || var <= 0.0 {
        return 1.0;
    }
    let mut sum = 0.0;
    for l in 1..=CORRELATION_LAGS.min(n.saturating_sub(1)) {
        let c: f64 = (0..n - l).map(|i| (r[i] - mean) * (r[i + l] - mean)).sum();
        sum += c / var;
    }
    (1.0 + 2.0 * sum).max(1.0)
}

/// The Bayesian information criterion `n_eff ln(RSS / n) + p ln(n_eff)` with
/// `n_eff = n / c`.
pub fn bic(rss: f64, n: usize, p: usize, c: f64) -> f64 {
    let n_eff = n as f64 / c;
    n_eff * (rss / n as f64).ln() + p as f64 * n_eff.ln()
}
