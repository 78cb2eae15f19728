//! `settle gcode` on lasers, mills and slicer features: the working moves (the laser on at
//! `S > 0`) are what count, a file without one is refused, the fly-axis error of a scan
//! line is the closed-form following error of the mode, and the error per feature type.

use settle::workflows::gcode::{GcodeOptions, measure};
use settle_gcode::config::GrblSettings;
use settle_gcode::job::JobConfig;
use settle_planner::firmware::Firmware;

use crate::support::one_mode::OneMode;
use crate::support::write;

const ONE_MODE: &str = "name = \"one mode\"\n\
     [axis.x]\nmodes = [{ frequency_hz = 40.0, damping_ratio = 0.05 }]\n\
     [axis.y]\nmodes = [{ frequency_hz = 40.0, damping_ratio = 0.05 }]\n";

/// GRBL at 6000 mm/min and 3000 mm/s^2 on X and Y, 1000 steps/mm, laser mode.
fn grbl(file: std::path::PathBuf, machine: &str) -> GcodeOptions {
    let s = GrblSettings::parse(
        "$100=1000\n$101=1000\n$110=6000\n$111=6000\n$120=3000\n$121=3000\n$32=1\n",
        "grbl.txt",
    )
    .expect("settings");
    let mut o = GcodeOptions::new(file, machine, Firmware::Grbl).expect("options");
    o.job = JobConfig::from_grbl(&s).expect("job");
    o
}

/// One scan line along X with the laser on (GRBL, one block from rest to rest: the
/// trapezoid at 3000 mm/s^2 to 100 mm/s over 30 mm) on a one-mode machine (40 Hz, zeta
/// 0.05): the error along X, `e = x - x_cmd`, obeys `e'' + 2 zeta w e' + w^2 e = -a(t)`,
/// phase by phase the free vibration of `e + a/w^2` about `-a/w^2`; the fly-axis error is
/// `|e|` at the samples of the working move and of the ringing after it (which belongs
/// to the last move). Y never moves: the contour error, the distance to the line, sees
/// only the overshoot past its end. Before
/// working moves counted, a laser line measured nothing (every error 0 um).
#[test]
fn a_scan_line_measures_the_closed_form_error_along_the_fly_axis() {
    let dir = tempfile::tempdir().expect("tempdir");
    let machine = write(dir.path(), "one_mode.toml", ONE_MODE);
    let file = write(dir.path(), "line.nc", "G90\nM3 S500\nG1 X30 F6000\n");
    let o = measure(&grbl(file, machine.to_str().expect("utf-8"))).expect("runs");
    let mode = OneMode::new(40.0, 0.05);
    let (vmax, amax, d) = (0.1, 3.0, 0.03);
    let ta = vmax / amax;
    let tc = (d - vmax * vmax / amax) / vmax;
    let t_end = 2.0 * ta + tc;
    assert!(
        (o.print_time_s - t_end).abs() <= 1e-12,
        "{}",
        o.print_time_s
    );
    // e at time t of the move (or after it).
    let e_at = |t: f64| {
        let (mut e, mut v) = (0.0, 0.0);
        let mut t0 = 0.0;
        for (acc, dur) in [(amax, ta), (0.0, tc), (-amax, ta), (0.0, f64::INFINITY)] {
            if t <= t0 + dur {
                return mode.phase(e, v, acc, t - t0).0;
            }
            (e, v) = mode.phase(e, v, acc, dur);
            t0 += dur;
        }
        e
    };
    let tail = o.streamed.tail.expect("ringing after the move");
    let dt = 1.0 / 2000.0;
    let last = ((t_end + tail.duration_s) / dt).round() as u64;
    let expected = (1..=last)
        .map(|k| e_at(k as f64 * dt).abs() * 1e6)
        .fold(0.0, f64::max);
    let fly = &o.streamed.fly;
    assert_eq!(fly.raster(), Some(0), "a scan line along X");
    let got = fly.worst[0].as_ref().expect("a worst").error_um;
    assert!(
        (got - expected).abs() <= 1e-9 * expected,
        "fly-axis error {got} vs closed form {expected}"
    );
    assert!(expected > 50.0, "{expected}");
    // The contour error sees only what leaves the segment (the overshoot past its end).
    assert!(o.worst_um < got, "contour {} vs fly {got}", o.worst_um);
}

