//! Arcs cut into the straight segments each firmware plans, point for point.
//!
//! Each firmware recomputes the sweep with its own formula and full-circle rule from the
//! start, the end and the centre offset, then places its points with its own arithmetic:
//!
//! - **Klipper** (`klippy/extras/gcode_arcs.py`, `planArc`): `n = max(1, floor(L /
//!   resolution))` with `L` the helical length, points at `i * sweep / n` by exact
//!   rotation of the start radius vector, Z and E in equal steps. Double precision, as
//!   Klipper's Python: these points match Klipper's to the last bit when no `G92` offset is
//!   in force.
//! - **Marlin** (`Marlin/src/gcode/motion/G2_G3.cpp`, `plan_arc`, at MarlinFirmware/Marlin
//!   commit 136aac24): segment count from the flat arc length, `MIN_CIRCLE_SEGMENTS`
//!   (scaled by the fraction of a circle), `MAX_ARC_SEGMENT_MM`/`MIN_ARC_SEGMENT_MM` and
//!   optionally `ARC_SEGMENTS_PER_SEC`; points by a small-angle rotation recurrence
//!   (`sin T = t - t^3/6`, `cos T = 1 - t^2/2`) with an exact recomputation every
//!   `N_ARC_CORRECTION` segments. Computed in single precision like the firmware (its
//!   positions are `float`), so the drift of the recurrence is Marlin's own.
//! - **RepRapFirmware** (`GCodes::DoArcMove` and `GCodes::ReadMove`,
//!   `src/GCodes/GCodes.cpp`, constants in `src/Config/Configuration.h`, 3.5):
//!   segment length `clamp(min(sqrt(8 r 0.005), feed / 200 per s), 0.02, 1.0)` mm, count
//!   `max(1, trunc(r sweep / length + 0.8))`, angles by incremental rotation with a full
//!   sine/cosine every 9th segment, Z and E each step `(end - current) / segments left`.
//!   Single precision like the firmware.
//! - **Prusa-Firmware-Buddy** ([`crate::read::prusa_arcs`]): Marlin's `plan_arc` with a
//!   segment length from a deviation of 0.02 mm and the feed rate.
//! - **GRBL** ([`crate::read::grbl::arcs`]): segments from the arc tolerance `$12`.
//!
//! The returned points exclude the start and end at the move's end point (every firmware
//! sends its last segment to the target as written; Klipper's last E is its running sum
//! of equal steps, which can differ from the target E in the last bit).

use std::f32::consts::TAU as TAU32;
use std::f64::consts::TAU;

use crate::read::dialect::Dialect;
use crate::read::geometry::{Move, Path, Point};
pub use crate::read::grbl::arcs::GrblArcs;
use crate::read::marlin_arc::{ArcTurn, MarlinArc};
pub use crate::read::prusa_arcs::PrusaArcs;

/// Klipper's `[gcode_arcs]` section.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KlipperArcs {
    /// `resolution`, mm (Klipper's default 1.0).
    pub resolution_mm: f64,
}

impl Default for KlipperArcs {
    fn default() -> Self {
        KlipperArcs { resolution_mm: 1.0 }
    }
}

/// Marlin's arc settings (`Configuration_adv.h`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MarlinArcs {
    /// `MAX_ARC_SEGMENT_MM` (default 1.0 mm).
    pub max_segment_mm: f64,
    /// `MIN_ARC_SEGMENT_MM` (default 0.1 mm).
    pub min_segment_mm: f64,
    /// `MIN_CIRCLE_SEGMENTS` (default 72: 5 degrees a segment).
    pub min_circle_segments: u32,
    /// `ARC_SEGMENTS_PER_SEC` (off by default): segment length from the feed rate.
    pub segments_per_second: Option<f64>,
    /// `N_ARC_CORRECTION` (default 25): exact recomputation every this many segments.
    pub n_arc_correction: u32,
}

impl Default for MarlinArcs {
    fn default() -> Self {
        MarlinArcs {
            max_segment_mm: 1.0,
            min_segment_mm: 0.1,
            min_circle_segments: 72,
            segments_per_second: None,
            n_arc_correction: 25,
        }
    }
}

/// RepRapFirmware's arc constants (`src/Config/Configuration.h`; compiled in).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RrfArcs {
    /// `MaxArcDeviation` (0.005 mm).
    pub max_deviation_mm: f64,
    /// `MinArcSegmentLength` (0.02 mm).
    pub min_segment_mm: f64,
    /// `MaxArcSegmentLength` (1.0 mm).
    pub max_segment_mm: f64,
    /// `MaxArcSegmentsPerSec` (200).
    pub max_segments_per_s: f64,
    /// `SegmentsPerFulArcCalculation` (8): incremental rotations between full sin/cos.
    pub segments_per_full_calc: u32,
}

