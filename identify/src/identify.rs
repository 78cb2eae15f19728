//! From a recording or a processed spectrum to the modes of one axis.

use crate::IdentifyError;
use crate::direction::{self, Direction};
use crate::excitation::SweepTest;
use crate::fit::{ringdown, sweep};
use crate::read::klipper_grid::bin_grid;
use crate::read::klipper_psd::ProcessedPsd;
use crate::read::{Recording, RecordingFormat};
use crate::result::{AxisIdentification, Figure, Method};
use crate::trust::{
    check_duration, check_spectrum_vibration, check_trust, check_vibration, free_recording,
};
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

/// Which column of a Klipper processed spectrum to fit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SpectrumColumn {
    /// `psd_xyz`, the total over the sensor axes (what Klipper tunes against; it does not
    /// depend on how the sensor is mounted), or a multi-data-set file's first column.
    #[default]
    Total,
    /// One sensor axis's column (`psd_x` = 0, `psd_y` = 1, `psd_z` = 2).
    Axis(usize),
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
    /// Which column of a processed spectrum to fit (default the total).
    pub column: SpectrumColumn,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            test: SweepTest::klipper(),
            max_modes: 3,
            method: MethodChoice::Auto,
            column: SpectrumColumn::Total,
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
    check_vibration(&source, rec)?;
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
        MethodChoice::Auto if rec.format == RecordingFormat::RrfM956 => false,
        MethodChoice::Auto if free_recording(rec, duration, &opts.test) => false,
        MethodChoice::Auto => {
            check_duration(&source, duration, &opts.test)?;
            true
        }
    };
    let fs = rec.mean_rate_hz();
    if use_sweep && opts.test.freq_start_hz >= NYQUIST_USE * fs {
        return Err(IdentifyError::NeedsTestParameters {
            file: source,
            reason: format!(
                "a sample rate of {fs:.1} Hz sees up to {:.1} Hz, below the test's first frequency {} Hz: record at a higher rate or give the test's band (--freq-start, --freq-end)",
                NYQUIST_USE * fs,
                opts.test.freq_start_hz
            ),
        });
    }
    // What the test excited above the Nyquist frequency folds back to `fs - f`: into the
    // band analysed (up to NYQUIST_USE * fs) once the test ends above (1 - NYQUIST_USE) * fs.
    // There it would be fitted as modes the machine does not have, or move the ones it has.
    if use_sweep && opts.test.freq_end_hz > (1.0 - NYQUIST_USE) * fs {
        return Err(IdentifyError::NeedsTestParameters {
            file: source,
            reason: format!(
                "the test sweeps up to {} Hz, past the Nyquist frequency {:.1} Hz of this recording's {fs:.1} Hz sample rate: what it excited above {:.1} Hz folds back to {:.1} Hz and up (aliasing), inside the band analysed (up to {:.1} Hz); record at more than {:.0} Hz, or give the test's band (--freq-start, --freq-end) if it was narrower",
                opts.test.freq_end_hz,
                fs / 2.0,
                fs / 2.0,
                fs - opts.test.freq_end_hz,
                NYQUIST_USE * fs,
                opts.test.freq_end_hz / (1.0 - NYQUIST_USE),
            ),
        });
    }
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
            opts.test.freq_end_hz.min(NYQUIST_USE * fs),
        )
    } else {
        (5.0, NYQUIST_USE * fs)
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
        check_trust(
            &source,
            &fit.modes,
            &fit.diagnostics,
            fit.diagnostics.span,
            fs / 2.0,
        )?;
        let shown = ((1.5 * opts.test.freq_end_hz).min(fs / 2.0) / bin) as usize + 1;
        let figure = spectrum_figure(
            &welch.freqs_hz()[..shown.min(psd.len())],
            &psd,
            &fit,
            0,
            &ones,
        );
        let mut notes = Vec::new();
        if opts.test.freq_end_hz > NYQUIST_USE * fs {
            notes.push(unseen_band(
                fit.diagnostics.span,
                opts.test.freq_end_hz,
                format!(
                    "{:.1} Hz, 0.45 x the sample rate of {fs:.1} Hz (above it accelerometers' anti-alias filters cut in); record at more than {:.0} Hz to see the whole test",
                    NYQUIST_USE * fs,
                    opts.test.freq_end_hz / NYQUIST_USE
                ),
            ));
        }
        return Ok(AxisIdentification {
            source,
            direction: Some(dir),
            dominant_sensor_axis: Some(dir.nearest_axis),
            named_axis: rec.named_axis,
            modes: fit.modes,
            method: Method::SweepFit,
            diagnostics: fit.diagnostics,
            notes,
            figure,
        });
    }
    let s = project_samples(rec, &axes, &dir);
    let fit = ringdown::fit(&source, &s, fs, opts.max_modes)?;
    check_trust(
        &source,
        &fit.modes,
        &fit.diagnostics,
        (lo_hz, hi_hz),
        fs / 2.0,
    )?;
    let mut model = vec![f64::NAN; s.len()];
    model[fit.window.0..fit.window.1].copy_from_slice(&fit.curve);
    let x = rec.time_s.iter().map(|t| t - rec.time_s[0]).collect();
    Ok(AxisIdentification {
        source,
        direction: Some(dir),
        dominant_sensor_axis: Some(dir.nearest_axis),
        named_axis: rec.named_axis,
        figure: Figure {
            x,
            measured: s,
            model,
            mode_freqs_hz: fit.modes.iter().map(|m| m.frequency_hz.value).collect(),
            components: Vec::new(),
            labels: ("time (s)", "acceleration along the motion (mm/s^2)"),
        },
        modes: fit.modes,
        method: Method::RingDownFit,
        diagnostics: fit.diagnostics,
        notes: Vec::new(),
    })
}

