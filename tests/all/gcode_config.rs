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
/// written; a printer.cfg is not Marlin's M503 reply.
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
        (
            &["--firmware", "marlin"],
            &delta,
            "not Marlin's reply to M503",
        ),
        (&[], &dir.path().join("missing.cfg"), "missing.cfg"),
    ];
    for (extra, config, key) in cases {
        let stderr = refused_config(&gcode, config, extra, &dir.path().join("out"));
        assert!(
            stderr.contains(&*config.file_name().expect("a name").to_string_lossy())
                && stderr.contains(key),
            "{config:?}: {stderr}"
        );
    }
}

/// A setting the job cannot use is named at the line of the configuration that set it,
/// with its key and what is allowed, exit 2, nothing written: the old binary named a
/// config.g's `M593` and `M669`, and a printer.cfg's shaper frequency, without a line
/// (`c.g: key M593: ...`), and took Marlin's `M92 X0.0000001`, `M493 A1e308`, `M494
/// X0.5` (Marlin's M494 takes 0 to 0.1 s) and `M205 B5000000` (a block stretched to 5 s)
/// and GRBL's `$100=0.0000001` (at 1e-7 steps/mm a move is no whole step: it reported
/// 60 mm of error as measured).
#[test]
fn a_configurations_bad_setting_is_named_at_its_line() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let gcode = write(d, "m.gcode", "G90\nM83\nG1 X10 F6000\nG1 X20 E1\n");
    let cases: [(&str, &str, &str, &str, &str); 9] = [
        (
            "c.g",
            "M92 X80 Y80\n; RepRapFirmware's M593 takes F from 5.722 to 1000 Hz\nM593 P\"ei3\" F2000 S0.1\n",
            "rrf",
            "c.g:3: key `M593.F`",
            "5.722 to 1000 Hz",
        ),
        (
            "k.g",
            "M92 X80\nM669 K3\n",
            "rrf",
            "k.g:2: key `M669 K`",
            "cartesian and corexy",
        ),
        (
            "s.cfg",
            "[printer]\nkinematics: cartesian\nmax_velocity: 300\nmax_accel: 3000\n[input_shaper]\nshaper_type: mzv\nshaper_freq_x: 0.001\nshaper_freq_y: 40\n",
            "klipper",
            "s.cfg:7: key `input_shaper.shaper_freq_x`",
            "below 1 Hz",
        ),
        (
            "steps.txt",
            "echo:  M203 X500 Y500\necho:  M92 X0.0000001 Y80\n",
            "marlin",
            "steps.txt:2: key `M92.X`",
            "1 to 1e6 steps/mm",
        ),
        (
            "ft.txt",
            "echo:  M203 X500 Y500\necho:; Fixed-Time Motion:\necho:  M493 S1 A1e308\n",
            "marlin",
            "ft.txt:3: key `M493.A`",
            "10 to 500 Hz",
        ),
        (
            "zeta.txt",
            "echo:  M203 X500 Y500\necho:  M493 X C1 A40 I1\n",
            "marlin",
            "zeta.txt:2: key `M493.I`",
            "0.01 to below 1",
        ),
        (
            "smooth.txt",
            "echo:  M203 X500 Y500\necho:; FT Motion:\necho:  M494 T0 X0.5 Y0 Z0 E0.02\n",
            "marlin",
            "smooth.txt:3: key `M494.X`",
            "0 to 0.1 s",
        ),
        (
            "segment.txt",
            "echo:  M203 X500 Y500\necho:  M205 B5000000.00 S0.00 T0.00 J0.08\n",
            "marlin",
            "segment.txt:2: key `M205.B`",
            "0 to 1000000 us",
        ),
        (
            "grbl.txt",
            "$110=6000\n$100=0.0000001\n",
            "grbl",
            "grbl.txt:2: key `$100`",
            "1 to 1e6 steps/mm",
        ),
    ];
    for (name, text, firmware, at, allowed) in cases {
        let config = write(d, name, text);
        let stderr = refused_config(&gcode, &config, &["--firmware", firmware], &d.join("out"));
        assert!(
            stderr.contains(at) && stderr.contains(allowed),
            "{name}: {stderr}"
        );
    }
}

