//! Raster turnarounds and step-axis moves from PVT segments.
//!
//! **Symmetric 2-segment turnaround** (fly axis). At the scan-region edge the axis moves at
//! `v` with zero acceleration; one segment brings it to rest with the acceleration linear
//! from 0 to the apex value `-a_apex`, the mirror segment takes it back to `-v` with the
//! acceleration returning to 0. Solving `a0 = 0`, `v1 = 0` with the PVT formulas gives the
//! half time `t_out = -2 v0/a1` and the overtravel `d_out = -4 v0^2/(3 a1)`
//! (`a1 = -a_apex`). The jerk is `a_apex/t_out` on both halves.
//!
//! **Symmetric 4(+1)-segment step** (step axis, at rest at both ends). The acceleration
//! rises linearly from 0 to `a_max` over `t_in`, falls to 0 over `t_out`, stays 0 for
//! `t_edge` (constant velocity, the "+1"), falls to `-a_max` over `t_out` and returns to 0
//! over `t_in`. For a step `d` ([`four_plus_one_rise_s`])
//! `t_in = sqrt(tau^2 + 3 d/a_max) - tau - t_out` with `tau = (2 t_out + 3 t_edge)/4`; the
//! first rise covers `a_max t_in^2/6` and reaches `a_max t_in/2`, the fall after it covers
//! `a_max t_out (2 t_out + 3 t_in)/6` and reaches `a_max (t_out + t_in)/2`
//! ([`FourPlusOne::d_in`], [`FourPlusOne::v_in`], [`FourPlusOne::d_out`],
//! [`FourPlusOne::v_edge`]). `planner/tests/all/pvt.rs` rederives the quadratic `t_in`
//! solves.

use crate::PlanError;
use crate::pvt::{Knot, Pvt};

/// The symmetric 2-segment turnaround.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TwoSegment {
    /// Duration of each half (s): edge to apex, apex to edge.
    pub t_out_s: f64,
    /// Overtravel beyond the edge (u, a magnitude).
    pub d_out: f64,
    /// Acceleration magnitude at the apex (u/s^2).
    pub a_apex: f64,
    /// Jerk magnitude on both halves (u/s^3).
    pub jerk: f64,
}

/// The 2-segment turnaround at scan speed `v > 0` with apex acceleration `a_apex > 0`.
pub fn two_segment(v: f64, a_apex: f64) -> Result<TwoSegment, PlanError> {
    for (name, value) in [("v_scan", v), ("a_apex", a_apex)] {
        if !(value.is_finite() && value > 0.0) {
            return Err(PlanError::InvalidLimit { name, value });
        }
    }
    let a1 = -a_apex;
    let t_out_s = -2.0 * v / a1;
    Ok(TwoSegment {
        t_out_s,
        d_out: -4.0 * v * v / (3.0 * a1),
        a_apex,
        jerk: a_apex / t_out_s,
    })
}

impl TwoSegment {
    /// The three knots of the turnaround starting at time `t0` at the edge `x_edge` moving
    /// in direction `dir` (+1 or -1) at speed `v`: edge, apex, edge again moving back.
    pub fn knots(&self, t0: f64, x_edge: f64, v: f64, dir: f64) -> [Knot; 3] {
        [
            Knot::new(t0, x_edge, dir * v),
            Knot::new(t0 + self.t_out_s, x_edge + dir * self.d_out, 0.0),
            Knot::new(t0 + 2.0 * self.t_out_s, x_edge, -dir * v),
        ]
    }
}

/// The symmetric 4(+1)-segment step move.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FourPlusOne {
    /// Step size (u, > 0).
    pub d: f64,
    /// Peak acceleration (u/s^2).
    pub a_max: f64,
    /// Rise time of the acceleration at the start, and its fall at the end (s).
    pub t_in_s: f64,
    /// Fall/rise time around the constant-velocity edge (s).
    pub t_out_s: f64,
    /// Constant-velocity time (s).
    pub t_edge_s: f64,
}

