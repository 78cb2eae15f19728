//! Step 2, jerk limited: a profile of a *given* duration from a safe state (for time
//! synchronisation), in closed form.
//!
//! For a fixed duration `T` the profiles from the start to the target's velocity and
//! acceleration that respect the limits form a convex set: the constraints (jerk,
//! acceleration and velocity within bounds, the end velocity and acceleration) are linear
//! in the jerk function. The end positions they reach therefore form an interval
//! `[pmin(T), pmax(T)]`, and if two feasible profiles of duration `T` end at `p_lo <= dp
//! <= p_hi`, the mixture `lambda x + (1 - lambda) y` of their jerk functions (on the union
//! of their breakpoints) is feasible and ends at `dp` for `lambda = (dp - p_lo)/(p_hi -
//! p_lo)`.
//!
//! The interval's ends are reached by the profiles that Pontryagin's principle allows:
//! bang-bang jerk between holds at the acceleration limits and cruises at the velocity
//! limits, at most two switches between them. For a given duration each case has at most
//! one member, in closed form: three arcs (`none`: `s = (T - af + a0)/2`; `acc0` and `acc1`:
//! one root of a quadratic; `acc0_acc1`: linear), in both senses (UDU, DUD), and the
//! cruises at `vmax` and `vmin` between time-optimal changes. So step 2 needs no root
//! finding: it evaluates these members, checks that `dp` lies between the highest and the
//! lowest end position (otherwise `T` lies in a blocked interval), and mixes the two. When
//! `dp` is (within rounding) one member's own end position, that member is the profile.

use crate::Segment;
use crate::fastest::{Cand, Cruises, cruise_lasting};
use crate::jerk_arcs::{Arcs, Sink};
use crate::segs::Segs;
use crate::udu::check;
use crate::unit::{Scale, Unit};

/// The extreme-position members of duration `t` (normalised): highest and lowest end
/// position with their profiles.
struct Extremes {
    hi: Option<(f64, Cand)>,
    lo: Option<(f64, Cand)>,
    u: Unit,
}

impl Extremes {
    fn offer(&mut self, c: Cand) {
        let p = c.end_p(&self.u);
        if !p.is_finite() {
            return;
        }
        if self.hi.is_none_or(|(ph, _)| p > ph) {
            self.hi = Some((p, c));
        }
        if self.lo.is_none_or(|(pl, _)| p < pl) {
            self.lo = Some((p, c));
        }
    }
}

impl Sink for Extremes {
    fn t_max(&self) -> f64 {
        f64::INFINITY
    }
    fn offer_arcs(&mut self, arcs: Arcs) -> bool {
        self.offer(Cand::Arcs(arcs));
        false
    }
}

/// Append the segments (physical units) of a profile from the start of `u` lasting `t`
/// (normalised) and reaching the target; false (nothing appended) if none exists.
pub(crate) fn lasting(
    u: &Unit,
    t: f64,
    sc: &Scale,
    cruises: &mut Cruises,
    out: &mut Vec<Segment>,
) -> bool {
    let mut ex = Extremes {
        hi: None,
        lo: None,
        u: *u,
    };
    // A cruise member at vmax, where it exists, is the highest-reaching profile under the
    // envelope argument of `fastest::cruise_is_optimal` (every profile's velocity stays
    // below the cruise profile's); vmin mirrored. Then the three-arc family on that side
    // is only needed if the other side does not reach below (above) the target.
    let safe = u.safe();
    let mut top = [false; 2];
    for (k, vlim) in [u.vmax, u.vmin].into_iter().enumerate() {
        if let Some(c) = cruises.lasting(u, k, t) {
            ex.offer(c);
            top[k] = safe && envelope(u, vlim.signum());
        }
    }
    let brackets = |ex: &Extremes| matches!((ex.hi, ex.lo), (Some((h, _)), Some((l, _))) if l <= u.dp && u.dp <= h);
    match top {
        [true, false] => {
            family(&u.mirror(), t, -1.0, &mut ex);
            if !brackets(&ex) {
                family(u, t, 1.0, &mut ex);
            }
        }
        [false, true] => {
            family(u, t, 1.0, &mut ex);
            if !brackets(&ex) {
                family(&u.mirror(), t, -1.0, &mut ex);
            }
        }
        [true, true] => {}
        [false, false] => {
            family(u, t, 1.0, &mut ex);
            family(&u.mirror(), t, -1.0, &mut ex);
        }
    }
    if !safe {
        unsafe_members(u, t, &mut ex);
    }
    let (Some((p_hi, hi)), Some((p_lo, lo))) = (ex.hi, ex.lo) else {
        return false;
    };
    let tol = 1e-12 * (1.0 + p_hi.abs().max(p_lo.abs()).max(u.dp.abs()));
    if u.dp > p_hi + tol || u.dp < p_lo - tol {
        return false;
    }
    if (p_hi - u.dp).abs() <= tol || p_hi - p_lo <= tol {
        hi.segments(sc, out);
    } else if (u.dp - p_lo).abs() <= tol {
        lo.segments(sc, out);
    } else {
        let (mut x, mut y) = (Segs::<8>::default(), Segs::<8>::default());
        hi.segments(sc, &mut x);
        lo.segments(sc, &mut y);
        let lambda = ((u.dp - p_lo) / (p_hi - p_lo)).clamp(0.0, 1.0);
        crate::mixture::mix(x.as_slice(), y.as_slice(), u.a0 * sc.a, lambda, out);
    }
    true
}

