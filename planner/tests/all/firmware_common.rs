//! Shared helpers of the firmware planner tests.

use settle_planner::firmware::{FirmwarePlanner, LinearMove, PlannedMove};

/// One millimetre (m).
pub const MM: f64 = 1e-3;

/// Assert `got` is within `tol` (relative) of `want`.
#[allow(dead_code)]
pub fn assert_rel(what: &str, got: f64, want: f64, tol: f64) {
    let r = (got - want).abs() / want.abs().max(1e-300);
    assert!(r <= tol, "{what}: got {got:.15e}, want {want:.15e}");
}

/// A move between two XY points (mm, at Z = 0) at `speed` (mm/s), extruding `e_mm`.
pub fn xye(from: [f64; 2], to: [f64; 2], e_mm: f64, speed: f64) -> LinearMove {
    LinearMove::new(
        [from[0] * MM, from[1] * MM, 0.0],
        [to[0] * MM, to[1] * MM, 0.0],
        e_mm * MM,
        speed * MM,
    )
}

/// A travel move between two XY points (mm) at `speed` (mm/s).
#[allow(dead_code)]
pub fn xy(from: [f64; 2], to: [f64; 2], speed: f64) -> LinearMove {
    xye(from, to, 0.0, speed)
}

/// Push `moves`, finish, and return every planned move and the print time.
#[allow(dead_code)]
pub fn plan_with(p: &mut dyn FirmwarePlanner, moves: &[LinearMove]) -> (Vec<PlannedMove>, f64) {
    let mut out = Vec::new();
    for m in moves {
        p.push(m).expect("move");
        out.extend(std::iter::from_fn(|| p.pop()));
    }
    p.finish();
    out.extend(std::iter::from_fn(|| p.pop()));
    (out, p.print_time_s())
}

/// Time of a trapezoid leg of length `l` cruising at `v` with acceleration `a`, from
/// `v0` to `v1`: both ramps, and the cruise over the rest.
#[allow(dead_code)]
pub fn leg(l: f64, v: f64, a: f64, v0: f64, v1: f64) -> f64 {
    (v - v0) / a
        + (v - v1) / a
        + (l - (v * v - v0 * v0) / (2.0 * a) - (v * v - v1 * v1) / (2.0 * a)) / v
}
