//! The outputs of `settle gcode`: `layers.csv` (one row per layer), `summary.md` (print
//! time, worst and 95th-percentile contour error, the worst spots with their G-code
//! lines, the layers) and `ringing-layer-<n>.svg/.png` (the maps of the worst layers).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::GcodeOutcome;
use crate::error::Error;
use crate::kinds::gcode::stats::LayerMap;
use crate::output::atomic::{create_dir, write_atomic};
use crate::output::plot::ringing::{MapPanel, MapSpot, RingingMap};

/// layers.csv's columns.
pub const LAYER_COLUMNS: [&str; 14] = [
    "layer",
    "z_mm",
    "start_s",
    "duration_s",
    "moves",
    "simulated",
    "print_moves",
    "worst_um",
    "p95_um",
    "mean_move_worst_um",
    "worst_line",
    "worst_x_mm",
    "worst_y_mm",
    "end_residual_um",
];

/// layers.csv as bytes.
pub fn layers_csv(o: &GcodeOutcome) -> Result<Vec<u8>, csv::Error> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record(LAYER_COLUMNS)?;
    let num = |v: f64| format!("{v}");
    for l in &o.layers {
        let mut row = vec![
            l.layer.to_string(),
            l.z_mm.map(num).unwrap_or_default(),
            num(l.start_s),
            num(l.duration_s),
            l.moves.to_string(),
        ];
        match &l.stats {
            Some(s) => {
                row.push("true".into());
                row.push(s.print_moves.to_string());
                row.push(num(s.worst_um()));
                row.push(num(s.p95_um));
                row.push(num(s.mean_move_worst_um));
                match &s.worst {
                    Some(w) => row.extend([w.line.to_string(), num(w.x_mm), num(w.y_mm)]),
                    None => row.extend([String::new(), String::new(), String::new()]),
                }
                row.push(s.end_residual_um.map(num).unwrap_or_default());
            }
            None => {
                row.push("false".into());
                row.extend(std::iter::repeat_n(String::new(), 8));
            }
        }
        w.write_record(&row)?;
    }
    w.into_inner().map_err(|e| csv::Error::from(e.into_error()))
}