/// Does the velocity envelope bound every profile of `u` in direction `s` (`1`: below the
/// cruise profile at `vmax`; `-1`: above the one at `vmin`)? It does when the target is
/// forward safe (`vf + af|af|/2 <= vmax`) and the start backward safe
/// (`v0 - a0|a0|/2 <= vmax`), mirrored for `vmin`; see `fastest::cruise_is_optimal`.
fn envelope(u: &Unit, s: f64) -> bool {
    let vlim = if s > 0.0 { u.vmax } else { u.vmin };
    let (v0, a0, vf, af) = (s * u.v0, s * u.a0, s * u.vf, s * u.af);
    vf + 0.5 * af * af.abs() <= s * vlim && v0 - 0.5 * a0 * a0.abs() <= s * vlim
}

/// From a state that must leave the velocity limits whatever it does (the brake could not
/// make it safe: the limits are too tight for its acceleration), the convexity argument
/// has no feasible set to work on, and the three-arc members reject what they see beyond
/// the limits. There the profiles of the oracle's semantics are used as well: a
/// time-optimal change to a peak velocity `vp` within the limits (the limits are not
/// checked inside it), a cruise at `vp`, and a time-optimal change to the target, lasting
/// `t`, for `vp` sampled across the limits. Mixing the two members that bracket the target
/// reaches it. (Rare: about 2 in 100,000 random problems.)
fn unsafe_members(u: &Unit, t: f64, ex: &mut Extremes) {
    crate::udud::lasting(u, t, 1.0, ex);
    crate::udud::lasting(&u.mirror(), t, -1.0, ex);
    const N: usize = 64;
    for k in 0..=N {
        let vp = u.vmin + (u.vmax - u.vmin) * k as f64 / N as f64;
        if let Some(c) = cruise_lasting(u, vp, t) {
            ex.offer(c);
        }
    }
}

/// The members of duration `t` of each three-arc case of the UDU family of `u` (or, on
/// the mirrored problem with `sign = -1`, of the DUD family).
fn family(u: &Unit, t: f64, sign: f64, out: &mut impl Sink) {
    let (a0, af, v0, vf, amax, amin) = (u.a0, u.af, u.v0, u.vf, u.amax, u.amin);
    let dv = vf - v0;
    let h = 0.5 * (a0 * a0 - af * af);
    // none: T = 2 s + af - a0.
    let s = 0.5 * (t - af + a0);
    let k = dv + h;
    if s > 0.0 {
        let a1 = 0.5 * (s + k / s);
        check(
            u,
            sign,
            [a1 - a0, 0.0, s, 0.0, af - a1 + s],
            a1,
            a1 - s,
            out,
        );
    } else if s == 0.0 && k == 0.0 {
        check(u, sign, [-a0, 0.0, 0.0, 0.0, af], 0.0, 0.0, out);
    }
    // acc0: amax T = x^2 - 2 amax x + c0 with x = A2 <= amax.
    let c = amax * (2.0 * amax - a0 + af) + dv + h - amax * amax - amax * t;
    let d = amax * amax - c;
    if d >= 0.0 {
        let x = c / (amax + d.sqrt());
        let h1 = (x * x - (amax * amax - dv - h)) / amax;
        check(
            u,
            sign,
            [amax - a0, h1, amax - x, 0.0, af - x],
            amax,
            x,
            out,
        );
    }
    // acc1: amin T = -x^2 + 2 amin x + c1 with x = A1 >= amin.
    let c = amin * (af - a0 - 2.0 * amin) + dv + h + amin * amin - amin * t;
    let d = amin * amin + c;
    if d >= 0.0 {
        let x = amin + d.sqrt();
        let h2 = (x * x - (dv + h + amin * amin)) / (-amin);
        check(
            u,
            sign,
            [x - a0, 0.0, x - amin, h2, af - amin],
            x,
            amin,
            out,
        );
    }
    // acc0_acc1: T linear in h1.
    let e = amax * amax - amin * amin - h;
    let t0 = 2.0 * amax - a0 - 2.0 * amin + af + (dv - e) / amin;
    let h1 = (t - t0) / (1.0 - amax / amin);
    let h2 = (dv - e - h1 * amax) / amin;
    check(
        u,
        sign,
        [amax - a0, h1, amax - amin, h2, af - amin],
        amax,
        amin,
        out,
    );
}
