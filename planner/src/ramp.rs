//! The up-down velocity change in closed form (normalised units, jerk 1): jerk `+1` from
//! `a0` to a peak `A`, a hold at the limit if the peak reaches it, jerk `-1` to `a1`, with
//! its duration and distance, no segments and no search. From a safe state this is the
//! time-optimal change up to a cruise at `vmax`, and (mirrored) the change down from it to
//! the target; `velocity::change`, which considers every shape, is the general fallback.

use crate::Segment;
use crate::segs::Push;
use crate::unit::Scale;
use crate::velocity::Change;

/// A velocity change of three phases: jerk `sign` for `t1`, a hold, jerk `-sign` for `t2`
/// (an up-down change for `sign = 1`, down-up for `-1`), with the distance covered.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Ramp {
    t1: f64,
    hold: f64,
    t2: f64,
    sign: f64,
    /// Distance covered (normalised).
    pub dist: f64,
}

impl Ramp {
    /// From `(v0, a0)` to `(v1, a1)` with the peak at most `alim > 0`; `None` when the
    /// peak `A`, `A^2 = v1 - v0 + (a0^2 + a1^2)/2`, would lie below `a0` or `a1` (another
    /// shape is needed).
    pub(crate) fn up_down(v0: f64, a0: f64, v1: f64, a1: f64, alim: f64) -> Option<Self> {
        let q = v1 - v0 + 0.5 * (a0 * a0 + a1 * a1);
        let lo = a0.max(a1);
        if q.is_nan() || q < 0.0 || q.sqrt() < lo - 1e-12 {
            return None;
        }
        let mut a = q.sqrt().max(lo);
        let mut hold = 0.0;
        if a > alim {
            a = alim;
            hold =
                ((v1 - v0) - (alim * alim - a0 * a0) / 2.0 - (alim * alim - a1 * a1) / 2.0) / alim;
            hold = hold.max(0.0);
        }
        let (t1, t2) = (a - a0, a - a1);
        let va = v0 + 0.5 * (a * a - a0 * a0);
        let vb = va + a * hold;
        const SIXTH: f64 = 1.0 / 6.0;
        let dist = t1 * (v0 + t1 * (0.5 * a0 + t1 * SIXTH))
            + hold * (va + a * hold / 2.0)
            + t2 * (vb + t2 * (0.5 * a - t2 * SIXTH));
        Some(Self {
            t1,
            hold,
            t2,
            sign: 1.0,
            dist,
        })
    }

    /// The same change mirrored (velocities and accelerations negated).
    pub(crate) fn mirrored(self) -> Self {
        Self {
            sign: -self.sign,
            dist: -self.dist,
            ..self
        }
    }

    /// A change from `velocity::change` (jerk `j1`, hold, jerk `-j1`, normalised), started
    /// from `(v0, a0)`.
    pub(crate) fn from_change(c: &Change, v0: f64, a0: f64) -> Self {
        let d = |k: usize| c.segments[k].duration_s();
        let sign = match c.segments[0] {
            Segment::Jerk { jerk, .. } if jerk < 0.0 => -1.0,
            _ => 1.0,
        };
        Self {
            t1: d(0),
            hold: d(1),
            t2: d(2),
            sign,
            dist: c.end(v0, a0).p,
        }
    }

    /// Duration (normalised).
    pub(crate) fn duration(&self) -> f64 {
        self.t1 + self.hold + self.t2
    }

    /// Append the change's segments (those that last), in physical units `sc`.
    pub(crate) fn segments(&self, sc: &Scale, out: &mut impl Push) {
        let j = self.sign * sc.j;
        out.push_jerk(self.t1 * sc.t, j);
        out.push_jerk(self.hold * sc.t, 0.0);
        out.push_jerk(self.t2 * sc.t, -j);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::velocity::{Bounds, change};

    #[test]
    fn equals_the_general_change_where_it_applies() {
        let b = Bounds {
            amax: 1.0,
            amin: -1.0,
            jmax: 1.0,
        };
        for (v0, a0, v1, a1) in [
            (0.0, 0.0, 1.0, 0.0),
            (0.0, 0.0, 3.0, 0.0),
            (-0.5, -0.8, 0.7, 0.0),
            (0.2, 0.6, 0.5, -0.3),
            (1.0, 0.9, 1.5, 0.2),
        ] {
            let r = Ramp::up_down(v0, a0, v1, a1, 1.0).expect("up-down applies");
            let c = change(v0, a0, v1, a1, &b).expect("change");
            let unit = Scale {
                t: 1.0,
                a: 1.0,
                v: 1.0,
                p: 1.0,
                j: 1.0,
            };
            let mut segs = Vec::new();
            r.segments(&unit, &mut segs);
            let e = crate::Profile::new(
                crate::State {
                    p: 0.0,
                    v: v0,
                    a: a0,
                },
                segs,
            )
            .expect("valid")
            .end();
            assert!((r.duration() - c.duration_s()).abs() < 1e-12, "{r:?} {c:?}");
            assert!(
                (e.p - r.dist).abs() < 1e-12 && (e.v - v1).abs() < 1e-12,
                "{e:?}"
            );
            assert!((e.a - a1).abs() < 1e-12);
        }
        // Peak below the start: not this shape.
        assert!(Ramp::up_down(0.0, 0.9, 0.1, 0.0, 1.0).is_none());
    }
}
