//! Where a G-code job's layers come from (`settle gcode --layer-source`, `[gcode]
//! layer_source`), and the bound on their number: a CNC finishing toolpath changes Z all
//! the time and, without slicer markers, has a layer at every change; `markers` makes it
//! one layer with the same samples, `z` takes a marked file's layers from Z; a job that
//! opens layer 50,001 is refused before anything is written.

use std::fmt::Write as _;
use std::path::Path;

use settle::studies::gcode::GcodeJob;
use settle::workflows::gcode::{GcodeOptions, measure};
use settle_gcode::LayerMode;
use settle_planner::firmware::Firmware;

use crate::support::{root, run_ok, settle, write};

/// A 3D-finishing (surfacing) pass in the manner of a CAM program's output: `rows` raster
/// rows 0.1 mm apart along Y, each 41 points 0.5 mm apart along X, Z following
/// `-1 + 0.8 sin(x / 5) cos(y / 4)` mm rounded to 0.1 mm, a plunge (`G1 Z`) wherever Z
/// changes, the spindle on. With it, how many layers the Z fallback finds: one at each
/// feed move in a plane (X, Y only, of some length) at a Z other than the last layer's.
fn finishing(rows: u32) -> (String, usize) {
    let mut s = String::from("G21\nG90\nG94\nM3 S10000\nG0 Z5\nG0 X0 Y0\nG1 Z0 F300\n");
    let (mut x, mut y, mut z) = (0.0_f64, 0.0_f64, 0.0_f64);
    let mut layer_z: Option<f64> = None;
    let mut layers = 0;
    let mut planar = |from: [f64; 2], to: [f64; 2], z: f64| {
        if from != to && layer_z.is_none_or(|l| (l - z).abs() > 1e-6) {
            layer_z = Some(z);
            layers += 1;
        }
    };
    for r in 0..rows {
        let y_new = f64::from(r) * 0.1;
        let _ = writeln!(s, "G1 Y{y_new:.2} F1500");
        let y_text: f64 = format!("{y_new:.2}").parse().expect("number");
        planar([x, y], [x, y_text], z);
        y = y_text;
        let mut xs: Vec<f64> = (0..41).map(|i| f64::from(i) * 0.5).collect();
        if r % 2 == 1 {
            xs.reverse();
        }
        for x_new in xs {
            let z_new = -1.0 + 0.8 * (x_new / 5.0).sin() * (y / 4.0).cos();
            let z_text = format!("{z_new:.1}");
            let z_new: f64 = z_text.parse().expect("number");
            if z_new != z {
                let _ = writeln!(s, "G1 Z{z_text}");
                z = z_new;
            }
            let _ = writeln!(s, "G1 X{x_new:.2}");
            planar([x, y], [x_new, y], z);
            x = x_new;
        }
    }
    s.push_str("G0 Z5\nM5\nM2\n");
    (s, layers)
}

/// A job of `n` layers from Z: a plunge, then a 1 mm cut, alternating between Z -0.1 and
/// 0, after 7 lines; layer `k` (from 1) is opened by line `7 + 2k`.
fn z_layers_job(n: u32) -> String {
    let mut text = String::from("G21\nG90\nG94\nM3 S10000\nG0 Z5\nG0 X0 Y0\nG1 Z0 F300\n");
    for k in 0..n {
        let (z, x) = if k % 2 == 0 {
            ("-0.1", "1")
        } else {
            ("0", "0")
        };
        let _ = writeln!(text, "G1 Z{z}\nG1 X{x} F1500");
    }
    text
}

/// `settle gcode` on printer_xy with GRBL's settings of a Shapeoko 3.
fn grbl_job(file: &Path, mode: LayerMode) -> GcodeOptions {
    GcodeOptions::with_config(
        file.to_path_buf(),
        "printer_xy",
        Some(Firmware::Grbl),
        root().join("gcode/prints/shapeoko3_grbl_settings.txt"),
    )
    .expect("options")
    .with_layer_mode(mode)
}

