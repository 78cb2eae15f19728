//! Step 1 without a cruise: three jerk arcs `+j, -j, +j` (UDU), with a hold at `amax`
//! after the first arc and at `amin` after the second, and the mirror image (DUD). With
//! the cruise profiles at `vmax` and `vmin` (see `fastest`) these are every candidate for
//! the time-optimal profile from a safe state: by Pontryagin's principle the jerk of a
//! time-optimal profile is bang-bang between boundary arcs (holds at an acceleration
//! limit, cruises at a velocity limit), with at most two switches between them, so without
//! a cruise the shape is UDU or DUD with holds. (Four-arc shapes whose acceleration only
//! touches zero, the peak-velocity profiles of kinds UD|UD and DU|DU of `udud`, are never
//! fastest; the test-only oracle still lists them and the property test checks this.)
//!
//! Each case is named after the limits it reaches and reduces to one polynomial in one
//! unknown, derived for this crate with sympy (`planner/derivations/udu.py`), in the
//! normalised units of [`Unit`] (jerk 1), where `dv = vf - v0`:
//! - `none` (no hold): unknown `s = A1 - A2 = t2`. The acceleration and velocity equations
//!   give `A1 + A2 = K / s` with `K = dv - (af^2 - a0^2)/2`, the duration is
//!   `T = 2 s + af - a0`, and position is the depressed quartic
//!   `s^4 + c2 s^2 + c1 s - K^2 = 0`.
//! - `acc0` (hold `h1` at `A1 = amax`): unknown `A2`; `h1 = (A2^2 - m)/amax`, a quartic.
//! - `acc1` (hold `h2` at `A2 = amin`): unknown `A1`; `h2 = (A1^2 - m')/(-amin)`, a quartic.
//! - `acc0_acc1` (both holds): unknown `h1`, a quadratic.
//!
//! In every case the duration is monotone in the unknown, so the roots come out in order
//! of duration: a search for the fastest profile takes the first valid root of each case,
//! and only looks where the duration beats the best found so far. The valid root is
//! picked among spurious ones by checking the profile: non-negative phase times, the
//! acceleration limits, and the velocity peak (the only place a UDU profile from a safe
//! state to a holdable target can leave the velocity limits).

use crate::case_poly::case_roots;
use crate::jerk_arcs::{Arcs, Sink, reaches};
use crate::unit::Unit;

/// Every case of the UDU family of `u` (`sign = 1`) or, given the mirrored problem and
/// `sign = -1`, of the DUD family.
pub(crate) fn family(u: &Unit, sign: f64, out: &mut impl Sink) {
    none(u, sign, out);
    acc0(u, sign, out);
    acc1(u, sign, out);
    acc0_acc1(u, sign, out);
}

/// Validate phase times (rounding below zero is clamped) and the velocity peak; offer.
pub(crate) fn check(
    u: &Unit,
    sign: f64,
    t: [f64; 5],
    a1: f64,
    a2: f64,
    out: &mut impl Sink,
) -> bool {
    valid(u, t, a1, a2).is_some_and(|t| out.offer_arcs(three(sign, t)))
}

/// As [`check`], for a root of a case polynomial. The polynomials are the position
/// equations times nonzero factors, so their roots reach the target (the one spurious
/// root, `s = 0` of `none` when `K = 0`, is divided out there); `debug_assertions` builds
/// check it.
fn check_root(u: &Unit, sign: f64, t: [f64; 5], a1: f64, a2: f64, out: &mut impl Sink) -> bool {
    let Some(t) = valid(u, t, a1, a2) else {
        return false;
    };
    let arcs = three(sign, t);
    debug_assert!(reaches(u, &arcs), "{u:?} {arcs:?}");
    out.offer_arcs(arcs)
}

fn three(sign: f64, t: [f64; 5]) -> Arcs {
    Arcs {
        sign,
        four: false,
        t: [t[0], t[1], t[2], t[3], t[4], 0.0],
    }
}

/// Phase times (rounding below zero clamped) if they, the extremes and the velocity peak
/// are valid.
fn valid(u: &Unit, mut t: [f64; 5], a1: f64, a2: f64) -> Option<[f64; 5]> {
    let scale = 1.0 + t.iter().map(|x| x.abs()).sum::<f64>();
    if t.iter().any(|x| x.is_nan() || *x < -1e-12 * scale) {
        return None;
    }
    let atol = 1e-12 * (u.amax - u.amin);
    if a1 > u.amax + atol || a2 < u.amin - atol || a1 < a2 - atol {
        return None;
    }
    for x in &mut t {
        *x = x.max(0.0);
    }
    if a1 > 0.0 && a2 < 0.0 {
        // The velocity peaks where the second arc crosses zero acceleration.
        let peak = u.v0 + 0.5 * (a1 * a1 - u.a0 * u.a0) + t[1] * a1 + 0.5 * a1 * a1;
        if peak > u.vmax + u.v_tol() {
            return None;
        }
    }
    Some(t)
}

