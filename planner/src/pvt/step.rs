//! Rest-to-rest step moves from PVT segments.
//!
//! **Symmetric**: the acceleration is `0 -> A` over `t0`, held at `A` over `t1`,
//! `A -> -A` over `t2`, held at `-A` over `t1`, `-A -> 0` over `t0` (knots at the
//! `Ki/2`, `Ko/2`, `1 - Ko/2`, `1 - Ki/2` fractions of the step; the middle segments
//! hold the maximum acceleration). Within the limits the fastest member is
//! `t0 = A/jmax`, `t2 = 2 t0`, `A <= amax`: the time-optimal S-curve; when `vmax` would be
//! exceeded a constant-velocity segment splits the middle one (the "+1" segment). It is
//! planned from [`crate::scurve::timing`] and written as PVT knots.
//!
//! **Asymmetric** (an asymmetric move in a symmetric time frame, `t4 = t0`, continuous
//! acceleration): four segments `t0, t1, t1, t0` with accelerations `0 -> a0 -> -a0 -> -a0
//! -> a3 -> 0` (a 5-segment move with `t2 = 0`, `a1 = a2 = -a0`). Peak acceleration and
//! peak jerk come in the first half, so the move ends gently (the intent is less residual
//! vibration; the scan sweeps measure it). With `Ki` the fraction of the step covered at
//! the first knot times two, the closed form is, in units of the step `d` and `t1`:
//! `Ko = (3Ki^2 - Ki)/(Ki + 1)`, `t0 = t4 = 2Ki/(1 - Ki) t1`, `x0 = Ki/2`,
//! `x1 = -(Ki^2 - 4Ki - 1)/(8Ki)`, `x3 = 1 - Ko/2`, `v0 = v1 = 3(1 - Ki)/4`,
//! `v3 = -(9Ki^2 - 12Ki + 3)/(4Ki + 4)`, `a0 = (3Ki^2 - 6Ki + 3)/(4Ki)`,
//! `a3 = -(9Ki^3 - 21Ki^2 + 15Ki - 3)/(4Ki^2 + 4Ki)`. Valid for `1/3 < Ki < 1` (`Ko > 0`,
//! `a3 < 0`). The shape is fixed by `Ki`; `t1` is the smallest that keeps acceleration,
//! jerk and velocity within the limits. `planner/tests/all/pvt.rs` checks the closed form
//! against the PVT equations.

use crate::pvt::{Knot, Pvt};
use crate::{Limits, PlanError, Segment, State};

/// A step must be finite and nonzero (a zero step has no knots; callers return
/// [`crate::Profile::empty`]).
fn check_d(d: f64) -> Result<(), PlanError> {
    if !d.is_finite() {
        return Err(PlanError::NonFinite {
            name: "distance",
            value: d,
        });
    }
    if d == 0.0 {
        return Err(PlanError::InvalidInput {
            reason: "a PVT step needs a nonzero distance",
        });
    }
    Ok(())
}

fn jmax(lim: &Limits, kind: &'static str) -> Result<f64, PlanError> {
    lim.jmax().ok_or(PlanError::MissingJerkLimit { kind })
}

/// The fastest symmetric PVT step of signed `d` from `x0` under `lim` (needs jmax).
pub fn symmetric(x0: f64, d: f64, lim: &Limits) -> Result<Pvt, PlanError> {
    check_d(d)?;
    let j = jmax(lim, "pvt_sym")?;
    let tm = crate::scurve::timing(d.abs(), lim.vmax(), lim.amax(), j);
    let s = d.signum();
    let phases = [
        (tm.t_jerk, s * j),
        (tm.t_const_acc, 0.0),
        (tm.t_jerk, -s * j),
        (tm.t_cruise, 0.0),
        (tm.t_jerk, -s * j),
        (tm.t_const_acc, 0.0),
        (tm.t_jerk, s * j),
    ];
    // Knots relative to x0 (their precision is that of the step, not of x0), shifted at
    // the end.
    let mut st = State {
        p: 0.0,
        v: 0.0,
        a: 0.0,
    };
    let mut t = 0.0;
    let mut knots = vec![Knot::new(0.0, 0.0, 0.0)];
    let mut acc: Vec<(f64, f64)> = Vec::with_capacity(7);
    let mut a_seg_start = 0.0;
    for (i, &(dur, jerk)) in phases.iter().enumerate() {
        st = Segment::Jerk {
            duration_s: dur,
            jerk,
        }
        .end_state(&st);
        // Exact accelerations at the phase ends: +-A, or 0 around the cruise.
        st.a = match i {
            0 | 1 => s * tm.a_peak,
            4 | 5 => -s * tm.a_peak,
            _ => 0.0,
        };
        t += dur;
        // No knot where the acceleration passes through zero without a cruise: the two
        // jerk phases around it are one linear-acceleration segment (5 segments in all).
        let merge = i == 2 && tm.t_cruise == 0.0;
        if dur > 0.0 && !merge {
            knots.push(Knot::new(t, st.p, st.v));
            acc.push((a_seg_start, st.a));
            a_seg_start = st.a;
        }
    }
    // The end at rest exactly on the target.
    if let Some(last) = knots.last_mut() {
        last.x = d;
        last.v = 0.0;
    }
    Pvt::with_accels(knots, acc, 0.0, 0.0)?.shifted(x0)
}