/// A finishing pass of 12 rows has 264 layers from Z (and layer 0, the moves before the
/// first); under `markers` it is one layer, and the contour error's worst and 95th
/// percentile are the same numbers, bit for bit: layers only group the samples.
#[test]
fn markers_make_a_finishing_pass_one_layer_with_the_same_samples() {
    let dir = tempfile::tempdir().expect("tempdir");
    let (text, z_layers) = finishing(12);
    assert_eq!(z_layers, 264);
    let file = write(dir.path(), "finish.nc", &text);
    let auto = measure(&grbl_job(&file, LayerMode::Auto)).expect("runs");
    let markers = measure(&grbl_job(&file, LayerMode::Comments)).expect("runs");
    let numbers: Vec<u32> = auto.layers.iter().map(|l| l.layer).collect();
    assert_eq!(numbers, (0..=264).collect::<Vec<u32>>());
    let one: Vec<(u32, u64)> = markers.layers.iter().map(|l| (l.layer, l.moves)).collect();
    let moves: u64 = auto.layers.iter().map(|l| l.moves).sum();
    assert_eq!(one, [(0, moves)]);
    assert!(auto.worst_um > 1.0, "{}", auto.worst_um);
    assert_eq!(auto.worst_um.to_bits(), markers.worst_um.to_bits());
    assert_eq!(auto.p95_um.to_bits(), markers.p95_um.to_bits());
    assert_eq!(auto.print_time_s.to_bits(), markers.print_time_s.to_bits());
    let line = |o: &settle::workflows::gcode::GcodeOutcome| o.worst().first().map(|s| s.line);
    assert_eq!(line(&auto), line(&markers));
}

/// A printer file with two `;LAYER:` markers and three planes: its layers are the
/// markers' by default and under `markers`, the three planes under `z` (whose first
/// plunge, before the first plane, is layer 0's).
#[test]
fn z_takes_a_marked_files_layers_from_z() {
    let dir = tempfile::tempdir().expect("tempdir");
    let file = write(
        dir.path(),
        "marked.gcode",
        ";LAYER:0\nG1 Z0.2 F600\nG1 X10 Y0 E1 F3000\nG1 X10 Y10 E2\n\
         G1 Z0.4\nG1 X0 Y10 E3\n;LAYER:1\nG1 Z0.6\nG1 X0 Y0 E4\nG1 X10 Y0 E5\n",
    );
    let z_of = |mode| {
        let opts = GcodeOptions::new(file.clone(), "printer_xy", Firmware::Klipper)
            .expect("options")
            .with_layer_mode(mode);
        let o = measure(&opts).expect("runs");
        o.layers
            .iter()
            .map(|l| (l.layer, l.z_mm.map(|z| (z * 1e6).round() / 1e6)))
            .collect::<Vec<_>>()
    };
    let marked = [(1, Some(0.2)), (2, Some(0.6))];
    assert_eq!(z_of(LayerMode::Auto), marked);
    assert_eq!(z_of(LayerMode::Comments), marked);
    assert_eq!(
        z_of(LayerMode::ZChange),
        [(0, None), (1, Some(0.2)), (2, Some(0.4)), (3, Some(0.6))]
    );
}

/// The flag on the command line: the run's command (report.html) repeats it, layers.csv
/// has one row; an unknown source is refused with what is allowed.
#[test]
fn the_layer_source_flag_reaches_the_outputs() {
    let dir = tempfile::tempdir().expect("tempdir");
    let (text, _) = finishing(4);
    let file = write(dir.path(), "finish.nc", &text);
    let out_dir = dir.path().join("out");
    run_ok(
        settle()
            .arg("gcode")
            .arg(&file)
            .args(["--machine", "printer_xy", "--firmware", "grbl", "--config"])
            .arg(root().join("gcode/prints/shapeoko3_grbl_settings.txt"))
            .args(["--layer-source", "markers", "--out"])
            .arg(&out_dir),
    );
    let csv = std::fs::read_to_string(out_dir.join("layers.csv")).expect("layers.csv");
    assert_eq!(csv.lines().count(), 2, "{csv}");
    let html = std::fs::read_to_string(out_dir.join("report.html")).expect("report.html");
    assert!(
        html.contains("shapeoko3_grbl_settings.txt --layer-source markers --out"),
        "no --layer-source in the command line"
    );
    let bad = settle()
        .arg("gcode")
        .arg(&file)
        .args(["--machine", "printer_xy", "--layer-source", "comments"])
        .output()
        .expect("runs");
    let stderr = String::from_utf8_lossy(&bad.stderr);
    assert_eq!(bad.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("`comments`: allowed: auto (slicer markers, else changes of Z), markers"),
        "{stderr}"
    );
}

