//! Slicer feature types (`;TYPE:`), speed and extrusion factors (`M220`, `M221`), the
//! machine's travel and limits the file raises.

use settle_gcode::job::{Job, JobConfig};
use settle_gcode::{Dialect, EventKind, Reader, ReaderOptions};
use settle_planner::firmware::Firmware;

use super::moves;

#[test]
fn feature_comments_tag_the_moves_after_them() {
    let text = ";TYPE:External perimeter\nG1 X10 E1 F600\n;TYPE:Solid infill\nG1 Y10 E2\n\
                ;TYPE:External perimeter\nG1 X0 E3\n; FEATURE: Outer wall\nG1 Y0 E4\n";
    let mut r = Reader::new(text.as_bytes(), ReaderOptions::new(Dialect::Marlin));
    let tags: Vec<u16> = r
        .by_ref()
        .filter_map(|e| match e.expect("valid").kind {
            EventKind::Move(m) => Some(m.feature),
            _ => None,
        })
        .collect();
    assert_eq!(tags, [1, 2, 1, 3]);
    assert_eq!(
        r.features(),
        ["", "External perimeter", "Solid infill", "Outer wall"]
    );
    // Cura's names.
    let m = moves(";TYPE:WALL-OUTER\nG1 X1 E1\n", Dialect::Marlin);
    assert_eq!(m[0].feature, 1);
}

#[test]
fn speed_and_extrusion_factors_scale_the_file() {
    // M220 S50 halves the feed of the moves after it; Klipper's M220 without S is 100 %.
    let m = moves(
        "G1 X10 F6000\nM220 S50\nG1 X20\nM220\nG1 X30\n",
        Dialect::Klipper,
    );
    let feeds: Vec<f64> = m.iter().map(|m| m.feed_mm_s).collect();
    assert_eq!(feeds, [100.0, 50.0, 100.0]);
    // Marlin's percent is whole (M220.cpp `value_int`); without S it only reports.
    let m = moves("M220 S50.7\nG1 X10 F6000\nM220\nG1 X20\n", Dialect::Marlin);
    assert_eq!((m[0].feed_mm_s, m[1].feed_mm_s), (50.0, 50.0));
    // M221 S90: absolute E keeps its file position, the extrusion after it is 90 %
    // (Klipper's cmd_M221): E2 -> E4 extrudes 1.8 mm.
    let m = moves("M82\nG1 X1 E2 F600\nM221 S90\nG1 X2 E4\n", Dialect::Klipper);
    assert!(
        (m[1].extrusion_mm() - 1.8).abs() < 1e-12,
        "{}",
        m[1].extrusion_mm()
    );
}

fn job(cfg: JobConfig, text: &str) -> Result<Job<&[u8]>, settle_gcode::GcodeError> {
    let reader = Reader::new(text.as_bytes(), cfg.reader_options());
    let mut j = Job::new(reader, cfg)?;
    j.run_to_end()?;
    Ok(j)
}

#[test]
fn klipper_refuses_a_move_out_of_range_with_its_own_words() {
    let text = "[printer]\nkinematics: cartesian\nmax_velocity: 300\nmax_accel: 7000\n\
                [stepper_x]\nstep_pin: a\ndir_pin: b\nenable_pin: c\nrotation_distance: 40\n\
                microsteps: 16\nendstop_pin: d\nposition_endstop: 0\nposition_max: 235\n";
    let c = settle_gcode::config::KlipperConfig::parse(text, "printer.cfg").expect("config");
    let cfg = JobConfig::from_klipper(&c).expect("job config");
    assert_eq!(cfg.travel_mm[0], Some((0.0, 235.0)));
    let err = job(cfg.clone(), "G1 X100 F6000\nG1 X240 E1\n")
        .expect_err("refused")
        .to_string();
    assert!(
        err.contains(":2:") && err.contains("Move out of range: 240.000 0.000 0.000 [1.000]"),
        "{err}"
    );
    // A slicer's M204 S15000 over max_accel 7000: Klipper follows the file; it is called out.
    let j = job(cfg, "M204 S15000\nG1 X100 F6000\nM204 S16000\n").expect("runs");
    let o = &j.summary().overrides;
    assert_eq!(o.len(), 1, "{o:?}");
    assert_eq!(
        (o[0].line, o[0].configured, o[0].file),
        (1, 7000.0, 15000.0)
    );
    // Raised twice, the second time higher.
    assert_eq!((o[0].raises, o[0].highest), (2, 16000.0));
    assert_eq!(o[0].limit, "max_accel (mm/s^2)");
}

#[test]
fn grbl_travel_is_checked_on_the_job_extent_and_notes_reach_the_summary() {
    use settle_gcode::config::GrblSettings;
    let s = GrblSettings::parse("$130=100\n$20=1\n$22=1\n", "grbl.txt").expect("settings");
    let cfg = JobConfig::from_grbl(&s).expect("config");
    // 120 mm of X travel cannot fit 100 mm whatever the work offset: ALARM:2.
    let err = job(cfg.clone(), "G0 X-60\nG0 X60\n")
        .expect_err("refused")
        .to_string();
    assert!(err.contains("ALARM:2") && err.contains("$130"), "{err}");
    // M6 is listed as not followed.
    let j = job(cfg, "T1 M6\nG0 X10\n").expect("runs");
    assert!(
        j.summary().ignored.keys().any(|k| k.starts_with("M6:")),
        "{:?}",
        j.summary().ignored
    );
    let _ = Firmware::Grbl;
}

