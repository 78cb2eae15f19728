//! Marlin's arc set out and turned (Marlin/src/gcode/motion/G2_G3.cpp `plan_arc`, which
//! Prusa-Firmware-Buddy keeps): what Marlin's and Buddy's arc cutters (the `segments`
//! and `prusa_arcs` modules) share, in single precision as the firmware computes it.

use std::f32::consts::TAU as TAU32;

use crate::read::geometry::Move;

/// An arc as Marlin's `plan_arc` sets it out (Prusa-Firmware-Buddy keeps it), in single
/// precision: the radius vector from the centre to the start, and the angular travel,
/// a whole turn when the end is within 1e-6 mm of the start.
pub(crate) struct MarlinArc {
    /// The centre's offset from the start (`I`, `J`).
    pub offset: [f32; 2],
    /// From the centre to the start.
    pub rvec: [f32; 2],
    pub radius: f32,
    pub center: [f32; 2],
    /// Signed (negative clockwise), and its size.
    pub angular: f32,
    pub abs_angular: f32,
    /// A whole turn (the end at the start).
    pub whole: bool,
}

impl MarlinArc {
    /// The arc of `mv` about the offset `(i, j)`; `None` when the angular travel is too
    /// small to detect (Marlin then returns without a move: "Angular travel too small to
    /// detect? Just return.").
    pub(crate) fn new(mv: &Move, i: f64, j: f64, clockwise: bool) -> Option<Self> {
        let (s, t) = (mv.start, mv.end);
        let f = |v: f64| v as f32;
        let (cur_p, cur_q, cart_p, cart_q) = (f(s.x_mm), f(s.y_mm), f(t.x_mm), f(t.y_mm));
        let offset = [f(i), f(j)];
        let rvec = [-offset[0], -offset[1]];
        let radius = (rvec[0] * rvec[0] + rvec[1] * rvec[1]).sqrt();
        let (center_p, center_q) = (cur_p - rvec[0], cur_q - rvec[1]);
        let (rt_x, rt_y) = (cart_p - center_p, cart_q - center_q);
        let near = |a: f32, b: f32| (-0.000_001..=0.000_001).contains(&(a - b));
        let whole = near(cur_p, cart_p) && near(cur_q, cart_q);
        let angular = if whole {
            if clockwise { -TAU32 } else { TAU32 }
        } else {
            let mut a = (rvec[0] * rt_y - rvec[1] * rt_x).atan2(rvec[0] * rt_x + rvec[1] * rt_y);
            if a == 0.0 {
                return None;
            }
            if a >= 0.0 && clockwise {
                a -= TAU32;
            } else if a < 0.0 && !clockwise {
                a += TAU32;
            }
            a
        };
        Some(Self {
            offset,
            rvec,
            radius,
            center: [center_p, center_q],
            angular,
            abs_angular: angular.abs(),
            whole,
        })
    }
}

/// Marlin's turn of the arc's radius vector from one segment's end to the next (Marlin's
/// `plan_arc`, which Prusa-Firmware-Buddy keeps): a rotation by the segment's angle
/// (`sin_t`, `cos_t`), and every `N_ARC_CORRECTION` segments the vector computed afresh
/// from the centre's offset (`-offset` turned by `k theta`), in single precision.
pub(crate) struct ArcTurn {
    n_corr: u32,
    recalc: u32,
    theta: f32,
    sin_cos: (f32, f32),
    offset: [f32; 2],
}

impl ArcTurn {
    /// The turn of segments of angle `theta` (`sin_cos` its rotation), corrected every
    /// `n_arc_correction` segments (at least 1: every one), about a centre at `offset`
    /// from the start.
    pub(crate) fn new(
        n_arc_correction: u32,
        theta: f32,
        sin_cos: (f32, f32),
        offset: [f32; 2],
    ) -> Self {
        let n_corr = n_arc_correction.max(1);
        Self {
            n_corr,
            recalc: n_corr,
            theta,
            sin_cos,
            offset,
        }
    }

    /// Turn `rvec` to the end of segment `k` (from 1).
    pub(crate) fn next(&mut self, k: u32, rvec: &mut [f32; 2]) {
        let ((sin_t, cos_t), offset) = (self.sin_cos, self.offset);
        self.recalc = self.recalc.saturating_sub(1);
        if self.n_corr > 1 && self.recalc != 0 {
            let r_new_y = rvec[0] * sin_t + rvec[1] * cos_t;
            rvec[0] = rvec[0] * cos_t - rvec[1] * sin_t;
            rvec[1] = r_new_y;
        } else {
            self.recalc = self.n_corr;
            let (sin_k, cos_k) = (k as f32 * self.theta).sin_cos();
            rvec[0] = -offset[0] * cos_k + offset[1] * sin_k;
            rvec[1] = -offset[0] * sin_k - offset[1] * cos_k;
        }
    }
}
