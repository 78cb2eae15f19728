//! From a recording or a processed spectrum to the modes of one axis.

use crate::IdentifyError;
use crate::direction::{self, Direction};
use crate::excitation::SweepTest;
use crate::fit::{ringdown, sweep};
use crate::read::klipper_psd::ProcessedPsd;
use crate::read::{Recording, RecordingFormat};
use crate::result::{AxisIdentification, Figure, Method};
use crate::welch::Welch;

/// Which fit to use on a recording.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MethodChoice {
    /// A sweep fit when the recording lasts at least half the test
    /// ([`SweepTest::duration_s`]) and is not an M956 file; a ring-down fit otherwise.
    Auto,
    /// Always the sweep fit.
    Sweep,
    /// Always the ring-down fit.
    RingDown,
}

/// Options of an identification.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// The resonance test that produced a sweep recording (Klipper's parameters).
    pub test: SweepTest,
    /// Most modes to fit per axis (1 to 4; default 3).
    pub max_modes: usize,
    /// Which fit.
    pub method: MethodChoice,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            test: SweepTest::klipper(),
            max_modes: 3,
            method: MethodChoice::Auto,
        }
    }
}

impl Options {
    fn check(&self) -> Result<(), IdentifyError> {
        let t = &self.test;
        let bad = |name, value, allowed| {
            Err(IdentifyError::InvalidOption {
                name,
                value,
                allowed,
            })
        };
        if !(1..=4).contains(&self.max_modes) {
            return bad("max_modes", self.max_modes as f64, "1 to 4");
        }
        if !(t.freq_start_hz >= 1.0 && t.freq_end_hz >= t.freq_start_hz + 5.0) {
            return bad(
                "test.freq_end_hz",
                t.freq_end_hz,
                "at least 5 Hz above freq_start_hz >= 1 Hz",
            );
        }
        if !(t.accel_per_hz > 0.0 && t.hz_per_sec > 0.0) {
            return bad(
                "test.accel_per_hz / test.hz_per_sec",
                t.accel_per_hz.min(t.hz_per_sec),
                "> 0",
            );
        }
        if !(t.sweeping_accel_mm_s2 >= 0.0 && t.sweeping_period_s >= 0.0) {
            return bad(
                "test.sweeping_accel_mm_s2 / sweeping_period_s",
                t.sweeping_accel_mm_s2.min(t.sweeping_period_s),
                ">= 0",
            );
        }
        Ok(())
    }
}

