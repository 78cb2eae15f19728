//! Arc geometry against closed forms.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use settle_gcode::{Dialect, GcodeError, Path};

use crate::{close_rel, error, moves};

fn only_arc(text: &str) -> (settle_gcode::Move, settle_gcode::Arc) {
    let mv = *moves(text, Dialect::Marlin).last().expect("a move");
    match mv.path {
        Path::Arc(a) => (mv, a),
        Path::Line => panic!("not an arc"),
    }
}

#[test]
fn quarter_circle_length_is_pi_r_over_2() {
    let r = 7.3;
    let (mv, a) = only_arc(&format!("G1 X{r} Y0\nG3 X0 Y{r} I-{r} J0"));
    assert!(
        close_rel(mv.length_mm(), FRAC_PI_2 * r, 1e-9),
        "{}",
        mv.length_mm()
    );
    assert!(close_rel(a.sweep_rad, FRAC_PI_2, 1e-12));
    assert_eq!((a.centre_x_mm, a.centre_y_mm, a.radius_mm), (0.0, 0.0, r));
    // G2 to the same point goes the other way round: three quarters, clockwise.
    let (mv, a) = only_arc(&format!("G1 X{r} Y0\nG2 X0 Y{r} I-{r} J0"));
    assert!(close_rel(mv.length_mm(), 1.5 * PI * r, 1e-9));
    assert!(a.clockwise());
}

#[test]
fn full_circle_and_helix() {
    let r = 4.0;
    let (mv, a) = only_arc(&format!("G1 X{r} Y0 F600\nG2 I-{r} J0 E3"));
    assert!(a.is_full_circle() && a.clockwise());
    assert!(close_rel(mv.length_mm(), TAU * r, 1e-9));
    let h = 1.7;
    let (mv, a) = only_arc(&format!("G1 X{r} Y0\nG3 X{r} Y0 Z{h} I-{r} J0"));
    assert!(a.is_full_circle() && !a.clockwise());
    assert!(close_rel(
        mv.length_mm(),
        ((TAU * r).powi(2) + h * h).sqrt(),
        1e-9
    ));
    // A helical half turn (sweep pi) rising 0.4.
    let (mv, _) = only_arc(&format!("G1 X{r} Y0\nG3 X-{r} Y0 Z0.4 I-{r} J0"));
    assert!(close_rel(
        mv.length_mm(),
        ((PI * r).powi(2) + 0.16).sqrt(),
        1e-9
    ));
    // The midpoint of that half turn is the top of the circle, at half the rise.
    let p = mv.point_at(0.5);
    assert!(p.x_mm.abs() < 1e-12 && (p.y_mm - r).abs() < 1e-12 && (p.z_mm - 0.2).abs() < 1e-15);
}

/// OrcaSlicer's spiral lift (its `z_hop_types = Spiral Lift`), as it writes it before a
/// travel: `G17`, then a helix that ends where it starts, with `P1`. Klipper reads no `P`
/// (klippy/extras/gcode_arcs.py takes X Y Z E F I J and passes over other words) and
/// traces an arc ending at its start as one full turn; the reader notes the `P` it passed
/// over. Marlin reads `P` as extra turns only when built with ARC_P_CIRCLES, and
/// RepRapFirmware not at all: those dialects refuse the word, naming what they take.
#[test]
fn orca_spiral_lift_is_one_full_turn_under_klipper() {
    use settle_gcode::{EventKind, Note};
    let text = "G1 X81.256 Y78.477 Z.4 F30000\nG17\nG3 Z.8 I.044 J-1.216 P1  F30000\n";
    let ev = crate::events(text, Dialect::Klipper);
    let notes: Vec<_> = ev
        .iter()
        .filter_map(|e| match &e.kind {
            EventKind::Note(Note::IgnoredByFirmware { command, .. }) => Some(command.as_str()),
            _ => None,
        })
        .collect();
    assert_eq!(notes, ["G3 P1"]);
    // Written without spaces, the note still names the P word alone.
    let compact = "G1 X81.256 Y78.477 Z.4 F30000\nG17\nG3Z.8I.044J-1.216P1F30000\n";
    let listed = crate::events(compact, Dialect::Klipper)
        .iter()
        .filter_map(|e| match &e.kind {
            EventKind::Note(Note::IgnoredByFirmware { command, .. }) => Some(command.clone()),
            _ => None,
        })
        .collect::<Vec<_>>();
    assert_eq!(listed, ["G3 P1"]);
    let mv = *moves(text, Dialect::Klipper).last().expect("a move");
    let Path::Arc(a) = mv.path else {
        panic!("not an arc")
    };
    assert!(a.is_full_circle() && !a.clockwise());
    let r = 0.044f64.hypot(1.216);
    assert!(close_rel(a.radius_mm, r, 1e-12));
    assert!(close_rel(mv.length_mm(), (TAU * r).hypot(0.4), 1e-9));
    assert_eq!(
        (mv.end.x_mm, mv.end.y_mm, mv.end.z_mm),
        (81.256, 78.477, 0.8)
    );
    assert!(!mv.is_working());
    for d in [Dialect::Marlin, Dialect::Rrf] {
        match error(text, d) {
            GcodeError::UnknownParameter { param, .. } => assert_eq!(param, "P", "{d}"),
            other => panic!("{d}: {other}"),
        }
    }
}