impl Default for RrfArcs {
    fn default() -> Self {
        RrfArcs {
            max_deviation_mm: 0.005,
            min_segment_mm: 0.02,
            max_segment_mm: 1.0,
            max_segments_per_s: 200.0,
            segments_per_full_calc: 8,
        }
    }
}

/// Which firmware's arc segmentation to reproduce, with its settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ArcSegmentation {
    /// Klipper.
    Klipper(KlipperArcs),
    /// Marlin.
    Marlin(MarlinArcs),
    /// Prusa-Firmware-Buddy.
    Prusa(PrusaArcs),
    /// RepRapFirmware.
    Rrf(RrfArcs),
    /// GRBL.
    Grbl(GrblArcs),
}

impl ArcSegmentation {
    /// The firmware's defaults.
    pub fn default_for(dialect: Dialect) -> Self {
        match dialect {
            Dialect::Klipper => ArcSegmentation::Klipper(KlipperArcs::default()),
            Dialect::Marlin => ArcSegmentation::Marlin(MarlinArcs::default()),
            Dialect::Prusa => ArcSegmentation::Prusa(PrusaArcs::default()),
            Dialect::Rrf => ArcSegmentation::Rrf(RrfArcs::default()),
            Dialect::Grbl => ArcSegmentation::Grbl(GrblArcs::default()),
        }
    }
}

impl Move {
    /// The points the firmware plans straight segments to, start excluded, end included
    /// (a line gives just its end; an arc Marlin would drop as too short gives none).
    pub fn segments_for(&self, how: &ArcSegmentation) -> Vec<Point> {
        let mut out = Vec::new();
        self.segments_into(how, &mut out);
        out
    }

    /// [`Move::segments_for`] into a reused buffer (cleared first).
    pub fn segments_into(&self, how: &ArcSegmentation, out: &mut Vec<Point>) {
        out.clear();
        match (&self.path, how) {
            (Path::Line, _) => out.push(self.end),
            (Path::Arc(_), ArcSegmentation::Klipper(p)) => klipper(self, p, out),
            (Path::Arc(_), ArcSegmentation::Marlin(p)) => marlin(self, p, out),
            (Path::Arc(_), ArcSegmentation::Prusa(p)) => {
                crate::read::prusa_arcs::prusa(self, p, out)
            }
            (Path::Arc(_), ArcSegmentation::Rrf(p)) => rrf(self, p, out),
            (Path::Arc(_), ArcSegmentation::Grbl(p)) => crate::read::grbl::arcs::grbl(self, p, out),
        }
    }
}

/// Centre offset and direction of an arc move (Klipper's, Marlin's and RepRapFirmware's
/// cutters: only GRBL's reader takes arcs outside the XY plane).
fn arc_of(mv: &Move) -> (f64, f64, bool) {
    match &mv.path {
        Path::Arc(a) => {
            debug_assert_eq!(a.plane, crate::read::arc::Plane::Xy);
            (a.offset_i_mm, a.offset_j_mm, a.clockwise())
        }
        Path::Line => (0.0, 0.0, false),
    }
}

fn klipper(mv: &Move, p: &KlipperArcs, out: &mut Vec<Point>) {
    let (i, j, clockwise) = arc_of(mv);
    let (s, t) = (mv.start, mv.end);
    let (r_p, r_q) = (-i, -j);
    let (center_p, center_q) = (s.x_mm - r_p, s.y_mm - r_q);
    let (rt_a, rt_b) = (t.x_mm - center_p, t.y_mm - center_q);
    let mut angular = (r_p * rt_b - r_q * rt_a).atan2(r_p * rt_a + r_q * rt_b);
    if angular < 0.0 {
        angular += TAU;
    }
    if clockwise {
        angular -= TAU;
    }
    if angular == 0.0 && s.x_mm == t.x_mm && s.y_mm == t.y_mm {
        angular = TAU;
    }
    let linear = t.z_mm - s.z_mm;
    let flat = r_p.hypot(r_q) * angular;
    let travel = if linear != 0.0 {
        flat.hypot(linear)
    } else {
        flat.abs()
    };
    let segments = (travel / p.resolution_mm).floor().max(1.0);
    let (theta_per, linear_per) = (angular / segments, linear / segments);
    let e_per = (t.e_mm - s.e_mm) / segments;
    let n = segments as u64;
    let mut e = s.e_mm;
    for k in 1..=n {
        e += e_per;
        if k == n {
            // XYZ land on the target; E is Klipper's running sum.
            out.push(Point::new(t.x_mm, t.y_mm, t.z_mm, e));
            break;
        }
        let kf = k as f64;
        let (sin, cos) = (kf * theta_per).sin_cos();
        let rp = -i * cos + j * sin;
        let rq = -i * sin - j * cos;
        out.push(Point::new(
            center_p + rp,
            center_q + rq,
            s.z_mm + kf * linear_per,
            e,
        ));
    }
}

