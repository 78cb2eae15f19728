//! What is refused before and after a fit: a recording whose duration does not match
//! the resonance test it is said to hold (the test's parameters are then missing), and a
//! fit whose result cannot be stood behind.

use crate::IdentifyError;
use crate::excitation::SweepTest;
use crate::read::{
    MIN_PEAK_PSD, MIN_VIBRATION_M956_MM_S2, MIN_VIBRATION_MM_S2, Recording, RecordingFormat,
};
use crate::result::{Diagnostics, IdentifiedMode};

/// How much longer than the test a sweep recording may last (factor, plus seconds): Klipper
/// and Shake&Tune start the sensor a moment before the test and stop it after.
const DURATION_SLACK: (f64, f64) = (1.5, 10.0);

/// A Klipper raw file that is not a resonance test's (`ACCELEROMETER_MEASURE` writes
/// `adxl345-*.csv`; `TEST_RESONANCES` writes `raw_data_*.csv`) and lasts less than half
/// the test: a free recording, such as the ring-down after a move.
pub(crate) fn free_recording(rec: &Recording, duration_s: f64, test: &SweepTest) -> bool {
    let name = std::path::Path::new(&rec.source)
        .file_name()
        .map(|n| n.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    rec.format == RecordingFormat::KlipperRaw
        && !name.starts_with("raw_data")
        && duration_s < 0.5 * test.duration_s()
}

/// A recording must hold a vibration: some sensor axis must deviate from its mean by at
/// least one count of the finest sensor its firmware reads ([`MIN_VIBRATION_MM_S2`] for
/// Klipper's and Shake&Tune's files, [`MIN_VIBRATION_M956_MM_S2`] for M956's). Without one
/// (a sensor that read a constant, a file of zeros, values far below any sensor's
/// resolution) there is nothing to identify, and every spectrum of it is zero or rounding.
/// Every axis the file holds must vary too: a live sensor's axes all carry noise of a
/// count or more, so an axis that reads one value throughout while another varies was not
/// measured (a broken or unconnected axis, a column overwritten), and the direction of the
/// motion, found from all of them, would be found without it.
pub(crate) fn check_vibration(source: &str, rec: &Recording) -> Result<(), IdentifyError> {
    const NAMES: [&str; 3] = ["x", "y", "z"];
    let resolution = if rec.format == RecordingFormat::RrfM956 {
        MIN_VIBRATION_M956_MM_S2
    } else {
        MIN_VIBRATION_MM_S2
    };
    let mut largest = 0.0_f64;
    let mut means = Vec::new();
    let mut constant = Vec::new();
    for (k, c) in rec.accel_mm_s2.iter().enumerate() {
        let Some(c) = c else { continue };
        let mean = c.iter().sum::<f64>() / c.len() as f64;
        let dev = c.iter().fold(0.0_f64, |m, v| m.max((v - mean).abs()));
        largest = largest.max(dev);
        means.push(format!("{} {mean}", NAMES[k]));
        if c.iter().all(|v| *v == c[0]) {
            constant.push((NAMES[k], c[0]));
        }
    }
    if largest >= resolution {
        if let Some((name, value)) = constant.first() {
            return Err(IdentifyError::AxisNotMeasured {
                file: source.to_string(),
                reason: format!(
                    "sensor axis {name} reads {value} mm/s^2 in all {} samples while another axis varies by up to {largest:.3e} mm/s^2; a sensor's every axis carries noise of a count or more: check the sensor's wiring and `axes_map`, and that the file's columns are the sensor's",
                    rec.len()
                ),
            });
        }
        return Ok(());
    }
    let what = if largest == 0.0 {
        format!(
            "every sensor axis reads one value throughout ({} mm/s^2)",
            means.join(", ")
        )
    } else {
        format!(
            "no sensor axis deviates from its mean by more than {largest:.3e} mm/s^2 ({} mm/s^2)",
            means.join(", ")
        )
    };
    let finest = if rec.format == RecordingFormat::RrfM956 {
        "one count of the finest resolution RepRapFirmware reads, 1/16384 g"
    } else {
        "one count of the finest sensor Klipper reads, an MPU-9250's 1/4096 g"
    };
    Err(IdentifyError::NoVibration {
        file: source.to_string(),
        reason: format!(
            "{what}; a recording of a moving machine varies by at least {resolution:.3} mm/s^2 ({finest}; no sensor resolves less): check the file's unit, and that the sensor was read while the machine moved"
        ),
    })
}

/// A processed spectrum's column `name` must hold a peak of at least [`MIN_PEAK_PSD`]
/// inside `band_hz`: a spectrum of zeros (a sensor that read a constant) holds no
/// vibration.
pub(crate) fn check_spectrum_vibration(
    source: &str,
    name: &str,
    freq_hz: &[f64],
    column: &[f64],
    band_hz: (f64, f64),
) -> Result<(), IdentifyError> {
    let largest = freq_hz
        .iter()
        .zip(column)
        .filter(|(f, _)| **f >= band_hz.0 && **f <= band_hz.1)
        .fold(0.0_f64, |m, (_, v)| m.max(*v));
    if largest >= MIN_PEAK_PSD {
        return Ok(());
    }
    let what = if largest == 0.0 {
        format!(
            "column `{name}` is 0 at every frequency from {} to {} Hz",
            band_hz.0, band_hz.1
        )
    } else {
        format!(
            "column `{name}` peaks at {largest:.3e} (mm/s^2)^2/Hz between {} and {} Hz",
            band_hz.0, band_hz.1
        )
    };
    Err(IdentifyError::NoVibration {
        file: source.to_string(),
        reason: format!(
            "{what}; a spectrum of a resonance test peaks at {MIN_PEAK_PSD:.0e} (mm/s^2)^2/Hz or more (the PSD of a vibration at the 1e-6 mm/s^2 resolution Klipper writes)"
        ),
    })
}

/// A sweep recording must last about as long as the test it is said to hold: the test's
/// parameters shape the model, so a recording of another test would be fitted against the
/// wrong excitation. Klipper's raw files and Shake&Tune's do not record the parameters.
pub(crate) fn check_duration(
    source: &str,
    duration_s: f64,
    test: &SweepTest,
) -> Result<(), IdentifyError> {
    let d = test.duration_s();
    if duration_s >= 0.9 * d && duration_s <= DURATION_SLACK.0 * d + DURATION_SLACK.1 {
        return Ok(());
    }
    Err(IdentifyError::NeedsTestParameters {
        file: source.to_string(),
        reason: format!(
            "the recording lasts {duration_s:.1} s, but a resonance test from {} to {} Hz at {} Hz/s lasts {d:.1} s; the file does not record the test's parameters, and the fit needs them (they shape the excitation it models): give --freq-start, --freq-end and --hz-per-sec as in the TEST_RESONANCES command (and --accel-per-hz, --sweeping-accel, --sweeping-period where [resonance_tester] sets them), or --method ringdown for a free decay",
            test.freq_start_hz, test.freq_end_hz, test.hz_per_sec
        ),
    })
}

/// Refuse a fit that cannot be stood behind: a frequency that is not finite, at or above
/// `nyquist_hz` or outside `band_hz` (the span the data cover), a damping ratio outside
/// `(0, 1)`, an uncertainty that is not finite or not smaller than its value, a fit that
/// did not converge.
pub(crate) fn check_trust(
    source: &str,
    modes: &[IdentifiedMode],
    diagnostics: &Diagnostics,
    band_hz: (f64, f64),
    nyquist_hz: f64,
) -> Result<(), IdentifyError> {
    let fail = |reason: String| {
        Err(IdentifyError::Unreliable {
            file: source.to_string(),
            reason,
        })
    };
    if !diagnostics.converged {
        return fail(
            "the least-squares fit stopped at its iteration limit without converging".into(),
        );
    }
    for m in modes {
        let (f, z) = (m.frequency_hz, m.damping_ratio);
        let name = format!("the mode at {:.2} Hz", f.value);
        if !(f.value.is_finite() && f.value > 0.0) {
            return fail(format!("a mode frequency of {} Hz", f.value));
        }
        if f.value >= nyquist_hz {
            return fail(format!(
                "{name} lies at or above the Nyquist frequency {nyquist_hz:.1} Hz"
            ));
        }
        if f.value < band_hz.0 || f.value > band_hz.1 {
            return fail(format!(
                "{name} lies outside the {:.1}-{:.1} Hz the data cover",
                band_hz.0, band_hz.1
            ));
        }
        if !(z.value.is_finite() && z.value > 0.0 && z.value < 1.0) {
            return fail(format!("{name} has a damping ratio of {}", z.value));
        }
        for (what, e) in [("frequency", f), ("damping ratio", z)] {
            if !(e.sigma.is_finite() && e.sigma < e.value) {
                return fail(format!(
                    "{name}: its {what} {} has an uncertainty of {} (not smaller than the value)",
                    e.value, e.sigma
                ));
            }
        }
    }
    Ok(())
}