#[test]
fn r_form_short_and_long_arcs() {
    // Chord 6 and radius 5: the short arc sweeps 2 asin(0.6), the long one the rest.
    let short = 2.0 * (0.6f64).asin();
    let (mv, a) = only_arc("G1 X0 Y0\nG3 X6 Y0 R5");
    assert!(
        close_rel(mv.length_mm(), 5.0 * short, 1e-9),
        "{}",
        mv.length_mm()
    );
    // Counter-clockwise from (0,0) to (6,0) the short way dips below the chord: the
    // centre is above it, at (3, 4).
    assert!(
        (a.centre_x_mm - 3.0).abs() < 1e-12 && (a.centre_y_mm - 4.0).abs() < 1e-12,
        "{a:?}"
    );
    let (mv, a) = only_arc("G1 X0 Y0\nG3 X6 Y0 R-5");
    assert!(close_rel(mv.length_mm(), 5.0 * (TAU - short), 1e-9));
    assert!((a.centre_y_mm + 4.0).abs() < 1e-12);
    assert_eq!(a.radius_word_mm, Some(-5.0));
    // Clockwise the short way: the centre below.
    let (_, a) = only_arc("G1 X0 Y0\nG2 X6 Y0 R5");
    assert!((a.centre_y_mm + 4.0).abs() < 1e-12);
    // Exactly half the chord: a half circle on it.
    let (mv, a) = only_arc("G1 X0 Y0\nG2 X6 Y0 R3");
    assert!(close_rel(mv.length_mm(), 3.0 * PI, 1e-9) && a.centre_y_mm.abs() < 1e-15);
}

#[test]
fn r_slightly_short_is_a_half_circle_and_too_short_is_an_error() {
    // RepRapFirmware's slack: R^2 - d^2/4 >= -0.02 R^2, i.e. R >= 3 / sqrt(1.02) for chord 6.
    let (mv, a) = only_arc("G1 X0 Y0\nG3 X6 Y0 R2.98");
    assert!(close_rel(a.radius_mm, 3.0, 1e-12) && close_rel(mv.length_mm(), 3.0 * PI, 1e-9));
    match error("G1 X0 Y0\nG3 X6 Y0 R2.9", Dialect::Marlin) {
        GcodeError::ArcRadiusTooSmall {
            at,
            radius_mm,
            chord_mm,
            ..
        } => {
            assert_eq!((at.line, radius_mm, chord_mm), (2, 2.9, 6.0));
        }
        e => panic!("{e}"),
    }
}

#[test]
fn end_radius_tolerance_follows_grbl() {
    // 0.004 mm off on a 10 mm radius: within 0.005 mm, accepted; the arc keeps the start
    // radius and ends at the written end point.
    let mv = *moves("G1 X10 Y0\nG3 X0 Y10.004 I-10 J0", Dialect::Marlin)
        .last()
        .expect("test value");
    assert_eq!((mv.end.x_mm, mv.end.y_mm), (0.0, 10.004));
    // 0.02 mm off on 10 mm (0.2 %): refused, with the line and both radii.
    match error("G1 X10 Y0\n\nG3 X0 Y10.02 I-10 J0", Dialect::Marlin) {
        GcodeError::ArcRadiusMismatch {
            at,
            start_radius_mm,
            end_radius_mm,
            ..
        } => {
            assert_eq!(at.line, 3);
            assert_eq!(start_radius_mm, 10.0);
            assert!((end_radius_mm - 10.02).abs() < 1e-12);
        }
        e => panic!("{e}"),
    }
    // 0.02 mm off on a 100 mm radius (0.02 %): accepted.
    moves("G1 X100 Y0\nG3 X0 Y100.02 I-100 J0", Dialect::Marlin);
    // 0.6 mm off on 1000 mm (0.06 %) is over grbl's 0.5 mm cap: refused.
    assert!(matches!(
        error("G1 X1000 Y0\nG3 X0 Y1000.6 I-1000 J0", Dialect::Marlin),
        GcodeError::ArcRadiusMismatch { .. }
    ));
}