/// A raster is lines along one axis; a vector job's straight lines run along both. A
/// 30 x 31 mm rectangle cut with the laser on is not a raster, though more than half its
/// length (62 of 122 mm) is lines along Y: its error along a side misplaces no pixel, and
/// summary.md has no raster section. Ten scan lines along X with that rectangle around
/// them (360 mm along X, 62 along Y: more than a tenth) are not one either; with a
/// diagonal outline instead (no line along Y) they are, fly axis X.
#[test]
fn a_vector_cut_is_not_a_raster() {
    let dir = tempfile::tempdir().expect("tempdir");
    let machine = write(dir.path(), "one_mode.toml", ONE_MODE);
    let rectangle = "G1 X30 F6000\nG1 Y31\nG1 X0\nG1 Y0\n";
    let mut scan = String::new();
    for k in 0..10 {
        let x = if k % 2 == 0 { 30 } else { 0 };
        scan.push_str(&format!("G0 Y{}\nG1 X{x} F6000\n", 1 + 2 * k));
    }
    let diamond = "G0 X15 Y0\nG1 X30 Y15 F6000\nG1 X15 Y30\nG1 X0 Y15\nG1 X15 Y0\n";
    for (name, body, want) in [
        ("rectangle", rectangle.to_string(), None),
        (
            "scan and rectangle",
            format!("{scan}G0 X0 Y0\n{rectangle}"),
            None,
        ),
        ("scan and diamond", format!("{scan}{diamond}"), Some(0)),
    ] {
        let file = write(dir.path(), "job.nc", &format!("G90\nM4 S500\n{body}M5\n"));
        let o = measure(&grbl(file, machine.to_str().expect("utf-8"))).expect("runs");
        assert_eq!(o.streamed.fly.raster(), want, "{name}");
        let summary = settle::workflows::gcode::report::summary_md(&o, &[]);
        assert_eq!(summary.contains("## Raster scan"), want.is_some(), "{name}");
    }
}

#[test]
fn a_file_without_a_working_move_is_refused() {
    let dir = tempfile::tempdir().expect("tempdir");
    let machine = write(dir.path(), "one_mode.toml", ONE_MODE);
    // The laser is never switched on: nothing is engraved, nothing to measure.
    let file = write(dir.path(), "off.nc", "G90\nG1 X30 F6000\nG1 Y10\n");
    let err = measure(&grbl(file, machine.to_str().expect("utf-8")))
        .expect_err("refused")
        .to_string();
    assert!(
        err.contains("none of them working") && err.contains("M3 or M4"),
        "{err}"
    );
}

#[test]
fn the_error_is_given_per_feature_type_with_the_outer_wall_first() {
    let dir = tempfile::tempdir().expect("tempdir");
    let machine = write(dir.path(), "one_mode.toml", ONE_MODE);
    // A square of outer wall with a sharp corner, then infill across it.
    let file = write(
        dir.path(),
        "walls.gcode",
        "G90\nM83\nG1 X10 Y10 F6000\n;TYPE:External perimeter\nG1 X40 E1 F6000\nG1 Y40 E1\n\
         G1 X10 E1\nG1 Y10 E1\n;TYPE:Solid infill\nG1 X40 Y40 E2 F3000\n",
    );
    let o = measure(
        &GcodeOptions::new(file, machine.to_str().expect("utf-8"), Firmware::Klipper)
            .expect("options"),
    )
    .expect("runs");
    assert_eq!(o.features, ["", "External perimeter", "Solid infill"]);
    let f = &o.streamed.features.stats;
    let (wall, infill) = (&f[&1], &f[&2]);
    assert!(wall.errors.total() > 0 && infill.errors.total() > 0);
    // Every working sample is one of the two: their worst is the job's.
    assert_eq!(wall.worst_um().max(infill.worst_um()), o.worst_um);
    let csv = String::from_utf8(settle::workflows::gcode::features::features_csv(&o).expect("csv"))
        .expect("utf-8");
    let second = csv.lines().nth(1).expect("a row");
    assert!(second.starts_with("External perimeter,true,"), "{csv}");
}

