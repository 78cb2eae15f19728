//! The second family of the any-state planner: three jerk arcs `+j, -j, +j` (UDU) or the
//! mirror (DUD), with optional holds at the acceleration limits between them, where the
//! middle arc need not pass through zero acceleration. The peak-velocity family in
//! `position` cannot produce such profiles, and they are the fastest when, for example,
//! the acceleration stays negative throughout a short deceleration.
//!
//! Parametrisation (UDU): the first extreme acceleration `A1` in `[a0, amax]`, continued by
//! the hold time `h1` at `amax`. The velocity change fixes the second extreme:
//! `A2^2 = A1^2 + (af^2 - a0^2)/2 - j (dv - h1 amax)` (both signs tried), or, below `amin`,
//! a hold at `amin` whose length takes up the rest of `dv`. The remaining position
//! equation is solved by bracketing and bisection over the parameter.

use crate::velocity::Bounds;
use crate::{Limits, Segment, State};

/// Run a one-sense solver `f(s, t, vmax, vmin, bounds, sign)` on the problem and on its
/// mirror image (p, v, a -> -p, -v, -a, the limits swapped), where `sign = -1` tells `f` to
/// mirror its segments back. UDU on the mirror is DUD; UDUD is DUDU.
pub(crate) fn both_senses<T>(
    s: &State,
    t: &State,
    lim: &Limits,
    b: &Bounds,
    f: impl Fn(&State, &State, f64, f64, &Bounds, f64) -> Vec<T>,
) -> Vec<T> {
    let mut out = f(s, t, lim.vmax(), lim.vmin(), b, 1.0);
    let m = |x: &State| State {
        p: -x.p,
        v: -x.v,
        a: -x.a,
    };
    let mb = Bounds {
        amax: -b.amin,
        amin: -b.amax,
        jmax: b.jmax,
    };
    out.extend(f(&m(s), &m(t), -lim.vmin(), -lim.vmax(), &mb, -1.0));
    out
}

/// Candidate profiles `(duration, segments)` of the UDU and DUD families from `s` to `t`.
pub fn candidates(s: &State, t: &State, lim: &Limits, b: &Bounds) -> Vec<(f64, Vec<Segment>)> {
    both_senses(s, t, lim, b, udu)
}

/// UDU candidates; `sign` = -1 mirrors the resulting segments back.
fn udu(
    s: &State,
    t: &State,
    vmax: f64,
    vmin: f64,
    b: &Bounds,
    sign: f64,
) -> Vec<(f64, Vec<Segment>)> {
    let j = b.jmax;
    let dv = t.v - s.v;
    let dp = t.p - s.p;
    if s.a > b.amax || t.a > b.amax {
        return Vec::new();
    }
    let h_max = (vmax - vmin) / b.amax;
    // Parameter x: A1 = x for x in [a0, amax]; hold h1 = x - amax beyond.
    let x_lo = s.a;
    let x_hi = b.amax + h_max;
    let build = |x: f64, branch: f64| -> Option<[Segment; 5]> {
        let (a1, h1) = if x <= b.amax {
            (x, 0.0)
        } else {
            (b.amax, x - b.amax)
        };
        let q = a1 * a1 + 0.5 * (t.a * t.a - s.a * s.a) - j * (dv - h1 * b.amax);
        if q < 0.0 {
            return None;
        }
        let mut a2 = branch * q.sqrt();
        let mut h2 = 0.0;
        if a2 > a1 || a2 > t.a {
            return None;
        }
        if a2 < b.amin {
            // Hold at amin: dv = h1 amax + (2 A1^2 - 2 amin^2 + af^2 - a0^2)/(2j) + h2 amin.
            a2 = b.amin;
            h2 = (dv
                - h1 * b.amax
                - (2.0 * a1 * a1 - 2.0 * a2 * a2 + t.a * t.a - s.a * s.a) / (2.0 * j))
                / a2;
            if h2 < 0.0 {
                return None;
            }
        }
        let (t1, t2, t3) = ((a1 - s.a) / j, (a1 - a2) / j, (t.a - a2) / j);
        if t1 < 0.0 || t2 < 0.0 || t3 < 0.0 {
            return None;
        }
        Some([
            Segment::Jerk {
                duration_s: t1,
                jerk: sign * j,
            },
            Segment::Accel {
                duration_s: h1,
                accel: sign * a1,
            },
            Segment::Jerk {
                duration_s: t2,
                jerk: -sign * j,
            },
            Segment::Accel {
                duration_s: h2,
                accel: sign * a2,
            },
            Segment::Jerk {
                duration_s: t3,
                jerk: sign * j,
            },
        ])
    };
    let start = State {
        p: 0.0,
        v: sign * s.v,
        a: sign * s.a,
    };
    let dist = |segs: &[Segment; 5]| {
        let mut st = start;
        for seg in segs {
            st = seg.end_state(&st);
        }
        sign * st.p
    };
    let mut out = Vec::new();
    for branch in [1.0, -1.0] {
        let g = |x: f64| build(x, branch).map(|segs| dist(&segs) - dp);
        // Knots: the ends, the start of the hold, and where the second extreme meets zero,
        // af or amin (the branches' domain edges), so narrow valid bands are sampled.
        let c = 0.5 * (t.a * t.a - s.a * s.a) - j * dv;
        let mut knots = vec![x_lo, b.amax.max(x_lo), x_hi];
        for k in [0.0, t.a * t.a, b.amin * b.amin] {
            let r = k - c;
            if r >= 0.0 {
                knots.extend([r.sqrt(), -r.sqrt()]);
            }
            knots.push(b.amax + (k - b.amax * b.amax - c) / (j * b.amax));
        }
        knots.retain(|x| x.is_finite() && *x >= x_lo && *x <= x_hi);
        knots.sort_by(f64::total_cmp);
        knots.dedup();
        for x in super::roots::roots(&g, &knots) {
            if let Some(segs) = build(x, branch) {
                let dur = segs.iter().map(Segment::duration_s).sum();
                if velocity_within(&start, &segs, vmax, vmin, sign) {
                    out.push((dur, segs.to_vec()));
                }
            }
        }
    }
    out
}

/// The velocity stays within `[vmin, vmax]` (in the unmirrored frame) at segment ends and
/// at interior extrema.
pub(crate) fn velocity_within(
    start: &State,
    segs: &[Segment],
    vmax: f64,
    vmin: f64,
    sign: f64,
) -> bool {
    let tol = 1e-12 * vmax.abs().max(vmin.abs());
    let mut st = *start;
    let ok = |v: f64| {
        let v = sign * v;
        v <= vmax + tol && v >= vmin - tol
    };
    for seg in segs {
        let (a0, jerk) = seg.accel_and_jerk(&st);
        if jerk != 0.0 {
            let tau = -a0 / jerk;
            if tau > 0.0 && tau < seg.duration_s() && !ok(seg.sample(&st, tau).v) {
                return false;
            }
        }
        st = seg.end_state(&st);
        if !ok(st.v) {
            return false;
        }
    }
    true
}