#[test]
fn bounds_include_the_quadrant_points_passed() {
    // Three quarters clockwise from (5,0) about the origin to (0,5): passes (0,-5), (-5,0).
    let mv = *moves("G1 X5 Y0\nG2 X0 Y5 I-5 J0", Dialect::Rrf)
        .last()
        .expect("test value");
    let b = mv.bounds();
    assert_eq!(
        (b.min_mm[0], b.max_mm[0], b.min_mm[1], b.max_mm[1]),
        (-5.0, 5.0, -5.0, 5.0)
    );
    // A quarter counter-clockwise from (5,0) to (0,5) passes no other quadrant point.
    let mv = *moves("G1 X5 Y0\nG3 X0 Y5 I-5 J0", Dialect::Rrf)
        .last()
        .expect("test value");
    let b = mv.bounds();
    assert_eq!(
        (b.min_mm[0], b.max_mm[0], b.min_mm[1], b.max_mm[1]),
        (0.0, 5.0, 0.0, 5.0)
    );
}

#[test]
fn malformed_arcs_are_errors() {
    let e = |t: &str| error(t, Dialect::Marlin);
    assert!(matches!(e("G2 X1 Y1"), GcodeError::ArcWithoutCentre { .. }));
    assert!(matches!(
        e("G2 X1 Y1 I0 J0"),
        GcodeError::ArcWithoutCentre { .. }
    ));
    assert!(matches!(
        e("G2 X1 Y1 R0"),
        GcodeError::ArcWithoutCentre { .. }
    ));
    assert!(matches!(
        e("G2 X1 Y1 I1 R1"),
        GcodeError::ArcMixedForms { .. }
    ));
    assert!(matches!(
        e("G1 X1 Y1\nG2 X1 Y1 R3"),
        GcodeError::ArcDegenerate { .. }
    ));
    assert!(matches!(
        e("G2 X2 Y0 I1 J0 K1"),
        GcodeError::UnknownParameter { .. }
    ));
    assert!(matches!(
        e("G18\nG2 X2 Y0 I1"),
        GcodeError::Unsupported { .. }
    ));
}

/// The first error of a Klipper job on `text` (its chunks pulled until one fails).
fn job_error(text: &str) -> GcodeError {
    use settle_gcode::job::{Job, JobConfig};
    let cfg = JobConfig::defaults(settle_planner::firmware::Firmware::Klipper).expect("defaults");
    let reader = settle_gcode::Reader::new(
        text.as_bytes(),
        settle_gcode::ReaderOptions::new(cfg.dialect),
    );
    let mut job = Job::new(reader, cfg).expect("job");
    match job.by_ref().collect::<Result<Vec<_>, _>>() {
        Err(e) => e,
        Ok(c) => panic!("{} chunks, no error", c.len()),
    }
}

#[test]
fn an_arc_cut_into_more_than_the_segment_bound_is_refused_at_its_line() {
    // Klipper cuts an arc into floor(length / 1 mm) segments (gcode_arcs' resolution):
    // a full circle of radius 15,916 mm is 2 pi 15,916 = 100,003.2 mm, 100,003 segments,
    // three past the bound; nothing of it is planned.
    let text = "G28\nG1 X10 Y10 F6000\nG2 X10 Y10 I15916 J0 F600000\n";
    match job_error(text) {
        GcodeError::ArcTooManySegments {
            at,
            command,
            segments,
            max,
            length_mm,
            ..
        } => {
            assert_eq!((at.line, command.as_str()), (3, "G2"));
            assert_eq!((segments, max), (100_003, settle_gcode::MAX_ARC_SEGMENTS));
            assert!(close_rel(length_mm, TAU * 15_916.0, 1e-12), "{length_mm}");
        }
        e => panic!("{e}"),
    }
    // The same circle a hair smaller, 15,915 mm (99,996 segments), is planned.
    let text = "G28\nG1 X10 Y10 F6000\nG2 X10 Y10 I15915 J0 F600000\nG1 X20 Y10 F0.1\n";
    match job_error(text) {
        GcodeError::TooLong { at, .. } => assert_eq!(at.line, 4),
        e => panic!("{e}"),
    }
}
