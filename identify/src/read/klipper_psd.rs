//! Klipper's processed spectra (`resonances_*.csv`, `calibration_data_*.csv`).
//!
//! Written by `save_calibration_data` in Klipper's `klippy/extras/shaper_calibrate.py`:
//! a header `freq,psd_x,psd_y,psd_z,psd_xyz` (or, for several data sets since October
//! 2025, `freq,<name>,<name>...` holding each set's `psd_xyz` only), optionally followed by
//! the shapers' responses: older files append columns named like `zv(49.6)`, newer ones a
//! column `shapers:` (empty in every row) before them. Rows: frequency `%.1f`, PSD `%.3e`,
//! shaper responses `%.3f`.
//!
//! Two kinds of PSD: a file with shaper columns (`SHAPER_CALIBRATE`, `calibration_data_*`)
//! holds the PSD after `CalibrationData.normalize_to_frequencies`, a file without them
//! (`TEST_RESONANCES`, `resonances_*`) the PSD as computed. (Klipper's
//! `scripts/calibrate_shaper.py` told them apart by `'mzv' in header` until October 2025;
//! since then only by the `shapers:` column, so it normalises older `calibration_data_*`
//! files a second time: identify/tests/corpus/MANIFEST.md, the bassco files.) The
//! normalisation divides by `f + 0.1` and removes low frequencies: until December 2024 by
//! setting every bin below 5 Hz to zero, since then by multiplying bins below 10 Hz by
//! `exp(1 - (10 / (f + 0.1))^2)`. The reader tells these apart by the bins between 0 and
//! 5 Hz: all exactly zero means the older rule.

use super::{MAX_PSD, MAX_RATE_HZ, MAX_SPECTRUM_ROWS, parse_number, truncate};
use crate::IdentifyError;

/// Highest frequency a row may have (Hz): the Nyquist frequency of the fastest
/// recording a reader accepts ([`MAX_RATE_HZ`]).
pub const MAX_FREQ_HZ: f64 = MAX_RATE_HZ / 2.0;

/// Fewest frequency rows accepted.
pub const MIN_ROWS: usize = 16;

/// How the stored PSD relates to the PSD of the recording.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Normalisation {
    /// Stored as computed (`resonances_*.csv`).
    Raw,
    /// Divided by `f + 0.1`, zero below 5 Hz (Klipper until November 2024).
    ByFrequencyZeroBelow5Hz,
    /// Divided by `f + 0.1`, times `exp(1 - (10 / (f + 0.1))^2)` below 10 Hz (Klipper
    /// since December 2024).
    ByFrequencyTaperBelow10Hz,
}

impl Normalisation {
    /// Stored PSD = factor(f) x PSD of the recording. Zero where the file holds no
    /// information.
    pub fn factor(self, freq_hz: f64) -> f64 {
        match self {
            Normalisation::Raw => 1.0,
            Normalisation::ByFrequencyZeroBelow5Hz => {
                if freq_hz < 5.0 {
                    0.0
                } else {
                    1.0 / (freq_hz + 0.1)
                }
            }
            Normalisation::ByFrequencyTaperBelow10Hz => {
                let base = 1.0 / (freq_hz + 0.1);
                if freq_hz < 10.0 {
                    base * (1.0 - (10.0 / (freq_hz + 0.1)).powi(2)).exp()
                } else {
                    base
                }
            }
        }
    }
}

/// A processed spectrum as read.
#[derive(Debug, Clone, PartialEq)]
pub struct ProcessedPsd {
    /// The file, for messages.
    pub source: String,
    /// Frequencies as written (Hz, rounded to 0.1 Hz by Klipper's `%.1f`).
    pub freq_hz: Vec<f64>,
    /// The PSD columns in file order with their header names: `psd_x`, `psd_y`, `psd_z`,
    /// `psd_xyz` ((mm/s^2)^2/Hz before normalisation), or one column per data set.
    pub columns: Vec<(String, Vec<f64>)>,
    /// True for the per-axis layout (`psd_x,psd_y,psd_z,psd_xyz`).
    pub per_axis: bool,
    /// Names of the shaper columns (`zv(49.6)`...).
    pub shapers: Vec<String>,
    /// True when the header holds the `shapers:` column (Klipper since October 2025); the
    /// rule by which Klipper's `scripts/calibrate_shaper.py` takes a file's PSD as already
    /// normalised.
    pub shapers_marker: bool,
    /// How the PSD was normalised.
    pub normalisation: Normalisation,
    /// The last line read (for messages).
    pub last_line: usize,
}

impl ProcessedPsd {
    /// The PSD summed over the sensor axes (`psd_xyz`, or the first data set's column).
    pub fn sum(&self) -> &[f64] {
        let i = if self.per_axis { 3 } else { 0 };
        &self.columns[i].1
    }

    /// The per-axis PSD of sensor axis `k` (0 = x), when the file holds it.
    pub fn axis(&self, k: usize) -> Option<&[f64]> {
        (self.per_axis && k < 3).then(|| self.columns[k].1.as_slice())
    }
}

