//! `settle tune --criterion klipper FILE.csv`: Klipper's own shaper choice on a processed
//! resonance CSV (`resonances_*.csv`, `calibration_data_*.csv`), as its
//! `scripts/calibrate_shaper.py` makes it: read the PSD columns (one data set per column,
//! or `psd_xyz` of the per-axis layout), normalise them to the test's frequencies unless
//! the header holds the `shapers:` column (the script's rule), then `find_best_shaper` with
//! Klipper's defaults (settle-planner's `shaper_select`, matched against the script). The
//! output repeats the script's lines, so the two can be compared word for word.

use std::fmt::Write as _;
use std::path::Path;

use settle_identify::read::klipper_psd;
use settle_planner::shaper_select::{CalibrationData, SelectOptions, Selection, find_best_shaper};

use crate::error::Error;
use crate::workflows::{Exit, Report};

/// Klipper's choice on the processed CSV at `path`.
pub fn choose(path: &Path) -> Result<Selection, Error> {
    let text = crate::input::file::read_text(path, crate::input::file::limit::RECORDING)?;
    let psd = klipper_psd::parse(&path.display().to_string(), &text)
        .map_err(|e| Error::input(path, e.to_string()))?;
    // calibrate_shaper.py normalises unless the header has the `shapers:` column.
    let header = text
        .lines()
        .find(|l| !l.trim_start().starts_with('#'))
        .unwrap_or_default();
    let normalise = !header.contains(",shapers:");
    let columns: Vec<&Vec<f64>> = if psd.per_axis {
        vec![&psd.columns[3].1]
    } else {
        psd.columns.iter().map(|(_, c)| c).collect()
    };
    let data: Vec<CalibrationData> = columns
        .into_iter()
        .map(|c| {
            let mut d = CalibrationData {
                freq_hz: psd.freq_hz.clone(),
                psd_sum: c.clone(),
                ..CalibrationData::default()
            };
            if normalise {
                d.normalize_to_frequencies();
            }
            d
        })
        .collect();
    find_best_shaper(&data, &SelectOptions::default())
        .map_err(|e| Error::input(path, e.to_string()))
}

/// What `settle tune --criterion klipper FILE.csv` prints: calibrate_shaper.py's lines.
pub fn report(path: &Path) -> Result<Report, Error> {
    let sel = choose(path)?;
    let mut r = Report::new(Exit::Ok);
    r.out(format!("Processing resonances from {}", path.display()));
    for s in &sel.per_shaper {
        r.out(format!(
            "Fitted shaper '{}' frequency = {:.1} Hz (vibrations = {:.1}%, smoothing ~= {:.3})",
            s.kind.name(),
            s.frequency_hz,
            s.vibrations * 100.0,
            s.smoothing_mm
        ));
        let mut line = String::new();
        let _ = write!(
            line,
            "To avoid too much smoothing with '{}', suggested max_accel <= {:.0} mm/sec^2",
            s.kind.name(),
            (s.max_accel_mm_s2 / 100.0).round_ties_even() * 100.0 // Python 3 round()
        );
        r.out(line);
    }
    r.out(format!(
        "Recommended shaper is {} @ {:.1} Hz",
        sel.recommended.kind.name(),
        sel.recommended.frequency_hz
    ));
    Ok(r)
}
