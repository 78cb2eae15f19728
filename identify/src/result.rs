//! What identification returns: modes with uncertainties, how they were found, and the
//! data for a figure.

use crate::direction::Direction;

/// A value and its standard deviation (same unit).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    /// The estimate.
    pub value: f64,
    /// One standard deviation (from the fit's covariance; see the method's notes).
    pub sigma: f64,
}

impl Estimate {
    /// Whether `truth` lies within `k` standard deviations.
    pub fn covers(&self, truth: f64, k: f64) -> bool {
        (self.value - truth).abs() <= k * self.sigma
    }
}

/// Where a participation weight came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WeightBasis {
    /// Fitted to the measured response (sweep fit).
    Fitted,
    /// A single mode in a free decay: weight 1 by the convention that a real structure's
    /// weights sum to 1 (a free decay does not show the participation).
    AssumedSingleMode,
    /// Several modes in a free decay: their amplitudes depend on the move that excited
    /// them, which the recording does not state, so the weights are not identified.
    NotIdentified,
}

/// One identified mode, in settle's modal convention (settle-sim's `Mode`): toolhead =
/// command + sum weight_k e_k with `e_k'' + 2 zeta_k w_k e_k' + w_k^2 e_k = -a_cmd`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IdentifiedMode {
    /// Natural frequency `w_k / 2 pi` (Hz).
    pub frequency_hz: Estimate,
    /// Damping ratio.
    pub damping_ratio: Estimate,
    /// Participation weight in the toolhead error; `None` unless [`WeightBasis::Fitted`] or
    /// [`WeightBasis::AssumedSingleMode`] (then 1 with sigma 0).
    pub weight: Option<Estimate>,
    /// Where the weight came from.
    pub weight_basis: WeightBasis,
    /// Where this mode shows as a peak (Hz): a sweep fit, the maximum of the mode's own
    /// transmissibility `|1 + w r^2 / (1 - r^2 + 2 i zeta r)|^2` ([`response_peak_hz`]);
    /// a ring-down fit, the damped frequency `f sqrt(1 - zeta^2)`. This is the frequency a
    /// spectrum (Klipper's graph, Shake&Tune's) shows; the natural frequency differs from
    /// it by the damping and, for a weight other than 1, by the weight.
    pub peak_hz: f64,
}

/// The frequency (Hz) where `|T|^2 = |1 + w r^2 / (1 - r^2 + 2 i zeta r)|^2`, `r = nu /
/// f`, is largest, for `r` in `[0.2, 5]`: a grid of 2,000 points then golden-section
/// search around the best (to `1e-9` of `f`). `f` when the response has no maximum inside
/// (a weight of 0).
pub fn response_peak_hz(frequency_hz: f64, damping_ratio: f64, weight: f64) -> f64 {
    let t2 = |r: f64| {
        let h = nalgebra::Complex::new(1.0 - r * r, 2.0 * damping_ratio * r);
        (nalgebra::Complex::new(1.0, 0.0) + weight * r * r / h).norm_sqr()
    };
    let (lo, hi, n) = (0.2f64, 5.0f64, 2000);
    let at = |i: usize| lo * (hi / lo).powf(i as f64 / n as f64);
    let best = (0..=n)
        .max_by(|&a, &b| t2(at(a)).total_cmp(&t2(at(b))))
        .unwrap_or(0);
    if best == 0 || best == n {
        return frequency_hz;
    }
    let (mut a, mut b) = (at(best - 1), at(best + 1));
    let g = (5f64.sqrt() - 1.0) / 2.0;
    while b - a > 1e-9 {
        let (c, d) = (b - g * (b - a), a + g * (b - a));
        if t2(c) > t2(d) {
            b = d;
        } else {
            a = c;
        }
    }
    frequency_hz * 0.5 * (a + b)
}

/// How the modes were found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// Klipper's resonance sweep: the Welch PSD fitted with the modal model times the
    /// sweep's spectrum ([`crate::fit::sweep`]).
    SweepFit,
    /// A free decay fitted with a sum of damped sinusoids ([`crate::fit::ringdown`]).
    RingDownFit,
}

