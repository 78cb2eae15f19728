//! Corner rounding error of a measured motion: for each path point, how close the
//! toolhead came to it while the plan was passing it.
//!
//! The time line is split between consecutive points at the midpoints of their planned
//! passing times ([`super::CornerPlan::time_s`]); a sample belongs to the point whose window
//! holds its time. The corner rounding error of a point is the smallest distance from the
//! point of all samples in its window: zero for a toolhead that touches the sharp corner,
//! the planned [`super::CornerPlan::deviation_m`] for one that follows the plan exactly.
//! Each update is a binary search over the windows, `O(log n)`.

use super::geometry::PathGeometry;
use super::vector::{dist, from_slice};

/// Streaming corner-rounding accumulator.
#[derive(Debug, Clone)]
pub struct CornerRounding<'a> {
    geometry: &'a PathGeometry,
    /// Window boundaries: sample time `t` belongs to point `partition_point(bounds <= t)`.
    bounds: Vec<f64>,
    min_m: Vec<f64>,
}

impl<'a> CornerRounding<'a> {
    /// An empty accumulator for the points of `geometry`.
    pub fn new(geometry: &'a PathGeometry) -> Self {
        let c = geometry.corners();
        let bounds = c
            .windows(2)
            .map(|w| 0.5 * (w[0].time_s + w[1].time_s))
            .collect();
        Self {
            geometry,
            bounds,
            min_m: vec![f64::INFINITY; c.len()],
        }
    }

    /// Add a sample: toolhead position `q` (2 or 3 coordinates, m) at time `t_s`.
    pub fn update(&mut self, t_s: f64, q: &[f64]) {
        let k = self.bounds.partition_point(|&b| b <= t_s);
        let d = dist(self.geometry.points()[k].position, from_slice(q));
        if d < self.min_m[k] {
            self.min_m[k] = d;
        }
    }

    /// Per point: the smallest distance of its window's samples from it (m; infinite if
    /// no sample fell in the window).
    pub fn min_distances_m(&self) -> &[f64] {
        &self.min_m
    }

    /// The largest rounding error over the interior points (the corners), m; 0 for a path
    /// without corners.
    pub fn max_corner_rounding_m(&self) -> f64 {
        let n = self.min_m.len();
        if n <= 2 {
            return 0.0;
        }
        self.min_m[1..n - 1].iter().copied().fold(0.0, f64::max)
    }
}
