//! Metrics of motion along a path, computed streaming beside
//! [`crate::measure::accumulator::Accumulator`] whenever the trajectory carries path geometry.
//!
//! Definitions (toolhead position `q`, a vector over the machine's axes, which are the
//! path's coordinates):
//! - `max_contour_error_um`: the largest distance from `q` to the *commanded* path (the
//!   planned lines, blend arcs and velocity-jump arcs) over the samples with `t <= T`.
//! - `contour_error_after_um`: the same, largest over the samples after the move (`t > T`,
//!   the observation window): how far the residual vibration leaves the path.
//! - `max_sharp_error_um`: the largest distance from `q` to the path as drawn (the sharp
//!   polyline through the points) for `t <= T`: commanded rounding plus following.
//! - `corner_rounding_um`: the commanded path's largest distance from a sharp corner (the
//!   planned deviation of the blends and velocity jumps; 0 for exact stop).
//! - `toolhead_corner_rounding_um`: for each corner, the toolhead's closest approach to the
//!   corner point while the plan passes it; the largest over the corners.
//! - `corner_speed_mm_s`: the lowest planned speed at an interior point (the corner speed
//!   of a two-segment corner).

use settle_planner::path::{CornerRounding, PathGeometry};

/// Column names in `runs.csv`.
pub mod columns {
    /// Planned corner speed (mm/s).
    pub const CORNER_SPEED: &str = "corner_speed_mm_s";
    /// Commanded corner rounding (um).
    pub const CORNER_ROUNDING: &str = "corner_rounding_um";
    /// Toolhead to commanded path during the move (um).
    pub const MAX_CONTOUR: &str = "max_contour_error_um";
    /// Toolhead to commanded path after the move (um).
    pub const CONTOUR_AFTER: &str = "contour_error_after_um";
    /// Toolhead to the sharp path during the move (um).
    pub const MAX_SHARP: &str = "max_sharp_error_um";
    /// Toolhead's closest approach to the corner (um).
    pub const TOOLHEAD_ROUNDING: &str = "toolhead_corner_rounding_um";
    /// Every column, in `runs.csv` order.
    pub const ALL: [&str; 6] = [
        CORNER_SPEED,
        CORNER_ROUNDING,
        MAX_CONTOUR,
        CONTOUR_AFTER,
        MAX_SHARP,
        TOOLHEAD_ROUNDING,
    ];
}

/// Path metrics of one run (lengths in um, speeds in mm/s).
#[derive(Debug, Clone, PartialEq)]
pub struct PathMetrics {
    /// Lowest planned speed at an interior point (mm/s); `inf` for a path without corners.
    pub corner_speed_mm_s: f64,
    /// Largest commanded distance from a sharp corner (um).
    pub corner_rounding_um: f64,
    /// Largest toolhead distance from the commanded path during the move (um).
    pub max_contour_error_um: f64,
    /// Largest toolhead distance from the commanded path after the move (um).
    pub contour_error_after_um: f64,
    /// Largest toolhead distance from the sharp path during the move (um).
    pub max_sharp_error_um: f64,
    /// Largest closest approach of the toolhead to a corner (um).
    pub toolhead_corner_rounding_um: f64,
}

impl PathMetrics {
    /// The values in [`columns::ALL`] order.
    pub fn values(&self) -> [f64; 6] {
        [
            self.corner_speed_mm_s,
            self.corner_rounding_um,
            self.max_contour_error_um,
            self.contour_error_after_um,
            self.max_sharp_error_um,
            self.toolhead_corner_rounding_um,
        ]
    }
}

/// Streaming accumulator of [`PathMetrics`].
#[derive(Debug, Clone)]
pub struct PathAccumulator<'a> {
    geometry: &'a PathGeometry,
    move_end_s: f64,
    hint: usize,
    rounding: CornerRounding<'a>,
    max_during_m: f64,
    max_after_m: f64,
    max_sharp_m: f64,
}

impl<'a> PathAccumulator<'a> {
    /// For a path planned to end at `move_end_s` (T).
    pub fn new(geometry: &'a PathGeometry, move_end_s: f64) -> Self {
        Self {
            geometry,
            move_end_s,
            hint: 0,
            rounding: CornerRounding::new(geometry),
            max_during_m: 0.0,
            max_after_m: 0.0,
            max_sharp_m: 0.0,
        }
    }

    /// One toolhead sample (m, one coordinate per path axis) at `t_s`; returns its contour
    /// error (m).
    pub fn push(&mut self, t_s: f64, toolhead_m: &[f64]) -> f64 {
        let q = &toolhead_m[..self.geometry.dim().min(toolhead_m.len())];
        let d = self.geometry.contour_error_hinted(q, &mut self.hint);
        if t_s <= self.move_end_s {
            self.max_during_m = self.max_during_m.max(d);
            self.max_sharp_m = self.max_sharp_m.max(self.geometry.sharp_error(q));
            self.rounding.update(t_s, q);
        } else {
            self.max_after_m = self.max_after_m.max(d);
        }
        d
    }

    /// The metrics of everything pushed.
    pub fn finish(&self) -> PathMetrics {
        let c = self.geometry.corners();
        let interior = if c.len() > 2 { &c[1..c.len() - 1] } else { &[] };
        PathMetrics {
            corner_speed_mm_s: interior
                .iter()
                .map(|p| p.speed * 1e3)
                .fold(f64::INFINITY, f64::min),
            corner_rounding_um: interior
                .iter()
                .map(|p| p.deviation_m * 1e6)
                .fold(0.0, f64::max),
            max_contour_error_um: self.max_during_m * 1e6,
            contour_error_after_um: self.max_after_m * 1e6,
            max_sharp_error_um: self.max_sharp_m * 1e6,
            toolhead_corner_rounding_um: self.rounding.max_corner_rounding_m() * 1e6,
        }
    }
}
