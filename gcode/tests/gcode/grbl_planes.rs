//! GRBL's arcs in the ZX (G18) and YZ (G19) planes, as grbl/gcode.c takes them (G18: Z
//! then X, Y linear; G19: Y then Z, X linear; the offsets K/I and J/K) and
//! grbl/motion_control.c `mc_arc` cuts them: by hand on small arcs, and on two real
//! Fusion 360 jobs (gcode/prints/cnc/PROVENANCE.md) whose lead-in and lead-out arcs
//! must meet the cuts they lead into tangentially.

use settle_gcode::{
    Arc, ArcSegmentation, Dialect, EventKind, Move, Path, Plane, Point, Reader, ReaderOptions,
};

use super::moves;

fn grbl_cut(m: &Move) -> Vec<Point> {
    m.segments_for(&ArcSegmentation::default_for(Dialect::Grbl))
}

fn err(text: &str, dialect: Dialect) -> String {
    Reader::new(text.as_bytes(), ReaderOptions::new(dialect))
        .find_map(Result::err)
        .expect("an error")
        .to_string()
}

#[test]
fn a_zx_arc_turns_from_z_towards_x_about_its_k_i_centre() {
    // From X0 Y0 Z0 to X1 Z1 about X1 Z0 (I1 K0: the centre is the start plus K along Z
    // and I along X), Y from 0 to 2 (the linear axis). In (Z, X) the start radius is
    // (0, -1) and the end's (1, 0): a quarter turn counter-clockwise, so G3 takes the
    // quarter and G2 the three quarters the other way.
    let m = moves("G1 F600\nG18 G3 X1 Y2 Z1 I1 K0\n", Dialect::Grbl);
    let Path::Arc(a) = &m[0].path else {
        panic!("an arc")
    };
    assert_eq!(a.plane, Plane::Zx);
    assert_eq!(
        (a.centre_x_mm, a.centre_y_mm),
        (0.0, 1.0),
        "centre Z 0, X 1"
    );
    assert!((a.sweep_rad - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
    // Its length: the helix's, sqrt((r pi/2)^2 + 2^2).
    let by_hand = std::f64::consts::FRAC_PI_2.hypot(2.0);
    assert!((m[0].length_mm() - by_hand).abs() < 1e-12);
    // Halfway: at 45 degrees from the start, X 1 - cos 45, Z sin 45, Y 1.
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let mid = m[0].point_at(0.5);
    for (got, want) in [(mid.x_mm, 1.0 - h), (mid.y_mm, 1.0), (mid.z_mm, h)] {
        assert!((got - want).abs() < 1e-12, "{got} vs {want}");
    }
    // GRBL's cut at $12 = 0.002 mm: floor(|0.5 * pi/2 * 1| / sqrt(0.002 (2 - 0.002))) =
    // floor(0.785398 / 0.063214) = 12 segments, every point on the circle in ZX, Y in
    // equal steps.
    let pts = grbl_cut(&m[0]);
    assert_eq!(pts.len(), 12);
    for (k, p) in pts.iter().enumerate() {
        assert!(((p.x_mm - 1.0).hypot(p.z_mm) - 1.0).abs() < 1e-12);
        assert!((p.y_mm - 2.0 * (k + 1) as f64 / 12.0).abs() < 1e-12);
    }
    // The box holds the arc's extreme in its plane: its -X quadrant point is not on it
    // (X from 0 to 1, Z from 0 to 1 on this quarter) but the three quarters of G2 pass
    // through X 0 .. 2 and Z -1 .. 1.
    let long = moves("G1 F600\nG18 G2 X1 Z1 I1 K0\n", Dialect::Grbl);
    let b = long[0].bounds();
    assert_eq!((b.min_mm[0], b.max_mm[0]), (0.0, 2.0));
    assert_eq!((b.min_mm[2], b.max_mm[2]), (-1.0, 1.0));
    assert_eq!(
        grbl_cut(&long[0]).len(),
        37,
        "floor(0.5 * 3 pi/2 / 0.063214)"
    );
}

#[test]
fn a_yz_arc_turns_from_y_towards_z_about_its_j_k_centre() {
    // From the origin to Y1 Z1 about Y0 Z1 (J0 K1), X from 0 to 3: in (Y, Z) the start
    // radius is (0, -1), the end's (1, 0): G3 is the quarter.
    let m = moves("G1 F600\nG19 G3 X3 Y1 Z1 J0 K1\n", Dialect::Grbl);
    let Path::Arc(a) = &m[0].path else {
        panic!("an arc")
    };
    assert_eq!(a.plane, Plane::Yz);
    assert!((a.sweep_rad - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let mid = m[0].point_at(0.5);
    for (got, want) in [(mid.x_mm, 1.5), (mid.y_mm, h), (mid.z_mm, 1.0 - h)] {
        assert!((got - want).abs() < 1e-12, "{got} vs {want}");
    }
    for p in grbl_cut(&m[0]) {
        assert!((p.y_mm.hypot(p.z_mm - 1.0) - 1.0).abs() < 1e-12);
    }
    // G17 again: the next arc is in XY.
    let m = moves(
        "G1 F600\nG19 G3 Y1 Z1 J0 K1\nG17 G2 X1 Y0 I0 J-1\n",
        Dialect::Grbl,
    );
    let Path::Arc(a) = &m[1].path else {
        panic!("an arc")
    };
    assert_eq!(a.plane, Plane::Xy);
}

#[test]
fn what_grbl_refuses_in_a_plane_and_the_other_firmwares() {
    // No axis word of the plane: error:32 (grbl/gcode.c), G17 and G18 alike.
    let e = err("G1 F600\nG18 G2 Y5 I1\n", Dialect::Grbl);
    assert!(e.contains("error:32"), "{e}");
    let e = err("G1 F600\nG2 Z5 I1\n", Dialect::Grbl);
    assert!(e.contains("error:32"), "{e}");
    // No offset of the plane: J alone in G18 leaves no centre.
    let e = err("G1 F600\nG18 G2 X1 Z1 J1\n", Dialect::Grbl);
    assert!(e.contains("centre"), "{e}");
    // The printer firmwares' readers keep to G17.
    for d in [Dialect::Klipper, Dialect::Marlin, Dialect::Rrf] {
        let e = err("G1 X1 F600\nG18\nG2 X2 Z1 I1 K0\n", d);
        assert!(e.contains("G18/G19 arcs are read under GRBL"), "{d:?}: {e}");
    }
}

/// The direction of travel (unit, XYZ) of `m` at its start (`at_end` false) or end:
/// a line's direction, an arc's tangent (its radius turned a quarter in its plane).
fn direction(m: &Move, at_end: bool) -> [f64; 3] {
    let (s, e) = (m.start.xyz(), m.end.xyz());
    let d = match &m.path {
        Path::Line => [e[0] - s[0], e[1] - s[1], e[2] - s[2]],
        Path::Arc(a) => tangent(
            a,
            if at_end { e } else { s },
            e[a.plane.axes()[2]] - s[a.plane.axes()[2]],
        ),
    };
    let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    d.map(|v| v / n)
}

fn tangent(a: &Arc, p: [f64; 3], linear_mm: f64) -> [f64; 3] {
    let [first, second, linear] = a.plane.axes();
    let r = [p[first] - a.centre_x_mm, p[second] - a.centre_y_mm];
    // Counter-clockwise (G3): the radius turned +90 degrees; its speed r |sweep| along
    // the circle, `linear_mm` along the linear axis over the same sweep.
    let turn = if a.clockwise() { -1.0 } else { 1.0 };
    let mut t = [0.0; 3];
    t[first] = -r[1] * turn * a.sweep_rad.abs();
    t[second] = r[0] * turn * a.sweep_rad.abs();
    t[linear] = linear_mm;
    t
}

#[test]
fn fusion_360s_lead_arcs_meet_their_cuts_tangentially() {
    // Fusion 360's GRBL post leads into and out of each pass along a small arc in a
    // vertical plane (G18 or G19, radius 0.18 mm here) tangent to the cut: read with the
    // planes as GRBL takes them, every such arc leaves the move before it and enters the
    // one after it without turning; read in the mirrored planes (X then Z, Z then Y) the
    // turn would be 180 degrees. The header's ZMIN is the deepest point of the job.
    for (name, zmin) in [
        ("1084_btn_18bit_first.nc", -5.5),
        ("1089_wall_27bit.nc", -13.3),
    ] {
        let path = super::print_path(&format!("cnc/{name}"));
        let text = std::fs::read_to_string(&path).expect("print");
        assert!(
            text.contains(&format!("ZMIN={zmin} ")),
            "{name}: its header"
        );
        // By hand from the text (its words are spaced): the arcs (G2, G3) while G18 or
        // G19 holds (the plane is modal).
        let (mut plane, mut by_hand) = ("G17", 0);
        for line in text.lines() {
            for w in line.split_whitespace() {
                match w {
                    "G17" | "G18" | "G19" => plane = w,
                    "G2" | "G3" if plane != "G17" => by_hand += 1,
                    _ => {}
                }
            }
        }
        let mv: Vec<Move> = Reader::open(&path, ReaderOptions::new(Dialect::Grbl))
            .expect("opens")
            .filter_map(|e| match e.expect("GRBL reads every line").kind {
                EventKind::Move(m) => Some(m),
                _ => None,
            })
            .collect();
        let lowest = mv
            .iter()
            .map(|m| m.bounds().min_mm[2])
            .fold(f64::INFINITY, f64::min);
        assert_eq!(lowest, zmin, "{name}: the header's ZMIN");
        let mut seen = 0;
        for (k, m) in mv.iter().enumerate() {
            let Path::Arc(a) = &m.path else { continue };
            if a.plane == Plane::Xy {
                continue;
            }
            seen += 1;
            assert!(m.is_working(), "{name}: the spindle runs on a lead arc");
            for (before, after, at) in [
                (mv.get(k.wrapping_sub(1)), Some(m), "into"),
                (Some(m), mv.get(k + 1), "out of"),
            ] {
                let (Some(b), Some(c)) = (before, after) else {
                    continue;
                };
                let (u, v) = (direction(b, true), direction(c, false));
                let cos = u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
                assert!(
                    cos > 0.9999,
                    "{name}: move {k} ({:?}): the turn {at} it, cos {cos}",
                    a.plane
                );
            }
        }
        assert_eq!(seen, by_hand, "{name}: G18/G19 arcs");
        assert!(seen >= 6, "{name}");
    }
}
