//! The jerk-unlimited (trapezoid) variant in closed form: step 1 (fastest), its local
//! optima (for time synchronisation), and step 2 (a given duration).
//!
//! The acceleration jumps, so from a velocity inside the limits a profile is a phase at
//! constant acceleration to a peak velocity `vp`, a cruise at `vp`, and a phase to `vf`,
//! then a jump to `af`. Without a cruise, up-down (`amax` then `amin`) needs
//! `vp^2 (1/(2 amax) - 1/(2 amin)) = dp + v0^2/(2 amax) - vf^2/(2 amin)` with `vp >= v0, vf`,
//! and down-up the mirror; with a cruise, `vp` is `vmax` or `vmin`. (Up-up and down-down
//! cover a fixed distance, `(vf^2 - v0^2)/(2a)`, and are a candidate only for exactly that
//! distance.) For a given duration the highest-reaching profile is up-down, or up, cruise
//! at `vmax`, down; the lowest the mirror; a mixture of the two (see `mixture`) reaches any
//! distance between.

use crate::segs::{Push, Segs};
use crate::{Limits, Segment, State};

/// A trapezoid profile: `a1` until `vp`, cruise, `a2` until `vf`, jump to `af`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Trap {
    t1: f64,
    a1: f64,
    cruise: f64,
    t2: f64,
    a2: f64,
    af: f64,
    /// Distance covered (units).
    dist: f64,
}

impl Trap {
    /// `v0 -> vp` at the limit in that direction, cruise, `vp -> vf`.
    fn new(v0: f64, vp: f64, cruise: f64, vf: f64, af: f64, lim: &Limits) -> Self {
        let acc = |dv: f64| if dv >= 0.0 { lim.amax() } else { lim.amin() };
        let (a1, a2) = (acc(vp - v0), acc(vf - vp));
        let (t1, t2) = ((vp - v0) / a1, (vf - vp) / a2);
        Self {
            t1,
            a1,
            cruise,
            t2,
            a2,
            af,
            dist: 0.5 * (v0 + vp) * t1 + vp * cruise + 0.5 * (vp + vf) * t2,
        }
    }

    /// Duration (s).
    pub(crate) fn duration(&self) -> f64 {
        self.t1 + self.cruise + self.t2
    }

    /// Append the segments.
    pub(crate) fn segments(&self, out: &mut impl Push) {
        for (duration_s, accel) in [
            (self.t1, self.a1),
            (self.cruise, 0.0),
            (self.t2, self.a2),
            (0.0, self.af),
        ] {
            out.push_seg(Segment::Accel { duration_s, accel });
        }
    }
}

/// Every locally fastest profile from `s` (velocity inside the limits) to `target`.
fn each(s: &State, target: &State, lim: &Limits, mut f: impl FnMut(Trap)) {
    let (v0, vf, af) = (s.v, target.v, target.a);
    let dp = target.p - s.p;
    let (amax, amin) = (lim.amax(), lim.amin());
    for vlim in [lim.vmax(), lim.vmin()] {
        let full = Trap::new(v0, vlim, 0.0, vf, af, lim);
        let cruise = (dp - full.dist) / vlim;
        if cruise >= 0.0 && cruise.is_finite() {
            f(Trap::new(v0, vlim, cruise, vf, af, lim));
        }
    }
    let tol = 1e-12 * lim.vmax().max(-lim.vmin());
    // Up-down (peak above v0 and vf) and down-up (valley below both).
    for (up, down) in [(amax, amin), (amin, amax)] {
        let q = (dp + v0 * v0 / (2.0 * up) - vf * vf / (2.0 * down))
            / (1.0 / (2.0 * up) - 1.0 / (2.0 * down));
        if q.is_nan() || q < 0.0 {
            continue;
        }
        for vp in [q.sqrt(), -q.sqrt()] {
            let ok = if up > 0.0 {
                vp >= v0.max(vf) - tol && vp <= lim.vmax() + tol
            } else {
                vp <= v0.min(vf) + tol && vp >= lim.vmin() - tol
            };
            if ok {
                let vp = if up > 0.0 {
                    vp.max(v0).max(vf)
                } else {
                    vp.min(v0).min(vf)
                };
                f(Trap::new(v0, vp, 0.0, vf, af, lim));
            }
        }
    }
    // One phase straight to vf, when that covers the distance exactly.
    let direct = Trap::new(v0, v0, 0.0, vf, af, lim);
    if (direct.dist - dp).abs() <= 1e-12 * dp.abs().max(direct.dist.abs()).max(1e-300) {
        f(direct);
    }
}

