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
    /// The residuals' correlation `1 + 2 sum rho_l` over the first lags (at least 1):
    /// ring-down fit, the factor the covariance was inflated by; sweep fit, the factor
    /// its model selection counts the bins by (its covariance comes from the Welch
    /// estimate's own, see [`crate::fit::sweep`]).
    pub residual_correlation: f64,
    /// Number of frequency bins (sweep) or samples (ring-down) fitted.
    pub points: usize,
    /// Bayesian information criterion of each model size tried, `(modes, BIC)`; the one
    /// returned is the smallest model whose larger neighbour does not lower it by
    /// [`crate::fit::BIC_MARGIN`] with every mode significant.
    pub candidates: Vec<(usize, f64)>,
    /// Fitted band or window: `(start, end)` in Hz (sweep) or s (ring-down).
    pub span: (f64, f64),
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
    /// The modes, lowest frequency first.
    pub modes: Vec<IdentifiedMode>,
    /// How they were found.
    pub method: Method,
    /// How well the model fits.
    pub diagnostics: Diagnostics,
    /// Data for a figure.
    pub figure: Figure,
}
