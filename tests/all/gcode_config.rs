//! `settle gcode --config`: the planner's limits and the input shapers of a firmware
//! configuration (Klipper's printer.cfg, RepRapFirmware's config.g), and per-axis
//! `--shaper`.

use std::path::{Path, PathBuf};

use settle::workflows::gcode::{GcodeOptions, measure, parse_shapers};
use settle_planner::firmware::Firmware;

use crate::support::{root, settle, write};

fn with_config(file: PathBuf, config: PathBuf) -> GcodeOptions {
    GcodeOptions::with_config(file, "printer_xy", None, config).expect("options")
}

fn print_time(dir: &Path, gcode: &str, config: Option<(&str, &str)>) -> f64 {
    let file = write(dir, "move.gcode", gcode);
    let opts = match config {
        Some((name, text)) => with_config(file, write(dir, name, text)),
        None => GcodeOptions::new(file, "printer_xy", Firmware::Klipper).expect("options"),
    };
    measure(&opts).expect("runs").print_time_s
}

/// One straight move from rest to rest is a trapezoid: d/v + v/a, with v the lower of
/// the feed rate and the configuration's speed limit and a its acceleration (the cruise
/// speed is reached: v^2/a is far below the move). Klipper's `max_velocity` and
/// `max_accel` from printer.cfg; RepRapFirmware's `M203` (mm/min) speed and its `M204 P`
/// printing acceleration, below `M201 X`, from config.g.
#[test]
fn a_configurations_limits_give_the_trapezoid_times_of_its_firmware() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let at_100 = "G90\nM83\nG1 X100 E1 F6000\n";
    let at_500 = "G90\nM83\nG1 X100 E1 F30000\n";
    let fast = (
        "a.cfg",
        "[printer]\nkinematics: cartesian\nmax_velocity: 200\nmax_accel: 5000\n",
    );
    let slow = (
        "b.cfg",
        "[printer]\nkinematics: corexy\nmax_velocity: 80\nmax_accel: 2000\n",
    );
    let rrf = (
        "config.g",
        "M203 X12000 Y12000 Z600\nM201 X5000 Y5000 Z200\nM204 P2500 T4000\n",
    );
    let cases = [
        (at_100, None, 1.0 + 100.0 / 3000.0), // Klipper's example max_accel, no config
        (at_100, Some(fast), 1.0 + 100.0 / 5000.0),
        (at_500, Some(fast), 0.5 + 200.0 / 5000.0),
        (at_100, Some(slow), 1.25 + 80.0 / 2000.0),
        (at_500, Some(slow), 1.25 + 80.0 / 2000.0),
        (at_100, Some(rrf), 1.0 + 100.0 / 2500.0),
        (at_500, Some(rrf), 0.5 + 200.0 / 2500.0),
    ];
    for (gcode, config, want) in cases {
        let t = print_time(d, gcode, config);
        assert!(
            (t - want).abs() <= 1e-12 * want,
            "{config:?} {gcode:?}: {t} s, the trapezoid takes {want} s"
        );
    }
}

/// printer.cfg's `[input_shaper]` per axis gives the same job, bit for bit, as the same
/// shapers written on the command line (`--shaper x=...,y=...`), and differs from one
/// shaper on both axes; `--shaper` on one axis keeps the configuration's other one.
#[test]
fn a_configurations_shapers_are_per_axis_as_on_the_command_line() {
    let dir = tempfile::tempdir().expect("tempdir");
    let file = root().join("gcode/prints/cube_layer.gcode");
    // Klipper's example limits (the defaults settle gcode takes without --config).
    let cfg = write(
        dir.path(),
        "printer.cfg",
        "[printer]\nkinematics: cartesian\nmax_velocity: 500\nmax_accel: 3000\n\
         max_z_velocity: 25\nmax_z_accel: 30\n\
         [input_shaper]\nshaper_type_x: mzv\nshaper_freq_x: 48\n\
         shaper_type_y: ei\nshaper_freq_y: 39.3\ndamping_ratio_y: 0.08\n",
    );
    let from_config = measure(&with_config(file.clone(), cfg.clone())).expect("runs");
    let cli = |spec: &str| {
        measure(
            &GcodeOptions::new(file.clone(), "printer_xy", Firmware::Klipper)
                .expect("options")
                .with_shapers(parse_shapers(spec).expect("shapers")),
        )
        .expect("runs")
    };
    let per_axis = cli("x=mzv@48,y=ei@39.3/0.08");
    assert_eq!(from_config.worst_um.to_bits(), per_axis.worst_um.to_bits());
    assert_eq!(from_config.p95_um.to_bits(), per_axis.p95_um.to_bits());
    assert_eq!(
        from_config.print_time_s.to_bits(),
        per_axis.print_time_s.to_bits()
    );
    assert_eq!(from_config.setting, "klipper + X mzv@48 Hz, Y ei@39.3 Hz");
    let both = cli("mzv@48");
    assert_ne!(both.worst_um.to_bits(), per_axis.worst_um.to_bits());
    // Only Y named: X keeps the configuration's MZV at 48 Hz.
    let y_only =
        measure(&with_config(file, cfg).with_shapers(parse_shapers("y=mzv@48").expect("shapers")))
            .expect("runs");
    assert_eq!(y_only.worst_um.to_bits(), both.worst_um.to_bits());
}

