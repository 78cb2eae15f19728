//! A one-axis problem from a safe state in normalised units, and its mirror image.
//!
//! Units: jerk 1, acceleration `a_u = max(amax, -amin)`, time `a_u / jmax`, velocity
//! `a_u^2 / jmax`, position `a_u^3 / jmax^2`. In these units every quantity of an ordinary
//! problem is of order one, whatever the physical scale (the suites span limits from 1e-3
//! to 1e6), so the case polynomials are well scaled and absolute tolerances mean something.

use crate::{Limits, State};

/// The problem from a safe start `(v0, a0)` (position 0) to `(vf, af)` at distance `dp`,
/// under `[amin, amax]` and `[vmin, vmax]`, jerk limit 1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Unit {
    pub v0: f64,
    pub a0: f64,
    pub vf: f64,
    pub af: f64,
    pub dp: f64,
    pub amax: f64,
    pub amin: f64,
    pub vmax: f64,
    pub vmin: f64,
}

/// Physical size of the units of [`Unit`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Scale {
    /// Time unit (s).
    pub t: f64,
    /// Acceleration unit.
    pub a: f64,
    /// Velocity unit.
    pub v: f64,
    /// Position unit.
    pub p: f64,
    /// Jerk limit (the jerk unit).
    pub j: f64,
}

impl Scale {
    /// The units for limits `lim` with jerk limit `j`.
    pub(crate) fn new(lim: &Limits, j: f64) -> Self {
        let a = lim.amax().max(-lim.amin());
        let t = a / j;
        let v = a * t;
        Self {
            t,
            a,
            v,
            p: v * t,
            j,
        }
    }
}

impl Unit {
    /// The problem from `s` to `target` in the units `sc`.
    pub(crate) fn new(s: &State, target: &State, lim: &Limits, sc: &Scale) -> Self {
        // One division: 1/t = j/a, 1/v = 1/(a t), 1/p = 1/(v t).
        let ra = 1.0 / sc.a;
        let rt = sc.j * ra;
        let rv = ra * rt;
        let rp = rv * rt;
        Self {
            v0: s.v * rv,
            a0: s.a * ra,
            vf: target.v * rv,
            af: target.a * ra,
            dp: (target.p - s.p) * rp,
            amax: lim.amax() * ra,
            amin: lim.amin() * ra,
            vmax: lim.vmax() * rv,
            vmin: lim.vmin() * rv,
        }
    }

    /// The mirror image: p, v, a negated, upper and lower limits swapped.
    pub(crate) fn mirror(&self) -> Self {
        Self {
            v0: -self.v0,
            a0: -self.a0,
            vf: -self.vf,
            af: -self.af,
            dp: -self.dp,
            amax: -self.amin,
            amin: -self.amax,
            vmax: -self.vmin,
            vmin: -self.vmax,
        }
    }

    /// Can the start keep within the velocity limits (velocity inside them, and the
    /// velocity reached by ramping the acceleration to zero at full jerk inside too)?
    pub(crate) fn safe(&self) -> bool {
        let tol = self.v_tol();
        let vz = self.v0 + 0.5 * self.a0 * self.a0.abs();
        [self.v0, vz]
            .iter()
            .all(|v| *v <= self.vmax + tol && *v >= self.vmin - tol)
    }

    /// Tolerance on velocities (as the limit checks elsewhere): 1e-12 of the larger limit.
    pub(crate) fn v_tol(&self) -> f64 {
        1e-12 * self.vmax.abs().max(self.vmin.abs())
    }
}
