//! `settle gcode` and the `[gcode]` study: a G-code job simulated on printer_xy.

use std::path::{Path, PathBuf};

use settle::spec::backend::Backend;
use settle::workflows::gcode::{GcodeOptions, gcode, measure, parse_shaper};
use settle_planner::firmware::Firmware;

use crate::support::{extra, root, settle, write};

fn options(file: PathBuf, firmware: Firmware) -> GcodeOptions {
    GcodeOptions::new(file, "printer_xy", firmware).expect("options")
}

/// One straight printing move along X: the Y axis is commanded to stay at 0 and the modal
/// plant keeps an axis at rest exactly at rest, so the toolhead never leaves the line
/// `y = 0` and its contour error is how far it runs past the line's ends (the overshoot
/// of the stop, or a lag behind the start). Klipper's trapezoid at 100 mm/s and
/// 3000 mm/s^2 over 30 mm takes d/v + v/a = 0.3 + 1/30 s.
#[test]
fn a_straight_line_errs_only_past_its_ends_and_takes_its_trapezoid_time() {
    let dir = tempfile::tempdir().expect("tempdir");
    let file = write(dir.path(), "line.gcode", "G90\nM83\nG1 X30 E1 F6000\n");
    let o = measure(&options(file, Firmware::Klipper)).expect("runs");
    let t = 0.3 + 100.0 / 3000.0;
    assert!(
        (o.print_time_s - t).abs() <= 1e-12 * t,
        "{}",
        o.print_time_s
    );
    let w = &o.worst()[0];
    assert_eq!((w.line, w.y_mm), (3, 0.0));
    let past = (w.x_mm - 30.0).max(-w.x_mm) * 1e3;
    assert!(
        past > 0.0 && (o.worst_um - past).abs() <= 1e-9 * past,
        "{w:?}"
    );
    assert!(o.streamed.samples as f64 >= t * 2000.0 - 1.0);
    assert!(o.streamed.fault.is_none() && o.streamed.lost_steps == 0);
}

/// The cube layer through Klipper with MZV: outputs written, one layers.csv row per layer,
/// the worst spot on a printing line of the file, p95 below the worst, and the print time
/// the job's own planner reports.
#[test]
fn the_cube_layer_writes_layers_summary_and_a_ringing_map() {
    let dir = tempfile::tempdir().expect("tempdir");
    let file = root().join("gcode/prints/cube_layer.gcode");
    let opts = GcodeOptions {
        out: Some(dir.path().join("out")),
        ..options(file.clone(), Firmware::Klipper)
            .with_shaper(Some(parse_shaper("mzv@48").expect("shaper")))
    };
    let o = gcode(&opts).expect("runs");
    let text = std::fs::read_to_string(&file).expect("file");
    let lines: Vec<&str> = text.lines().collect();
    let worst = &o.worst()[0];
    let line = lines[worst.line as usize - 1];
    assert!(line.starts_with("G1 ") && line.contains(" E"), "{line}");
    assert!(o.worst_um > 0.0 && o.p95_um > 0.0 && o.p95_um <= o.worst_um * 1.001);
    let csv = std::fs::read_to_string(dir.path().join("out/layers.csv")).expect("csv");
    assert_eq!(csv.lines().count(), 1 + o.layers.len());
    let md = std::fs::read_to_string(dir.path().join("out/summary.md")).expect("md");
    assert!(md.contains(&format!("| {} |", worst.line)), "{md}");
    let layer = o.maps()[0].layer;
    for ext in ["svg", "png"] {
        let p = dir.path().join(format!("out/ringing-layer-{layer}.{ext}"));
        assert!(std::fs::metadata(&p).expect("map").len() > 1000, "{p:?}");
    }
    // The print time is the planner's, whatever is simulated.
    let one = measure(&GcodeOptions {
        layers: Some((1, 1)),
        ..opts.clone()
    })
    .expect("runs");
    assert_eq!(one.print_time_s.to_bits(), o.print_time_s.to_bits());
    // Layer 0 (before the first layer's Z) holds travel only: nothing to measure.
    let none = measure(&GcodeOptions {
        layers: Some((0, 0)),
        ..opts.clone()
    })
    .expect_err("refused");
    assert!(
        none.to_string()
            .contains("layers 0 to 0 hold no working move, so nothing to measure"),
        "{none}"
    );
}

