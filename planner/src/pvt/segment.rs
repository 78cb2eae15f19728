//! The PVT building block: over a segment of duration `t` the acceleration is
//! linear from `a0` to `a1` (constant jerk `(a1 - a0)/t`), so
//!
//! - `x1 = x0 + v0 t + a0 t^2/2 + (a1 - a0) t^2/6`, `v1 = v0 + (a0 + a1) t/2`;
//! - given both ends `(x0, v0)`, `(x1, v1)` and `t`:
//!   `a0 = (6 (x1 - x0) - 4 t v0 - 2 t v1)/t^2`,
//!   `a1 = -(6 (x1 - x0) - 2 t v0 - 4 t v1)/t^2`;
//! - given both ends and `a0`, the duration solves `a0 t^2/6 + (2 v0 + v1) t/3 = x1 - x0`:
//!   `t = 6 (x1 - x0)/((2 v0 + v1) +- sqrt((2 v0 + v1)^2 + 6 a0 (x1 - x0)))` (the
//!   quadratic's roots written cancellation free).
//!
//! All three are checked against each other and against [`crate::Segment`] integration in
//! `planner/tests/all/pvt.rs`.

/// End position and velocity of a segment: `(x1, v1)`.
pub fn end(x0: f64, v0: f64, a0: f64, a1: f64, t: f64) -> (f64, f64) {
    (
        x0 + v0 * t + a0 * t * t / 2.0 + (a1 - a0) * t * t / 6.0,
        v0 + (a0 + a1) * t / 2.0,
    )
}

/// Start and end acceleration `(a0, a1)` of the segment through `(x0, v0)` and `(x1, v1)`
/// lasting `t > 0`.
pub fn accels(x0: f64, v0: f64, x1: f64, v1: f64, t: f64) -> (f64, f64) {
    let dx = x1 - x0;
    (
        (6.0 * dx - 4.0 * t * v0 - 2.0 * t * v1) / (t * t),
        -(6.0 * dx - 2.0 * t * v0 - 4.0 * t * v1) / (t * t),
    )
}

/// The durations `t > 0` of segments from `(x0, v0)` with start acceleration `a0` that
/// arrive at `(x1, v1)`: up to two, smallest first. The end
/// acceleration of each is then `2 (v1 - v0)/t - a0`.
pub fn durations_given_a0(x0: f64, v0: f64, a0: f64, x1: f64, v1: f64) -> Vec<f64> {
    let dx = x1 - x0;
    let b = 2.0 * v0 + v1;
    let disc = b * b + 6.0 * a0 * dx;
    if disc < 0.0 {
        return Vec::new();
    }
    let s = disc.sqrt();
    let mut out: Vec<f64> = [b + s, b - s]
        .into_iter()
        .map(|den| 6.0 * dx / den)
        .filter(|t| t.is_finite() && *t > 0.0)
        .collect();
    // With a0 = 0 one denominator is 0 or 2b: the linear case b t/3 = dx, no special case.
    out.sort_by(f64::total_cmp);
    out.dedup();
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accels_invert_end() {
        let (x0, v0, a0, a1, t) = (0.3, -1.2, 2.5, -4.0, 0.7);
        let (x1, v1) = end(x0, v0, a0, a1, t);
        let (b0, b1) = accels(x0, v0, x1, v1, t);
        assert!((b0 - a0).abs() < 1e-12 && (b1 - a1).abs() < 1e-12);
        let ts = durations_given_a0(x0, v0, a0, x1, v1);
        assert!(ts.iter().any(|&s| (s - t).abs() < 1e-12), "{ts:?}");
    }
}