/// `settle gcode GCODE --machine printer_xy --config CONFIG EXTRA --out OUT`: exit 2 and
/// nothing written at `out`; its standard error.
fn refused_config(gcode: &Path, config: &Path, extra: &[&str], out: &Path) -> String {
    let run = settle()
        .arg("gcode")
        .arg(gcode)
        .args(["--machine", "printer_xy", "--config"])
        .arg(config)
        .args(extra)
        .arg("--out")
        .arg(out)
        .output()
        .expect("settle runs");
    let stderr = String::from_utf8_lossy(&run.stderr).into_owned();
    assert_eq!(run.status.code(), Some(2), "{config:?}: {stderr}");
    assert!(!out.exists(), "{config:?} wrote {out:?}");
    stderr
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

/// A Marlin reply to `M503` (OctoPrint's terminal copy) with limits below Marlin's
/// defaults and a ZV shaper per axis.
const M503: &str = "Send: M503\r\n\
    Recv: echo:; Steps per unit:\r\n\
    Recv: echo:  M92 X100.00 Y100.00 Z400.00 E93.00\r\n\
    Recv: echo:; Max feedrates (units/s):\r\n\
    Recv: echo:  M203 X200.00 Y200.00 Z5.00 E25.00\r\n\
    Recv: echo:; Max Acceleration (units/s2):\r\n\
    Recv: echo:  M201 X2000.00 Y2000.00 Z100.00 E5000.00\r\n\
    Recv: echo:; Acceleration (units/s2) (P<print-accel> R<retract-accel> T<travel-accel>):\r\n\
    Recv: echo:  M204 P1200.00 R1500.00 T1800.00\r\n\
    Recv: echo:; Advanced (B<min_segment_time_us> S<min_feedrate> T<min_travel_feedrate> J<junc_dev>):\r\n\
    Recv: echo:  M205 B20000.00 S0.00 T0.00 J0.05\r\n\
    Recv: echo:; Input Shaping:\r\n\
    Recv: echo:  M593 X F40.00 D0.15\r\n\
    Recv: echo:  M593 Y F35.50 D0.10\r\n\
    Recv: echo:  M900 K0.05\r\n\
    Recv: ok\r\n";

/// The same commands written at the top of a G-code file.
const M503_AS_GCODE: &str = "M203 X200.00 Y200.00 Z5.00 E25.00\n\
    M201 X2000.00 Y2000.00 Z100.00 E5000.00\nM204 P1200.00 R1500.00 T1800.00\n\
    M205 B20000.00 S0.00 T0.00 J0.05\nM593 X F40.00 D0.15\nM593 Y F35.50 D0.10\n";

/// Marlin under its M503 reply plans a job exactly as under the same commands at the
/// file's top (M92, which settle's G-code reader does not follow, set on the planner):
/// print time, worst and p95 contour error bit for bit. One move from rest to rest is
/// the trapezoid of `M204 P` (1200 mm/s^2, below `M201 X`) at the feed rate.
#[test]
fn a_marlin_m503_reply_plans_as_its_commands_at_the_files_top() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let m503 = write(d, "m503.txt", M503);
    let job = "G90\nM83\nG1 X60 E1 F6000\nG1 X60 Y40 E1\nG1 X0 Y0 E1\n";
    let file = write(d, "job.gcode", job);
    let from_reply = measure(
        &GcodeOptions::with_config(file, "printer_xy", Some(Firmware::Marlin), m503)
            .expect("options"),
    )
    .expect("runs");
    let prepended = write(d, "prepended.gcode", &format!("{M503_AS_GCODE}{job}"));
    let mut opts = GcodeOptions::new(prepended, "printer_xy", Firmware::Marlin).expect("options");
    let settle_gcode::job::PlannerConfig::Marlin(c) = &mut opts.job.planner else {
        panic!("Marlin's planner")
    };
    c.steps_per_m = [100e3, 100e3, 400e3, 93e3];
    let written = measure(&opts).expect("runs");
    assert_eq!(
        from_reply.print_time_s.to_bits(),
        written.print_time_s.to_bits()
    );
    assert_eq!(from_reply.worst_um.to_bits(), written.worst_um.to_bits());
    assert_eq!(from_reply.p95_um.to_bits(), written.p95_um.to_bits());
    assert_eq!(
        from_reply.setting,
        "marlin + X marlin:m593@40 Hz, Y marlin:m593@35.5 Hz"
    );
    let (settings, notes) = from_reply.config.as_ref().expect("read");
    assert!(
        settings.ends_with(
            "marlin: M203 X200 Y200 mm/s, M201 X2000 Y2000 mm/s^2, M204 P1200 T1800 mm/s^2, \
             M205 J0.05 mm, M92 X100 Y100 steps/mm; shaper X marlin:m593@40 Hz, Y marlin:m593@35.5 Hz"
        ),
        "{settings}"
    );
    assert_eq!(notes.len(), 1, "{notes:?}");
    assert!(notes[0].contains(":15: M900 (linear advance)"), "{notes:?}");

    // One move: 60 mm at 100 mm/s is the trapezoid of the reply's 1200 mm/s^2, d/v + v/a
    // (0.683 s; Marlin's blocks start and end a little above rest, its least step rate
    // and entry speed, so 0.6 % less), not of Marlin's default 3000 mm/s^2 (0.633 s).
    let one = write(d, "one.gcode", "G90\nM83\nG1 X60 E1 F6000\n");
    let t = measure(
        &GcodeOptions::with_config(
            one.clone(),
            "printer_xy",
            Some(Firmware::Marlin),
            d.join("m503.txt"),
        )
        .expect("options"),
    )
    .expect("runs")
    .print_time_s;
    let want = 60.0 / 100.0 + 100.0 / 1200.0;
    assert!(t < want && t > 0.99 * want, "{t} s, trapezoid {want} s");
    let default =
        measure(&GcodeOptions::new(one, "printer_xy", Firmware::Marlin).expect("options"))
            .expect("runs")
            .print_time_s;
    let at_default = 60.0 / 100.0 + 100.0 / 3000.0;
    assert!(
        default < at_default && default > 0.99 * at_default,
        "{default} s, trapezoid {at_default} s"
    );
}