/// The same corner as G-code through settle's planner (`[gcode]`) and as a `[corner]` run
/// (same machine, planner, limits, sample clock): the same metrics, on the same linear
/// model. printer_xy's belts depend on position: the G-code job is linearised at the
/// centre of its printing moves (X 10, Y 10 mm: the corner's legs span 0..20 mm), the
/// corner run at its start, so the corner run is simulated here at the G-code job's
/// point. The windowed planner cuts its chunks at other instants than `plan_path` ends its
/// segments, so the plant's steps split at different times; the modal plant is exact for
/// any split, so the results differ by rounding only: 1e-9 relative is far above that
/// (1e-16 per step, 1e4 steps).
#[test]
fn a_gcode_corner_gives_the_metrics_of_the_corner_study() {
    let load = |name: &str| {
        let (_, mut runs) = settle::load_runs(&root().join("scenarios").join(name)).expect("loads");
        settle::execute::set_backend(Path::new(name), &mut runs, Backend::Modal).expect("modal");
        assert_eq!(runs.len(), 1);
        runs.remove(0)
    };
    let (g_run, c_run) = (
        load("gcode_corner.toml"),
        load("gcode_corner_reference.toml"),
    );
    let g = settle::execute::execute(&g_run, None).expect("runs");
    let axes = settle::execute::axes_of(&c_run).expect("axes");
    let names: Vec<String> = axes.iter().map(|a| a.name.clone()).collect();
    let point = settle::studies::plan(&g_run, &names)
        .expect("plans")
        .linearise_at_m
        .expect("printer_xy's belts depend on position");
    assert_eq!(point, vec![10.0 * 1e-3, 10.0 * 1e-3]);
    let mut planned = settle::studies::plan(&c_run, &names).expect("plans");
    assert!(planned.probe.is_none() && planned.linearise_at_m.is_none());
    assert!(
        planned.motion.whole().is_some(),
        "a corner is planned whole"
    );
    let c = settle::execute::run_motion(
        axes,
        Backend::Modal,
        &settle::execute::SimOptions {
            linearise_at_m: Some(point),
            ..settle::execute::sim_options(&c_run)
        },
        &mut planned.motion,
        &settle::execute::observe_of(&c_run),
        None,
    )
    .expect("plans")
    .expect("runs");
    let close = |a: f64, b: f64, what: &str| {
        assert!(
            (a - b).abs() <= 1e-9 * a.abs().max(b.abs()),
            "{what}: gcode {a} vs corner {b}"
        );
    };
    close(g.move_time_s, c.move_time_s, "move_time_s");
    close(g.residual_peak_um, c.residual_peak_um, "residual_peak_um");
    close(g.residual_rms_um, c.residual_rms_um, "residual_rms_um");
    close(
        g.max_following_error_um,
        c.max_following_error_um,
        "max_following_error_um",
    );
    for (a, b) in g.settle_time_s.iter().zip(&c.settle_time_s) {
        close(
            a.unwrap_or(f64::INFINITY),
            b.unwrap_or(f64::INFINITY),
            "settle_time_s",
        );
    }
    // Contour error against the G-code's lines = the corner kind's error to the sharp path.
    let sharp = c.path.as_ref().expect("path metrics").max_sharp_error_um;
    close(
        extra(&g, "contour_worst_um"),
        sharp,
        "contour vs sharp error",
    );
    close(extra(&g, "print_time_s"), c.move_time_s, "print time");
}