/// Widen `[lo, hi]` by rounding, so roots on a case boundary are not lost.
fn pad(lo: f64, hi: f64) -> (f64, f64) {
    let e = 1e-12 * (1.0 + lo.abs().max(hi.abs()));
    (lo - e, hi + e)
}

/// No hold: unknown `s = A1 - A2`.
fn none(u: &Unit, sign: f64, out: &mut impl Sink) {
    let (a0, af, v0) = (u.a0, u.af, u.v0);
    let k = (u.vf - v0) - 0.5 * (af * af - a0 * a0);
    // A1 = (s^2 + K)/(2 s) <= amax and A2 = (K - s^2)/(2 s) >= amin bound s on both sides
    // (lower roots in cancellation-free form).
    let (d1, d2) = (u.amax * u.amax - k, u.amin * u.amin + k);
    if d1 < 0.0 || d2 < 0.0 {
        return;
    }
    let (r1, r2) = (d1.sqrt(), d2.sqrt());
    let lo = (k / (u.amax + r1)).max(-k / (-u.amin + r2)).max(0.0);
    let mut hi = (u.amax + r1).min(-u.amin + r2);
    // Velocity peak A1^2 - a0^2/2 + v0 <= vmax where A2 < 0, i.e. s^2 > K.
    let w = u.vmax - v0 + 0.5 * a0 * a0;
    let rw = w.max(0.0).sqrt();
    let s_v = if w >= k { rw + (w - k).sqrt() } else { 0.0 };
    hi = hi.min(s_v.max(k.max(0.0).sqrt()));
    hi = hi.min(0.5 * (out.t_max() - af + a0));
    if lo > hi {
        return;
    }
    let (lo, hi) = pad(lo, hi);
    let c1 = 4.0 * k * af + 4.0 / 3.0 * a0 * a0 * a0 - 2.0 * a0 * a0 * af - 4.0 * a0 * v0
        + 2.0 / 3.0 * af * af * af
        + 4.0 * af * v0
        - 4.0 * u.dp;
    let c2 = 4.0 * k - 4.0 * a0 * a0 + 8.0 * v0;
    // With K = 0 (e.g. rest to rest) the quartic is s times a cubic: drop the factor.
    let roots = if k == 0.0 {
        case_roots(&[c1, c2, 0.0, 1.0], lo, hi)
    } else {
        case_roots(&[-k * k, c1, c2, 0.0, 1.0], lo, hi)
    };
    for &s in roots.as_slice() {
        if s.is_nan() || s <= 0.0 {
            continue;
        }
        let a1 = if s > 0.0 { 0.5 * (s + k / s) } else { 0.0 };
        let a2 = a1 - s;
        if check_root(u, sign, [a1 - a0, 0.0, s, 0.0, af - a2], a1, a2, out) {
            return;
        }
    }
}

/// Hold at `A1 = amax`: unknown `x = A2`, duration decreasing in `x`.
fn acc0(u: &Unit, sign: f64, out: &mut impl Sink) {
    let (a0, af, v0, vf, amax) = (u.a0, u.af, u.v0, u.vf, u.amax);
    let dv = vf - v0;
    let h = 0.5 * (a0 * a0 - af * af);
    // h1 = (x^2 - m)/amax >= 0.
    let m = amax * amax - dv - h;
    let mut lo = u.amin;
    let hi = af.min(amax);
    let t_max = out.t_max();
    if t_max.is_finite() {
        // amax (T(x) - t_max) = x^2 - 2 amax x + c: shorter than t_max above the lower root.
        let c = amax * (2.0 * amax - a0 + af) + dv + h - amax * amax - amax * t_max;
        let d = amax * amax - c;
        if d <= 0.0 {
            return;
        }
        lo = lo.max(c / (amax + d.sqrt()));
    }
    // Velocity peak (x < 0): v0 + amax^2 - a0^2/2 + x^2 - m <= vmax.
    let mv = u.vmax - v0 - amax * amax + 0.5 * a0 * a0 + m;
    lo = lo.max(if mv >= 0.0 { -mv.sqrt() } else { 0.0 });
    // h1 >= 0 keeps x out of (-sqrt(m), sqrt(m)): up to two intervals, in order of duration
    // (descending x).
    let r = m.max(0.0).sqrt();
    let parts = if m <= 0.0 {
        [(lo, hi), (1.0, 0.0)]
    } else {
        [(lo.max(r), hi), (lo, hi.min(-r))]
    };
    if parts.iter().all(|(l, h)| l > h) {
        return;
    }
    let c0 = -0.25 * a0.powi(4) + 2.0 / 3.0 * a0.powi(3) * amax - 0.5 * a0 * a0 * amax * amax
        + a0 * a0 * v0
        - 2.0 * a0 * amax * v0
        + 0.25 * af.powi(4)
        - 2.0 / 3.0 * af.powi(3) * amax
        - 0.5 * af * af * amax * amax
        - af * af * vf
        + 2.0 * af * amax * vf
        + amax * amax * (v0 + vf)
        - 2.0 * amax * u.dp
        + (vf - v0) * (vf + v0);
    let c = [
        c0,
        2.0 * amax * (af * af - 2.0 * vf),
        amax * amax - af * af + 2.0 * vf,
        -2.0 * amax,
        1.0,
    ];
    for (lo, hi) in parts {
        if lo > hi {
            continue;
        }
        let (lo, hi) = pad(lo, hi);
        for &x in case_roots(&c, lo, hi).as_slice().iter().rev() {
            let h1 = (x * x - m) / amax;
            if check_root(
                u,
                sign,
                [amax - a0, h1, amax - x, 0.0, af - x],
                amax,
                x,
                out,
            ) {
                return;
            }
        }
    }
}

