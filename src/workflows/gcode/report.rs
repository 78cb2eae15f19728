//! The outputs of `settle gcode`: `layers.csv` (one row per layer), `summary.md` (print
//! time, worst and 95th-percentile contour error, the worst spots with their G-code
//! lines, the layers), `ringing-layer-<n>.svg/.png` (the maps of the worst layers),
//! `split-layer-<n>.svg/.png` (each of those layers' smoothing and vibration) and,
//! written last, `report.html` ([`write_html`]): the same in one self-contained page with
//! the figures embedded, the layers in a sortable, filterable table, the worst spots with
//! the text of their G-code lines, and the provenance (the file's SHA-256, the machine,
//! the planner, settle's version, the backend).

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use settle_gcode::job::ShaperSetting;

use std::io::BufRead as _;

use super::{DEFAULT_SAMPLE_RATE_HZ, GcodeOptions, GcodeOutcome, XyShapers};
use crate::error::Error;
use crate::output::atomic::{create_dir, write_atomic, write_atomic_with};
use crate::output::html::{Cell, Figure, Image, InputFile, Provenance, Report, Stat, Table};
use crate::output::plot::ringing::{CONTOUR_ERROR, MapPanel, MapSpot, RingingMap};
use crate::output::sha256::Sha256;
use crate::spec::backend::Backend;
use crate::studies::gcode::stats::LayerMap;

/// The most configuration notes summary.md and report.html list (a configuration of
/// 16 MiB may hold a note per line; stderr lists every one).
pub const MAX_LISTED_NOTES: usize = 100;

/// layers.csv's columns.
pub const LAYER_COLUMNS: [&str; 16] = [
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
    "smoothing_worst_um",
    "vibration_worst_um",
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
                row.push(num(s.split_worst.smoothing_um));
                row.push(num(s.split_worst.vibration_um));
            }
            None => {
                row.push("false".into());
                row.extend(std::iter::repeat_n(String::new(), 10));
            }
        }
        w.write_record(&row)?;
    }
    w.into_inner().map_err(|e| csv::Error::from(e.into_error()))
}

/// What makes the run a failed one, first on summary.md and report.html: a simulation
/// fault, lost steps (with where the first was seen); as (what, why) pairs.
fn failures(o: &GcodeOutcome) -> Vec<(&'static str, String)> {
    let mut out = Vec::new();
    if let Some(f) = &o.streamed.fault {
        out.push(("Simulation fault", f.to_string()));
    }
    if o.streamed.lost_steps > 0 {
        let mut why = format!(
            "{} full steps: a motor's load angle passed 90 electrical degrees, more torque than it has",
            o.streamed.lost_steps
        );
        if let Some(l) = &o.streamed.first_lost_step {
            why += &format!(
                " (first seen on axis {} at {:.3} s, line {}, layer {})",
                l.axis, l.time_s, l.line, l.layer
            );
        }
        why += "; the part would differ from this toolpath after that.";
        out.push(("Lost steps", why));
    }
    out
}

