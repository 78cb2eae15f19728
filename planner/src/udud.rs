//! Step 1 from a state that must still leave the velocity limits after its brake: four
//! jerk arcs whose acceleration touches zero between them, `+j, -j` to `(vp, 0)` then
//! `+j, -j` to the target (UDUD, holds at `amax` allowed in both halves), and the mirror
//! (DUDU). These are the peak-velocity profiles (a change to a velocity peak `(vp, 0)`,
//! then a change to the target) whose two phases accelerate the same way. From a safe state
//! they are never fastest (Pontryagin: at most two switches between boundary arcs, and a
//! touch of zero acceleration is none), so the search only runs where the brake leaves the
//! state unsafe in the other direction (limits so tight that braking one way overshoots the
//! other); there the peak velocity `vp` is required to lie within the limits, as in the
//! oracle.
//!
//! Cases (normalised units, jerk 1), named after the limits reached, polynomials derived
//! with sympy (`planner/derivations/udud.py`):
//! - `none`: peaks `A`, `B` with `A^2 + B^2 = C = dv + (a0^2 + af^2)/2`, parametrised
//!   rationally, `A = r (1 - s^2)/(1 + s^2)`, `B = r 2s/(1 + s^2)`, `r = sqrt(C)`,
//!   `s in [0, 1]`: position is a sextic in `s`.
//! - `acc0` (hold at `A = amax`): a quartic in `B`; `acc1` (hold at `B = amax`): a
//!   quartic in `A`; `acc0_acc1`: linear in the first hold.

use crate::case_poly::case_roots;
use crate::jerk_arcs::{Arcs, Sink, reaches};
use crate::unit::Unit;

/// Every case of the UDUD family of `u` (`sign = 1`), or on the mirrored problem with
/// `sign = -1` the DUDU family.
pub(crate) fn family(u: &Unit, sign: f64, out: &mut impl Sink) {
    let (a0, af, v0, vf, amax, dp) = (u.a0, u.af, u.v0, u.vf, u.amax, u.dp);
    let dv = vf - v0;
    let lo_a = a0.max(0.0);
    let lo_b = af.max(0.0);
    // Constant term shared by acc0 and acc1 (sympy's, divided by 12).
    let k0 = (-3.0 * a0.powi(4) + 8.0 * a0.powi(3) * amax - 6.0 * a0 * a0 * amax * amax
        + 12.0 * a0 * a0 * v0
        - 24.0 * a0 * amax * v0
        + 3.0 * af.powi(4)
        - 8.0 * af.powi(3) * amax
        + 6.0 * af * af * amax * amax
        + 12.0 * af * af * vf
        - 24.0 * af * amax * vf
        + 12.0 * amax * amax * (v0 + vf)
        - 24.0 * amax * dp
        - 12.0 * v0 * v0
        + 12.0 * vf * vf)
        / 12.0;
    // The first hold in terms of the other peak x: (C - amax^2 - x^2)/amax.
    let c = dv + 0.5 * (a0 * a0 + af * af);
    let hold = |x: f64| (c - amax * amax - x * x) / amax;
    // none.
    if c >= 0.0 {
        let r = c.sqrt();
        let (a2, a3) = (a0 * a0, a0 * a0 * a0);
        let base = 2.0 * a3 + 3.0 * a2 * af - 6.0 * a0 * v0 + af.powi(3)
            - 6.0 * af * r * r
            - 6.0 * af * v0
            - 6.0 * dp;
        let co = [
            base - 6.0 * a2 * r + 6.0 * r.powi(3) + 12.0 * r * v0,
            12.0 * r * (2.0 * r * r + 2.0 * v0 - a2),
            -3.0 * (-base + 2.0 * a2 * r + 6.0 * r.powi(3) - 4.0 * r * v0),
            24.0 * r * (2.0 * v0 - a2),
            3.0 * (base + 2.0 * a2 * r + 6.0 * r.powi(3) - 4.0 * r * v0),
            12.0 * r * (2.0 * r * r + 2.0 * v0 - a2),
            base + 6.0 * a2 * r - 6.0 * r.powi(3) - 12.0 * r * v0,
        ];
        for &s in case_roots(&co, -1e-12, 1.0 + 1e-12).as_slice() {
            let w = 1.0 + s * s;
            let (a, b) = (r * (1.0 - s * s) / w, r * 2.0 * s / w);
            check(u, sign, [a - a0, 0.0, a, b, 0.0, b - af], out);
        }
    }
    // acc0: A = amax, the second peak B free.
    let co = [
        k0,
        2.0 * amax * (af * af + 2.0 * vf),
        -(af * af + amax * amax + 2.0 * vf),
        -2.0 * amax,
        1.0,
    ];
    for &b in case_roots(&co, lo_b - 1e-12, amax + 1e-12).as_slice() {
        check(u, sign, [amax - a0, hold(b), amax, b, 0.0, b - af], out);
    }
    // acc1: B = amax, the first peak A free.
    let co = [
        k0,
        2.0 * amax * (2.0 * v0 - a0 * a0),
        a0 * a0 + amax * amax - 2.0 * v0,
        2.0 * amax,
        -1.0,
    ];
    for &a in case_roots(&co, lo_a - 1e-12, amax + 1e-12).as_slice() {
        check(u, sign, [a - a0, 0.0, a, amax, hold(a), amax - af], out);
    }
    // acc0_acc1: both peaks at amax; linear in the first hold.
    let c0 =
        k0 * 12.0 - 12.0 * a0 * a0 * amax * amax + 24.0 * amax.powi(4) + 24.0 * amax * amax * v0;
    let h1 = -c0 / (24.0 * amax.powi(3));
    let h2 = (c - 2.0 * amax * amax - amax * h1) / amax;
    check(u, sign, [amax - a0, h1, amax, amax, h2, amax - af], out);
}