#[test]
fn each_layer_gives_each_feature_types_worst_and_p95() {
    let dir = tempfile::tempdir().expect("tempdir");
    let machine = write(dir.path(), "one_mode.toml", ONE_MODE);
    // Layer 1: outer wall only; layer 2: outer wall, then infill across it.
    let square = "G1 X40 E1 F6000\nG1 Y40 E1\nG1 X10 E1\nG1 Y10 E1\n";
    let file = write(
        dir.path(),
        "layers.gcode",
        &format!(
            "G90\nM83\nG1 X10 Y10 F6000\n;LAYER_CHANGE\n;Z:0.2\nG1 Z0.2\n;TYPE:External perimeter\n\
             {square};LAYER_CHANGE\n;Z:0.4\nG1 Z0.4\n{square};TYPE:Solid infill\nG1 X40 Y40 E2 F3000\n"
        ),
    );
    let o = measure(
        &GcodeOptions::new(file, machine.to_str().expect("utf-8"), Firmware::Klipper)
            .expect("options"),
    )
    .expect("runs");
    use settle::workflows::gcode::features::{layer_features_csv, layer_outer_wall};
    let stats = |layer: u32| {
        o.layers
            .iter()
            .find(|l| l.layer == layer)
            .and_then(|l| l.stats.clone())
            .expect("simulated layer")
    };
    // A layer of outer wall alone: its outer wall's numbers are the layer's, counted by
    // the layer's own histogram.
    let (l1, l2) = (stats(1), stats(2));
    let (w1, p1) = layer_outer_wall(&o, 1).expect("outer wall in layer 1");
    assert_eq!((w1, p1), (l1.worst_um(), l1.p95_um));
    // With infill too, the larger of the two types' worst is the layer's.
    let f = &o.streamed.features;
    let (w2, p2) = layer_outer_wall(&o, 2).expect("outer wall in layer 2");
    let infill = f.layer_worst[&(2, 2)];
    assert_eq!(w2.max(infill), l2.worst_um());
    assert!(p2 > 0.0 && p2 <= w2 * 1.001 && f.layer_p95[&(2, 2)] > 0.0);
    let csv = String::from_utf8(layer_features_csv(&o).expect("csv")).expect("utf-8");
    let rows: Vec<&str> = csv.lines().collect();
    assert_eq!(rows.len(), 4, "{csv}");
    assert!(
        rows[1].starts_with("1,0.2,External perimeter,true,")
            && rows[3].starts_with("2,0.4,Solid infill,false,"),
        "{csv}"
    );
}

/// A real Fusion 360 job for a GRBL mill (gcode/prints/cnc/PROVENANCE.md: passes led in
/// and out along arcs in the ZX and YZ planes, G18/G19) reads whole and runs. Without a
/// shaper its smoothing (the command's distance to the written path) is GRBL's rounding
/// of every target to whole steps (grbl/planner.c): at most half a step on X and on Y,
/// `hypot(0.5, 0.5) / steps_per_mm`, plus the corner bridge of a junction's speed jump
/// (docs/guide/your-print.md: below 0.1 um here). At 40 steps/mm (the Shapeoko 3's
/// `$100`, gcode/prints/shapeoko3_grbl_settings.txt) that is 17.68 um; at 1000 steps/mm,
/// 0.71 um, and the job's smoothing falls with it: it is the step grid's. summary.md says
/// so with the job's numbers.
#[test]
fn a_real_fusion_360_jobs_smoothing_is_grbls_step_grid() {
    let file = crate::support::root().join("gcode/prints/cnc/1084_btn_18bit_first.nc");
    let shapeoko = std::fs::read_to_string(
        crate::support::root().join("gcode/prints/shapeoko3_grbl_settings.txt"),
    )
    .expect("settings");
    let mut worst = Vec::new();
    for steps in [40.0, 1000.0] {
        let text = format!("{shapeoko}\n$100={steps}\n$101={steps}\n");
        let s = GrblSettings::parse(&text, "grbl.txt").expect("settings");
        let mut o = GcodeOptions::new(file.clone(), "printer_xy", Firmware::Grbl).expect("options");
        o.job = JobConfig::from_grbl(&s).expect("job");
        let out = measure(&o).expect("the job runs");
        let smoothing = out.streamed.split_worst.smoothing_um;
        let bound = 0.5f64.hypot(0.5) / steps * 1e3 + 0.1;
        assert!(
            smoothing > 0.0 && smoothing <= bound,
            "{steps} steps/mm: smoothing {smoothing} um, bound {bound} um"
        );
        // summary.md gives the job's own half step and the bound.
        let summary = settle::workflows::gcode::report::summary_md(&out, &[]);
        let half = format!("X {0:.2} um, Y {0:.2} um here", 0.5e3 / steps);
        let together = format!("up to {:.2} um together", bound - 0.1);
        assert!(
            summary.contains(&half) && summary.contains(&together),
            "{summary}"
        );
        worst.push(smoothing);
    }
    assert!(worst[1] < worst[0] / 10.0, "{worst:?}");
}