/// Hold at `A2 = amin`: unknown `x = A1`, duration increasing in `x`.
fn acc1(u: &Unit, sign: f64, out: &mut impl Sink) {
    let (a0, af, v0, vf, amin) = (u.a0, u.af, u.v0, u.vf, u.amin);
    let dv = vf - v0;
    let h = 0.5 * (a0 * a0 - af * af);
    // h2 = (x^2 - m)/(-amin) >= 0.
    let m = dv + h + amin * amin;
    let lo = a0.max(amin);
    let mut hi = u.amax;
    let t_max = out.t_max();
    if t_max.is_finite() {
        // amin (T(x) - t_max) = -x^2 + 2 amin x + c: shorter than t_max below the upper
        // root of x^2 - 2 amin x - c.
        let c = amin * (af - a0 - 2.0 * amin) + dv + h + amin * amin - amin * t_max;
        let d = amin * amin + c;
        if d <= 0.0 {
            return;
        }
        hi = hi.min(amin + d.sqrt());
    }
    // Velocity peak (x > 0): v0 + x^2 - a0^2/2 <= vmax.
    hi = hi.min((u.vmax - v0 + 0.5 * a0 * a0).max(0.0).sqrt());
    // h2 >= 0 keeps x out of (-sqrt(m), sqrt(m)): up to two intervals, in order of duration
    // (ascending x).
    let r = m.max(0.0).sqrt();
    let parts = if m <= 0.0 {
        [(lo, hi), (1.0, 0.0)]
    } else {
        [(lo, hi.min(-r)), (lo.max(r), hi)]
    };
    if parts.iter().all(|(l, h)| l > h) {
        return;
    }
    let c0 = 0.25 * a0.powi(4)
        - 2.0 / 3.0 * a0.powi(3) * amin
        - 0.5 * a0 * a0 * amin * amin
        - a0 * a0 * v0
        + 2.0 * a0 * amin * v0
        - 0.25 * af.powi(4)
        + 2.0 / 3.0 * af.powi(3) * amin
        - 0.5 * af * af * amin * amin
        + af * af * vf
        - 2.0 * af * amin * vf
        + amin * amin * (v0 + vf)
        + 2.0 * amin * u.dp
        + (v0 - vf) * (v0 + vf);
    let c = [
        c0,
        2.0 * amin * (a0 * a0 - 2.0 * v0),
        amin * amin - a0 * a0 + 2.0 * v0,
        -2.0 * amin,
        1.0,
    ];
    for (lo, hi) in parts {
        if lo > hi {
            continue;
        }
        let (lo, hi) = pad(lo, hi);
        for &x in case_roots(&c, lo, hi).as_slice() {
            let h2 = (x * x - m) / (-amin);
            if check_root(
                u,
                sign,
                [x - a0, 0.0, x - amin, h2, af - amin],
                x,
                amin,
                out,
            ) {
                return;
            }
        }
    }
}

