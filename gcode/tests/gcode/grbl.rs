//! The GRBL dialect against grbl/gcode.c's rules: several commands a line, modal motion,
//! the spindle and laser state and when GRBL stops for them, units, offsets, `$` lines.

use std::f64::consts::TAU;

use settle_gcode::{Dialect, EventKind, Move, Reader, ReaderOptions, Setting, Tool};

use super::{events, moves};

fn laser(text: &str) -> Vec<EventKind> {
    let opts = ReaderOptions {
        laser_mode: true,
        ..ReaderOptions::new(Dialect::Grbl)
    };
    Reader::new(text.as_bytes(), opts)
        .map(|e| e.expect("valid").kind)
        .collect()
}

fn err(text: &str) -> String {
    Reader::new(text.as_bytes(), ReaderOptions::new(Dialect::Grbl))
        .find_map(Result::err)
        .expect("an error")
        .to_string()
}

fn dwells(kinds: &[EventKind]) -> usize {
    kinds
        .iter()
        .filter(|k| matches!(k, EventKind::Dwell { .. }))
        .count()
}

#[test]
fn words_without_spaces_several_commands_and_modal_motion() {
    let m = moves(
        "G00 G17 G40 G21 G54\nG90\nG0X10Y5\nG1X20F600\nX30 Y5\nG91 X-5\n",
        Dialect::Grbl,
    );
    assert_eq!(m.len(), 4);
    assert!(m[0].rapid && !m[1].rapid && !m[2].rapid);
    // X30 Y5 continues G1 at F600 (10 mm/s); G91 X-5 moves back 5 mm.
    assert_eq!((m[2].end.x_mm, m[2].feed_mm_s), (30.0, 10.0));
    assert_eq!(m[3].end.x_mm, 25.0);
}

#[test]
fn the_laser_fires_on_feed_moves_at_s_and_stops_only_where_grbl_stops() {
    // LightBurn's layout for GRBL: M4 (dynamic power) once, S on the moves.
    let k = laser("G90\nM4\nG0 X1 Y1\nG1 X10 S800 F3000\nX12 S0\nX20 S500\nG0 X0\nM5\n");
    let mv: Vec<&Move> = k
        .iter()
        .filter_map(|e| match e {
            EventKind::Move(m) => Some(m),
            _ => None,
        })
        .collect();
    assert_eq!(mv[0].tool, Tool::Off, "G0 runs with the laser off");
    assert_eq!(
        mv[1].tool,
        Tool::Laser {
            s: 800.0,
            dynamic: true
        }
    );
    assert!(mv[1].is_working() && !mv[2].is_working() && mv[3].is_working());
    assert!(!mv[4].is_working());
    // Laser mode: S changes on moving lines do not stop the machine; M4 and M5 do.
    assert_eq!(dwells(&k), 2);
    // Without laser mode the same file stops at every S change with the spindle on.
    let spindle = events(
        "G90\nM3 S1000\nG1 X10 F600\nX20 S2000\nX30 S3000\nM5\n",
        Dialect::Grbl,
    );
    let kinds: Vec<_> = spindle.into_iter().map(|e| e.kind).collect();
    assert_eq!(dwells(&kinds), 4, "M3, two S changes, M5");
    let cuts = moves(
        "M3 S1000\nG0 Z5\nG1 Z-1 F100\nG1 X10\nM5\nG1 X0\n",
        Dialect::Grbl,
    );
    let working: Vec<bool> = cuts.iter().map(Move::is_working).collect();
    assert_eq!(working, [false, true, true, false]);
    assert_eq!(cuts[1].tool, Tool::Spindle { s: 1000.0 });
}

#[test]
fn inches_dwell_seconds_inverse_time_and_offsets() {
    // G20: 1 inch = 25.4 mm, F in inches per minute.
    let m = moves("G20 G1 X1 F60\n", Dialect::Grbl);
    assert_eq!((m[0].end.x_mm, m[0].feed_mm_s), (25.4, 25.4));
    // G4 P is seconds in GRBL.
    let e = events("G4 P1.5\n", Dialect::Grbl);
    assert_eq!(e[0].kind, EventKind::Dwell { duration_s: 1.5 });
    // G93: F is per minute of move time: 10 mm in 1/6 min is 1 mm/s.
    let m = moves("G93 G1 X10 F6\n", Dialect::Grbl);
    assert!((m[0].feed_mm_s - 1.0).abs() < 1e-12, "{}", m[0].feed_mm_s);
    // G92 renames (offset 10), G10 L20 P1 X0 makes the G54 offset 15 - 10 = 5 (work =
    // machine - G54 - G92), G92.1 drops the G92 offset: X1 is machine 6. G53 moves in
    // machine coordinates.
    let m = moves(
        "G1 X10 F600\nG92 X0\nG1 X5\nG10 L20 P1 X0\nG92.1\nG1 X1\nG53 G0 X0\n",
        Dialect::Grbl,
    );
    let ends: Vec<f64> = m.iter().map(|m| m.end.x_mm).collect();
    assert_eq!(ends, [10.0, 15.0, 6.0, 0.0]);
}