/// summary.md.
pub fn summary_md(o: &GcodeOutcome, maps: &[String]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# {}\n", o.file.display());
    for (what, why) in failures(o) {
        let _ = writeln!(s, "**{what}**: {why}\n");
    }
    let _ = writeln!(
        s,
        "{} planner on `{}` ({} backend).\n",
        o.setting,
        o.machine,
        o.backend.name()
    );
    let _ = writeln!(
        s,
        "| print time | worst contour error | p95 contour error | worst smoothing | worst vibration | simulated |"
    );
    let _ = writeln!(s, "|---:|---:|---:|---:|---:|---:|");
    let um = |v: f64| match o.measured_nothing() {
        true => "not measured".to_string(),
        false => format!("{v:.2} um"),
    };
    let _ = writeln!(
        s,
        "| {:.1} s ({:.1} min) | {} | {} | {} | {} | {:.1} s of print |\n",
        o.print_time_s,
        o.print_time_s / 60.0,
        um(o.worst_um),
        um(o.p95_um),
        um(o.streamed.split_worst.smoothing_um),
        um(o.streamed.split_worst.vibration_um),
        o.streamed.simulated_s
    );
    let _ = writeln!(
        s,
        "Contour error: distance in XY from the simulated toolhead to the commanded path of \
the moves active at that time, over working moves (extruding, or the laser or spindle on \
in a feed move); p95 is the 95th percentile of all working samples. It has two parts: \
smoothing, the distance from the commanded (shaped) position to that path, what the shaper \
trades for speed (zero without one), and vibration, the distance from the toolhead to the \
commanded position's own path (a lag along it is not vibration), what the machine adds \
(zero on a rigid one); each column is that part's own largest.\n"
    );
    if let Some([x, y]) = o.grbl_steps_per_mm {
        let (hx, hy) = (0.5e3 / x, 0.5e3 / y);
        let _ = writeln!(
            s,
            "GRBL rounds every target to whole steps (`$100`-`$102`, grbl/planner.c), so its \
command runs up to half a step off the written path on each axis: X {hx:.2} um, Y {hy:.2} um \
here ($100 {x}, $101 {y} steps/mm at the job's start), up to {:.2} um together; that counts \
as smoothing, with a shaper or without.\n",
            hx.hypot(hy)
        );
    }
    if let Some((settings, _)) = &o.config {
        let _ = writeln!(s, "Planner {settings}.\n");
    }
    if let Some(p) = &o.linearised_at {
        let _ = writeln!(
            s,
            "The modal backend linearised the machine at {}.\n",
            p.describe()
        );
    }
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
    let _ = writeln!(s, "## Worst spots\n");
    let _ = writeln!(
        s,
        "| error (um) | smoothing (um) | vibration (um) | line | layer | X (mm) | Y (mm) | time (s) |"
    );
    let _ = writeln!(s, "|---:|---:|---:|---:|---:|---:|---:|---:|");
    for w in o.worst() {
        let _ = writeln!(
            s,
            "| {:.2} | {:.2} | {:.2} | {} | {} | {:.2} | {:.2} | {:.3} |",
            w.error_um,
            w.split.smoothing_um,
            w.split.vibration_um,
            w.line,
            w.layer,
            w.x_mm,
            w.y_mm,
            w.time_s
        );
    }
    let _ = writeln!(s, "\n## Layers\n");
    let outer = super::features::has_outer_wall(o);
    let _ = writeln!(
        s,
        "| layer | Z (mm) | time (s) | moves | worst (um) | p95 (um) | worst line | smoothing (um) | vibration (um) |{}",
        if outer {
            " outer wall worst (um) | outer wall p95 (um) |"
        } else {
            ""
        }
    );
    let _ = writeln!(
        s,
        "|---:|---:|---:|---:|---:|---:|---:|---:|---:|{}",
        if outer { "---:|---:|" } else { "" }
    );
    for l in &o.layers {
        let z = l.z_mm.map_or(String::new(), |z| format!("{z:.2}"));
        let (w, p, line, sm, vib) = match &l.stats {
            Some(st) => (
                format!("{:.2}", st.worst_um()),
                format!("{:.2}", st.p95_um),
                st.worst
                    .as_ref()
                    .map_or(String::new(), |w| w.line.to_string()),
                format!("{:.2}", st.split_worst.smoothing_um),
                format!("{:.2}", st.split_worst.vibration_um),
            ),
            None => ("-".into(), "-".into(), "-".into(), "-".into(), "-".into()),
        };
        let wall = if !outer {
            String::new()
        } else {
            match super::features::layer_outer_wall(o, l.layer) {
                Some((w, p)) if p.is_nan() => format!(" {w:.2} | - |"),
                Some((w, p)) => format!(" {w:.2} | {p:.2} |"),
                None => " - | - |".into(),
            }
        };
        let _ = writeln!(
            s,
            "| {} | {z} | {:.2} | {} | {w} | {p} | {line} | {sm} | {vib} |{wall}",
            l.layer, l.duration_s, l.moves
        );
    }
    if let Some(w) = o.non_planar_words() {
        let _ = writeln!(s, "\nNote: {w}.");
    }
    s.push_str(&super::features::summary_sections(o));
    if !o.overrides.is_empty() {
        let _ = writeln!(s, "\n## Limits the file raises\n");
        for v in &o.overrides {
            let _ = writeln!(s, "- {}", super::override_words(v));
        }
    }
    if !o.ignored.is_empty() {
        let _ = writeln!(s, "\n## Commands not followed\n");
        for (what, n) in &o.ignored {
            let _ = writeln!(s, "- {what}: {n}");
        }
    }
    if let Some((_, notes)) = o.config.as_ref().filter(|(_, n)| !n.is_empty()) {
        let _ = writeln!(s, "\n## Configuration notes\n");
        let _ = writeln!(
            s,
            "What reading `--config` noted: values read another way than written, and \
what the planner does not use.\n"
        );
        for n in notes.iter().take(MAX_LISTED_NOTES) {
            let _ = writeln!(s, "- {n}");
        }
        if notes.len() > MAX_LISTED_NOTES {
            let more = notes.len() - MAX_LISTED_NOTES;
            let _ = writeln!(s, "- ... and {more} more (stderr lists every one)");
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

/// The figure of one layer's smoothing or vibration (`vibration`), as [`map_panel`]'s:
/// each point coloured by that part, the worst spots (of the contour error) labelled
/// with it.
fn part_panel(m: &LayerMap, setting: &str, vibration: bool) -> MapPanel {
    let mut p = map_panel(m, setting);
    p.title = format!(
        "layer {}, {}, {setting}",
        m.layer,
        if vibration { "vibration" } else { "smoothing" }
    );
    for q in &mut p.points {
        q.error_um = if vibration {
            q.vibration_um
        } else {
            q.smoothing_um
        };
    }
    for (spot, s) in p.spots.iter_mut().zip(&m.spots) {
        spot.error_um = if vibration {
            s.split.vibration_um
        } else {
            s.split.smoothing_um
        };
    }
    p
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
            quantity: CONTOUR_ERROR.into(),
        }
        .write(dir, &stem)?;
        files.push(dir.join(format!("{stem}.svg")));
        files.push(dir.join(format!("{stem}.png")));
        stems.push(stem);
        // The same layer's two parts, side by side on one colour scale.
        let stem = format!("split-layer-{}", m.layer);
        RingingMap {
            title: format!("Smoothing and vibration, {}", o.file.display()),
            panels: vec![
                part_panel(m, &setting, false),
                part_panel(m, &setting, true),
            ],
            quantity: "smoothing or vibration (um)".into(),
        }
        .write(dir, &stem)?;
        files.push(dir.join(format!("{stem}.svg")));
        files.push(dir.join(format!("{stem}.png")));
        stems.push(stem);
    }
    if super::features::has_features(o) {
        for (file, bytes) in [
            ("features.csv", super::features::features_csv(o)),
            ("layer_features.csv", super::features::layer_features_csv(o)),
        ] {
            let path = dir.join(file);
            let bytes = bytes.map_err(|e| Error::write(&path, std::io::Error::other(e)))?;
            write_atomic(&path, &bytes)?;
            files.push(path);
        }
    }
    if let Some(fig) = super::features::z_figure(o) {
        crate::output::plot::write(&fig, dir, "error-z")?;
        files.push(dir.join("error-z.svg"));
        files.push(dir.join("error-z.png"));
    }
    let md = dir.join("summary.md");
    write_atomic(&md, summary_md(o, &stems).as_bytes())?;
    files.push(md);
    Ok(files)
}

/// The report page's file name in the output folder.
pub const REPORT: &str = "report.html";

/// The longest G-code line text the report shows (characters); longer lines end in `...`.
const LINE_CHARS: usize = 160;

/// One pass over `file`: its SHA-256 and the text of the lines `wanted` (1-based).
fn digest_and_lines(file: &Path, wanted: &[u64]) -> Result<(String, BTreeMap<u64, String>), Error> {
    let f = crate::input::file::open(file, crate::input::file::limit::GCODE)?;
    let mut reader = std::io::BufReader::new(f);
    let mut sha = Sha256::default();
    let mut lines = BTreeMap::new();
    let mut buf = Vec::new();
    let mut n = 0u64;
    loop {
        buf.clear();
        let read = reader
            .read_until(b'\n', &mut buf)
            .map_err(|e| crate::input::file::stream_error(file, e))?;
        if read == 0 {
            break;
        }
        sha.update(&buf);
        n += 1;
        if wanted.contains(&n) {
            let text = String::from_utf8_lossy(&buf);
            let text = text.trim_end_matches(['\n', '\r']);
            lines.insert(n, settle_gcode::excerpt(text, LINE_CHARS).into_owned());
        }
    }
    Ok((sha.hex(), lines))
}

/// A shaper as `--shaper` takes it: `mzv@48`, `ei@52/0.08`.
pub(crate) fn shaper_arg(s: &ShaperSetting) -> String {
    if s.damping_ratio == 0.1 {
        format!("{}@{}", s.shaper_type.name(), s.frequency_hz)
    } else {
        format!(
            "{}@{}/{}",
            s.shaper_type.name(),
            s.frequency_hz,
            s.damping_ratio
        )
    }
}

/// Shapers as `--shaper` and `--versus` take them: one spec (or `none`) for both axes, or
/// `x=SPEC,y=SPEC` with the axes named.
fn shapers_arg(s: &XyShapers) -> String {
    let one = |s: &Option<ShaperSetting>| s.as_ref().map_or("none".to_string(), shaper_arg);
    match (&s.x, &s.y) {
        (Some(x), Some(y)) if x == y => one(x),
        (x, y) => x
            .iter()
            .map(|x| format!("x={}", one(x)))
            .chain(y.iter().map(|y| format!("y={}", one(y))))
            .collect::<Vec<_>>()
            .join(","),
    }
}

/// The command that runs `opts` again.
pub fn command_line(opts: &GcodeOptions, dir: &Path) -> String {
    let mut c = format!(
        "settle gcode {} --machine {} --firmware {}",
        opts.file.display(),
        opts.machine,
        opts.job.firmware()
    );
    let shapers = XyShapers::text(&opts.job.shapers);
    match &opts.config {
        Some(config) => {
            let _ = write!(c, " --config {}", config.path.display());
            if config.job.shapers[..2] != opts.job.shapers[..2] {
                let _ = write!(c, " --shaper {shapers}");
            }
        }
        None if shapers != "none" => {
            let _ = write!(c, " --shaper {shapers}");
        }
        None => {}
    }
    if opts.job.layer_mode != settle_gcode::LayerMode::Auto {
        let _ = write!(c, " --layer-source {}", opts.job.layer_mode.name());
    }
    if let Some((a, b)) = opts.layers {
        let _ = write!(c, " --layers {a}..{b}");
    }
    if opts.backend != Backend::Modal {
        let _ = write!(c, " --backend {}", opts.backend.name());
    }
    if opts.driver != settle_sim::DriverMode::Linear {
        let _ = write!(c, " --driver {}", opts.driver);
    }
    if opts.skip_bad_lines {
        c.push_str(" --skip-bad-lines");
    }
    if opts.sample_rate_hz != DEFAULT_SAMPLE_RATE_HZ {
        let _ = write!(c, " --sample-rate-hz {}", opts.sample_rate_hz);
    }
    if opts.maps != 1 {
        let _ = write!(c, " --maps {}", opts.maps);
    }
    if let Some((fw, shapers)) = &opts.versus {
        let _ = write!(c, " --versus {fw}:{}", shapers_arg(shapers));
    }
    let _ = write!(c, " --out {}", dir.display());
    c
}

/// A number cell shown with `prec` decimals.
fn num(value: f64, prec: usize) -> Cell {
    Cell::Number {
        value,
        text: format!("{value:.prec$}"),
    }
}

/// The page of `o` (run with `opts`, written into `dir`, whose figures `figures` are given
/// as caption and SVG file, read as the page is written).
pub fn html_report(
    o: &GcodeOutcome,
    opts: &GcodeOptions,
    dir: &Path,
    figures: Vec<(String, PathBuf)>,
) -> Result<Report, Error> {
    let wanted: Vec<u64> = o.worst().iter().map(|w| w.line).collect();
    let (sha, texts) = digest_and_lines(&o.file, &wanted)?;
    let mut intro: Vec<String> = failures(o)
        .into_iter()
        .map(|(what, why)| format!("{what}: {why}"))
        .collect();
    let error = if o.measured_nothing() {
        "contour error not measured (the simulation faulted before any working sample)".to_string()
    } else {
        format!(
            "contour error worst {:.2} um, p95 {:.2} um",
            o.worst_um, o.p95_um
        )
    };
    intro.push(format!(
        "{} planner on {} ({} backend): print time {:.2} s{}, {error}; {:.1} s of print simulated.",
        o.setting,
        o.machine,
        o.backend.name(),
        o.print_time_s,
        if o.print_time_s >= 120.0 {
            format!(" ({})", crate::output::jobs::duration(o.print_time_s))
        } else {
            String::new()
        },
        o.streamed.simulated_s
    ));
    intro.push(format!(
        "Of the contour error, smoothing (the shaped command against the G-code path, what the shaper trades for speed) reaches {:.2} um and vibration (the toolhead against the shaped command's path, what the machine adds) {:.2} um.",
        o.streamed.split_worst.smoothing_um, o.streamed.split_worst.vibration_um
    ));
    if let Some(w) = o.worst().first() {
        intro.push(format!(
            "Worst at line {} (layer {}, X {:.2} Y {:.2} mm): {}",
            w.line,
            w.layer,
            w.x_mm,
            w.y_mm,
            texts.get(&w.line).map_or("", String::as_str)
        ));
    }
    if let Some(f) = super::features::fly_words(o) {
        intro.push(f);
    }
    for v in &o.overrides {
        intro.push(format!("Note: {}", super::override_words(v)));
    }
    if let Some(w) = o.non_planar_words() {
        intro.push(format!("Note: {w}."));
    }
    let mut tables = vec![Table {
        title: "Worst spots".into(),
        note: "The largest contour errors, at most one per move, with the G-code line of the move. Contour error: distance in XY from the simulated toolhead to the commanded path of the moves active at that time, over working moves (extruding, or the laser or spindle on in a feed move).".into(),
        header: ["error (um)", "line", "G-code", "layer", "X (mm)", "Y (mm)", "time (s)"]
            .map(String::from)
            .to_vec(),
        rows: o
            .worst()
            .iter()
            .map(|w| {
                vec![
                    num(w.error_um, 2),
                    Cell::number(w.line as f64),
                    Cell::text(texts.get(&w.line).cloned().unwrap_or_default()),
                    Cell::number(f64::from(w.layer)),
                    num(w.x_mm, 2),
                    num(w.y_mm, 2),
                    num(w.time_s, 3),
                ]
            })
            .collect(),
    }];
    if let Some(b) = &o.versus {
        tables.push(Table {
            title: "Two settings compared".into(),
            note: "The same file under both settings (--versus).".into(),
            header: [
                "setting",
                "print time (s)",
                "worst contour error (um)",
                "p95 (um)",
                "worst line",
            ]
            .map(String::from)
            .to_vec(),
            rows: [o, b.as_ref()]
                .iter()
                .map(|x| {
                    vec![
                        Cell::text(x.setting.as_str()),
                        num(x.print_time_s, 2),
                        num(x.worst_um, 2),
                        num(x.p95_um, 2),
                        x.worst()
                            .first()
                            .map_or(Cell::text(""), |w| Cell::number(w.line as f64)),
                    ]
                })
                .collect(),
        });
    }
    tables.extend(super::features::features_table(o));
    if super::features::has_features(o) {
        let csv = super::features::layer_features_csv(o)
            .map_err(|e| Error::write(dir.join("layer_features.csv"), std::io::Error::other(e)))?;
        tables.extend(
            Table::from_csv(
                "Feature types per layer (layer_features.csv)",
                &String::from_utf8_lossy(&csv),
            )
            .ok(),
        );
    }
    if !o.ignored.is_empty() {
        tables.push(Table {
            title: "Commands not followed".into(),
            note: String::new(),
            header: vec!["command".into(), "times".into()],
            rows: o
                .ignored
                .iter()
                .map(|(what, n)| vec![Cell::text(what.as_str()), Cell::number(*n as f64)])
                .collect(),
        });
    }
    if let Some((_, notes)) = o.config.as_ref().filter(|(_, n)| !n.is_empty()) {
        let more = notes.len().saturating_sub(MAX_LISTED_NOTES);
        tables.push(Table {
            title: "Configuration notes (--config)".into(),
            note: match more {
                0 => String::new(),
                n => format!("The first {MAX_LISTED_NOTES}; {n} more on stderr."),
            },
            header: vec!["note".into()],
            rows: notes
                .iter()
                .take(MAX_LISTED_NOTES)
                .map(|n| vec![Cell::text(n.as_str())])
                .collect(),
        });
    }
    let csv = layers_csv(o)
        .map_err(|e| Error::write(dir.join("layers.csv"), std::io::Error::other(e)))?;
    let layers = Table::from_csv("Layers (layers.csv)", &String::from_utf8_lossy(&csv)).ok();
    let file_name = o.file.display().to_string();
    let mut inputs = Vec::new();
    let machine = Path::new(&opts.machine);
    if opts.machine.ends_with(".toml") && machine.is_file() {
        inputs.push(InputFile {
            name: opts.machine.clone(),
            text: crate::input::file::read_text(machine, crate::input::file::limit::SETTINGS)?,
        });
    }
    Ok(Report {
        title: format!("settle gcode: {}", o.file.display()),
        intro,
        winners: Vec::new(),
        tables,
        sections: Vec::new(),
        figures: figures
            .into_iter()
            .map(|(title, svg)| Figure {
                title,
                image: Image::SvgFile(svg),
            })
            .collect(),
        runs: layers,
        failed: Vec::new(),
        provenance: Provenance {
            settle_version: env!("CARGO_PKG_VERSION").to_string(),
            backend: o.backend.name().to_string(),
            command_line: command_line(opts, dir),
            date: String::new(),
            facts: vec![
                Stat {
                    label: "G-code file".into(),
                    value: file_name,
                },
                Stat {
                    label: "its SHA-256".into(),
                    value: sha,
                },
                Stat {
                    label: "machine".into(),
                    value: o.machine.clone(),
                },
                Stat {
                    label: "firmware (planner)".into(),
                    value: o.setting.clone(),
                },
                Stat {
                    label: "driver model".into(),
                    value: opts.driver.to_string(),
                },
            ]
            .into_iter()
            .chain(o.config.as_ref().map(|(settings, _)| Stat {
                label: "planner settings".into(),
                value: settings.clone(),
            }))
            .chain(o.linearised_at.as_ref().map(|p| Stat {
                label: "linearised at (modal)".into(),
                value: p.describe(),
            }))
            .collect(),
            inputs,
        },
    })
}

/// Write `report.html` into `dir`, after every other output (it embeds the figures
/// written there: the ringing maps and the comparison's); returns its path.
pub fn write_html(o: &GcodeOutcome, opts: &GcodeOptions, dir: &Path) -> Result<PathBuf, Error> {
    let mut figures = Vec::new();
    for f in o
        .files
        .iter()
        .filter(|f| f.extension().is_some_and(|e| e == "svg"))
    {
        let stem = f
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let title = match stem.strip_prefix("ringing-layer-") {
            Some(n) => format!(
                "Ringing map of layer {n}: contour error along the toolpath, worst spots labelled ({})",
                o.setting
            ),
            None => match stem.strip_prefix("compare-layer-") {
                Some(n) => format!("Layer {n} under both settings, on one colour scale"),
                None => match stem.strip_prefix("split-layer-") {
                    Some(n) => format!(
                        "Layer {n}: the shaper's smoothing (command against the G-code path) and the machine's vibration (toolhead against the command's path), on one colour scale ({})",
                        o.setting
                    ),
                    None if stem == "error-z" => {
                        "Contour error against Z: per layer the worst and the 95th percentile"
                            .into()
                    }
                    None => stem.clone(),
                },
            },
        };
        figures.push((title, f.clone()));
    }
    let report = html_report(o, opts, dir, figures)?;
    let path = dir.join(REPORT);
    // The figures are copied from their files as the page is written: neither they nor
    // the page are held whole (a benchy's maps are several MB of SVG).
    write_atomic_with(&path, |w| {
        crate::output::html::render_to(&report, None, &(), w, &path)
    })?;
    Ok(path)
}
