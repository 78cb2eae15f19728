//! Step-2 shapes: profiles of a *given* duration that no time-optimal profile has —
//! three jerk arcs with a plateau at a free level, and four arcs (UDUD). Used by
//! `duration::with_duration` when stretching the peak-velocity family is not enough.

use super::roots::roots;
use super::three_arc::both_senses;
use crate::velocity::Bounds;
use crate::{Limits, Segment, State};

/// Step-2 profiles of the three-arc shape with one acceleration plateau at a *free* level
/// (time-optimal profiles hold only at the limits; a profile of a given longer duration
/// may hold anywhere). UDU with a hold at the first extreme `A1`:
/// with `c = (af^2 - a0^2)/2 - j dv` and `k = T j - af + a0`, the duration and velocity
/// equations give `A2 = A1 - sqrt(c + A1 k)` and `h1 = (k - 2 (A1 - A2))/j`; with the hold at
/// the second extreme `A2`: `A1 = A2 + sqrt(-c - A2 k')`, `k' = T j - af + a0` as well,
/// `h2 = T - (2 A1 - 2 A2 + af - a0)/j`. Position then fixes the free level, by bracketing.
/// DUD is the mirror image.
pub(crate) fn held_three_arc(
    s: &State,
    t: &State,
    lim: &Limits,
    b: &Bounds,
    duration_s: f64,
) -> Vec<Vec<Segment>> {
    both_senses(s, t, lim, b, |s, t, vmax, vmin, b, sign| {
        held_udu(s, t, vmax, vmin, b, duration_s, sign)
    })
}

fn held_udu(
    s: &State,
    t: &State,
    vmax: f64,
    vmin: f64,
    b: &Bounds,
    duration_s: f64,
    sign: f64,
) -> Vec<Vec<Segment>> {
    let j = b.jmax;
    let (a0, af) = (s.a, t.a);
    let dv = t.v - s.v;
    let dp = t.p - s.p;
    let c = 0.5 * (af * af - a0 * a0) - j * dv;
    let k = duration_s * j - af + a0;
    let start = State {
        p: 0.0,
        v: sign * s.v,
        a: sign * s.a,
    };
    let seg = |d: f64, jerk: f64| Segment::Jerk {
        duration_s: d,
        jerk,
    };
    // Build from the free level x; `first` = hold at A1, else hold at A2.
    let build = |x: f64, first: bool| -> Option<[Segment; 5]> {
        let (a1, a2, h1, h2) = if first {
            let r = c + x * k;
            if r < 0.0 {
                return None;
            }
            let a2 = x - r.sqrt();
            (x, a2, (k - 2.0 * (x - a2)) / j, 0.0)
        } else {
            let r = -c - x * k;
            if r < 0.0 {
                return None;
            }
            let a1 = x + r.sqrt();
            (a1, x, 0.0, duration_s - (2.0 * a1 - 2.0 * x + af - a0) / j)
        };
        let (t1, t2, t3) = ((a1 - a0) / j, (a1 - a2) / j, (af - a2) / j);
        let ok = [t1, t2, t3, h1, h2].iter().all(|d| *d >= 0.0) && a1 <= b.amax && a2 >= b.amin;
        ok.then(|| {
            [
                seg(t1, sign * j),
                seg(h1, 0.0),
                seg(t2, -sign * j),
                seg(h2, 0.0),
                seg(t3, sign * j),
            ]
        })
    };
    let dist = |segs: &[Segment; 5]| {
        let mut st = start;
        for sg in segs {
            st = sg.end_state(&st);
        }
        sign * st.p
    };
    let mut out = Vec::new();
    for first in [true, false] {
        let g = |x: f64| build(x, first).map(|segs| dist(&segs) - dp);
        let mut knots = vec![b.amin, b.amax, a0, af];
        if k != 0.0 {
            // Where the square root of either variant vanishes.
            knots.push(-c / k);
        }
        knots.retain(|x| x.is_finite() && *x >= b.amin && *x <= b.amax);
        knots.sort_by(f64::total_cmp);
        knots.dedup();
        for x in roots(&g, &knots) {
            if let Some(segs) = build(x, first)
                && super::three_arc::velocity_within(&start, &segs, vmax, vmin, sign)
            {
                out.push(segs.to_vec());
            }
        }
    }
    out
}

/// Step-2 profiles of four jerk arcs without plateaus, `+j, -j, +j, -j` (UDUD) and the
/// mirror: Ruckig's UDUD shape, which a given duration can need where no time-optimal
/// profile has it. With levels `A1` (peak), `A2` (valley), `A3` (peak), the duration fixes
/// `A3 = K - A1 + A2`, `K = (T j + a0 + af)/2`, and the velocity change is then *linear* in
/// `A2`: `A2 = (2 j dv + a0^2 + af^2 - 2 A1^2 - 2 (K - A1)^2) / (4 (K - A1))`. Position fixes
/// `A1`, by bracketing.
pub(crate) fn four_arc(
    s: &State,
    t: &State,
    lim: &Limits,
    b: &Bounds,
    duration_s: f64,
) -> Vec<Vec<Segment>> {
    both_senses(s, t, lim, b, |s, t, vmax, vmin, b, sign| {
        udud(s, t, vmax, vmin, b, duration_s, sign)
    })
}

fn udud(
    s: &State,
    t: &State,
    vmax: f64,
    vmin: f64,
    b: &Bounds,
    duration_s: f64,
    sign: f64,
) -> Vec<Vec<Segment>> {
    let j = b.jmax;
    let (a0, af) = (s.a, t.a);
    let dv = t.v - s.v;
    let dp = t.p - s.p;
    let kk = 0.5 * (duration_s * j + a0 + af);
    let rhs = 2.0 * j * dv + a0 * a0 + af * af;
    let start = State {
        p: 0.0,
        v: sign * s.v,
        a: sign * s.a,
    };
    let seg = |d: f64, jerk: f64| Segment::Jerk {
        duration_s: d,
        jerk,
    };
    let build = |a1: f64| -> Option<[Segment; 4]> {
        let den = 4.0 * (kk - a1);
        if den == 0.0 {
            return None;
        }
        let a2 = (rhs - 2.0 * a1 * a1 - 2.0 * (kk - a1) * (kk - a1)) / den;
        let a3 = kk - a1 + a2;
        let (t1, t2, t3, t4) = ((a1 - a0) / j, (a1 - a2) / j, (a3 - a2) / j, (a3 - af) / j);
        let ok = [t1, t2, t3, t4].iter().all(|d| *d >= 0.0)
            && a1 <= b.amax
            && a3 <= b.amax
            && a2 >= b.amin;
        ok.then(|| {
            [
                seg(t1, sign * j),
                seg(t2, -sign * j),
                seg(t3, sign * j),
                seg(t4, -sign * j),
            ]
        })
    };
    let dist = |segs: &[Segment; 4]| {
        let mut st = start;
        for sg in segs {
            st = sg.end_state(&st);
        }
        sign * st.p
    };
    let g = |x: f64| build(x).map(|segs| dist(&segs) - dp);
    let mut knots = vec![a0.max(b.amin), b.amax, kk];
    knots.retain(|x| x.is_finite() && *x >= a0 && *x <= b.amax);
    knots.sort_by(f64::total_cmp);
    knots.dedup();
    roots(&g, &knots)
        .into_iter()
        .filter_map(build)
        .filter(|segs| super::three_arc::velocity_within(&start, segs, vmax, vmin, sign))
        .map(|segs| segs.to_vec())
        .collect()
}