/// Holds at both limits: unknown `h1`, duration increasing in `h1`.
fn acc0_acc1(u: &Unit, sign: f64, out: &mut impl Sink) {
    let (a0, af, v0, vf, amax, amin) = (u.a0, u.af, u.v0, u.vf, u.amax, u.amin);
    let dv = vf - v0;
    let e = 0.5 * (2.0 * amax * amax - a0 * a0 - 2.0 * amin * amin + af * af);
    // h2 = (dv - e - h1 amax)/amin >= 0.
    let lo = ((dv - e) / amax).max(0.0);
    let mut hi = (u.vmax - v0 - amax * amax + 0.5 * a0 * a0) / amax;
    let t_max = out.t_max();
    if t_max.is_finite() {
        let t0 = 2.0 * amax - a0 - 2.0 * amin + af + (dv - e) / amin;
        hi = hi.min((t_max - t0) / (1.0 - amax / amin));
    }
    if lo > hi {
        return;
    }
    let n = 0.25 * a0.powi(4) - 2.0 / 3.0 * a0.powi(3) * amin - a0 * a0 * amax * amax
        + 2.0 * a0 * a0 * amax * amin
        - 0.5 * a0 * a0 * amin * amin
        - a0 * a0 * v0
        + 2.0 * a0 * amin * v0
        - 0.25 * af.powi(4)
        + 2.0 / 3.0 * af.powi(3) * amin
        - 0.5 * af * af * amin * amin
        + af * af * vf
        - 2.0 * af * amin * vf
        + amax.powi(4)
        - 2.0 * amax.powi(3) * amin
        + amax * amax * amin * amin
        + 2.0 * amax * amax * v0
        - 4.0 * amax * amin * v0
        + amin * amin * (v0 + vf)
        + 2.0 * amin * u.dp
        + (v0 - vf) * (v0 + vf);
    let c = [
        n / (amax * (amax - amin)),
        (2.0 * v0 - a0 * a0) / amax + 2.0 * amax - amin,
        1.0,
    ];
    let (lo, hi) = pad(lo, hi);
    for &h1 in case_roots(&c, lo, hi).as_slice() {
        let h2 = (dv - e - h1 * amax) / amin;
        let t = [amax - a0, h1, amax - amin, h2, af - amin];
        if check_root(u, sign, t, amax, amin, out) {
            return;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    struct All(Vec<Arcs>);
    impl Sink for All {
        fn t_max(&self) -> f64 {
            f64::INFINITY
        }
        fn offer_arcs(&mut self, arcs: Arcs) -> bool {
            self.0.push(arcs);
            false
        }
    }

    /// Integrate a three-arc profile (normalised) from (0, v0, a0) of `u`.
    fn end(u: &Unit, a: &Arcs) -> (f64, f64, f64) {
        let (mut p, mut v, mut acc) = (0.0, a.sign * u.v0, a.sign * u.a0);
        for (&t, j) in a.t.iter().zip(a.jerks()) {
            p += t * (v + t * (acc / 2.0 + t * j / 6.0));
            v += t * (acc + t * j / 2.0);
            acc += t * j;
        }
        (a.sign * p, a.sign * v, a.sign * acc)
    }

    #[test]
    fn every_case_reaches_its_target() {
        // Problems whose fastest three-arc profiles exercise each case.
        let base = Unit {
            v0: 0.0,
            a0: 0.0,
            vf: 0.0,
            af: 0.0,
            dp: 0.5,
            amax: 1.0,
            amin: -0.8,
            vmax: 100.0,
            vmin: -100.0,
        };
        let cases = [
            base,
            Unit { dp: 20.0, ..base },
            Unit {
                v0: 1.0,
                a0: 0.5,
                vf: -0.3,
                af: 0.2,
                dp: 3.0,
                ..base
            },
            Unit {
                v0: -2.0,
                a0: -0.7,
                vf: 1.0,
                af: -0.5,
                dp: 10.0,
                ..base
            },
            Unit {
                v0: 3.0,
                a0: 0.9,
                vf: 0.5,
                af: 0.9,
                dp: 1.0,
                ..base
            },
            Unit {
                vf: 3.0,
                af: 0.5,
                dp: 6.0,
                ..base
            },
            Unit {
                vf: 2.0,
                af: -0.5,
                dp: 4.0,
                ..base
            },
        ];
        let mut kinds = [false; 4];
        for u in cases {
            let mut all = All(Vec::new());
            family(&u, 1.0, &mut all);
            family(&u.mirror(), -1.0, &mut all);
            assert!(!all.0.is_empty(), "{u:?}");
            for a in &all.0 {
                let (p, v, acc) = end(&u, a);
                assert!(
                    (p - u.dp).abs() < 1e-9 * (1.0 + u.dp.abs())
                        && (v - u.vf).abs() < 1e-9
                        && (acc - u.af).abs() < 1e-9,
                    "{u:?} {a:?} -> {p} {v} {acc}"
                );
                kinds[usize::from(a.t[1] > 0.0) + 2 * usize::from(a.t[3] > 0.0)] = true;
            }
        }
        assert!(kinds.iter().all(|k| *k), "cases covered: {kinds:?}");
    }
}