fn marlin(mv: &Move, p: &MarlinArcs, out: &mut Vec<Point>) {
    let (i, j, clockwise) = arc_of(mv);
    let (s, t) = (mv.start, mv.end);
    let f = |v: f64| v as f32;
    let Some(MarlinArc {
        offset,
        mut rvec,
        radius,
        center: [center_p, center_q],
        angular,
        abs_angular,
        whole,
    }) = MarlinArc::new(mv, i, j, clockwise)
    else {
        return;
    };
    let min_segments = if whole {
        p.min_circle_segments as f32
    } else {
        (p.min_circle_segments as f32 * (abs_angular / TAU32)).ceil()
    };
    let travel_l = f(t.z_mm) - f(s.z_mm);
    let travel_e = f(t.e_mm) - f(s.e_mm);
    let flat_mm = radius * abs_angular;
    // Marlin compares the signed Z travel here.
    if flat_mm < 0.0001 && travel_l < 0.0001 {
        return;
    }
    let (max_mm, min_mm) = (f(p.max_segment_mm), f(p.min_segment_mm));
    let ideal = match p.segments_per_second {
        Some(sps) => (f(mv.feed_mm_s) * (1.0 / f(sps))).clamp(min_mm, max_mm),
        None => max_mm,
    };
    let nominal = (flat_mm / ideal).floor().max(min_segments);
    let nominal_mm = flat_mm / nominal;
    let segments = if nominal_mm > max_mm {
        (flat_mm / max_mm).ceil()
    } else if nominal_mm < min_mm {
        (flat_mm / min_mm).floor().max(1.0)
    } else {
        nominal
    } as u32;
    if segments > 1 {
        let theta = angular / segments as f32;
        let sq = theta * theta;
        let sin_t = theta - sq * theta / 6.0;
        let cos_t = 1.0 - 0.5 * sq;
        let (per_l, per_e) = (travel_l / segments as f32, travel_e / segments as f32);
        let (mut raw_l, mut raw_e) = (f(s.z_mm), f(s.e_mm));
        let mut turn = ArcTurn::new(p.n_arc_correction, theta, (sin_t, cos_t), offset);
        for k in 1..segments {
            turn.next(k, &mut rvec);
            raw_l += per_l;
            raw_e += per_e;
            out.push(Point::new(
                f64::from(center_p + rvec[0]),
                f64::from(center_q + rvec[1]),
                f64::from(raw_l),
                f64::from(raw_e),
            ));
        }
    }
    out.push(t);
}

fn rrf(mv: &Move, p: &RrfArcs, out: &mut Vec<Point>) {
    let (i, j, clockwise) = arc_of(mv);
    let (s, t) = (mv.start, mv.end);
    let f = |v: f64| v as f32;
    let (i, j) = (f(i), f(j));
    let (c0, c1) = (f(s.x_mm) + i, f(s.y_mm) + j);
    let whole_circle = s.x_mm == t.x_mm && s.y_mm == t.y_mm;
    let final_theta = (f(t.y_mm) - c1).atan2(f(t.x_mm) - c0);
    let radius = (i * i + j * j).sqrt();
    let mut angle = (-j).atan2(-i);
    let total_arc = if whole_circle {
        TAU32
    } else {
        let a = if clockwise {
            angle - final_theta
        } else {
            final_theta - angle
        };
        if a < 0.0 { a + TAU32 } else { a }
    };
    let by_deviation = (8.0 * radius * f(p.max_deviation_mm)).sqrt();
    let by_rate = (mv.feed_mm_s * (1.0 / p.max_segments_per_s)) as f32;
    let seg_len = by_deviation
        .min(by_rate)
        .clamp(f(p.min_segment_mm), f(p.max_segment_mm));
    let total = ((radius * total_arc / seg_len + 0.8) as u32).max(1);
    let mut inc = total_arc / total as f32;
    if clockwise {
        inc = -inc;
    }
    let (inc_sin, inc_cos) = inc.sin_cos();
    let (mut cos_a, mut sin_a) = (0.0f32, 0.0f32);
    let mut till_full = 0u32;
    let (mut z, mut e) = (f(s.z_mm), f(s.e_mm));
    let (z_end, e_end) = (f(t.z_mm), f(t.e_mm));
    for k in 1..total {
        angle += inc;
        if till_full == 0 {
            till_full = p.segments_per_full_calc;
            (sin_a, cos_a) = angle.sin_cos();
        } else {
            till_full -= 1;
            let new_cos = cos_a * inc_cos - sin_a * inc_sin;
            let new_sin = sin_a * inc_cos + cos_a * inc_sin;
            (cos_a, sin_a) = (new_cos, new_sin);
        }
        let left = (total - k + 1) as f32;
        z += (z_end - z) / left;
        e += (e_end - e) / left;
        out.push(Point::new(
            f64::from(c0 + radius * cos_a),
            f64::from(c1 + radius * sin_a),
            f64::from(z),
            f64::from(e),
        ));
    }
    out.push(t);
}
