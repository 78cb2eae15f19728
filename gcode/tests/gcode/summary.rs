//! Summary statistics of the shipped test prints, against numbers worked from their
//! geometry (gcode/examples/test_prints.rs).

use std::f64::consts::PI;

use settle_gcode::{Dialect, LimitChange, Reader, ReaderOptions, Summary};

use crate::print_path;

fn summary(name: &str, d: Dialect) -> Summary {
    Summary::read(Reader::open(print_path(name), ReaderOptions::new(d)).expect("test value"))
        .expect("test value")
}

#[test]
fn cube_layer() {
    let s = summary("cube_layer.gcode", Dialect::Marlin);
    // Two square perimeters inset 0.225 and 0.675 mm in a 20 mm square.
    assert!(
        (s.print_length_mm - 4.0 * (19.55 + 18.65)).abs() < 1e-9,
        "{}",
        s.print_length_mm
    );
    assert_eq!((s.print_moves, s.layers, s.dwells), (8, 1, 1));
    assert_eq!(s.bounds_print.min_mm, [100.225, 100.225, 0.2]);
    assert_eq!(s.bounds_print.max_mm, [119.775, 119.775, 0.2]);
    assert_eq!(s.limits.len(), 1);
    assert_eq!(
        s.limits[0].change,
        LimitChange::Accel {
            print_mm_s2: Some(1500.0),
            travel_mm_s2: Some(1500.0),
            retract_mm_s2: None
        }
    );
    assert_eq!(s.notes.len(), 1); // G28
    assert!((s.retracted_mm - 1.6).abs() < 1e-9);
}

#[test]
fn ringing_tower() {
    let s = summary("ringing_tower.gcode", Dialect::Klipper);
    // Five layers of a 20-edge wall: the 40 mm square with a 3 mm deep notch per side adds
    // 2 * 3 mm a side: 4 * (40 + 6) = 184 mm a layer.
    assert_eq!((s.layers, s.print_moves, s.extruder_moves), (5, 100, 10));
    assert!((s.print_length_mm - 5.0 * 184.0).abs() < 1e-9);
    assert_eq!(s.print_feed_range_mm_s, Some((150.0, 150.0)));
    let ignored: Vec<_> = s.ignored.keys().map(String::as_str).collect();
    assert_eq!(ignored, ["M104", "M106", "M107", "M140"]);
    assert!(matches!(
        s.limits[0].change,
        LimitChange::VelocityLimit {
            accel_mm_s2: Some(4000.0),
            ..
        }
    ));
    let text = s.to_string();
    assert!(
        text.contains("layers: 5")
            && text.contains("ignored commands: M104 x2, M106 x1, M107 x1, M140 x2"),
        "{text}"
    );
}

#[test]
fn arc_part() {
    let s = summary("arc_part.gcode", Dialect::Rrf);
    // Per layer: a 30 x 20 plate with 5 mm corners (2 * 20 + 2 * 10 straight + 2 pi 5),
    // the 4 mm hole (8 pi), and the two half-turn arcs through (104, 110): pi * 2 short and
    // 3 (2 pi - 2 asin(2/3)) long.
    let long = 3.0 * (2.0 * PI - 2.0 * (2.0f64 / 3.0).asin());
    let per_layer = 60.0 + 10.0 * PI + 8.0 * PI + 2.0 * PI + long;
    assert!(
        (s.print_length_mm - 2.0 * per_layer).abs() < 1e-9,
        "{} vs {}",
        s.print_length_mm,
        2.0 * per_layer
    );
    assert_eq!((s.layers, s.arc_moves), (2, 2 * 7 + 1));
    // The rounded corners reach the plate's edges; the hole and the two half turns stay
    // inside (the long arc's centre is (102, 110 + sqrt 5), its top 115.24).
    let b = &s.bounds_print;
    for (got, want) in [
        (b.min_mm[0], 95.0),
        (b.max_mm[0], 125.0),
        (b.min_mm[1], 100.0),
        (b.max_mm[1], 120.0),
    ] {
        assert!((got - want).abs() < 1e-9, "{b:?}");
    }
}
