//! Fitting the modal model: to a sweep's spectrum ([`sweep`]) or to a free decay
//! ([`ringdown`]), with model selection and uncertainties shared here.

pub mod lm;
pub mod main_peak;
pub mod pencil;
pub mod rejected;
pub mod ringdown;
pub mod sweep;
pub mod sweep_model;
pub mod sweep_residual;

/// The checks after a sweep fit read only the bins where the measured PSD stands at least
/// this many times above the fitted noise floor.
pub const SIGNAL_OVER_FLOOR: f64 = 3.0;

/// A fitted spectrum, per fitted bin: the data and the model (the recording's PSD, before
/// any stored normalisation), the fitted noise floor, the bins' frequencies and the bin
/// width (Hz). What the checks after a sweep fit read ([`main_peak`], [`rejected`]).
#[derive(Debug, Clone, Copy)]
pub struct FittedSpectrum<'a> {
    /// Measured PSD per bin.
    pub data: &'a [f64],
    /// Fitted PSD per bin.
    pub model: &'a [f64],
    /// Fitted noise floor.
    pub noise: f64,
    /// Frequency per bin (Hz).
    pub freq: &'a [f64],
    /// Bin width (Hz).
    pub bin: f64,
}

/// A larger model must lower the Bayesian information criterion by at least this much
/// (Kass & Raftery's "very strong" evidence: a BIC difference above 10).
pub const BIC_MARGIN: f64 = 10.0;

/// A mode counts as present when its weight (sweep) or amplitude (ring-down) and its
/// damping ratio lie at least this many standard deviations from zero.
pub const SIGNIFICANCE: f64 = 3.0;

/// Most lags (points) over which residual correlation is summed.
const CORRELATION_LAGS: usize = 12;

/// `c = 1 + 2 sum_l rho_l` of the residuals (at least 1), the sum cut where Geyer's
/// initial positive sequence ends (C. J. Geyer, "Practical Markov chain Monte Carlo",
/// Statistical Science 7, 1992): the pairs `rho_2k + rho_2k+1` (`rho_0 = 1`) are summed
/// while they stay positive, at most `CORRELATION_LAGS` (12) lags. Neighbouring PSD bins share
/// the window's kernel and neighbouring samples share sensor filtering, so `n` residuals
/// carry about `n / c` independent ones. Multiplies the covariance and divides `n` in the
/// BIC. Summing a fixed number of lags instead would count the negative correlation that
/// fitting itself leaves in residuals (it removes their smooth part, the very part `c`
/// measures) and undercount the noise's.
pub fn correlation_inflation(r: &[f64]) -> f64 {
    let n = r.len();
    let mean = r.iter().sum::<f64>() / n.max(1) as f64;
    let var: f64 = r.iter().map(|x| (x - mean).powi(2)).sum();
    if var.is_nan() || var <= 0.0 {
        return 1.0;
    }
    let rho = |l: usize| -> f64 {
        if l == 0 {
            return 1.0;
        }
        if l >= n {
            return 0.0;
        }
        (0..n - l)
            .map(|i| (r[i] - mean) * (r[i + l] - mean))
            .sum::<f64>()
            / var
    };
    let mut sum = 0.0;
    for k in 0..=CORRELATION_LAGS / 2 {
        let pair = rho(2 * k) + rho(2 * k + 1);
        if pair <= 0.0 {
            break;
        }
        sum += pair;
    }
    (2.0 * sum - 1.0).max(1.0)
}

/// The Bayesian information criterion `n_eff ln(RSS / n) + p ln(n_eff)` with
/// `n_eff = n / c`.
pub fn bic(rss: f64, n: usize, p: usize, c: f64) -> f64 {
    let n_eff = n as f64 / c;
    n_eff * (rss / n as f64).ln() + p as f64 * n_eff.ln()
}

/// True when `larger` (with `c` from its own residuals) lowers the BIC of `smaller` by
/// more than [`BIC_MARGIN`], both scored with that same `c`. The residual correlation
/// belongs to the noise, which the better model's residuals show: a model that misses a
/// mode leaves that mode's smooth misfit in its residuals, which would inflate its own
/// `c` and shrink its `n_eff`, and BICs of different `n_eff` are not comparable (their
/// `n_eff ln(RSS / n)` terms scale with it).
pub fn bic_prefers(larger: &lm::LmFit, smaller: &lm::LmFit, n: usize, c: f64) -> bool {
    let big = bic(larger.rss, n, larger.theta.len(), c);
    let small = bic(smaller.rss, n, smaller.theta.len(), c);
    big < small - BIC_MARGIN
}
