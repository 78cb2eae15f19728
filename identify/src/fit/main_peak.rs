//! A sweep fit must reproduce the spectrum's main peak, or it is no answer.

use super::{FittedSpectrum, SIGNAL_OVER_FLOOR};
use crate::IdentifyError;

/// The fitted model must reproduce the spectrum's main peak as Klipper's graph shows it:
/// the frequency where `P / (f + 0.1)` (Klipper's `normalize_to_frequencies`) is largest
/// over the bins where the signal stands at least [`SIGNAL_OVER_FLOOR`] times above the
/// noise floor, taken alike from the data and from the model, must agree within 3 % or
/// one bin. A model that places its peak elsewhere (one broad mode across a sharp peak and
/// its shoulders, a spectrum the modal model does not hold) is not an answer: the error
/// says where the data peak and where the model does.
pub fn check(source: &str, s: FittedSpectrum) -> Result<(), IdentifyError> {
    let FittedSpectrum {
        data,
        model,
        noise,
        freq,
        bin,
    } = s;
    let floor = noise.max(0.0);
    let peak_of = |p: &[f64]| -> Option<usize> {
        (0..p.len())
            .filter(|&j| data[j] > SIGNAL_OVER_FLOOR * floor)
            .max_by(|&a, &b| (p[a] / (freq[a] + 0.1)).total_cmp(&(p[b] / (freq[b] + 0.1))))
    };
    let (Some(d), Some(m)) = (peak_of(data), peak_of(model)) else {
        return Ok(());
    };
    let (fd, fm) = (freq[d], freq[m]);
    // Both are bin frequencies: one bin apart passes despite rounding.
    if (fd - fm).abs() <= (MAIN_PEAK_TOLERANCE * fd).max(bin) * (1.0 + 1e-9) {
        return Ok(());
    }
    Err(IdentifyError::Unreliable {
        file: source.to_string(),
        reason: format!(
            "the spectrum peaks at {fd:.1} Hz (Klipper's normalised PSD), the fitted modes at {fm:.1} Hz: the modal model does not explain this spectrum's main peak (more modes with --max-modes, or the test's parameters if they differ from the defaults?)"
        ),
    })
}

/// See [`check`]: 3 %.
pub const MAIN_PEAK_TOLERANCE: f64 = 0.03;