/// Bad G-code: exit 2, the file and line in the message, nothing written.
#[test]
fn bad_gcode_exits_2_with_file_and_line_and_writes_nothing() {
    let dir = tempfile::tempdir().expect("tempdir");
    let long = format!("G1 X1 ;{}\n", "x".repeat(10_000_000));
    let mut bgcode = b"GCDE".to_vec();
    bgcode.extend_from_slice(&[1, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0x1a, 0, 0, 0]);
    let cases: [(&str, Vec<u8>, &str); 8] = [
        (
            "benchy.bgcode",
            bgcode,
            "benchy.bgcode: binary G-code, byte 18: truncated: the block's parameters needs 2 bytes, the file ends at byte 18",
        ),
        (
            "benchy.gcode.gz",
            vec![0x1f, 0x8b, 8, 0, 0, 0, 0, 0, 0, 3],
            "benchy.gcode.gz:1:1: gzip-compressed",
        ),
        (
            "benchy.gcode.3mf",
            b"PK\x03\x04\x14\x00\x00\x00\x08\x00".to_vec(),
            "benchy.gcode.3mf:1:1: a sliced 3MF (.gcode.3mf, as Bambu Studio and OrcaSlicer export a plate: a zip archive whose G-code is Metadata/plate_<n>.gcode)",
        ),
        (
            "garbage.gcode",
            (0..=255u8).cycle().take(4096).collect(),
            "garbage.gcode:1",
        ),
        (
            "long.gcode",
            format!("G90\n{long}").into_bytes(),
            "long.gcode:2",
        ),
        (
            "nan.gcode",
            b"G90\nG1 X1 F600\nG1 XNaN Y2\n".to_vec(),
            "nan.gcode:3",
        ),
        (
            "arc.gcode",
            b"G90\nG1 X0 Y0 F600\nG2 X10 Y0 I3 J0\n".to_vec(),
            "arc.gcode:3",
        ),
        ("feed.gcode", b"G90\nG1 X5 F0\n".to_vec(), "feed.gcode:2"),
    ];
    for (name, bytes, expect) in cases {
        let file = dir.path().join(name);
        std::fs::write(&file, bytes).expect("writes");
        let out_dir = dir.path().join(format!("out-{name}"));
        let out = settle()
            .args(["gcode", "--machine", "printer_xy", "--out"])
            .arg(&out_dir)
            .arg(&file)
            .output()
            .expect("runs");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{name}: {stderr}");
        assert!(
            stderr.contains(expect),
            "{name}: expected `{expect}` in {stderr}"
        );
        assert!(!stderr.contains("panicked"), "{stderr}");
        assert!(!out_dir.exists(), "{name}: nothing written");
    }
}

/// Regression: settle's planner turns a corner with a velocity jump (a 1 us piece of
/// 5000 m/s^2); the chunk is stepped in its own time so that no step starts a rounding
/// error before such a piece and holds its acceleration for a whole sample. The worst
/// error is then a property of the machine, not of the sample rate (2 vs 10 kHz: the
/// worst sample moves by less than a sample interval of the ~50 Hz ringing, < 1 %).
#[test]
fn the_contour_error_does_not_depend_on_the_sample_rate() {
    let file = root().join("gcode/prints/ringing_tower.gcode");
    let at = |rate: f64| {
        measure(&GcodeOptions {
            sample_rate_hz: rate,
            ..options(file.clone(), Firmware::Settle)
        })
        .expect("runs")
        .worst_um
    };
    let (a, b) = (at(2000.0), at(10_000.0));
    assert!((a - b).abs() <= 0.01 * b, "{a} vs {b}");
    assert!(b < 100.0, "{b}");
}