/// The asymmetric shape for one `Ki`, in units of the step `d` and the segment time
/// `t1` (positions in `d`, times in `t1`, velocities in `d/t1`, accelerations in `d/t1^2`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AsymShape {
    /// `Ki`: twice the fraction of the step covered at the first knot (1/3 < Ki < 1).
    pub ki: f64,
    /// `Ko = (3Ki^2 - Ki)/(Ki + 1)`.
    pub ko: f64,
    /// `t0 = t4` in units of `t1`.
    pub t0: f64,
    /// Knot positions x0, x1, x3.
    pub x: [f64; 3],
    /// Knot velocities v0 (= v1), v3.
    pub v: [f64; 2],
    /// Knot accelerations a0 (peak; `a1 = a2 = -a0`) and a3.
    pub a: [f64; 2],
}

impl AsymShape {
    /// The shape for `ki` in (1/3, 1).
    pub fn new(ki: f64) -> Result<Self, PlanError> {
        if !(ki.is_finite() && ki > 1.0 / 3.0 && ki < 1.0) {
            return Err(PlanError::InvalidLimit {
                name: "ki",
                value: ki,
            });
        }
        let ko = (3.0 * ki * ki - ki) / (ki + 1.0);
        Ok(Self {
            ki,
            ko,
            t0: -2.0 * ki / (ki - 1.0),
            x: [
                ki / 2.0,
                -(ki * ki - 4.0 * ki - 1.0) / (8.0 * ki),
                1.0 - ko / 2.0,
            ],
            v: [
                -(3.0 * ki - 3.0) / 4.0,
                -(9.0 * ki * ki - 12.0 * ki + 3.0) / (4.0 * ki + 4.0),
            ],
            a: [
                (3.0 * ki * ki - 6.0 * ki + 3.0) / (4.0 * ki),
                -(9.0 * ki.powi(3) - 21.0 * ki * ki + 15.0 * ki - 3.0) / (4.0 * ki * ki + 4.0 * ki),
            ],
        })
    }

    /// Duration in units of `t1`: `2 t0 + 2`.
    pub fn duration(&self) -> f64 {
        2.0 * self.t0 + 2.0
    }

    /// Peak |jerk| in units of `d/t1^3` (the `a0 -> -a0` segment).
    pub fn peak_jerk(&self) -> f64 {
        let [a0, a3] = self.a;
        [a0 / self.t0, 2.0 * a0, (a3 + a0).abs(), a3.abs() / self.t0]
            .into_iter()
            .fold(0.0, f64::max)
    }

    /// Peak speed in units of `d/t1` (mid `a0 -> -a0` segment: `v0 + a0/4`).
    pub fn peak_velocity(&self) -> f64 {
        self.v[0] + self.a[0] / 4.0
    }

    /// The smallest `t1` (s) keeping a step of `|d|` within `lim` (jerk needed).
    pub fn t1_for(&self, d: f64, lim: &Limits) -> Result<f64, PlanError> {
        let j = jmax(lim, "pvt_asym")?;
        let d = d.abs();
        Ok((self.a[0] * d / lim.amax())
            .sqrt()
            .max((self.peak_jerk() * d / j).cbrt())
            .max(self.peak_velocity() * d / lim.vmax()))
    }

    /// The knots of a step of signed `d` from `x0` with segment time `t1` (s).
    pub fn knots(&self, x0: f64, d: f64, t1: f64) -> [Knot; 5] {
        let t0 = self.t0 * t1;
        let vs = d / t1;
        [
            Knot::new(0.0, x0, 0.0),
            Knot::new(t0, x0 + self.x[0] * d, self.v[0] * vs),
            Knot::new(t0 + t1, x0 + self.x[1] * d, self.v[0] * vs),
            Knot::new(t0 + 2.0 * t1, x0 + self.x[2] * d, self.v[1] * vs),
            Knot::new(2.0 * t0 + 2.0 * t1, x0 + d, 0.0),
        ]
    }
}

/// The fastest asymmetric PVT step of signed `d` from `x0` with the shape `ki` (see
/// [`AsymShape::ki`]; the kind's default is 0.5) under `lim` (needs jmax).
pub fn asymmetric(x0: f64, d: f64, ki: f64, lim: &Limits) -> Result<Pvt, PlanError> {
    check_d(d)?;
    let shape = AsymShape::new(ki)?;
    let t1 = shape.t1_for(d, lim)?;
    let sc = d / (t1 * t1);
    let (a0, a3) = (shape.a[0] * sc, shape.a[1] * sc);
    let acc = vec![(0.0, a0), (a0, -a0), (-a0, a3), (a3, 0.0)];
    Pvt::with_accels(shape.knots(0.0, d, t1).to_vec(), acc, 0.0, 0.0)?.shifted(x0)
}