#[test]
fn grbl_refuses_what_it_does_not_run() {
    assert!(err("G1 X10\n").contains("error:22"), "{}", err("G1 X10\n"));
    assert!(err("G1 X1 E2 F100\n").contains("extruder"));
    assert!(err("G0 G1 X1\n").contains("error:21"));
    assert!(err("G64\n").contains("error:20"));
    assert!(err("G38.2 Z-5 F10\n").contains("probe"));
    assert!(err("$J=G91 X1 F100\n").contains("jog"));
    assert!(err("M3 S-1\n").contains("error:4"));
}

#[test]
fn dollar_settings_apply_only_while_idle_and_m6_is_not_followed() {
    let k = laser("$32=1\n$110=6000\nG1 X10 F600\n$110=3000\nG4 P0\n$120=200\nT1 M6\n");
    let settings: Vec<_> = k
        .iter()
        .filter_map(|e| match e {
            EventKind::Setting(Setting::Grbl { number, value }) => Some((*number, *value)),
            _ => None,
        })
        .collect();
    assert_eq!(settings, [(32, 1.0), (110, 6000.0), (120, 200.0)]);
    let notes = k.iter().filter(|e| matches!(e, EventKind::Note(_))).count();
    assert_eq!(notes, 2, "$110=3000 while moving (error:8), and M6");
}

#[test]
fn arcs_are_cut_by_the_arc_tolerance() {
    // A quarter circle of 10 mm: floor(|0.5 * pi/2 * 10| / sqrt(0.002 (20 - 0.002))) =
    // floor(7.854 / 0.19999) = 39 segments.
    let m = moves("G1 X10 F600\nG3 X0 Y10 I-10 J0\n", Dialect::Grbl);
    let pts = m[1].segments_for(&settle_gcode::ArcSegmentation::default_for(Dialect::Grbl));
    assert_eq!(pts.len(), 39);
    let r = |p: &settle_gcode::Point| p.x_mm.hypot(p.y_mm);
    assert!(pts.iter().all(|p| (r(p) - 10.0).abs() < 1e-9));
}

#[test]
fn a_job_plans_a_laser_file_with_the_settings_it_was_given() {
    use settle_gcode::config::GrblSettings;
    use settle_gcode::job::{Job, JobConfig};
    // 100 mm/s^2 and 6000 mm/min on X and Y, $11 = 0.01 mm, 1000 steps/mm: the square
    // corner of settle-planner's GRBL test (two 10 mm legs at F600 through the junction
    // deviation speed 1.84776 mm/s) takes 2.166459 s; M4 and M5 stop the machine (no
    // time); the G0 back to the start runs at the rapid rate, 100 mm/s: a 10 mm diagonal
    // of 14.142 mm is a triangle at 141.42 mm/s^2 (0.632 s).
    let settings =
        "$100=1000\n$101=1000\n$110=6000\n$111=6000\n$120=100\n$121=100\n$11=0.01\n$32=1\n";
    let s = GrblSettings::parse(settings, "grbl.txt").expect("settings");
    let cfg = JobConfig::from_grbl(&s).expect("config");
    let file = "G90\nM4\nG1 X10 S500 F600\nY10\nM5\nG0 X0 Y0\n";
    let reader = Reader::new(file.as_bytes(), cfg.reader_options());
    let mut job = Job::new(reader, cfg).expect("job");
    job.run_to_end().expect("plans");
    let a = 100.0 * 2f64.sqrt();
    let rapid = 2.0 * (10.0 * 2f64.sqrt() / a).sqrt();
    let s_half = 0.5f64.sqrt();
    let vj = (a * 0.01 * s_half / (1.0 - s_half)).sqrt();
    let leg = 10.0 / 100.0 + (10.0 - vj) / 100.0 + (10.0 - 0.5 - (100.0 - vj * vj) / 200.0) / 10.0;
    let want = 2.0 * leg + rapid;
    assert!((2.0 * leg - 2.166459).abs() < 1e-6);
    assert!(
        (job.print_time_s() - want).abs() < 1e-9,
        "{} {want}",
        job.print_time_s()
    );
    let summary = job.summary();
    assert!(summary.layers.iter().all(|l| l.working_s > 0.0));
}

