//! Shake&Tune's `.stdata` files.
//!
//! Written by `MeasurementsManager` in Shake&Tune's `shaketune/helpers/accelerometer.py`: a
//! zstd stream of JSON lines, one measurement per line, each `{"name": <str>, "samples":
//! [[t, x, y, z], ...]}` with the samples as Klipper's accelerometer client delivers them
//! (time in s, acceleration in mm/s^2, axes map applied). Line numbers in errors count
//! the lines of the decompressed text.

use serde::Deserialize;

use super::{
    KLIPPER_CLIP_REMEDY, MAX_ACCEL_MM_S2, MAX_SAMPLES, MIN_SAMPLES, Recording, RecordingFormat,
    check_accel, check_clipping, check_times, klipper_clip_axis, too_many_samples,
};
use crate::IdentifyError;

#[derive(Deserialize)]
struct Measurement {
    name: String,
    samples: Vec<[f64; 4]>,
}

/// Parse the bytes of a `.stdata` file into one recording per measurement.
pub fn parse(file: &str, bytes: &[u8]) -> Result<Vec<Recording>, IdentifyError> {
    // Decompressed text is capped as a recording file is: a small file can inflate to GBs.
    let limit = settle_files::limit::RECORDING;
    let not_text = |e: &dyn std::fmt::Display| {
        IdentifyError::format(
            file,
            1,
            format!("data that do not decompress to text ({e})"),
            "a zstd-compressed stream of JSON lines (Shake&Tune .stdata)",
        )
    };
    let inflated = zstd::stream::read::Decoder::new(bytes)
        .and_then(|d| settle_files::read::read_capped(d, limit.bytes))
        .map_err(|e| not_text(&e))?
        .ok_or_else(|| {
            settle_files::FileError::too_large(
                file,
                format!("more than {} bytes of text once decompressed", limit.bytes),
                limit,
            )
        })?;
    let text = String::from_utf8(inflated).map_err(|e| not_text(&e))?;
    let mut out = Vec::new();
    let mut last = 0;
    for (i, line) in text.lines().enumerate() {
        let n = i + 1;
        last = n;
        if line.trim().is_empty() {
            continue;
        }
        // Each sample is one `[`: more than the limit is refused before it is held.
        if line.bytes().filter(|&b| b == b'[').count() > MAX_SAMPLES + 1 {
            return Err(too_many_samples(file, n));
        }
        let m: Measurement = serde_json::from_str(line).map_err(|e| {
            IdentifyError::format(
                file,
                n,
                format!("invalid JSON at column {}: {e}", e.column()),
                "one JSON object per line: {\"name\": <text>, \"samples\": [[t, x, y, z], ...]} with finite numbers",
            )
        })?;
        if m.samples.len() < MIN_SAMPLES {
            return Err(IdentifyError::TooFewSamples {
                file: file.to_string(),
                line: n,
                what: "samples",
                found: m.samples.len(),
                needed: MIN_SAMPLES,
            });
        }
        let time_s: Vec<f64> = m.samples.iter().map(|s| s[0]).collect();
        check_times(file, &time_s, |_| n)?;
        let too_large = |v: &f64| v.abs() > MAX_ACCEL_MM_S2;
        if let Some(i) = m.samples.iter().position(|s| s[1..].iter().any(too_large)) {
            for (k, axis) in ["x", "y", "z"].iter().enumerate() {
                let v = m.samples[i][k + 1];
                let column = format!("samples[{i}] {axis}");
                check_accel(file, n, &column, &v.to_string(), v)?;
            }
        }
        let axes: [Vec<f64>; 3] =
            std::array::from_fn(|k| m.samples.iter().map(|s| s[k + 1]).collect());
        let clip: Vec<_> = axes
            .iter()
            .zip(["x", "y", "z"])
            .map(|(a, name)| klipper_clip_axis(name.to_string(), a))
            .collect();
        // A sample is named by its index in the measurement's `samples` (the line holds
        // them all), as `check_accel` names it.
        let name_of = |c: &str, i: usize| format!("samples[{i}] {c}");
        check_clipping(
            file,
            &clip,
            |_| n,
            |i| time_s[i],
            name_of,
            KLIPPER_CLIP_REMEDY,
        )?;
        let span = time_s[time_s.len() - 1] - time_s[0];
        let [x, y, z] = axes;
        out.push(Recording {
            source: file.to_string(),
            format: RecordingFormat::ShakeTune,
            name: Some(m.name.clone()),
            sample_rate_hz: time_s.len() as f64 / span,
            accel_mm_s2: [Some(x), Some(y), Some(z)],
            time_s,
            named_axis: None,
            last_line: n,
        });
    }
    if out.is_empty() {
        return Err(IdentifyError::TooFewSamples {
            file: file.to_string(),
            line: last.max(1),
            what: "measurements",
            found: 0,
            needed: 1,
        });
    }
    Ok(out)
}