/// A result, not a tool failure: two 2 mm arcs at 50 mm/s after a travel, at 6000 mm/s^2
/// (the synthetic slicer file's fastest layer, where the 100 MB run lost its step). Klipper
/// cuts the arcs into 1 mm chords and passes each junction with a velocity jump, 50 per
/// second, near printer_xy's modes: the rotor's load angle passes 90 electrical degrees on
/// the linear driver (and the full driver on rapier slips poles on the same file). The
/// run is a failed run, a result: a message says what happened and where, the outputs are
/// written, summary.md and report.html saying so at their top, the exit code is 0 (1 with
/// `--fail-on-failed-runs`).
#[test]
fn lost_steps_are_reported_as_a_result_with_where_they_happen() {
    let dir = tempfile::tempdir().expect("tempdir");
    let file = write(
        dir.path(),
        "arcs.gcode",
        "G90\nM83\nM204 S6000\nG0 X100 Y100 F9000\nG2 X102 Y102 I2 J0 E0.1 F3000\nG3 X100 Y100 I-2 J0 E0.1\n",
    );
    let out_dir = dir.path().join("out");
    let gcode = |out_dir: &std::path::Path, extra: &[&str]| {
        settle()
            .args(["gcode", "--machine", "printer_xy", "--out"])
            .arg(out_dir)
            .arg(&file)
            .args(extra)
            .output()
            .expect("runs")
    };
    let out = gcode(&out_dir, &[]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    assert_eq!(
        gcode(&dir.path().join("strict"), &["--fail-on-failed-runs"])
            .status
            .code(),
        Some(1)
    );
    // stderr is a pipe here, not a terminal: no progress bar.
    assert!(!stderr.contains("of G-code simulated"), "{stderr}");
    assert!(
        stderr.contains("result: the machine loses steps")
            && stderr.contains("load angle passed 90 electrical degrees"),
        "{stderr}"
    );
    let o = measure(&options(file, Firmware::Klipper)).expect("runs");
    let l = o.streamed.first_lost_step.as_ref().expect("where");
    assert!(
        l.max_load_angle_deg > 90.0 && (5..=6).contains(&l.line),
        "{l:?}"
    );
    assert!(stderr.contains(&format!("line {}", l.line)), "{stderr}");
    // Both pages say so first, before any number.
    let md = std::fs::read_to_string(out_dir.join("summary.md")).expect("summary");
    let lost = md
        .find("**Lost steps**")
        .expect("summary.md names the lost steps");
    assert!(lost < md.find("| print time").expect("figures"), "{md}");
    let html = std::fs::read_to_string(out_dir.join("report.html")).expect("report");
    let lost = html
        .find("<p>Lost steps: ")
        .expect("report.html names the lost steps");
    let first = html.find("<header>").expect("header") + "<header>\n<h1>".len();
    assert!(
        !html[first..lost].contains("<p>") && html[lost..].contains(&format!("line {}", l.line)),
        "report.html opens with the lost steps"
    );
}

/// A spiral vase in a file that marks no layer: every printing move rises, so no planar
/// printing move starts a layer from Z and the whole vase is one layer. That layer's
/// numbers are over the vase's whole height: settle says so (in the outcome, summary.md
/// and on standard error) with the height, the first and last Z of its extruding moves.
/// A planar print says nothing.
#[test]
fn a_spiral_vase_without_layer_markers_is_said_to_be_one_layer_over_its_height() {
    let dir = tempfile::tempdir().expect("tempdir");
    // A 20 mm square, four sides a turn, rising 0.05 mm a side from Z 0.2: 10 turns, to
    // Z 2.2 mm.
    let mut text = String::from("G90\nM83\nG1 Z0.2 F600\nG1 X0 Y0 F6000\n");
    let corners = [(20.0, 0.0), (20.0, 20.0), (0.0, 20.0), (0.0, 0.0)];
    for side in 1..=40 {
        let (x, y) = corners[(side - 1) % 4];
        let z = 0.2 + 0.05 * side as f64;
        text.push_str(&format!("G1 X{x} Y{y} Z{z:.2} E0.5 F3000\n"));
    }
    let file = write(dir.path(), "spiral.gcode", &text);
    let o = measure(&options(file, Firmware::Klipper)).expect("runs");
    let spans: Vec<_> = o.layers.iter().filter_map(|l| l.print_z_mm).collect();
    assert_eq!(spans, [[0.2, 2.2]]);
    let words = o.non_planar_words().expect("said");
    assert!(
        words.starts_with("layer 0's extruding moves rise from Z 0.20 to 2.20 mm:"),
        "{words}"
    );
    let report = o.report();
    assert!(
        report.stderr.contains(&format!("note: {words}")),
        "{}",
        report.stderr
    );
    let summary = settle::workflows::gcode::report::summary_md(&o, &[]);
    assert!(summary.contains(&format!("Note: {words}.")), "{summary}");

    // A planar square of two layers: nothing to say.
    let planar = "G90\nM83\nG1 Z0.2 F600\nG1 X20 E1 F3000\nG1 Y20 E1\nG1 Z0.4\nG1 X0 E1\n";
    let file = write(dir.path(), "planar.gcode", planar);
    let o = measure(&options(file, Firmware::Klipper)).expect("runs");
    assert_eq!(o.layers.len(), 3);
    assert!(o.non_planar_words().is_none());
}

/// A file that marks its layers (PrusaSlicer's `;LAYER_CHANGE`, `;Z:`) and extrudes in
/// its start G-code on the way down, as PrusaSlicer's MK4 start G-code's purge does (`G0
/// E7 X15 Z0.2` from Z 15): the moves before the first marker are layer 0, which is not
/// one plane; the words say so, not that the file marks no layers. A marked layer with a
/// move that rises while extruding is named as such.
#[test]
fn a_marked_file_says_which_layer_is_not_one_plane_and_why() {
    let dir = tempfile::tempdir().expect("tempdir");
    let start = "; generated by PrusaSlicer 2.8.1\nG90\nM83\nG0 X0 Y-4 Z15 F4800\nG0 E7 X15 Z0.2 F500\nG0 X25 E4 F500\n";
    let layers = ";LAYER_CHANGE\n;Z:0.2\nG1 X0 Y0 F6000\nG1 X20 E1 F3000\nG1 Y20 E1\n;LAYER_CHANGE\n;Z:0.4\nG1 Z0.4\nG1 X0 E1\n";
    let file = write(dir.path(), "purge.gcode", &format!("{start}{layers}"));
    let o = measure(&options(file, Firmware::Klipper)).expect("runs");
    let spans: Vec<_> = o.layers.iter().map(|l| l.print_z_mm).collect();
    assert_eq!(
        spans,
        [Some([0.2, 15.0]), Some([0.2, 0.2]), Some([0.4, 0.4])]
    );
    let words = o.non_planar_words().expect("said");
    assert_eq!(
        words,
        "layer 0 (the moves before the file's first layer marker: its start G-code) extrudes between Z 0.20 and 15.00 mm: not one plane (a purge line that extrudes on its way down, say), so its per-layer numbers (Z, time, contour error) are over that whole height, not one layer's"
    );

    // A marked layer (layer 2: layer 0 is what comes before the first marker, none here)
    // that rises 2 mm while extruding.
    let rising = format!("; generated by PrusaSlicer 2.8.1\nG90\nM83\n{layers}G1 X20 Z2.4 E1\n");
    let file = write(dir.path(), "rising.gcode", &rising);
    let o = measure(&options(file, Firmware::Klipper)).expect("runs");
    let words = o.non_planar_words().expect("said");
    assert!(
        words.starts_with("layer 2's extruding moves span Z 0.40 to 2.40 mm: not one plane (non-planar moves within one layer the file marks)"),
        "{words}"
    );

    // PrusaSlicer 2.8.1's MK4S cube (gcode/prints/bgcode/PROVENANCE.md): its start G-code
    // moves to Z 15 (line 270, `G0 X0 Y-4 Z15`) and purges on the way down to Z 0.2
    // (`G0 E7 X15 Z0.2`) before the first `;LAYER_CHANGE` (line 298).
    let cube = root().join("gcode/prints/bgcode/mini_cube_ps2.8.1_ref.gcode");
    let o = measure(&options(cube, Firmware::Klipper)).expect("runs");
    let words = o.non_planar_words().expect("said");
    assert!(
        words.starts_with("layer 0 (the moves before the file's first layer marker: its start G-code) extrudes between Z 0.20 and 15.00 mm:"),
        "{words}"
    );
}

#[test]
fn the_jobs_square_corner_velocity_is_0_or_a_speed_in_range() {
    // 0 stops at every corner; otherwise the range of a speed limit
    // (settle::spec::SPEED_RANGE_MM_S, 1e-3 to 1e6 mm/s): its ends are taken, the next
    // f64 beyond either end refused with the key and its line, as is a negative value.
    let path = root().join("scenarios/gcode_corner.toml");
    let good = std::fs::read_to_string(&path).expect("scenario");
    let at = |x: f64| {
        let t = good.replace(
            "square_corner_velocity_mm_s = 5.0\n",
            &format!("square_corner_velocity_mm_s = {x}\n"),
        );
        assert_ne!(t, good);
        t
    };
    let line = 1 + good
        .lines()
        .position(|l| l.starts_with("square_corner_velocity_mm_s"))
        .expect("key");
    for x in [0.0, 1e-3, 1e6] {
        settle::expand::parse_runs(&at(x), &path).unwrap_or_else(|e| panic!("{x}: {e}"));
    }
    let below = f64::from_bits(1e-3f64.to_bits() - 1);
    let above = f64::from_bits(1e6f64.to_bits() + 1);
    for x in [below, above, -5.0, f64::NEG_INFINITY] {
        let e = settle::expand::parse_runs(&at(x), &path).expect_err("refused");
        assert!(e.is_input_error(), "{e}");
        let msg = e.to_string();
        assert!(
            msg.contains(&format!("gcode_corner.toml:{line}:"))
                && msg.contains("key `gcode.square_corner_velocity_mm_s`")
                && msg.contains(
                    "0 (stop at every corner) or a finite number from 1e-3 to 1e6 (mm/s)"
                )
                && msg.contains(&format!("got {x}")),
            "{msg}"
        );
    }
}