/// The fastest profile from `s` to `target`.
pub(crate) fn fastest(s: &State, target: &State, lim: &Limits) -> Option<Trap> {
    let mut best: Option<Trap> = None;
    each(s, target, lim, |t| {
        if best.is_none_or(|b| t.duration() < b.duration()) {
            best = Some(t);
        }
    });
    best
}

/// Calls `f` with the duration of every locally fastest profile.
pub(crate) fn each_duration(s: &State, target: &State, lim: &Limits, mut f: impl FnMut(f64)) {
    each(s, target, lim, |t| f(t.duration()));
}

/// The highest-reaching profile lasting `t` (up, [cruise at vmax,] down), or with
/// `mirror` the lowest; `None` if no velocity change from `v0` to `vf` fits in `t`.
fn extreme(v0: f64, vf: f64, af: f64, lim: &Limits, t: f64, mirror: bool) -> Option<Trap> {
    let (up, down, vlim) = if mirror {
        (lim.amin(), lim.amax(), lim.vmin())
    } else {
        (lim.amax(), lim.amin(), lim.vmax())
    };
    // t = (vp - v0)/up + (vf - vp)/down, with vp beyond both v0 and vf.
    let vp = (t + v0 / up - vf / down) / (1.0 / up - 1.0 / down);
    let tol = 1e-12 * lim.vmax().max(-lim.vmin());
    let (lo, hi) = (v0.min(vf), v0.max(vf));
    let vp = if mirror {
        if vp > lo + tol {
            return None;
        }
        vp.min(lo)
    } else {
        if vp < hi - tol {
            return None;
        }
        vp.max(hi)
    };
    let beyond = if mirror { vp < vlim } else { vp > vlim };
    Some(if beyond {
        let full = Trap::new(v0, vlim, 0.0, vf, af, lim);
        Trap::new(v0, vlim, (t - full.duration()).max(0.0), vf, af, lim)
    } else {
        Trap::new(v0, vp, 0.0, vf, af, lim)
    })
}

/// Append the segments of a profile from `s` lasting `t` and reaching `target`; false
/// (nothing appended) if there is none.
pub(crate) fn lasting(
    s: &State,
    target: &State,
    lim: &Limits,
    t: f64,
    out: &mut Vec<Segment>,
) -> bool {
    let (v0, vf, af) = (s.v, target.v, target.a);
    let dp = target.p - s.p;
    let (Some(hi), Some(lo)) = (
        extreme(v0, vf, af, lim, t, false),
        extreme(v0, vf, af, lim, t, true),
    ) else {
        return false;
    };
    let tol = 1e-12 * hi.dist.abs().max(lo.dist.abs()).max(dp.abs()).max(1e-300);
    if dp > hi.dist + tol || dp < lo.dist - tol {
        return false;
    }
    if (hi.dist - dp).abs() <= tol || hi.dist - lo.dist <= tol {
        hi.segments(out);
    } else if (dp - lo.dist).abs() <= tol {
        lo.segments(out);
    } else {
        let (mut x, mut y) = (Segs::<8>::default(), Segs::<8>::default());
        hi.segments(&mut x);
        lo.segments(&mut y);
        let lambda = ((dp - lo.dist) / (hi.dist - lo.dist)).clamp(0.0, 1.0);
        crate::mixture::mix(x.as_slice(), y.as_slice(), s.a, lambda, out);
    }
    true
}