/// A configuration settle cannot follow: exit 2 naming the file and the key, nothing
/// written; a Marlin run has no configuration file to read.
#[test]
fn a_configuration_settle_cannot_follow_exits_2_and_writes_nothing() {
    let dir = tempfile::tempdir().expect("tempdir");
    let gcode = write(dir.path(), "m.gcode", "G90\nG1 X10 F6000\n");
    let delta = write(
        dir.path(),
        "delta.cfg",
        "[printer]\nkinematics: delta\nmax_velocity: 300\nmax_accel: 3000\n",
    );
    let bad_value = write(
        dir.path(),
        "bad.cfg",
        "[printer]\nkinematics: cartesian\nmax_velocity: 300\nmax_accel: -5\n",
    );
    let cases: [(&[&str], &Path, &str); 4] = [
        (&[], &delta, "printer.kinematics"),
        (&[], &bad_value, "printer.max_accel"),
        (&["--firmware", "marlin"], &delta, "--config"),
        (&[], &dir.path().join("missing.cfg"), "missing.cfg"),
    ];
    for (extra, config, key) in cases {
        let out_dir = dir.path().join("out");
        let out = settle()
            .arg("gcode")
            .arg(&gcode)
            .args(["--machine", "printer_xy", "--config"])
            .arg(config)
            .args(extra)
            .arg("--out")
            .arg(&out_dir)
            .output()
            .expect("settle runs");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{config:?}: {stderr}");
        assert!(
            stderr.contains(&*config.file_name().expect("a name").to_string_lossy())
                && stderr.contains(key),
            "{config:?}: {stderr}"
        );
        assert!(!out_dir.exists(), "{config:?} wrote {out_dir:?}");
    }
}

/// summary.md and report.html say what `--config` set and where the modal backend
/// linearised the machine: the cube layer is printed at X and Y 100 to 120 mm, so at X and
/// Y 110 mm.
#[test]
fn the_outputs_name_the_configurations_settings_and_the_linearisation_point() {
    let dir = tempfile::tempdir().expect("tempdir");
    let cfg = write(
        dir.path(),
        "printer.cfg",
        "[printer]\nkinematics: cartesian\nmax_velocity: 250\nmax_accel: 4500\n\
         [input_shaper]\nshaper_freq_x: 48\nshaper_freq_y: 39.3\n",
    );
    let out = dir.path().join("out");
    let opts = GcodeOptions {
        out: Some(out.clone()),
        ..with_config(root().join("gcode/prints/cube_layer.gcode"), cfg)
    };
    settle::workflows::gcode::gcode(&opts).expect("runs");
    let want_settings = "klipper: max_velocity 250 mm/s, max_accel 4500 mm/s^2, \
                         minimum_cruise_ratio 0.5, square_corner_velocity 5 mm/s; \
                         shaper X mzv@48 Hz, Y mzv@39.3 Hz";
    let want_point = "X 110.00 Y 110.00";
    for name in ["summary.md", "report.html"] {
        let text = std::fs::read_to_string(out.join(name)).expect("written");
        assert!(text.contains(want_settings), "{name}: {text}");
        assert!(text.contains(want_point), "{name}: {text}");
    }
}

/// Every real configuration of settle-gcode's corpus (gcode/tests/data/real/MANIFEST.md)
/// replays a job under its limits: vt627's, whose five includes name files that are not in
/// its repository, too (they are listed as notes, as `settle import` lists them).
#[test]
fn the_real_configurations_replay_a_job() {
    let real = root().join("gcode/tests/data/real");
    for file in [
        "voronpi/printer.cfg",
        "zippy/printer.cfg",
        "metis/printer.cfg",
        "vt627/printer.cfg",
        "railcore/sys/config.g",
    ] {
        let opts = with_config(
            root().join("gcode/prints/cube_layer.gcode"),
            real.join(file),
        );
        let m = measure(&opts).unwrap_or_else(|e| panic!("{file}: {e}"));
        assert!(m.print_time_s > 0.0 && m.worst_um.is_finite(), "{file}");
    }
}