/// summary.md.
pub fn summary_md(o: &GcodeOutcome, maps: &[String]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# {}\n", o.file.display());
    let _ = writeln!(
        s,
        "{} planner on `{}` ({} backend).\n",
        o.setting,
        o.machine,
        o.backend.name()
    );
    let _ = writeln!(
        s,
        "| print time | worst contour error | p95 contour error | simulated |"
    );
    let _ = writeln!(s, "|---:|---:|---:|---:|");
    let _ = writeln!(
        s,
        "| {:.1} s ({:.1} min) | {:.2} um | {:.2} um | {:.1} s of print |\n",
        o.print_time_s,
        o.print_time_s / 60.0,
        o.worst_um,
        o.p95_um,
        o.streamed.simulated_s
    );
    let _ = writeln!(
        s,
        "Contour error: distance in XY from the simulated toolhead to the commanded path of \
the moves active at that time, over printing moves; p95 is the 95th percentile of all \
printing samples.\n"
    );
    if o.streamed.preroll_s > 0.0 {
        let _ = writeln!(
            s,
            "The layer range was simulated from {:.2} s before its first move (the pre-roll, \
not counted), so that it starts from the vibration the layers before leave.\n",
            o.streamed.preroll_s
        );
    }
    if let Some(t) = &o.streamed.tail {
        let _ = writeln!(
            s,
            "Ringing after the last move: {:.2} um at most from the end point, {:.3} um after \
{:.2} s.\n",
            t.residual_peak_um, t.residual_last_um, t.duration_s
        );
    }
    if let Some(f) = &o.streamed.fault {
        let _ = writeln!(s, "**Simulation fault**: {f}\n");
    }
    if o.streamed.lost_steps > 0 {
        let _ = write!(
            s,
            "**Lost steps**: {} full steps: a motor's load angle passed 90 electrical degrees, \
more torque than it has",
            o.streamed.lost_steps
        );
        if let Some(l) = &o.streamed.first_lost_step {
            let _ = write!(
                s,
                " (first seen on axis {} at {:.3} s, line {}, layer {})",
                l.axis, l.time_s, l.line, l.layer
            );
        }
        let _ = writeln!(
            s,
            "; the part would differ from this toolpath after that.\n"
        );
    }
    let _ = writeln!(s, "## Worst spots\n");
    let _ = writeln!(
        s,
        "| error (um) | line | layer | X (mm) | Y (mm) | time (s) |"
    );
    let _ = writeln!(s, "|---:|---:|---:|---:|---:|---:|");
    for w in o.worst() {
        let _ = writeln!(
            s,
            "| {:.2} | {} | {} | {:.2} | {:.2} | {:.3} |",
            w.error_um, w.line, w.layer, w.x_mm, w.y_mm, w.time_s
        );
    }
    let _ = writeln!(s, "\n## Layers\n");
    let _ = writeln!(
        s,
        "| layer | Z (mm) | time (s) | moves | worst (um) | p95 (um) | worst line |"
    );
    let _ = writeln!(s, "|---:|---:|---:|---:|---:|---:|---:|");
    for l in &o.layers {
        let z = l.z_mm.map_or(String::new(), |z| format!("{z:.2}"));
        let (w, p, line) = match &l.stats {
            Some(st) => (
                format!("{:.2}", st.worst_um()),
                format!("{:.2}", st.p95_um),
                st.worst
                    .as_ref()
                    .map_or(String::new(), |w| w.line.to_string()),
            ),
            None => ("-".into(), "-".into(), "-".into()),
        };
        let _ = writeln!(
            s,
            "| {} | {z} | {:.2} | {} | {w} | {p} | {line} |",
            l.layer, l.duration_s, l.moves
        );
    }
    if !o.ignored.is_empty() {
        let _ = writeln!(s, "\n## Commands not followed\n");
        for (what, n) in &o.ignored {
            let _ = writeln!(s, "- {what}: {n}");
        }
    }
    if !maps.is_empty() {
        let _ = writeln!(s, "\n## Ringing maps\n");
        for m in maps {
            let _ = writeln!(s, "![{m}]({m}.svg)");
        }
    }
    s
}

/// The figure of one layer's map, titled with its setting.
pub fn map_panel(m: &LayerMap, setting: &str) -> MapPanel {
    MapPanel {
        title: format!("layer {}, {setting}", m.layer),
        points: m.points.clone(),
        spots: m
            .spots
            .iter()
            .take(3)
            .map(|s| MapSpot {
                x_mm: s.x_mm,
                y_mm: s.y_mm,
                error_um: s.error_um,
                line: s.line,
            })
            .collect(),
    }
}

/// Write the outputs into `dir`; returns the files written.
pub fn write(o: &GcodeOutcome, dir: &Path) -> Result<Vec<PathBuf>, Error> {
    create_dir(dir)?;
    let mut files = Vec::new();
    let csv_path = dir.join("layers.csv");
    let bytes = layers_csv(o).map_err(|e| Error::write(&csv_path, std::io::Error::other(e)))?;
    write_atomic(&csv_path, &bytes)?;
    files.push(csv_path);
    let setting = format!("{} on {}", o.setting, o.machine);
    let mut stems = Vec::new();
    for m in o.maps() {
        let stem = format!("ringing-layer-{}", m.layer);
        RingingMap {
            title: format!("Contour error, {}", o.file.display()),
            panels: vec![map_panel(m, &setting)],
        }
        .write(dir, &stem)?;
        files.push(dir.join(format!("{stem}.svg")));
        files.push(dir.join(format!("{stem}.png")));
        stems.push(stem);
    }
    let md = dir.join("summary.md");
    write_atomic(&md, summary_md(o, &stems).as_bytes())?;
    files.push(md);
    Ok(files)
}