/// The highest frequency analysed, as a fraction of the sample rate: 0.45 (90 % of the
/// Nyquist frequency; the sensor's anti-alias filter rolls off above that).
const NYQUIST_USE: f64 = 0.45;

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
    let column = match opts.column {
        SpectrumColumn::Total => psd.sum(),
        SpectrumColumn::Axis(k) => psd.axis(k).ok_or_else(|| {
            IdentifyError::format(
                &psd.source,
                (psd.last_line + 1 - psd.freq_hz.len())
                    .saturating_sub(1)
                    .max(1),
                "a spectrum without per-axis columns",
                "the header `freq,psd_x,psd_y,psd_z,psd_xyz` to fit one sensor axis's column (or fit the total)",
            )
        })?,
    };
    let name = match opts.column {
        SpectrumColumn::Total => usize::from(psd.per_axis) * 3,
        SpectrumColumn::Axis(k) => k,
    };
    check_spectrum_vibration(
        &psd.source,
        psd.columns.get(name).map_or("", |c| c.0.as_str()),
        &psd.freq_hz,
        column,
        (opts.test.freq_start_hz, opts.test.freq_end_hz),
    )?;
    stored[first_bin..].copy_from_slice(column);
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
    check_trust(
        &psd.source,
        &fit.modes,
        &fit.diagnostics,
        fit.diagnostics.span,
        f64::INFINITY,
    )?;
    let mut notes = Vec::new();
    let last_hz = psd.freq_hz.last().copied().unwrap_or(0.0);
    if opts.test.freq_end_hz > last_hz + bin_hz {
        notes.push(unseen_band(
            fit.diagnostics.span,
            opts.test.freq_end_hz,
            format!("the file's last row, {last_hz:.1} Hz"),
        ));
    }
    Ok(AxisIdentification {
        source: psd.source.clone(),
        direction: None,
        dominant_sensor_axis: dominant,
        named_axis: None,
        modes: fit.modes,
        method: Method::SweepFit,
        diagnostics: fit.diagnostics,
        notes,
        figure,
    })
}

/// The note for a test whose band reaches past what the data show: `span_hz` is the band
/// fitted, `end_hz` the test's last frequency, `limit` what ends the data.
fn unseen_band(span_hz: (f64, f64), end_hz: f64, limit: String) -> String {
    format!(
        "analysed {:.1} to {:.1} Hz of a test that swept up to {end_hz} Hz: the band analysed ends at {limit}; a mode between {:.1} and {end_hz} Hz is not seen here",
        span_hz.0, span_hz.1, span_hz.1
    )
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
    let on_bins = |values: &[f64]| {
        let mut out = vec![f64::NAN; n];
        for (&k, &m) in fit.bins.iter().zip(values) {
            if let Some(i) = k.checked_sub(offset).filter(|&i| i < n) {
                out[i] = m * factor[i];
            }
        }
        out
    };
    let model = on_bins(&fit.model);
    let components = fit.components.iter().map(|c| on_bins(c)).collect();
    Figure {
        x: x[..n].to_vec(),
        measured: measured[..n].to_vec(),
        model,
        mode_freqs_hz: fit.modes.iter().map(|m| m.frequency_hz.value).collect(),
        components,
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