/// Parse the text of a processed file; `file` names it in errors.
pub fn parse(file: &str, text: &str) -> Result<ProcessedPsd, IdentifyError> {
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
    let expected_header = "`freq,psd_x,psd_y,psd_z,psd_xyz` (or `freq,<data set>...`), optionally followed by shaper columns";
    let Some((hn, header)) = lines.next() else {
        return Err(IdentifyError::format(
            file,
            1,
            "an empty file",
            expected_header,
        ));
    };
    let names = split_header(header);
    if names.len() < 2 || names[0] != "freq" {
        return Err(IdentifyError::format(
            file,
            hn,
            format!("header `{}`", truncate(header)),
            expected_header,
        ));
    }
    let per_axis = names.len() >= 5 && names[1..5] == ["psd_x", "psd_y", "psd_z", "psd_xyz"];
    let marker = names.iter().position(|n| n == "shapers:");
    let psd_end = if per_axis {
        5
    } else {
        marker.unwrap_or(names.len())
    };
    let shaper_start = marker.map_or(psd_end, |m| m + 1);
    if psd_end < 2 || (per_axis && marker.is_some_and(|m| m != 5)) {
        return Err(IdentifyError::format(
            file,
            hn,
            format!("header `{}`", truncate(header)),
            expected_header,
        ));
    }
    let shapers: Vec<String> = names[shaper_start..].to_vec();
    let mut freq_hz = Vec::new();
    let mut columns: Vec<(String, Vec<f64>)> = names[1..psd_end]
        .iter()
        .map(|n| (n.clone(), Vec::new()))
        .collect();
    let mut last_line = hn;
    for (n, l) in lines {
        let fields: Vec<&str> = l.split(',').collect();
        if fields.len() != names.len() {
            return Err(IdentifyError::format(
                file,
                n,
                format!("{} fields (`{}`)", fields.len(), truncate(l)),
                format!("{} fields, one per header column", names.len()),
            ));
        }
        let f = parse_number(file, n, "freq", fields[0])?;
        if !(0.0..=MAX_FREQ_HZ).contains(&f) {
            return Err(IdentifyError::format(
                file,
                n,
                format!(
                    "frequency {} Hz in column `freq`",
                    truncate(fields[0].trim())
                ),
                format!(
                    "a frequency from 0 to {MAX_FREQ_HZ} Hz (half the fastest sample rate settle reads, {MAX_RATE_HZ} Hz: no spectrum of a recording goes higher)"
                ),
            ));
        }
        if freq_hz.last().is_some_and(|&p| f <= p) {
            return Err(IdentifyError::format(
                file,
                n,
                format!("frequency {f} Hz after {} Hz", freq_hz[freq_hz.len() - 1]),
                "frequencies increasing from row to row",
            ));
        }
        if freq_hz.len() == MAX_SPECTRUM_ROWS {
            return Err(IdentifyError::not_accepted(
                file,
                format!("more than {MAX_SPECTRUM_ROWS} frequency rows (line {n})"),
                format!("at most {MAX_SPECTRUM_ROWS} rows a spectrum"),
            ));
        }
        freq_hz.push(f);
        for (k, (name, col)) in columns.iter_mut().enumerate() {
            let v = parse_number(file, n, name, fields[k + 1])?;
            if v < 0.0 {
                return Err(IdentifyError::format(
                    file,
                    n,
                    format!("{v} in column `{name}`"),
                    "a power spectral density >= 0",
                ));
            }
            if v > MAX_PSD {
                return Err(IdentifyError::format(
                    file,
                    n,
                    format!("{v:.3e} in column `{name}`"),
                    format!(
                        "a power spectral density of at most {MAX_PSD:.0e} (mm/s^2)^2/Hz (that of accelerations up to 100,000 g; the file's unit or scale is wrong)"
                    ),
                ));
            }
            col.push(v);
        }
        if let Some(m) = marker
            && !fields[m].trim().is_empty()
        {
            return Err(IdentifyError::format(
                file,
                n,
                format!("`{}` under `shapers:`", truncate(fields[m])),
                "an empty field under the `shapers:` column",
            ));
        }
        for (k, name) in shapers.iter().enumerate() {
            parse_number(file, n, name, fields[shaper_start + k])?;
        }
        last_line = n;
    }
    if freq_hz.len() < MIN_ROWS {
        return Err(IdentifyError::TooFewSamples {
            file: file.to_string(),
            line: last_line,
            what: "frequency rows",
            found: freq_hz.len(),
            needed: MIN_ROWS,
        });
    }
    let normalisation = if shapers.is_empty() {
        Normalisation::Raw
    } else {
        let low: Vec<usize> = (0..freq_hz.len())
            .filter(|&i| freq_hz[i] > 0.0 && freq_hz[i] < 5.0)
            .collect();
        let sum = &columns[if per_axis { 3 } else { 0 }].1;
        if !low.is_empty() && low.iter().all(|&i| sum[i] == 0.0) {
            Normalisation::ByFrequencyZeroBelow5Hz
        } else {
            Normalisation::ByFrequencyTaperBelow10Hz
        }
    };
    Ok(ProcessedPsd {
        source: file.to_string(),
        freq_hz,
        columns,
        per_axis,
        shapers,
        shapers_marker: marker.is_some(),
        normalisation,
        last_line,
    })
}

/// Split a header line on commas, honouring Klipper's CSV quoting of data-set names
/// (`"a,b"` with `""` for a quote).
fn split_header(header: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut cur = String::new();
    let mut quoted = false;
    let mut chars = header.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' if quoted && chars.peek() == Some(&'"') => {
                cur.push('"');
                chars.next();
            }
            '"' => quoted = !quoted,
            ',' if !quoted => out.push(std::mem::take(&mut cur).trim().to_string()),
            _ => cur.push(c),
        }
    }
    out.push(cur.trim().to_string());
    out
}