/// Validate phase times, the zero-acceleration velocity `vp` (within the limits) and the
/// end position; offer.
fn check(u: &Unit, sign: f64, t: [f64; 6], out: &mut impl Sink) {
    if let Some(arcs) = valid(u, sign, t)
        && reaches(u, &arcs)
    {
        out.offer_arcs(arcs);
    }
}

/// The profile, if its phase times, peaks and zero-acceleration velocity `vp` (within the
/// limits) are valid.
fn valid(u: &Unit, sign: f64, t: [f64; 6]) -> Option<Arcs> {
    let scale = 1.0 + t.iter().map(|x| x.abs()).sum::<f64>();
    if t.iter().any(|x| x.is_nan() || *x < -1e-12 * scale) {
        return None;
    }
    let t = t.map(|x| x.max(0.0));
    let a = t[0] + u.a0;
    if a > u.amax * (1.0 + 1e-12) || t[3] > u.amax * (1.0 + 1e-12) {
        return None;
    }
    let vp = u.v0 + 0.5 * (a * a - u.a0 * u.a0) + t[1] * a + 0.5 * a * a;
    if vp > u.vmax + u.v_tol() || vp < u.vmin - u.v_tol() {
        return None;
    }
    Some(Arcs {
        sign,
        four: true,
        t,
    })
}

/// The members of duration `t` (normalised) of the UDUD family of `u` (or, on the mirrored
/// problem with `sign = -1`, of DUDU), for step 2 from a state that must leave the limits.
/// With `S = A + B`: no hold, `2 S = t + a0 + af` and `A^2 + B^2 = C` (two members); a hold
/// at one peak, a quadratic in the other peak; both holds last a fixed time (skipped).
pub(crate) fn lasting(u: &Unit, t: f64, sign: f64, out: &mut impl Sink) {
    let (a0, af, amax) = (u.a0, u.af, u.amax);
    let c = (u.vf - u.v0) + 0.5 * (a0 * a0 + af * af);
    let s = 0.5 * (t + a0 + af);
    let d = 2.0 * c - s * s;
    if d >= 0.0 {
        for r in [d.sqrt(), -d.sqrt()] {
            let (a, b) = (0.5 * (s + r), 0.5 * (s - r));
            check_lasting(u, sign, [a - a0, 0.0, a, b, 0.0, b - af], out);
        }
    }
    // One peak at amax with its hold (c - amax^2 - x^2)/amax, the other peak x free:
    // x^2 - 2 amax x - k = 0.
    let k = c - amax * amax + amax * (2.0 * amax - a0 - af - t);
    let e = amax * amax + k;
    if e >= 0.0 {
        for x in [amax + e.sqrt(), amax - e.sqrt()] {
            let hold = (c - amax * amax - x * x) / amax;
            check_lasting(u, sign, [amax - a0, hold, amax, x, 0.0, x - af], out);
            check_lasting(u, sign, [x - a0, 0.0, x, amax, hold, amax - af], out);
        }
    }
}

/// As `check`, without the position (a step-2 member reaches wherever it reaches).
fn check_lasting(u: &Unit, sign: f64, t: [f64; 6], out: &mut impl Sink) {
    if let Some(arcs) = valid(u, sign, t) {
        out.offer_arcs(arcs);
    }
}