/// The rise time `t_in` (s) of a 4(+1)-segment step of `d` (u) with fall/rise time `t_out`
/// (s), constant-velocity time `t_edge` (s) and peak acceleration `a_max` (u/s^2).
pub fn four_plus_one_rise_s(t_out: f64, t_edge: f64, a_max: f64, d: f64) -> f64 {
    (t_out * t_out / 4.0
        + 3.0 * t_edge * t_out / 4.0
        + 9.0 * t_edge * t_edge / 16.0
        + 3.0 * d / a_max)
        .sqrt()
        - 3.0 * t_out / 2.0
        - 3.0 * t_edge / 4.0
}

/// The 4(+1)-segment step of `d > 0` with peak acceleration `a_max` and given `t_out`,
/// `t_edge >= 0`. Errors when the step is too short for them (`t_in` would be negative).
pub fn four_plus_one(
    d: f64,
    a_max: f64,
    t_out: f64,
    t_edge: f64,
) -> Result<FourPlusOne, PlanError> {
    for (name, value) in [("d_step", d), ("a_max", a_max)] {
        if !(value.is_finite() && value > 0.0) {
            return Err(PlanError::InvalidLimit { name, value });
        }
    }
    for (name, value) in [("t_out", t_out), ("t_edge", t_edge)] {
        if !(value.is_finite() && value >= 0.0) {
            return Err(PlanError::InvalidLimit { name, value });
        }
    }
    let t_in_s = four_plus_one_rise_s(t_out, t_edge, a_max, d);
    if t_in_s.is_nan() || t_in_s < 0.0 {
        return Err(PlanError::InfeasibleTarget {
            reason: "step too short for t_out and t_edge at this acceleration",
        });
    }
    Ok(FourPlusOne {
        d,
        a_max,
        t_in_s,
        t_out_s: t_out,
        t_edge_s: t_edge,
    })
}

impl FourPlusOne {
    /// Distance after the rise (u): `a_max t_in^2/6`.
    pub fn d_in(&self) -> f64 {
        self.a_max * self.t_in_s * self.t_in_s / 6.0
    }
    /// Velocity after the rise (u/s): `a_max t_in/2`.
    pub fn v_in(&self) -> f64 {
        self.a_max * self.t_in_s / 2.0
    }
    /// Distance covered during the first `t_out` (u).
    pub fn d_out(&self) -> f64 {
        self.a_max * self.t_out_s * (2.0 * self.t_out_s + 3.0 * self.t_in_s) / 6.0
    }
    /// The constant edge velocity (u/s).
    pub fn v_edge(&self) -> f64 {
        self.a_max * (self.t_out_s + self.t_in_s) / 2.0
    }
    /// Total duration (s).
    pub fn duration_s(&self) -> f64 {
        2.0 * (self.t_in_s + self.t_out_s) + self.t_edge_s
    }

    /// The move from `x0` as PVT knots starting at time `t0` (zero-length segments
    /// dropped).
    pub fn knots(&self, t0: f64, x0: f64) -> Vec<Knot> {
        let (d1, d2, ve) = (self.d_in(), self.d_in() + self.d_out(), self.v_edge());
        let (ti, to, te) = (self.t_in_s, self.t_out_s, self.t_edge_s);
        let all = [
            Knot::new(t0, x0, 0.0),
            Knot::new(t0 + ti, x0 + d1, self.v_in()),
            Knot::new(t0 + ti + to, x0 + d2, ve),
            Knot::new(t0 + ti + to + te, x0 + self.d - d2, ve),
            Knot::new(t0 + ti + 2.0 * to + te, x0 + self.d - d1, self.v_in()),
            Knot::new(t0 + 2.0 * (ti + to) + te, x0 + self.d, 0.0),
        ];
        let mut out: Vec<Knot> = Vec::with_capacity(6);
        for k in all {
            if out.last().is_none_or(|l| k.t_s > l.t_s) {
                out.push(k);
            }
        }
        out
    }

    /// The move as a PVT from rest at `x0` to rest at `x0 + d`.
    pub fn pvt(&self, x0: f64) -> Result<Pvt, PlanError> {
        Pvt::new(self.knots(0.0, x0), 0.0, 0.0)
    }
}