/// Identify the modes of the axis a recording excited.
pub fn identify_recording(
    rec: &Recording,
    opts: &Options,
) -> Result<AxisIdentification, IdentifyError> {
    opts.check()?;
    let source = match &rec.name {
        Some(n) => format!("{} ({n})", rec.source),
        None => rec.source.clone(),
    };
    let axes: Vec<usize> = (0..3).filter(|&k| rec.accel_mm_s2[k].is_some()).collect();
    let channels: Vec<&[f64]> = rec
        .accel_mm_s2
        .iter()
        .flatten()
        .map(Vec::as_slice)
        .collect();
    let mut means = [0.0; 3];
    for (&k, c) in axes.iter().zip(&channels) {
        means[k] = c.iter().sum::<f64>() / c.len() as f64;
    }
    let duration = rec.time_s[rec.len() - 1] - rec.time_s[0];
    let use_sweep = match opts.method {
        MethodChoice::Sweep => true,
        MethodChoice::RingDown => false,
        MethodChoice::Auto => {
            rec.format != RecordingFormat::RrfM956 && duration >= 0.5 * opts.test.duration_s()
        }
    };
    let fs = rec.mean_rate_hz();
    let welch = if use_sweep {
        // Klipper's window and segment length at a quarter-segment hop (see
        // `Welch::with_hop`): the sweep model is the time integral that hop samples.
        let klipper = Welch::klipper(fs);
        let hop = klipper.nfft() / 4;
        klipper.with_hop(hop)
    } else {
        Welch::new(fs, short_nfft(rec.len()))
    };
    let Some(cross) = welch.cross(&channels) else {
        return Err(IdentifyError::TooFewSamples {
            file: source,
            line: rec.last_line,
            what: "samples",
            found: rec.len(),
            needed: welch.nfft() + 1,
        });
    };
    let bin = welch.bin_hz();
    let (lo_hz, hi_hz) = if use_sweep {
        (
            opts.test.freq_start_hz,
            opts.test.freq_end_hz.min(0.45 * fs),
        )
    } else {
        (5.0, 0.45 * fs)
    };
    let lo = (lo_hz / bin).ceil() as usize;
    let hi = ((hi_hz / bin).floor() as usize + 1)
        .min(cross[0].len())
        .max(lo + 1);
    let dir = direction::principal(&cross, &axes, lo, hi, means);
    if use_sweep {
        let psd = direction::project(&cross, &axes, &dir.vector);
        let ones = vec![1.0; psd.len()];
        let fit = sweep::fit(
            &source,
            &welch,
            &psd,
            &ones,
            &opts.test,
            opts.max_modes,
            None,
        )?;
        let shown = ((1.5 * opts.test.freq_end_hz).min(fs / 2.0) / bin) as usize + 1;
        let figure = spectrum_figure(
            &welch.freqs_hz()[..shown.min(psd.len())],
            &psd,
            &fit,
            0,
            &ones,
        );
        return Ok(AxisIdentification {
            source,
            direction: Some(dir),
            dominant_sensor_axis: Some(dir.nearest_axis),
            modes: fit.modes,
            method: Method::SweepFit,
            diagnostics: fit.diagnostics,
            figure,
        });
    }
    let s = project_samples(rec, &axes, &dir);
    let fit = ringdown::fit(&source, &s, fs, opts.max_modes)?;
    let mut model = vec![f64::NAN; s.len()];
    model[fit.window.0..fit.window.1].copy_from_slice(&fit.curve);
    let x = rec.time_s.iter().map(|t| t - rec.time_s[0]).collect();
    Ok(AxisIdentification {
        source,
        direction: Some(dir),
        dominant_sensor_axis: Some(dir.nearest_axis),
        figure: Figure {
            x,
            measured: s,
            model,
            mode_freqs_hz: fit.modes.iter().map(|m| m.frequency_hz.value).collect(),
            labels: ("time (s)", "acceleration along the motion (mm/s^2)"),
        },
        modes: fit.modes,
        method: Method::RingDownFit,
        diagnostics: fit.diagnostics,
    })
}

/// Significant digits of the PSD values in Klipper's processed files (`%.3e`,
/// `save_calibration_data` in `klippy/extras/shaper_calibrate.py`).
const KLIPPER_DIGITS: i32 = 4;

/// Identify the modes from a Klipper processed spectrum (`psd_xyz`, which does not
/// depend on how the sensor is mounted).
///
/// Klipper averages segments half a segment apart; the sweep model
/// ([`crate::fit::sweep_model`]) is the limit of a dense hop (the time integral of the
/// short-time spectrum), which half-segment sampling aliases where the sweep and the
/// sweeping wave's lines interfere: on the simulated two-mode sweep of
/// `tests/identify/sweep.rs` the residuals of such a fit oscillate with a period of two bins
/// (lag-2 autocorrelation -0.33 to -0.37, against -0.16 to +0.01 at a quarter-segment hop),
/// while the fitted parameters agree with a quarter-segment fit of the same samples to
/// within about one sigma. Raw recordings are analysed at a quarter-segment hop.
pub fn identify_spectrum(
    psd: &ProcessedPsd,
    opts: &Options,
) -> Result<AxisIdentification, IdentifyError> {
    opts.check()?;
    let (first_bin, bin_hz, bin_sigma_hz) = bin_grid(psd)?;
    // Klipper's 0.5 s segment: the kernel's shape in bins barely depends on the length.
    let welch = Welch::new(bin_hz * 2048.0, 2048);
    let len = first_bin + psd.freq_hz.len();
    let mut stored = vec![0.0; len];
    stored[first_bin..].copy_from_slice(psd.sum());
    let factor: Vec<f64> = (0..len)
        .map(|k| {
            if k < first_bin {
                0.0
            } else {
                psd.normalisation.factor(k as f64 * bin_hz)
            }
        })
        .collect();
    let mut fit = sweep::fit(
        &psd.source,
        &welch,
        &stored,
        &factor,
        &opts.test,
        opts.max_modes,
        Some(KLIPPER_DIGITS),
    )?;
    // Every frequency is a multiple of the bin width, which the file gives only through
    // its rounded frequencies: that uncertainty scales them all.
    for m in &mut fit.modes {
        let f = &mut m.frequency_hz;
        f.sigma = f.sigma.hypot(f.value * bin_sigma_hz / bin_hz);
    }
    let dominant = fit.modes.first().and_then(|m| {
        let row = ((m.frequency_hz.value / bin_hz).round() as usize).checked_sub(first_bin)?;
        (0..3)
            .filter_map(|k| psd.axis(k).map(|c| (k, c.get(row).copied().unwrap_or(0.0))))
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(k, _)| k)
    });
    let x: Vec<f64> = (0..len).map(|k| k as f64 * bin_hz).collect();
    let figure = spectrum_figure(
        &x[first_bin..],
        &stored[first_bin..],
        &fit,
        first_bin,
        &factor[first_bin..],
    );
    Ok(AxisIdentification {
        source: psd.source.clone(),
        direction: None,
        dominant_sensor_axis: dominant,
        modes: fit.modes,
        method: Method::SweepFit,
        diagnostics: fit.diagnostics,
        figure,
    })
}

