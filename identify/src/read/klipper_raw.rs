//! Klipper's raw accelerometer CSV.
//!
//! Written by `AccelQueryHelper::write_to_file` in Klipper's `klippy/extras/adxl345.py`
//! (used by `ACCELEROMETER_MEASURE` and `TEST_RESONANCES ... OUTPUT=raw_data`): a header
//! `#time,accel_x,accel_y,accel_z`, then one `%.6f,%.6f,%.6f,%.6f` row per sample: time (s,
//! the MCU's print time) and acceleration (mm/s^2) with the chip's `axes_map` already
//! applied. Klipper's own parser (`scripts/calibrate_shaper.py`, `np.loadtxt(...,
//! comments='#')`) skips every line starting with `#`; so does this one.

use super::{
    KLIPPER_CLIP_REMEDY, MAX_SAMPLES, MIN_SAMPLES, Recording, RecordingFormat, check_accel,
    check_clipping, check_times, klipper_clip_axis, parse_number, too_many_samples, truncate,
};
use crate::IdentifyError;

/// The header line Klipper writes.
pub const HEADER: &str = "#time,accel_x,accel_y,accel_z";

const COLUMNS: [&str; 4] = ["time", "accel_x", "accel_y", "accel_z"];

/// Parse the text of a raw file; `file` names it in errors.
pub fn parse(file: &str, text: &str) -> Result<Recording, IdentifyError> {
    let mut lines = text.lines().enumerate().map(|(i, l)| (i + 1, l.trim()));
    // The first non-empty line must be the header.
    let header = lines.by_ref().find(|(_, l)| !l.is_empty());
    match header {
        Some((_, l)) if l.replace(' ', "") == HEADER => {}
        Some((n, l)) => {
            return Err(IdentifyError::format(
                file,
                n,
                format!("header `{}`", truncate(l)),
                format!("the header `{HEADER}`"),
            ));
        }
        None => {
            return Err(IdentifyError::format(
                file,
                1,
                "an empty file",
                format!("the header `{HEADER}`"),
            ));
        }
    }
    let capacity = text.len() / 40;
    let mut time_s = Vec::with_capacity(capacity);
    let mut axes: [Vec<f64>; 3] = std::array::from_fn(|_| Vec::with_capacity(capacity));
    let mut line_numbers = Vec::with_capacity(capacity);
    let mut last_line = 1;
    for (n, l) in lines {
        if l.is_empty() || l.starts_with('#') {
            continue;
        }
        let mut fields = l.split(',');
        let mut row = [0.0; 4];
        for (k, v) in row.iter_mut().enumerate() {
            let Some(text) = fields.next() else {
                return Err(IdentifyError::format(
                    file,
                    n,
                    format!("{k} fields (`{}`)", truncate(l)),
                    "4 comma-separated numbers: time (s), accel_x, accel_y, accel_z (mm/s^2)",
                ));
            };
            *v = parse_number(file, n, COLUMNS[k], text)?;
            if k > 0 {
                check_accel(file, n, COLUMNS[k], text, *v)?;
            }
        }
        if fields.next().is_some() {
            return Err(IdentifyError::format(
                file,
                n,
                format!("more than 4 fields (`{}`)", truncate(l)),
                "4 comma-separated numbers: time (s), accel_x, accel_y, accel_z (mm/s^2)",
            ));
        }
        if time_s.len() == MAX_SAMPLES {
            return Err(too_many_samples(file, n));
        }
        time_s.push(row[0]);
        for (a, v) in axes.iter_mut().zip(&row[1..]) {
            a.push(*v);
        }
        line_numbers.push(n);
        last_line = n;
    }
    if time_s.len() < MIN_SAMPLES {
        return Err(IdentifyError::TooFewSamples {
            file: file.to_string(),
            line: last_line,
            what: "samples",
            found: time_s.len(),
            needed: MIN_SAMPLES,
        });
    }
    check_times(file, &time_s, |i| line_numbers[i])?;
    let clip: Vec<_> = axes
        .iter()
        .zip(&COLUMNS[1..])
        .map(|(a, c)| klipper_clip_axis(c.to_string(), a))
        .collect();
    check_clipping(
        file,
        &clip,
        |i| line_numbers[i],
        |i| time_s[i],
        |c, _| c.to_string(),
        KLIPPER_CLIP_REMEDY,
    )?;
    let span = time_s[time_s.len() - 1] - time_s[0];
    let [x, y, z] = axes;
    Ok(Recording {
        source: file.to_string(),
        format: RecordingFormat::KlipperRaw,
        name: None,
        sample_rate_hz: time_s.len() as f64 / span,
        time_s,
        accel_mm_s2: [Some(x), Some(y), Some(z)],
        named_axis: None,
        last_line,
    })
}
