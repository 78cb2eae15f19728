//! The figure of `settle identify`: per identified axis, the measured spectrum (or, for a
//! free decay, the measured acceleration), the fitted model on it, each mode's share of
//! the model (a spectrum: the model with that mode alone) and the modes marked; below it
//! the residual (a spectrum: measured over fitted, which is 1 where the model explains the
//! data; a decay: measured minus fitted).

use settle_identify::{AxisIdentification, Method};

use crate::output::plot::{Figure, Line, PALETTE, Panel, Rule};

/// The figure of `axis` identified as `id`.
pub fn figure(axis: &str, id: &AxisIdentification) -> Figure {
    let f = &id.figure;
    let spectrum = id.method == Method::SweepFit;
    // A log axis shows no zero or negative value (a processed spectrum is 0 below 5 Hz);
    // the model is NaN outside the fitted span.
    let keep = |y: f64| y.is_finite() && (!spectrum || y > 0.0);
    let points = |ys: &[f64]| -> Vec<(f64, f64)> {
        f.x.iter()
            .zip(ys)
            .filter(|(_, y)| keep(**y))
            .map(|(x, y)| (*x, *y))
            .collect()
    };
    let mut measured = Line::new(Some("measured".into()), PALETTE[0], points(&f.measured));
    measured.width = 1;
    let model = Line::new(Some("fitted model".into()), PALETTE[1], points(&f.model));
    let mut lines = vec![measured, model];
    for (k, (c, m)) in f.components.iter().zip(&id.modes).enumerate() {
        let mut l = Line::new(
            Some(format!("mode {k} alone ({:.1} Hz)", m.frequency_hz.value)),
            PALETTE[(k + 2) % PALETTE.len()],
            points(c),
        );
        l.width = 1;
        lines.push(l);
    }
    let residual: Vec<(f64, f64)> =
        f.x.iter()
            .zip(f.measured.iter().zip(&f.model))
            .filter_map(|(&x, (&y, &m))| {
                let r = if spectrum { y / m } else { y - m };
                (r.is_finite() && (!spectrum || r > 0.0)).then_some((x, r))
            })
            .collect();
    let modes: Vec<String> = id
        .modes
        .iter()
        .map(|m| {
            format!(
                "{:.1} Hz, zeta {:.3}",
                m.frequency_hz.value, m.damping_ratio.value
            )
        })
        .collect();
    let vrules = f
        .mode_freqs_hz
        .iter()
        .map(|&at| Rule {
            at,
            label: format!("{at:.1} Hz"),
        })
        .collect();
    let panel = Panel {
        title: format!("axis {axis}: {}", modes.join("; ")),
        x_label: f.labels.0.to_string(),
        y_label: f.labels.1.to_string(),
        lines,
        y_log: spectrum,
        vrules,
        legend: true,
        ..Panel::default()
    };
    let residual_panel = Panel {
        title: if spectrum {
            "residual: measured / fitted".into()
        } else {
            "residual: measured - fitted".into()
        },
        x_label: f.labels.0.to_string(),
        y_label: if spectrum {
            "ratio".into()
        } else {
            "acceleration (mm/s^2)".into()
        },
        lines: vec![Line::new(None, PALETTE[0], residual)],
        y_log: spectrum,
        hrules: vec![Rule {
            at: if spectrum { 1.0 } else { 0.0 },
            label: String::new(),
        }],
        ..Panel::default()
    };
    Figure {
        title: format!("settle identify: axis {axis} ({})", id.source),
        panels: vec![panel, residual_panel],
        columns: 1,
        width: 1000,
        row_height: 420,
        legend: Vec::new(),
    }
}