/// A spectrum figure: `x[i]` and `measured[i]` are bin `offset + i`; the model is shown
/// on the fitted bins in stored units (`factor` x the recording's PSD).
fn spectrum_figure(
    x: &[f64],
    measured: &[f64],
    fit: &sweep::SweepFit,
    offset: usize,
    factor: &[f64],
) -> Figure {
    let n = x.len().min(measured.len());
    let mut model = vec![f64::NAN; n];
    for (&k, &m) in fit.bins.iter().zip(&fit.model) {
        if let Some(i) = k.checked_sub(offset).filter(|&i| i < n) {
            model[i] = m * factor[i];
        }
    }
    Figure {
        x: x[..n].to_vec(),
        measured: measured[..n].to_vec(),
        model,
        mode_freqs_hz: fit.modes.iter().map(|m| m.frequency_hz.value).collect(),
        labels: ("frequency (Hz)", "power spectral density ((mm/s^2)^2/Hz)"),
    }
}

/// The acceleration along `dir` with the means (gravity, offsets) removed (mm/s^2).
fn project_samples(rec: &Recording, axes: &[usize], dir: &Direction) -> Vec<f64> {
    let mut s = vec![0.0; rec.len()];
    for &k in axes {
        if let Some(c) = &rec.accel_mm_s2[k] {
            let (d, mean) = (dir.vector[k], dir.mean_mm_s2[k]);
            for (o, v) in s.iter_mut().zip(c) {
                *o += d * (v - mean);
            }
        }
    }
    s
}

/// One segment over (nearly) the whole of a short recording: an even length.
fn short_nfft(n: usize) -> usize {
    (n & !1).max(2)
}

/// The bins of a processed spectrum: Klipper writes `k fs / nfft` rounded to 0.1 Hz, so
/// the rows are fitted with `f0 + j bin` and `f0` must be a whole number of bins. Returns
/// the first row's bin index, the bin width (Hz) and its standard deviation from the
/// rounding (uniform over 0.1 Hz, a variance of `0.01 / 12` per row, through the
/// regression's slope: `sqrt(0.01 / 12 / sum (j - mean j)^2)`).
fn bin_grid(psd: &ProcessedPsd) -> Result<(usize, f64, f64), IdentifyError> {
    let f = &psd.freq_hz;
    let n = f.len() as f64;
    let mean_j = (n - 1.0) / 2.0;
    let mean_f = f.iter().sum::<f64>() / n;
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (j, &v) in f.iter().enumerate() {
        sxy += (j as f64 - mean_j) * (v - mean_f);
        sxx += (j as f64 - mean_j).powi(2);
    }
    let bin = sxy / sxx;
    let f0 = mean_f - bin * mean_j;
    let first = (f0 / bin).round().max(0.0);
    let header_line = psd.last_line + 1 - f.len();
    if bin.is_nan() || bin < 0.5 {
        return Err(IdentifyError::format(
            &psd.source,
            header_line.saturating_sub(1).max(1),
            format!(
                "a spectrum on a {bin:.2} Hz grid (several data sets interpolated onto one grid)"
            ),
            "a spectrum on Klipper's own bins (fs / nfft, about 0.8 to 2 Hz): one data set per file",
        ));
    }
    for (j, &v) in f.iter().enumerate() {
        if (v - (first + j as f64) * bin).abs() > 0.06 {
            return Err(IdentifyError::format(
                &psd.source,
                header_line + j,
                format!("frequency {v} Hz off the grid of {bin:.4} Hz bins"),
                "evenly spaced bins k fs / nfft as Klipper writes them (rounded to 0.1 Hz)",
            ));
        }
    }
    Ok((first as usize, bin, (0.01 / 12.0 / sxx).sqrt()))
}