/// A real Cura file (gcode/prints/cura/PROVENANCE.md) marks its layers `;LAYER:n` and
/// names no Z: each layer's Z is where its first extruding move in a plane runs, 1 mm
/// apart from the header's `;MINZ:` to its `;MAXZ:` (`;Layer height: 1`), so error-z can
/// draw the layers (it had no Z to draw them at). One layer is simulated; every layer
/// is planned.
#[test]
fn a_cura_files_layers_are_at_the_z_they_print_at() {
    let file = crate::support::root().join("gcode/prints/cura/Kreistest.gcode");
    let text = std::fs::read_to_string(&file).expect("print");
    let header = |key: &str| -> f64 {
        let v = text.lines().find_map(|l| l.strip_prefix(key)).expect(key);
        v.trim().parse().expect("a number")
    };
    let (min_z, max_z) = (header(";MINZ:"), header(";MAXZ:"));
    let opts = GcodeOptions {
        layers: Some((1, 1)),
        ..GcodeOptions::new(file, "printer_xy", Firmware::Marlin).expect("options")
    };
    let out = measure(&opts).expect("the job runs");
    let z: Vec<f64> = out.layers.iter().map(|l| l.z_mm.expect("a Z")).collect();
    assert_eq!(z.len() as f64, header(";LAYER_COUNT:"));
    for (k, z) in z.iter().enumerate() {
        assert!(
            (z - (min_z + k as f64)).abs() < 1e-9,
            "layer {}: {z}",
            k + 1
        );
    }
    assert_eq!(z.last(), Some(&max_z));
}

/// `GcodeOptions` for `file` on `printer_xy` under GRBL with the repository's laser
/// settings (gcode/prints/laser_grbl_settings.txt).
fn laser_settings(file: std::path::PathBuf) -> GcodeOptions {
    let text = std::fs::read_to_string(
        crate::support::root().join("gcode/prints/laser_grbl_settings.txt"),
    )
    .expect("settings");
    let s = GrblSettings::parse(&text, "laser_grbl_settings.txt").expect("settings");
    let mut o = GcodeOptions::new(file, "printer_xy", Firmware::Grbl).expect("options");
    o.job = JobConfig::from_grbl(&s).expect("job");
    o
}

