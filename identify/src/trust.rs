//! What is refused before and after a fit: a recording whose duration does not match
//! the resonance test it is said to hold (the test's parameters are then missing), and a
//! fit whose result cannot be stood behind.

use crate::IdentifyError;
use crate::excitation::SweepTest;
use crate::read::{Recording, RecordingFormat};
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
