//! The frequency grid of a Klipper processed spectrum.

use super::klipper_psd::ProcessedPsd;
use crate::IdentifyError;

/// Half the rounding step of Klipper's `%.1f` frequencies (Hz), with room for the
/// binary representation of the written decimals.
const FREQ_ROUNDING_HZ: f64 = 0.05 + 1e-9;

/// The bins of a processed spectrum: Klipper writes `k fs / nfft` rounded to 0.1 Hz (`%.1f`
/// of bins of the *measured* sample rate, so consecutive steps alternate, e.g. 1.5 and 1.6
/// Hz), and the rows are fitted as bins `k0 + j` of one width. Every row `j` bounds that
/// width to `[(f_j - 0.05) / (k0 + j), (f_j + 0.05) / (k0 + j)]`; the width is the middle of
/// the intersection of these intervals, and its standard deviation the intersection's
/// width over `sqrt(12)` (uniform over it). A row that leaves the intersection empty is off
/// the grid. `k0` comes from a first estimate by least squares. Returns the first row's bin
/// index, the bin width (Hz) and its standard deviation.
pub fn bin_grid(psd: &ProcessedPsd) -> Result<(usize, f64, f64), IdentifyError> {
    let f = &psd.freq_hz;
    let n = f.len() as f64;
    let mean_j = (n - 1.0) / 2.0;
    let mean_f = f.iter().sum::<f64>() / n;
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (j, &v) in f.iter().enumerate() {
        sxy += (j as f64 - mean_j) * (v - mean_f);
        sxx += (j as f64 - mean_j).powi(2);
    }
    let rough = sxy / sxx;
    let header_line = psd.last_line + 1 - f.len();
    if rough.is_nan() || rough < 0.5 {
        return Err(IdentifyError::format(
            &psd.source,
            header_line.saturating_sub(1).max(1),
            format!(
                "a spectrum on a {rough:.2} Hz grid (several data sets interpolated onto one grid)"
            ),
            "a spectrum on Klipper's own bins (fs / nfft, about 0.8 to 2 Hz): one data set per file",
        ));
    }
    let first = ((mean_f - rough * mean_j) / rough).round().max(0.0);
    let (mut lo, mut hi) = (0.0f64, f64::INFINITY);
    for (j, &v) in f.iter().enumerate() {
        let k = first + j as f64;
        let (a, b) = if k == 0.0 {
            if v.abs() <= FREQ_ROUNDING_HZ {
                continue;
            }
            (f64::INFINITY, f64::NEG_INFINITY)
        } else {
            ((v - FREQ_ROUNDING_HZ) / k, (v + FREQ_ROUNDING_HZ) / k)
        };
        let (nlo, nhi) = (lo.max(a), hi.min(b));
        if nlo > nhi {
            return Err(IdentifyError::format(
                &psd.source,
                header_line + j,
                format!(
                    "frequency {v} Hz, which no bin width fitting the rows before it ({lo:.5} to {hi:.5} Hz) rounds to (bin {k})"
                ),
                "evenly spaced bins k fs / nfft as Klipper writes them (rounded to 0.1 Hz)",
            ));
        }
        (lo, hi) = (nlo, nhi);
    }
    Ok((first as usize, 0.5 * (lo + hi), (hi - lo) / 12f64.sqrt()))
}
