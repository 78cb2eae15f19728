//! The planned path's geometry, for metrics: contour error (distance from a point to the
//! commanded path) and what happens at each corner.
//!
//! The *planned* path is what the trajectory traces: straight lines, the blends' cubic arcs
//! and the short arcs of velocity jumps. The *sharp* path is the polyline through the
//! points as given. Both are indexed by a bounding-box tree, so one distance query costs
//! about `O(log n)` for a path of `n` pieces (fast enough for every sample of a
//! simulation); [`PathGeometry::contour_error_hinted`] also reuses the last answer as a
//! starting bound, which makes successive samples along the path cheaper still.

use super::blend::BlendCase;
use super::bvh::Bvh;
use super::distance_poly::distance_roots;
use super::polyline::{PathPoint, PointKind};
use super::vector::{V3, add, axpy, dist, dot, from_slice, scale, sub};

/// One primitive of a path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Primitive {
    /// The straight line from `a` to `b` (m).
    Line {
        /// Start (m).
        a: V3,
        /// End (m).
        b: V3,
    },
    /// The arc `p(t) = p0 + v0 t + a0 t^2/2 + j t^3/6` for `t` in `[0, duration_s]`: one
    /// constant-jerk segment of a blend or velocity jump.
    Arc {
        /// Start position (m).
        p0: V3,
        /// Start velocity (m/s).
        v0: V3,
        /// Start acceleration (m/s^2).
        a0: V3,
        /// Jerk (m/s^3).
        j: V3,
        /// Duration (s).
        duration_s: f64,
    },
}

impl Primitive {
    /// Position on an arc at `t` (the line's `a + t (b - a)` for `t` in `[0, 1]`).
    pub fn point_at(&self, t: f64) -> V3 {
        match *self {
            Primitive::Line { a, b } => axpy(a, t, sub(b, a)),
            Primitive::Arc { p0, v0, a0, j, .. } => add(
                axpy(axpy(p0, t, v0), 0.5 * t * t, a0),
                scale(j, t * t * t / 6.0),
            ),
        }
    }

    /// Distance from `q` to the primitive (m).
    pub fn distance(&self, q: V3) -> f64 {
        match *self {
            Primitive::Line { a, b } => {
                let ab = sub(b, a);
                let l2 = dot(ab, ab);
                let t = if l2 > 0.0 {
                    (dot(sub(q, a), ab) / l2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                dist(q, axpy(a, t, ab))
            }
            Primitive::Arc { duration_s, .. } => self.arc_distance(q, duration_s),
        }
    }

    /// Minimise `|p(t) - q|^2` over `[0, T]`: the minimum is at an end or at a root of
    /// `h(t) = (p(t) - q) . p'(t)`, a quintic, all of whose roots in `[0, T]` are found
    /// (see `distance_poly`), so no local minimum is missed however tightly the arc turns.
    fn arc_distance(&self, q: V3, total: f64) -> f64 {
        let Primitive::Arc { p0, v0, a0, j, .. } = *self else {
            return self.distance(q);
        };
        // p(t) - q = c0 + c1 t + c2 t^2 + c3 t^3.
        let c = [sub(p0, q), v0, scale(a0, 0.5), scale(j, 1.0 / 6.0)];
        let mut h = [0.0; 6];
        for (i, ci) in c.iter().enumerate() {
            for (k, ck) in c.iter().enumerate().skip(1) {
                h[i + k - 1] += k as f64 * dot(*ci, *ck);
            }
        }
        let mut best = dist(self.point_at(0.0), q).min(dist(self.point_at(total), q));
        let mut roots = [0.0; 5];
        let n = distance_roots(&h, 0.0, total, &mut roots);
        for &t in &roots[..n] {
            best = best.min(dist(self.point_at(t), q));
        }
        best
    }

    /// Axis-aligned bounding box (for an arc: of its Bezier control points, which contain
    /// it).
    pub fn bounds(&self) -> (V3, V3) {
        let pts: Vec<V3> = match *self {
            Primitive::Line { a, b } => vec![a, b],
            Primitive::Arc {
                p0,
                v0,
                a0,
                j,
                duration_s: t,
            } => {
                let c1 = scale(v0, t);
                let c2 = scale(a0, 0.5 * t * t);
                let c3 = scale(j, t * t * t / 6.0);
                vec![
                    p0,
                    axpy(p0, 1.0 / 3.0, c1),
                    add(axpy(p0, 2.0 / 3.0, c1), scale(c2, 1.0 / 3.0)),
                    add(add(add(p0, c1), c2), c3),
                ]
            }
        };
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in pts {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        (lo, hi)
    }
}

/// How the plan passes a point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CornerTransition {
    /// Every axis at rest on the point (path ends, waypoints, exact stop, zero speed).
    Stop,
    /// Straight through (no direction change) at the planned speed.
    Pass,
    /// The jerk-limited corner blend ([`super::blend`]): leaves `distance_m` before the
    /// point, rejoins `distance_m` after.
    Blend {
        /// Which acceleration shape.
        case: BlendCase,
        /// Blend distance `d` (m).
        distance_m: f64,
        /// Duration (s).
        duration_s: f64,
    },
    /// Sharp corner: the velocity vector changes by `dv` (m/s) within `duration_s`
    /// (the configured velocity-jump time), centred on the point.
    Jump {
        /// Magnitude of the velocity change (m/s).
        dv: f64,
        /// Duration of the change (s).
        duration_s: f64,
    },
}

/// What the plan does at one path point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CornerPlan {
    /// 0-based point index.
    pub index: usize,
    /// Waypoint or control point.
    pub kind: PointKind,
    /// Interior angle (rad); `pi` at the path's ends.
    pub theta_rad: f64,
    /// Planned speed at the point (m/s): the blend's entry and exit speed, or the speed of
    /// a sharp corner.
    pub speed: f64,
    /// How the point is passed.
    pub transition: CornerTransition,
    /// Planned distance from the point to the path (m): the corner rounding the plan
    /// commands (blend deviation, or `dv T/8` of a velocity jump).
    pub deviation_m: f64,
    /// When the plan is at (or passes closest to) the point (s).
    pub time_s: f64,
}

/// The geometry of a planned path.
#[derive(Debug, Clone, PartialEq)]
pub struct PathGeometry {
    dim: usize,
    points: Vec<PathPoint>,
    primitives: Vec<Primitive>,
    planned: Bvh,
    sharp: Vec<Primitive>,
    sharp_tree: Bvh,
    corners: Vec<CornerPlan>,
}

impl PathGeometry {
    pub(crate) fn new(
        dim: usize,
        points: Vec<PathPoint>,
        primitives: Vec<Primitive>,
        corners: Vec<CornerPlan>,
    ) -> Self {
        let planned = Bvh::build(&primitives.iter().map(Primitive::bounds).collect::<Vec<_>>());
        let sharp: Vec<Primitive> = points
            .windows(2)
            .map(|w| Primitive::Line {
                a: w[0].position,
                b: w[1].position,
            })
            .collect();
        let sharp_tree = Bvh::build(&sharp.iter().map(Primitive::bounds).collect::<Vec<_>>());
        Self {
            dim,
            points,
            primitives,
            planned,
            sharp,
            sharp_tree,
            corners,
        }
    }

