//! Arcs cut as Prusa-Firmware-Buddy cuts them (`plan_arc`,
//! lib/Marlin/Marlin/src/gcode/motion/G2_G3.cpp; constants in
//! include/marlin/Configuration_MK4_adv.h).
//!
//! Marlin's `plan_arc` with Prusa's segment length, which Prusa adapted from
//! RepRapFirmware: `clamp(min(sqrt(8 r MAX_ARC_DEVIATION), F / MIN_ARC_SEGMENTS_PER_SEC),
//! MIN_ARC_SEGMENT_MM, MAX_ARC_SEGMENT_MM)` (0.02 mm, 50 per s, 0.1 mm, 2 mm), count
//! `max(1, trunc(flat / length + 0.8))` with `flat` the arc's length in the plane (no
//! `MIN_CIRCLE_SEGMENTS`); points by the exact rotation `cos T`, `sin T` applied to the
//! previous radius vector, recomputed from the start every `N_ARC_CORRECTION` (25)
//! segments; Z and E at `start + i * travel / segments`. Single precision, as the firmware.

use crate::read::geometry::{Move, Path, Point};
use crate::read::marlin_arc::{ArcTurn, MarlinArc};

/// Prusa-Firmware-Buddy's arc constants (Configuration_MK4_adv.h; the same on its other
/// printers' files).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PrusaArcs {
    /// `MAX_ARC_DEVIATION` (0.02 mm).
    pub max_deviation_mm: f64,
    /// `MIN_ARC_SEGMENT_MM` (0.1 mm).
    pub min_segment_mm: f64,
    /// `MAX_ARC_SEGMENT_MM` (2 mm).
    pub max_segment_mm: f64,
    /// `MIN_ARC_SEGMENTS_PER_SEC` (50).
    pub min_segments_per_s: f64,
    /// `N_ARC_CORRECTION` (25).
    pub n_arc_correction: u32,
}

impl Default for PrusaArcs {
    fn default() -> Self {
        PrusaArcs {
            max_deviation_mm: 0.02,
            min_segment_mm: 0.1,
            max_segment_mm: 2.0,
            min_segments_per_s: 50.0,
            n_arc_correction: 25,
        }
    }
}

pub(crate) fn prusa(mv: &Move, p: &PrusaArcs, out: &mut Vec<Point>) {
    let Path::Arc(arc) = &mv.path else {
        out.push(mv.end);
        return;
    };
    let (s, t) = (mv.start, mv.end);
    let f = |v: f64| v as f32;
    let (i, j, clockwise) = (arc.offset_i_mm, arc.offset_j_mm, arc.clockwise());
    let Some(MarlinArc {
        offset,
        mut rvec,
        radius,
        center: [center_p, center_q],
        angular,
        abs_angular,
        ..
    }) = MarlinArc::new(mv, i, j, clockwise)
    else {
        return; // "Angular travel too small to detect? Just return."
    };
    let (start_l, start_e) = (f(s.z_mm), f(s.e_mm));
    let travel_l = f(t.z_mm) - start_l;
    let travel_e = f(t.e_mm) - start_e;
    let flat_mm = radius * abs_angular;
    let near_zero = |v: f32| (-0.000_001..=0.000_001).contains(&v);
    if flat_mm < 0.0001 && near_zero(travel_l) {
        if !near_zero(travel_e) {
            out.push(t); // "Handle retract/recover as G1"
        }
        return;
    }
    let segment_mm = (8.0 * radius * f(p.max_deviation_mm))
        .sqrt()
        .min(f(mv.feed_mm_s) * (1.0 / f(p.min_segments_per_s)))
        .clamp(f(p.min_segment_mm), f(p.max_segment_mm));
    let segments = ((flat_mm / segment_mm + 0.8) as u32).max(1);
    if segments > 1 {
        let theta = angular / segments as f32;
        let (sin_t, cos_t) = theta.sin_cos();
        let (per_l, per_e) = (travel_l / segments as f32, travel_e / segments as f32);
        let mut turn = ArcTurn::new(p.n_arc_correction, theta, (sin_t, cos_t), offset);
        for k in 1..segments {
            turn.next(k, &mut rvec);
            out.push(Point::new(
                f64::from(center_p + rvec[0]),
                f64::from(center_q + rvec[1]),
                f64::from(start_l + per_l * k as f32),
                f64::from(start_e + per_e * k as f32),
            ));
        }
    }
    out.push(t);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::read::arc::Arc;
    use crate::read::geometry::{MoveKind, Tool};

    fn half_circle(feed_mm_s: f64) -> Move {
        let (start, end) = (
            Point::new(0.0, 0.0, 0.2, 0.0),
            Point::new(20.0, 0.0, 0.2, 1.0),
        );
        let arc = Arc::from_offsets([0.0, 0.0], [20.0, 0.0], 10.0, 0.0, true, true)
            .expect("a half circle");
        Move {
            start,
            end,
            feed_mm_s,
            kind: MoveKind::Print,
            rapid: false,
            path: Path::Arc(arc),
            tool: Tool::Off,
            feature: 0,
        }
    }

    #[test]
    fn segment_count_follows_the_deviation_and_the_feed() {
        // A half circle of radius 10 mm: sqrt(8 * 10 * 0.02) = 1.265 mm a segment at
        // 100 mm/s (100 / 50 = 2 mm is longer), so trunc(31.416 / 1.265 + 0.8) = 25
        // segments; at 10 mm/s, 10 / 50 = 0.2 mm: trunc(157.08 + 0.8) = 157.
        let p = PrusaArcs::default();
        for (feed, want) in [(100.0, 25), (10.0, 157)] {
            let mv = half_circle(feed);
            let mut out = Vec::new();
            prusa(&mv, &p, &mut out);
            assert_eq!(out.len(), want, "{feed} mm/s");
            let last = out.last().expect("points");
            assert_eq!(*last, mv.end);
            for q in &out {
                let r = ((q.x_mm - 10.0).powi(2) + q.y_mm.powi(2)).sqrt();
                assert!((r - 10.0).abs() < 1e-4, "{q:?}");
            }
        }
    }
}