/// The words of a line as (letter, value), read by hand: `G1 X95.454Y106.321Z-0`.
fn words(line: &str) -> Vec<(char, f64)> {
    let code = line.split(';').next().unwrap_or("");
    let mut out = Vec::new();
    let mut chars = code.chars().peekable();
    while let Some(c) = chars.next() {
        if c.is_ascii_alphabetic() {
            let mut num = String::new();
            while let Some(&d) = chars.peek() {
                if d.is_ascii_digit() || d == '.' || d == '-' {
                    num.push(d);
                    chars.next();
                } else {
                    break;
                }
            }
            if let Ok(v) = num.parse() {
                out.push((c.to_ascii_uppercase(), v));
            }
        }
    }
    out
}

/// The length of an XY arc (plus its Z) from `from` to `to` read by hand from its words:
/// the sweep about the centre `from + (I, J)` in the arc's direction (a whole turn when it
/// ends where it starts), or for the R form the chord's angle `2 asin(chord / 2R)`, the
/// long way round for a negative R.
fn arc_length_by_hand(w: &[(char, f64)], from: [f64; 3], to: [f64; 3], cw: bool) -> f64 {
    let word = |c: char| w.iter().find(|&&(l, _)| l == c).map(|&(_, v)| v);
    let (sweep, r) = if let Some(rr) = word('R') {
        let chord = (to[0] - from[0]).hypot(to[1] - from[1]);
        let short = 2.0 * (chord / (2.0 * rr.abs())).asin();
        (if rr < 0.0 { TAU - short } else { short }, rr.abs())
    } else {
        let c = [
            from[0] + word('I').unwrap_or(0.0),
            from[1] + word('J').unwrap_or(0.0),
        ];
        let (a, b) = (
            [from[0] - c[0], from[1] - c[1]],
            [to[0] - c[0], to[1] - c[1]],
        );
        let ccw = (a[0] * b[1] - a[1] * b[0]).atan2(a[0] * b[0] + a[1] * b[1]);
        let sweep = match (cw, ccw) {
            (_, 0.0) => TAU,
            (true, s) if s < 0.0 => -s,
            (true, s) => TAU - s,
            (false, s) if s > 0.0 => s,
            (false, s) => TAU + s,
        };
        (sweep, a[0].hypot(a[1]))
    };
    (sweep * r).hypot(to[2] - from[2])
}

#[test]
fn the_shipped_laser_and_cnc_jobs_work_where_their_text_says() {
    // By hand from the text: the raster's G1 lines with S above 0 are the burn (laser
    // mode from its `$32=1`); every G1, G2 and G3 of the CNC contour cuts (M3 S10000
    // from the start, M5 at the end), plunges included, the rapids (G0) do not.
    for (name, laser) in [("laser_raster.gcode", true), ("cnc_contour.gcode", false)] {
        let text = std::fs::read_to_string(super::print_path(name)).expect("print");
        let (mut pos, mut s, mut by_hand, mut cuts) = ([0.0f64; 3], 0.0, 0.0, 0);
        let mut arcs = 0;
        for line in text.lines() {
            let w = words(line);
            let g = |n: f64| w.iter().any(|&(l, v)| l == 'G' && v == n);
            let mut to = pos;
            for &(l, v) in &w {
                match l {
                    'X' => to[0] = v,
                    'Y' => to[1] = v,
                    'Z' => to[2] = v,
                    'S' => s = v,
                    _ => {}
                }
            }
            let d = if g(2.0) || g(3.0) {
                arcs += 1;
                arc_length_by_hand(&w, pos, to, g(2.0))
            } else if g(1.0) {
                ((to[0] - pos[0]).powi(2) + (to[1] - pos[1]).powi(2) + (to[2] - pos[2]).powi(2))
                    .sqrt()
            } else {
                0.0
            };
            if d > 0.0 && (!laser || s > 0.0) {
                by_hand += d;
                cuts += 1;
            }
            pos = to;
        }
        // The contour's arcs: 3 rings in each of 2 pocket passes, 4 corners in each of
        // 3 profile passes.
        assert_eq!(arcs, if laser { 0 } else { 18 }, "{name}");
        let r = Reader::open(super::print_path(name), ReaderOptions::new(Dialect::Grbl))
            .expect("opens");
        let (mut settle, mut n) = (0.0, 0);
        for e in r {
            if let EventKind::Move(m) = e.expect("valid").kind
                && m.is_working()
            {
                settle += m.length_mm();
                n += 1;
            }
        }
        assert_eq!(n, cuts, "{name}");
        assert!(
            (settle - by_hand).abs() < 1e-9 * by_hand,
            "{name}: {settle} vs {by_hand}"
        );
    }
}

