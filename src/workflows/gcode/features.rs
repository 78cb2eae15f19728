//! The outputs of `settle gcode` about where on the part the error is: per slicer feature
//! type (`features.csv`, a section of summary.md, a table of report.html; the outer wall
//! first, then by worst error), per layer and type (`layer_features.csv`, a table of
//! report.html, the outer wall's columns of summary.md's layers), the fly-axis error of a raster job, and the figure of the
//! error against Z (`error-z.svg/png`: per layer the worst and 95th-percentile error, and
//! the outer wall's worst when the file names its features).

use std::fmt::Write as _;

use super::GcodeOutcome;
use crate::output::html::{Cell, Table};
use crate::output::plot::{Figure, Line, Marker, PALETTE, Panel};
use crate::studies::gcode::features::{FeatureStats, is_outer_wall};

/// features.csv's columns.
pub const FEATURE_COLUMNS: [&str; 9] = [
    "feature",
    "outer_wall",
    "samples",
    "worst_um",
    "p95_um",
    "worst_line",
    "worst_layer",
    "worst_x_mm",
    "worst_y_mm",
];

/// The name of feature index `i` (`(none named)` for moves before any `;TYPE:`).
fn name(o: &GcodeOutcome, i: u16) -> String {
    match o.features.get(usize::from(i)) {
        Some(n) if i > 0 => n.clone(),
        _ => "(none named)".into(),
    }
}

/// The feature types with samples, the outer wall first, then by worst error.
fn ranked(o: &GcodeOutcome) -> Vec<(String, &FeatureStats)> {
    let mut v: Vec<(String, &FeatureStats)> = o
        .streamed
        .features
        .stats
        .iter()
        .map(|(&i, s)| (name(o, i), s))
        .collect();
    v.sort_by(|a, b| {
        is_outer_wall(&b.0)
            .cmp(&is_outer_wall(&a.0))
            .then(b.1.worst_um().total_cmp(&a.1.worst_um()))
            .then(a.0.cmp(&b.0))
    });
    v
}

/// Whether the file names feature types.
pub fn has_features(o: &GcodeOutcome) -> bool {
    o.streamed.features.has_named()
}

/// features.csv as bytes.
pub fn features_csv(o: &GcodeOutcome) -> Result<Vec<u8>, csv::Error> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record(FEATURE_COLUMNS)?;
    for (n, s) in ranked(o) {
        let mut row = vec![
            n.clone(),
            is_outer_wall(&n).to_string(),
            s.errors.total().to_string(),
            format!("{}", s.worst_um()),
            format!("{}", s.errors.quantile_um(0.95)),
        ];
        match &s.worst {
            Some(w) => row.extend([
                w.line.to_string(),
                w.layer.to_string(),
                format!("{}", w.x_mm),
                format!("{}", w.y_mm),
            ]),
            None => row.extend(std::iter::repeat_n(String::new(), 4)),
        }
        w.write_record(&row)?;
    }
    w.into_inner().map_err(|e| csv::Error::from(e.into_error()))
}

/// layer_features.csv's columns.
pub const LAYER_FEATURE_COLUMNS: [&str; 6] = [
    "layer",
    "z_mm",
    "feature",
    "outer_wall",
    "worst_um",
    "p95_um",
];

/// The Z of layer `layer` (when the file gives one).
fn layer_z(o: &GcodeOutcome, layer: u32) -> Option<f64> {
    o.layers
        .iter()
        .find(|l| l.layer == layer)
        .and_then(|l| l.z_mm)
}

/// layer_features.csv as bytes: per layer, each feature type's worst and p95 (an empty
/// p95 when the layer's samples came in two separate runs).
pub fn layer_features_csv(o: &GcodeOutcome) -> Result<Vec<u8>, csv::Error> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record(LAYER_FEATURE_COLUMNS)?;
    let f = &o.streamed.features;
    for (&(layer, i), &worst) in &f.layer_worst {
        let n = name(o, i);
        let p95 = f.layer_p95.get(&(layer, i)).copied().unwrap_or(f64::NAN);
        w.write_record([
            layer.to_string(),
            layer_z(o, layer)
                .map(|z| format!("{z}"))
                .unwrap_or_default(),
            n.clone(),
            is_outer_wall(&n).to_string(),
            format!("{worst}"),
            if p95.is_nan() {
                String::new()
            } else {
                format!("{p95}")
            },
        ])?;
    }
    w.into_inner().map_err(|e| csv::Error::from(e.into_error()))
}

/// Whether the file names an outer wall among its feature types.
pub fn has_outer_wall(o: &GcodeOutcome) -> bool {
    o.features.iter().skip(1).any(|n| is_outer_wall(n))
}

/// The outer wall's worst and p95 (um) in layer `layer` (the outer-wall type with the
/// larger worst if the slicer names two); `None` when the layer has no outer wall.
pub fn layer_outer_wall(o: &GcodeOutcome, layer: u32) -> Option<(f64, f64)> {
    let f = &o.streamed.features;
    f.layer_worst
        .range((layer, 0)..=(layer, u16::MAX))
        .filter(|((_, i), _)| is_outer_wall(&name(o, *i)))
        .map(|(k, &w)| (w, f.layer_p95.get(k).copied().unwrap_or(f64::NAN)))
        .max_by(|a, b| a.0.total_cmp(&b.0))
}