/// A job's `M204 S` above the reply's `M204 P` and `T` is listed as raising them.
#[test]
fn a_jobs_m204_above_the_m503_reply_is_listed_as_raising_it() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let m503 = write(d, "m503.txt", M503);
    let file = write(d, "job.gcode", "G90\nM83\nM204 S3000\nG1 X60 E1 F6000\n");
    let m = measure(
        &GcodeOptions::with_config(file, "printer_xy", Some(Firmware::Marlin), m503)
            .expect("options"),
    )
    .expect("runs");
    let raised: Vec<(u64, &str, f64, f64)> = m
        .overrides
        .iter()
        .map(|o| (o.line, o.limit, o.configured, o.file))
        .collect();
    assert_eq!(
        raised,
        [
            (3, "M204 P print acceleration (mm/s^2)", 1200.0, 3000.0),
            (3, "M204 T travel acceleration (mm/s^2)", 1800.0, 3000.0),
        ]
    );
}

/// The command line: a reply is read (exit 0, the settings line, summary.md's
/// "Planner settings from" and report.html's); a refused value exits 2 naming the file
/// and line.
#[test]
fn settle_gcode_reads_a_marlin_m503_reply_end_to_end() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let m503 = write(d, "m503.txt", M503);
    let bad = write(d, "bad.txt", "echo:  M203 X200\necho:  M201 X-5\n");
    let gcode = write(d, "m.gcode", "G90\nM83\nG1 X10 E1 F6000\n");
    let run = |config: &Path, out: &Path| {
        settle()
            .arg("gcode")
            .arg(&gcode)
            .args([
                "--machine",
                "printer_xy",
                "--firmware",
                "marlin",
                "--config",
            ])
            .arg(config)
            .arg("--out")
            .arg(out)
            .output()
            .expect("settle runs")
    };
    let out = d.join("out");
    let ok = run(&m503, &out);
    let stdout = String::from_utf8_lossy(&ok.stdout);
    assert_eq!(
        ok.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
    let line = format!(
        "settings from {}: marlin: M203 X200 Y200 mm/s",
        m503.display()
    );
    assert!(stdout.contains(&line), "{stdout}");
    let summary = std::fs::read_to_string(out.join("summary.md")).expect("written");
    assert!(summary.contains(&format!("Planner {line}")), "{summary}");
    let html = std::fs::read_to_string(out.join("report.html")).expect("written");
    assert!(html.contains(&line), "report.html lacks {line}");
    let bad_out = d.join("bad-out");
    let refused = run(&bad, &bad_out);
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert_eq!(refused.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("bad.txt:2") && stderr.contains("M201"),
        "{stderr}"
    );
    assert!(!bad_out.exists());
}

/// What reading `--config` notes reaches the outputs, not only stderr: the real Voron's
/// printer.cfg sets `max_accel_to_decel: 6500` (line 41), which settle reads as Klipper
/// now does (`minimum_cruise_ratio = 0`, docs/Config_Changes.md of Klipper); summary.md's
/// "Configuration notes" and report.html's table carry that note word for word, as
/// stderr prints it.
#[test]
fn the_configurations_notes_are_in_summary_and_report() {
    let dir = tempfile::tempdir().expect("tempdir");
    let cfg = root().join("gcode/tests/data/real/voronpi/printer.cfg");
    let out = dir.path().join("out");
    let r = settle()
        .arg("gcode")
        .arg(root().join("gcode/prints/cube_layer.gcode"))
        .args(["--machine", "printer_xy", "--config"])
        .arg(&cfg)
        .arg("--out")
        .arg(&out)
        .output()
        .expect("settle runs");
    let stderr = String::from_utf8_lossy(&r.stderr);
    assert!(r.status.success(), "{stderr}");
    let note = stderr
        .lines()
        .find_map(|l| l.strip_prefix("note: "))
        .filter(|n| n.contains(":41: max_accel_to_decel = 6500 read as minimum_cruise_ratio = 0"))
        .unwrap_or_else(|| panic!("no max_accel_to_decel note: {stderr}"));
    let summary = std::fs::read_to_string(out.join("summary.md")).expect("written");
    let section = summary
        .split("## Configuration notes")
        .nth(1)
        .unwrap_or_else(|| panic!("no notes section: {summary}"));
    assert!(section.contains(&format!("- {note}\n")), "{section}");
    let html = std::fs::read_to_string(out.join("report.html")).expect("written");
    assert!(html.contains("Configuration notes (--config)"));
    let escaped = note
        .replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;");
    assert!(html.contains(&escaped), "report.html lacks {note}");
}
