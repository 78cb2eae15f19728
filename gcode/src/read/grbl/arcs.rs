//! How GRBL cuts an arc (grbl/motion_control.c `mc_arc`), in the arc's plane (G17, G18 or
//! G19; the plane's linear axis moves with the angle): the sweep from `atan2` with
//! the direction's full-circle rule (`ARC_ANGULAR_TRAVEL_EPSILON`, 5e-7 rad), `floor(|0.5
//! sweep r| / sqrt($12 (2 r - $12)))` segments of equal angle (the chord of each strays at
//! most `$12`, the arc tolerance, from the arc), the linear axis in equal steps, the last
//! segment to the target. The firmware rotates the radius vector with a third-order small-angle
//! recurrence and an exact correction every `N_ARC_CORRECTION` (12) segments, in single
//! precision; here each point is the exact rotation in double precision (the recurrence
//! drifts less than a micrometre over 12 segments of an arc tolerance's size).

use crate::read::geometry::{Move, Path, Point};

/// GRBL's `$12` (arc tolerance).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GrblArcs {
    /// `$12`, mm (GRBL's default 0.002 mm).
    pub tolerance_mm: f64,
}

impl Default for GrblArcs {
    fn default() -> Self {
        GrblArcs {
            tolerance_mm: 0.002,
        }
    }
}

/// `ARC_ANGULAR_TRAVEL_EPSILON` (grbl/config.h).
const EPSILON_RAD: f64 = 5e-7;

/// The points of `mv`'s arc, start excluded, end included.
pub(crate) fn grbl(mv: &Move, p: &GrblArcs, out: &mut Vec<Point>) {
    let Path::Arc(a) = &mv.path else {
        out.push(mv.end);
        return;
    };
    // The plane's first and second axis and its linear axis (G17: X, Y and Z).
    let [first, second, linear] = a.plane.axes();
    let (s0, s1) = (mv.start.xyz(), mv.end.xyz());
    let c = [a.centre_x_mm, a.centre_y_mm];
    let (r0, r1) = (
        [s0[first] - c[0], s0[second] - c[1]],
        [s1[first] - c[0], s1[second] - c[1]],
    );
    let mut sweep = (r0[0] * r1[1] - r0[1] * r1[0]).atan2(r0[0] * r1[0] + r0[1] * r1[1]);
    if a.clockwise() {
        if sweep >= -EPSILON_RAD {
            sweep -= std::f64::consts::TAU;
        }
    } else if sweep <= EPSILON_RAD {
        sweep += std::f64::consts::TAU;
    }
    let r = r0[0].hypot(r0[1]);
    let tol = p.tolerance_mm;
    let n = ((0.5 * sweep * r).abs() / (tol * (2.0 * r - tol)).sqrt()).floor();
    let n = if n.is_finite() {
        n.min(f64::from(u16::MAX)) as u32
    } else {
        0
    };
    for i in 1..n {
        let th = sweep * f64::from(i) / f64::from(n);
        let (s, co) = th.sin_cos();
        let f = f64::from(i) / f64::from(n);
        let mut q = [0.0; 3];
        q[first] = c[0] + r0[0] * co - r0[1] * s;
        q[second] = c[1] + r0[0] * s + r0[1] * co;
        q[linear] = s0[linear] + (s1[linear] - s0[linear]) * f;
        out.push(Point {
            x_mm: q[0],
            y_mm: q[1],
            z_mm: q[2],
            e_mm: mv.start.e_mm,
        });
    }
    out.push(mv.end);
}
