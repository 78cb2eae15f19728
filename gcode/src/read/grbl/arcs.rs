//! How GRBL cuts an arc (grbl/motion_control.c `mc_arc`): the sweep from `atan2` with
//! the direction's full-circle rule (`ARC_ANGULAR_TRAVEL_EPSILON`, 5e-7 rad), `floor(|0.5
//! sweep r| / sqrt($12 (2 r - $12)))` segments of equal angle (the chord of each strays at
//! most `$12`, the arc tolerance, from the arc), Z in equal steps, the last segment to
//! the target. The firmware rotates the radius vector with a third-order small-angle
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
    let c = [a.centre_x_mm, a.centre_y_mm];
    let (r0, r1) = (
        [mv.start.x_mm - c[0], mv.start.y_mm - c[1]],
        [mv.end.x_mm - c[0], mv.end.y_mm - c[1]],
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
        out.push(Point {
            x_mm: c[0] + r0[0] * co - r0[1] * s,
            y_mm: c[1] + r0[0] * s + r0[1] * co,
            z_mm: mv.start.z_mm + (mv.end.z_mm - mv.start.z_mm) * f,
            e_mm: mv.start.e_mm,
        });
    }
    out.push(mv.end);
}