#[test]
fn reprapfirmware_clamps_a_printer_move_to_its_m208_limits() {
    // RepRapFirmware 3.5/3.6 on a printer (GCodes::DoStraightMove, Kinematics::LimitPosition):
    // a coordinate past M208 is clamped and the clamped point is the new position. So the
    // file below runs exactly as the file with X200 written in place of X250 and without
    // the travel to X260 (clamped onto where the toolhead already is), the extrusion as
    // written.
    let c =
        settle_gcode::config::RrfConfig::parse("M208 X0:200 Y0:200\n", "config.g").expect("config");
    let cfg = JobConfig::from_rrf(&c).expect("job config");
    assert_eq!(cfg.travel_mm[0], Some((0.0, 200.0)));
    let run = |text: &str| {
        let reader = Reader::new(text.as_bytes(), cfg.reader_options());
        let mut j = Job::new(reader, cfg.clone()).expect("job");
        for chunk in j.by_ref() {
            chunk.expect("runs");
        }
        (j.print_time_s(), j.summary())
    };
    let (t, s) = run("M83\nG1 X100 Y100 F6000\nG1 X250 E1\nG0 X260\nG1 X100 Y150 E2\n");
    let (want, _) = run("M83\nG1 X100 Y100 F6000\nG1 X200 E1\nG1 X100 Y150 E2\n");
    assert_eq!(t.to_bits(), want.to_bits(), "{t} vs {want}");
    assert!(
        s.ignored.keys().any(|k| k.contains("M208 X limits")),
        "{:?}",
        s.ignored
    );
    // An arc ending past the limits is abandoned with an error (GCodes::DoArcMove); one
    // that only passes beyond them on the way is clamped point by point.
    let reader = |t: &'static str| Reader::new(t.as_bytes(), cfg.reader_options());
    let err = Job::new(
        reader("G1 X190 Y100 F6000\nG2 X210 Y100 I10 J0\n"),
        cfg.clone(),
    )
    .expect("job")
    .run_to_end()
    .expect_err("refused")
    .to_string();
    assert!(
        err.contains(":2:") && err.contains("G2/G3: outside machine limits"),
        "{err}"
    );
    // A full circle about (196, 100) of radius 6 reaches X 202: RepRapFirmware 3.5/3.6
    // runs its segments up to the last one inside X 200 (GCodes::ReadMove aborts the
    // segmented move) and the next move starts there. Clockwise from (190, 100) it rises
    // over the top and meets X 200 at cos = 2/3, Y = 100 + 6 sqrt(5/9) = 104.47: the last
    // segment inside ends before that, higher up the circle.
    let mut j = Job::new(
        reader("G1 X190 Y100 F6000\nG2 X190 Y100 I6 J0\nG1 X100 Y100\n"),
        cfg.clone(),
    )
    .expect("job");
    let mut moves = Vec::new();
    for chunk in j.by_ref() {
        for m in chunk.expect("runs").moves {
            if moves
                .last()
                .is_none_or(|l: &std::sync::Arc<settle_gcode::job::MoveInfo>| l.index != m.index)
            {
                moves.push(m);
            }
        }
    }
    assert_eq!(moves.len(), 3);
    let (arc, next) = (&moves[1], &moves[2]);
    assert!(
        arc.end_mm.x_mm <= 200.0
            && arc.end_mm.x_mm > 199.0
            && arc.end_mm.y_mm > 100.0 + 6.0 * (1.0f64 - 4.0 / 9.0).sqrt(),
        "{:?}",
        arc.end_mm
    );
    assert_eq!(next.start_mm, arc.end_mm);
    assert!(
        j.summary()
            .ignored
            .keys()
            .any(|k| k.starts_with("G2: an arc past the M208 limits on the way")),
        "{:?}",
        j.summary().ignored
    );
}

#[test]
fn every_command_the_planner_does_not_follow_is_listed_for_every_printer_firmware() {
    // A start of print as slicers write it: none of these is motion the planner runs.
    let text = "M104 S200\nM109 S200\nM106 S255\nG29\nT0\nM900 K0.05\nM84\nG1 X10 E1 F600\n";
    for firmware in [Firmware::Klipper, Firmware::Rrf, Firmware::Marlin] {
        let j = job(JobConfig::defaults(firmware).expect("defaults"), text).expect("runs");
        let ignored = j.summary().ignored;
        let names: Vec<&str> = ignored
            .keys()
            .map(|k| k.split(':').next().unwrap_or(""))
            .collect();
        assert_eq!(
            names,
            ["G29", "M104", "M106", "M109", "M84", "M900", "T0"],
            "{firmware:?}: {ignored:?}"
        );
        assert!(ignored.values().all(|&n| n == 1), "{ignored:?}");
        assert!(
            ignored
                .keys()
                .any(|k| k.starts_with("M109: waits for a temperature")),
            "{ignored:?}"
        );
    }
}
