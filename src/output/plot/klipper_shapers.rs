//! The graph of `settle tune --criterion klipper --out`: what Klipper's
//! `scripts/calibrate_shaper.py` draws for one axis. Top: the PSD summed over the sensor
//! axes (and each axis when the data hold them), and the PSD after the recommended shaper;
//! bottom: each shaper's remaining vibration at its chosen frequency, the worst over the
//! test damping ratios (the script's `vals`).

use std::path::PathBuf;

use settle_planner::shaper::{KLIPPER_DEFAULT_DAMPING_RATIO, Shaper, remaining_vibration};
use settle_planner::shaper_select::{CalibrationData, Fit, MAX_FREQ_HZ, SelectOptions, Selection};

use crate::output::plot::{Figure, Line, PALETTE, Panel, Rule};

/// The remaining vibration of `fit`'s shaper at `freq_hz`, worst over the test damping
/// ratios; `None` when the shaper cannot be built.
fn response(fit: &Fit, opts: &SelectOptions, freq_hz: &[f64]) -> Option<Vec<f64>> {
    let zeta = if opts.damping_ratio == 0.0 {
        KLIPPER_DEFAULT_DAMPING_RATIO
    } else {
        opts.damping_ratio
    };
    let shaper = Shaper::new(fit.shaper_type, fit.frequency_hz, zeta).ok()?;
    let (a, t) = (shaper.amplitudes(), shaper.times_s());
    Some(
        freq_hz
            .iter()
            .map(|&f| {
                opts.test_damping_ratios
                    .iter()
                    .map(|&dr| remaining_vibration(a, t, f, dr))
                    .fold(0.0, f64::max)
            })
            .collect(),
    )
}

/// The figure for the choice `selection` on one axis (`axis`: `x`, `y`, `z` or `all`),
/// from the spectrum `data` of `files`.
pub fn figure(
    axis: &str,
    files: &[PathBuf],
    data: &CalibrationData,
    selection: &Selection,
    opts: &SelectOptions,
) -> Figure {
    let max_freq = opts.max_freq_hz.unwrap_or(MAX_FREQ_HZ);
    let keep: Vec<usize> = (0..data.freq_hz.len())
        .filter(|&i| data.freq_hz[i] <= max_freq)
        .collect();
    let freq: Vec<f64> = keep.iter().map(|&i| data.freq_hz[i]).collect();
    let series =
        |v: &[f64]| -> Vec<(f64, f64)> { keep.iter().map(|&i| (data.freq_hz[i], v[i])).collect() };
    let mut psd_lines = vec![Line::new(
        Some("X+Y+Z".into()),
        PALETTE[4],
        series(&data.psd_sum),
    )];
    for (k, (name, p)) in [("X", &data.psd_x), ("Y", &data.psd_y), ("Z", &data.psd_z)]
        .into_iter()
        .enumerate()
    {
        if let Some(p) = p {
            let mut l = Line::new(Some(name.into()), PALETTE[k], series(p));
            l.width = 1;
            psd_lines.push(l);
        }
    }
    let rec = &selection.recommended;
    if let Some(v) = response(rec, opts, &freq) {
        let after = keep
            .iter()
            .zip(&v)
            .map(|(&i, r)| (data.freq_hz[i], data.psd_sum[i] * r))
            .collect();
        psd_lines.push(Line::new(
            Some(format!(
                "after {} @ {:.1} Hz",
                rec.shaper_type.name(),
                rec.frequency_hz
            )),
            PALETTE[5],
            after,
        ));
    }
    let mut shaper_lines = Vec::new();
    for (k, s) in selection.per_shaper.iter().enumerate() {
        if let Some(v) = response(s, opts, &freq) {
            let label = format!(
                "{} ({:.1} Hz, vibr={:.1}%, sm~={:.2}, accel<={:.0})",
                s.shaper_type.name(),
                s.frequency_hz,
                s.vibrations * 100.0,
                s.smoothing_mm,
                (s.max_accel_mm_s2 / 100.0).round_ties_even() * 100.0
            );
            let mut l = Line::new(
                Some(label),
                PALETTE[(k + 6) % PALETTE.len()],
                freq.iter().copied().zip(v).collect(),
            );
            l.width = if s == rec { 3 } else { 1 };
            shaper_lines.push(l);
        }
    }
    let files: Vec<String> = files.iter().map(|f| f.display().to_string()).collect();
    Figure {
        title: format!(
            "Klipper's choice, axis {axis}: {} @ {:.1} Hz ({})",
            rec.shaper_type.name(),
            rec.frequency_hz,
            files.join(", ")
        ),
        panels: vec![
            Panel {
                title: "power spectral density".into(),
                x_label: "frequency (Hz)".into(),
                y_label: "PSD (normalised to the test's frequencies)".into(),
                lines: psd_lines,
                vrules: vec![Rule {
                    at: rec.frequency_hz,
                    label: format!("{:.1} Hz", rec.frequency_hz),
                }],
                legend: true,
                ..Panel::default()
            },
            Panel {
                title: "shapers' remaining vibration (worst over the test damping ratios)".into(),
                x_label: "frequency (Hz)".into(),
                y_label: "remaining vibration (fraction)".into(),
                lines: shaper_lines,
                y_from_zero: true,
                legend: true,
                ..Panel::default()
            },
        ],
        columns: 1,
        width: 1000,
        row_height: 420,
        legend: Vec::new(),
    }
}