/// A real Inkscape Lasertools fill (gcode/prints/laser/PROVENANCE.md) sets the power on
/// lines of its own, `S90` before each line of its infill and `S1` after it. GRBL waits
/// for the machine to stop at an `S` change on a line that does not move (grbl/gcode.c,
/// `spindle_sync`), so every move of the infill runs from rest to rest: its time is the
/// sum of one trapezoid per move, computed here from the file's words alone (targets
/// rounded to whole steps, 80 steps/mm; the rate and acceleration along the move's
/// direction, the smallest over its axes of `$110/|u|` and `$120/|u|`; a `G0` at the
/// rapid rate, a `G1` at its `F`), and settle's planned time is that sum. The whole job
/// (the outlines after the infill run as joined lines) is a raster along Y; the frame
/// the plugin wrote for it and a real LaserWeb cut are not.
#[test]
fn real_laser_jobs_stop_where_grbl_stops_and_only_the_fill_is_a_raster() {
    let dir = crate::support::root().join("gcode/prints/laser");
    let job = dir.join("btc_laser_qr_unbt_0001.gcode");
    let text = std::fs::read_to_string(&job).expect("print");
    let settings = std::fs::read_to_string(
        crate::support::root().join("gcode/prints/laser_grbl_settings.txt"),
    )
    .expect("settings");
    for want in [
        "$100=80.000",
        "$101=80.000",
        "$110=6000.000",
        "$111=6000.000",
    ] {
        assert!(settings.contains(want), "{want}");
    }
    assert!(settings.contains("$120=1000.000") && settings.contains("$121=1000.000"));
    let (steps, vmax, amax) = (80.0, 100.0, 1000.0);
    // The infill: the lines before `;END infill`, then the laser off.
    let end = text.find(";END infill").expect("infill");
    let infill = format!("{}M05 S0\n", &text[..end]);
    let (mut at, mut feed, mut g0) = ([0i64; 2], 0.0, true);
    let mut by_hand = 0.0;
    let mut moves = 0;
    for line in infill.lines() {
        let line = line.split(';').next().unwrap_or("");
        let mut target = at;
        let mut moved = false;
        for w in line.split_whitespace() {
            let (k, v) = w.split_at(1);
            match k {
                "G" => g0 = v.parse::<f64>().expect("G") == 0.0,
                "F" => feed = v.parse::<f64>().expect("F") / 60.0,
                "X" | "Y" => {
                    let i = usize::from(k == "Y");
                    target[i] = (v.parse::<f64>().expect("coordinate") * steps).round() as i64;
                    moved = true;
                }
                _ => {}
            }
        }
        if !moved || target == at {
            continue;
        }
        let d = [
            (target[0] - at[0]) as f64 / steps,
            (target[1] - at[1]) as f64 / steps,
        ];
        let len = d[0].hypot(d[1]);
        let along = |limit: f64| {
            d.iter()
                .filter(|c| **c != 0.0)
                .map(|c| limit * len / c.abs())
                .fold(f64::INFINITY, f64::min)
        };
        let (rate, accel) = (along(vmax), along(amax));
        let v = if g0 { rate } else { feed.min(rate) };
        by_hand += if len <= v * v / accel {
            2.0 * (len / accel).sqrt()
        } else {
            len / v + v / accel
        };
        moves += 1;
        at = target;
    }
    assert_eq!(
        moves, 7574,
        "the infill's 3,787 G00 and 3,787 G01 that move"
    );
    let scratch = tempfile::tempdir().expect("tempdir");
    let infill_file = write(scratch.path(), "infill.gcode", &infill);
    let o = measure(&laser_settings(infill_file)).expect("the infill runs");
    assert!(
        (o.print_time_s - by_hand).abs() < 1e-6 * by_hand,
        "settle {} s, by hand {by_hand} s",
        o.print_time_s
    );
    let whole = measure(&laser_settings(job)).expect("the job runs");
    assert!(whole.print_time_s > o.print_time_s);
    // Two of its 6,243 working moves (lines 16787 and 17100 of the outlines, X 39.38 to
    // 39.37 and Y 53.18 to 53.17) round to the same step at 80 steps/mm: GRBL drops a
    // block of no step, and 6,241 working moves run.
    let ran: u64 = whole
        .layers
        .iter()
        .filter_map(|l| l.stats.as_ref())
        .map(|s| s.print_moves)
        .sum();
    assert_eq!(ran, 6241);
    assert_eq!(whole.streamed.fly.raster(), Some(1), "scan lines along Y");
    for name in [
        "btc_laser_qr_unbt_0001_bounding_box.gcode",
        "escaleras_300-02.gcode",
    ] {
        let o = measure(&laser_settings(dir.join(name))).expect("the job runs");
        assert_eq!(o.streamed.fly.raster(), None, "{name}");
        if name.starts_with("escaleras") {
            // Its 118,235.73 mm of cuts at the header's 1000 mm/min are a floor.
            assert!(
                o.print_time_s > 118_235.73 / (1000.0 / 60.0),
                "{}",
                o.print_time_s
            );
        }
    }
}