#[test]
fn a_setting_grbl_refuses_is_named_as_grbl_writes_it() {
    let e = settle_gcode::config::GrblSettings::parse("$100=80\n$110=0\n", "grbl.txt")
        .expect_err("GRBL refuses a max rate of 0");
    assert_eq!(
        e.to_string(),
        "grbl.txt:2: $110 = `0`: not allowed (allowed: from 1e-9 to 1e9)"
    );
}

/// A `$` value GRBL would not read, or beyond the 1e9 every other dialect's limits stop
/// at, is refused at its line: GRBL's `read_float` reads no exponent, so `$120=1e300`
/// leaves `e300` after the number (error:3, grbl/nuts_bolts.c, grbl/system.c); the same
/// in a settings file. A plain decimal up to 1e9 is read.
#[test]
fn a_setting_value_grbl_cannot_read_or_above_1e9_is_refused() {
    for (text, part) in [
        ("$120=1e300", "error:3"),
        ("$120=3000mm", "error:3"),
        ("$110=6e3", "error:3"),
        ("$120=10000000000", "0 to 1e9"),
        ("$11=1000000001", "0 to 1e9"),
        ("$120=nan", "error:2"),
    ] {
        let e = crate::error(&format!("G21\n{text}\nG1 X1 F100\n"), Dialect::Grbl);
        assert_eq!(e.line(), Some(2), "{text}");
        assert!(e.to_string().contains(part), "{text}: {e}");
        let e = settle_gcode::config::GrblSettings::parse(&format!("{text}\n"), "grbl.txt")
            .expect_err(text);
        assert!(e.to_string().contains(part), "{text}: {e}");
    }
    let s = settle_gcode::config::GrblSettings::parse("$120=1000000000\n$110=+6000.\n", "grbl.txt")
        .expect("plain decimals");
    assert_eq!((s.accel_mm_s2[0], s.max_rate_mm_min[0]), (1e9, 6000.0));
}

/// The `S` notes of `text` read with `$31`, `$30` = `range`: (line, reason).
fn s_notes(text: &str, range: [f64; 2]) -> Vec<(u64, &'static str)> {
    let opts = ReaderOptions {
        laser_mode: true,
        spindle_range: range,
        ..ReaderOptions::new(Dialect::Grbl)
    };
    Reader::new(text.as_bytes(), opts)
        .map(|e| e.expect("valid"))
        .filter_map(|e| match e.kind {
            EventKind::Note(settle_gcode::Note::IgnoredByFirmware { command, reason })
                if command == "S" =>
            {
                Some((e.line, reason))
            }
            _ => None,
        })
        .collect()
}

/// GRBL runs an `S` outside `$31..$30` at the nearer end (gnea/grbl
/// grbl/spindle_control.c `spindle_compute_pwm_value`: `rpm >= rpm_max` gives
/// `rpm_max`, `0 < rpm <= rpm_min` gives `rpm_min`, `S0` off; grblHAL's
/// `spindle_set_rpm` the same): which moves work is unchanged, and the file's power is
/// noted where it is not what runs. The old reader passed `S5000` on a `$30=1000` laser
/// without a word; negative `S` stays refused (error:4), and GRBL's `read_float`
/// (grbl/nuts_bolts.c) reads no exponent, so `S1e9` is `S1` followed by a word `E`
/// GRBL does not have.
#[test]
fn s_outside_the_spindle_range_runs_at_its_end_and_is_noted() {
    let text = "G90\nM4 S5000\nG1 X10 F600\nX20 S1000\nX30 S50\nX40 S0\nM5\n";
    let notes = s_notes(text, [100.0, 1000.0]);
    assert_eq!(notes.len(), 2, "{notes:?}");
    assert_eq!(notes[0].0, 2);
    assert!(notes[0].1.starts_with("above $30"), "{notes:?}");
    assert_eq!(notes[1].0, 5);
    assert!(notes[1].1.contains("below $31"), "{notes:?}");
    // Which moves work: every feed move with S above 0 (the clamp keeps it above 0).
    let working: Vec<bool> = laser(text)
        .into_iter()
        .filter_map(|k| match k {
            EventKind::Move(m) => Some(m.is_working()),
            _ => None,
        })
        .collect();
    assert_eq!(working, [true, true, true, false]);
    // The file's own $30 moves the end: S5000 is within $30=8000.
    assert!(s_notes("$30=8000\nM4 S5000\nG1 X10 F600\n", [0.0, 1000.0]).is_empty());
    assert!(err("M3 S-1\n").contains("error:4"));
    let e = err("M3 S1e9\n");
    assert!(e.contains("no extruder"), "{e}");
}