    /// Number of axes.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// The path points as given.
    pub fn points(&self) -> &[PathPoint] {
        &self.points
    }

    /// The planned path's primitives, in the order travelled.
    pub fn primitives(&self) -> &[Primitive] {
        &self.primitives
    }

    /// What the plan does at each point (one entry per point, ends included).
    pub fn corners(&self) -> &[CornerPlan] {
        &self.corners
    }

    /// Contour error: the distance (m) from `q` (2 or 3 coordinates) to the planned path.
    pub fn contour_error(&self, q: &[f64]) -> f64 {
        let q = from_slice(q);
        self.planned
            .nearest(q, |i| self.primitives[i].distance(q), None)
            .0
    }

    /// [`Self::contour_error`], starting the search from the primitive in `hint` (updated
    /// to the nearest one found): pass the same `hint` for successive samples.
    pub fn contour_error_hinted(&self, q: &[f64], hint: &mut usize) -> f64 {
        let q = from_slice(q);
        let (d, i) = self
            .planned
            .nearest(q, |i| self.primitives[i].distance(q), Some(*hint));
        *hint = i;
        d
    }

    /// The distance (m) from `q` to the sharp polyline through the points as given.
    pub fn sharp_error(&self, q: &[f64]) -> f64 {
        let q = from_slice(q);
        self.sharp_tree
            .nearest(q, |i| self.sharp[i].distance(q), None)
            .0
    }

    /// The largest planned corner deviation (m) over all points.
    pub fn max_planned_deviation_m(&self) -> f64 {
        self.corners
            .iter()
            .map(|c| c.deviation_m)
            .fold(0.0, f64::max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arc_distance_matches_dense_sampling() {
        // A quarter-circle-like cubic: p(t) = (t, t^2/2 * 4, 0) over [0, 1], plus a jerk.
        let arc = Primitive::Arc {
            p0: [0.0, 0.0, 0.0],
            v0: [1.0, 0.0, 0.0],
            a0: [0.0, 4.0, 0.0],
            j: [0.0, -3.0, 1.0],
            duration_s: 1.0,
        };
        for k in 0..50 {
            let q = [
                (k as f64 * 0.173).sin() * 1.5,
                (k as f64 * 0.291).cos() * 1.5,
                0.1 * (k % 3) as f64,
            ];
            let exact = arc.distance(q);
            let dense = (0..=200_000)
                .map(|i| dist(arc.point_at(i as f64 / 200_000.0), q))
                .fold(f64::INFINITY, f64::min);
            // Dense sampling is above the true minimum by at most (h v)^2 / (2 d) (and h v),
            // with the sample spacing h = 5e-6 and the speed v <= 3.2 here.
            let hv = 3.2 / 200_000.0;
            let tol = (hv * hv / (2.0 * exact)).min(hv) + 1e-14;
            assert!(exact <= dense + 1e-14, "{k}: {exact} vs {dense}");
            assert!(dense - exact <= tol, "{k}: {exact} vs {dense}");
        }
    }
}