/// Numbers that say how well the model fits.
#[derive(Debug, Clone, PartialEq)]
pub struct Diagnostics {
    /// Sweep fit: the fitted white noise floor of the analysed PSD ((mm/s^2)^2/Hz, as
    /// computed from the recording, before any Klipper normalisation). Ring-down fit: the
    /// residual's standard deviation (mm/s^2).
    pub noise_floor: f64,
    /// Root mean square of the fit's residuals (sweep fit: natural log of PSD; ring-down
    /// fit: mm/s^2).
    pub residual_rms: f64,
    /// A correlation factor `1 + 2 sum rho_l` (at least 1): ring-down fit, the residuals'
    /// over the first lags, the factor the covariance was inflated by; sweep fit, the
    /// spectrum's bins' own from the window (1.95 for Klipper's), the factor its model
    /// selection counts the bins by (its covariance comes from the Welch estimate's own,
    /// see [`crate::fit::sweep`]).
    pub residual_correlation: f64,
    /// Number of frequency bins (sweep) or samples (ring-down) fitted.
    pub points: usize,
    /// Bayesian information criterion of each model size tried, `(modes, BIC)`; the one
    /// returned is the smallest model whose larger neighbour does not lower it by
    /// [`crate::fit::BIC_MARGIN`] with every mode significant.
    pub candidates: Vec<(usize, f64)>,
    /// Fitted band or window: `(start, end)` in Hz (sweep) or s (ring-down).
    pub span: (f64, f64),
    /// Sweep fit: the peaks in the data that are not modes (where the data stand well over
    /// the fitted model), each with the reason, lowest first; empty for a ring-down fit.
    pub rejected: Vec<RejectedPeak>,
    /// Whether the final least-squares fit converged (its last step changed the sum of
    /// squares by less than `1e-12` of it) rather than stopping at its iteration limit.
    pub converged: bool,
}

/// A peak in the data that is not a mode, and why.
#[derive(Debug, Clone, PartialEq)]
pub struct RejectedPeak {
    /// Where (Hz).
    pub frequency_hz: f64,
    /// Why it is not a mode.
    pub reason: String,
}

/// Data for a figure: measured and fitted curves on one abscissa.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// Abscissa: frequency (Hz) for a sweep fit, time (s) for a ring-down fit.
    pub x: Vec<f64>,
    /// Measured values: PSD ((mm/s^2)^2/Hz, as stored in the source) or acceleration along
    /// the motion direction (mm/s^2).
    pub measured: Vec<f64>,
    /// The fitted model on the same abscissa (NaN outside the fitted span).
    pub model: Vec<f64>,
    /// The modes' positions: frequencies (Hz), for a spectrum figure.
    pub mode_freqs_hz: Vec<f64>,
    /// Each mode's share of the model on the same abscissa (a spectrum figure: the model
    /// with that mode alone; NaN outside the fitted span), in the order of the modes;
    /// empty for a ring-down fit.
    pub components: Vec<Vec<f64>>,
    /// Axis labels `(x, y)`.
    pub labels: (&'static str, &'static str),
}

/// The identification of one axis from one recording.
#[derive(Debug, Clone, PartialEq)]
pub struct AxisIdentification {
    /// The file (and measurement name) analysed.
    pub source: String,
    /// The direction in the sensor frame that carries the motion (`None` for a processed
    /// spectrum, which holds no cross spectra).
    pub direction: Option<Direction>,
    /// For a processed spectrum: the sensor axis whose PSD column holds most of the peak
    /// power (0 = x), when the file has per-axis columns.
    pub dominant_sensor_axis: Option<usize>,
    /// The single sensor axis the file names (an M956 capture of one axis), see
    /// [`crate::read::Recording::named_axis`].
    pub named_axis: Option<usize>,
    /// The modes, lowest frequency first.
    pub modes: Vec<IdentifiedMode>,
    /// How they were found.
    pub method: Method,
    /// How well the model fits.
    pub diagnostics: Diagnostics,
    /// What the reader must know to read the result: a part of the test's band the data
    /// could not show (above 0.45 x a recording's sample rate, past a spectrum's last
    /// row), where a mode would go unseen.
    pub notes: Vec<String>,
    /// Data for a figure.
    pub figure: Figure,
}