/// The summary.md sections: the feature types (when the file names them) and the
/// fly-axis error (when the job is a raster).
pub fn summary_sections(o: &GcodeOutcome) -> String {
    let mut s = String::new();
    if has_features(o) {
        let _ = writeln!(s, "\n## Feature types\n");
        let _ = writeln!(
            s,
            "The slicer's `;TYPE:` of each move; the outer wall is what the part is judged by.\n"
        );
        let _ = writeln!(
            s,
            "| feature | worst (um) | p95 (um) | worst line | layer |"
        );
        let _ = writeln!(s, "|---|---:|---:|---:|---:|");
        for (n, f) in ranked(o) {
            let (line, layer) = f
                .worst
                .as_ref()
                .map_or((String::new(), String::new()), |w| {
                    (w.line.to_string(), w.layer.to_string())
                });
            let n = if is_outer_wall(&n) {
                format!("**{n}**")
            } else {
                n
            };
            let _ = writeln!(
                s,
                "| {n} | {:.2} | {:.2} | {line} | {layer} |",
                f.worst_um(),
                f.errors.quantile_um(0.95)
            );
        }
    }
    if let Some(line) = fly_words(o) {
        let _ = writeln!(s, "\n## Raster scan\n\n{line}");
    }
    s
}

/// The fly-axis error of a raster job in words, `None` when the job is not a raster.
pub fn fly_words(o: &GcodeOutcome) -> Option<String> {
    let f = &o.streamed.fly;
    let a = f.raster()?;
    let axis = ["X", "Y"][a];
    let worst = f.worst[a].as_ref()?;
    Some(format!(
        "Fly axis {axis} ({:.0} of {:.0} mm of working moves are scan lines along it): error along the scan line inside the scan region (the laser on), toolhead minus command, worst {:.2} um at line {} (layer {}), p95 {:.2} um.",
        f.length_mm[a],
        f.working_mm,
        worst.error_um,
        worst.line,
        worst.layer,
        f.errors[a].quantile_um(0.95)
    ))
}

/// The report.html table of the feature types (`None` when the file names none).
pub fn features_table(o: &GcodeOutcome) -> Option<Table> {
    if !has_features(o) {
        return None;
    }
    let num = |v: f64| Cell::Number {
        value: v,
        text: format!("{v:.2}"),
    };
    Some(Table {
        title: "Feature types".into(),
        note: "Contour error per slicer feature type (;TYPE: comments), over its working samples; the outer wall first.".into(),
        header: ["feature", "worst (um)", "p95 (um)", "worst line", "layer"]
            .map(String::from)
            .to_vec(),
        rows: ranked(o)
            .into_iter()
            .map(|(n, f)| {
                let (line, layer) = f.worst.as_ref().map_or((Cell::text(""), Cell::text("")), |w| {
                    (Cell::number(w.line as f64), Cell::number(f64::from(w.layer)))
                });
                vec![Cell::text(n), num(f.worst_um()), num(f.errors.quantile_um(0.95)), line, layer]
            })
            .collect(),
    })
}

/// The figure of the error against Z: per simulated layer with a Z, its worst and p95,
/// and the outer wall's worst. `None` with fewer than two such layers.
pub fn z_figure(o: &GcodeOutcome) -> Option<Figure> {
    let layers: Vec<(f64, f64, f64)> = o
        .layers
        .iter()
        .filter_map(|l| Some((l.z_mm?, l.stats.as_ref()?)))
        .filter(|(_, s)| s.worst.is_some())
        .map(|(z, s)| (z, s.worst_um(), s.p95_um))
        .collect();
    if layers.len() < 2 {
        return None;
    }
    // A print climbs in Z layer by layer: lines. A mill's passes come back to the same
    // depths: markers only.
    let climbs = layers.windows(2).all(|w| w[1].0 > w[0].0);
    let styled = |label: &str, color, marker, points: Vec<(f64, f64)>| {
        let mut l = Line::new(Some(label.into()), color, points);
        l.marker = Some(marker);
        if !climbs {
            l.width = 0;
        }
        l
    };
    let mut lines = vec![
        styled(
            "worst",
            PALETTE[0],
            Marker::Circle,
            layers.iter().map(|l| (l.0, l.1)).collect(),
        ),
        styled(
            "p95",
            PALETTE[1],
            Marker::Square,
            layers.iter().map(|l| (l.0, l.2)).collect(),
        ),
    ];
    let outer: Vec<u16> = o
        .features
        .iter()
        .enumerate()
        .filter(|(_, n)| is_outer_wall(n))
        .map(|(i, _)| i as u16)
        .collect();
    if !outer.is_empty() {
        let z_of = |layer: u32| layer_z(o, layer);
        let mut pts: Vec<(f64, f64)> = o
            .streamed
            .features
            .layer_worst
            .iter()
            .filter(|((_, f), _)| outer.contains(f))
            .filter_map(|((layer, _), w)| Some((z_of(*layer)?, *w)))
            .collect();
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        if !pts.is_empty() {
            lines.push(styled(
                "outer wall, worst",
                PALETTE[2],
                Marker::Triangle,
                pts,
            ));
        }
    }
    Some(Figure {
        title: format!("Contour error against Z, {}", o.file.display()),
        panels: vec![Panel {
            title: format!("{} on {}", o.setting, o.machine),
            x_label: "Z (mm)".into(),
            y_label: "contour error (um)".into(),
            lines,
            y_from_zero: true,
            legend: true,
            ..Panel::default()
        }],
        columns: 1,
        width: 900,
        row_height: 420,
        legend: Vec::new(),
    })
}