/// 50,001 layers from Z ([`z_layers_job`]): refused at the line of the 50,001st layer's
/// cut (line 7 + 2 x 50,001), exit 2, the
/// message naming the bound and the way out; the output folder is not made, not even for
/// `--mcap`'s recording.
#[test]
fn a_job_of_50001_layers_is_refused_and_writes_nothing() {
    let dir = tempfile::tempdir().expect("tempdir");
    let file = write(
        dir.path(),
        "layers.nc",
        &z_layers_job(settle_gcode::MAX_LAYERS + 1),
    );
    let out_dir = dir.path().join("out");
    let out = settle()
        .arg("gcode")
        .arg(&file)
        .args([
            "--machine",
            "printer_xy",
            "--firmware",
            "grbl",
            "--mcap",
            "--out",
        ])
        .arg(&out_dir)
        .output()
        .expect("runs");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    for part in [
        "layers.nc:100009: this line opens layer 50001",
        "past the 50000 layers settle reads in a job",
        "give --layer-source markers",
    ] {
        assert!(stderr.contains(part), "{part:?} not in {stderr}");
    }
    assert!(!out_dir.exists(), "the output folder was made");
}

/// `[gcode] layer_source`: read into the job (default `auto`); an unknown value names the
/// scenario, the key and what is allowed.
#[test]
fn the_gcode_table_takes_a_layer_source() {
    let dir = tempfile::tempdir().expect("tempdir");
    write(
        dir.path(),
        "marked.gcode",
        ";LAYER:0\nG1 Z0.2 F600\nG1 X10 Y0 E1 F3000\nG1 X10 Y10 E2\n",
    );
    let scenario = |source: &str| {
        format!(
            "name = \"layer_source\"\n[machine]\npreset = \"printer_xy\"\n\
             [gcode]\nfile = \"marked.gcode\"\nfirmware = \"klipper\"\n{source}\
             [limits]\nvmax_mm_s = 300.0\namax_mm_s2 = 3000.0\njmax_mm_s3 = 100000.0\n"
        )
    };
    for (line, mode) in [
        ("", LayerMode::Auto),
        ("layer_source = \"markers\"\n", LayerMode::Comments),
        ("layer_source = \"z\"\n", LayerMode::ZChange),
    ] {
        let path = write(dir.path(), "job.toml", &scenario(line));
        let (_, runs) = settle::load_runs(&path).expect("loads");
        let job = runs[0].state::<GcodeJob>().expect("a G-code run");
        assert_eq!(job.layer_mode, mode, "{line}");
        // The job the runs plan reads its layers so.
        let cfg = settle::studies::gcode::job_config(&runs[0], job, None).expect("config");
        assert_eq!(cfg.layer_mode, mode, "{line}");
    }
    let path = write(
        dir.path(),
        "bad.toml",
        &scenario("layer_source = \"comments\"\n"),
    );
    let msg = settle::load_runs(&path).expect_err("refused").to_string();
    assert!(
        msg.contains("bad.toml")
            && msg.contains("gcode.layer_source")
            && msg.contains("`comments`: allowed: auto"),
        "{msg}"
    );
}

/// A sweep over a job of 50,001 layers from Z is refused when it is checked, at
/// `gcode.file`, with the line and the way out.
#[test]
fn the_gcode_study_refuses_a_job_of_50001_layers() {
    let dir = tempfile::tempdir().expect("tempdir");
    write(
        dir.path(),
        "layers.nc",
        &z_layers_job(settle_gcode::MAX_LAYERS + 1),
    );
    let path = write(
        dir.path(),
        "mill.toml",
        "name = \"mill\"\n[machine]\npreset = \"printer_xy\"\n\
         [gcode]\nfile = \"layers.nc\"\nfirmware = \"grbl\"\n\
         [limits]\nvmax_mm_s = 100.0\namax_mm_s2 = 1000.0\n",
    );
    let msg = settle::load_runs(&path).expect_err("refused").to_string();
    for part in [
        "gcode.file",
        "layers.nc:100009: this line opens layer 50001",
        "[gcode] layer_source = \"markers\"",
    ] {
        assert!(msg.contains(part), "{part:?} not in {msg}");
    }
}
