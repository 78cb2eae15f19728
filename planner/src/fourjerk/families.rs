//! The candidate families of the four-jerk planner, from a start whose acceleration is
//! within the limits (its velocity may still overshoot; the families then brake).
//!
//! - **UDU** (three arcs: up to `A1`, down to `A2 <= min(A1, 0)`, up to 0; holds at AMAX
//!   and DMAX where reached). One parameter `x` walks `A1` from the start acceleration up
//!   to AMAX and then the hold time at AMAX; the velocity equation fixes `A2` (or the hold
//!   at DMAX) in closed form; the position equation `p_end(x) = pf` is solved by
//!   bracketing every sign change on a grid refined at the structural knots and bisecting
//!   to full precision. When the middle arc passes through zero this is the peak-velocity
//!   family without cruise; otherwise the three-arc family.
//! - **Cruise**: the time-optimal change to `(vmax, 0)`, a cruise, the change to
//!   `(vf, 0)`; a closed form when the cruise is non-negative.
//! - **DUD** and the cruise at `-vmax`: the same on the mirrored problem.

use super::arc_algebra::{change_to_zero, mirror, push_down, push_hold, push_up, run};
use super::limits::FourJerkLimits;
use crate::{Segment, State};

/// A candidate: duration (s) and segments.
pub(crate) type Candidate = (f64, Vec<Segment>);

/// Duration of a segment list (s).
fn duration(segs: &[Segment]) -> f64 {
    segs.iter().map(Segment::duration_s).sum()
}

/// The UDU profile for parameter `x >= 0`, or `None` where the family has no member.
fn udu_at(s: &State, vf: f64, l: &FourJerkLimits, x: f64) -> Option<Vec<Segment>> {
    let up = l.amax - s.a;
    let (a1, h1) = if x <= up {
        (s.a + x, 0.0)
    } else {
        (l.amax, x - up)
    };
    let v1 = s.v + l.gu(a1) - l.gu(s.a) + l.amax * h1;
    let k = l.k_dec();
    let r = l.gd(a1) - (vf - v1);
    let floor = if a1 < 0.0 { k * a1 * a1 } else { 0.0 };
    if r.is_nan() || r < floor * (1.0 - 1e-12) - 1e-300 {
        return None;
    }
    let (a2, h2) = if r <= k * l.dmax * l.dmax {
        ((-(r / k).max(0.0).sqrt()).min(a1.min(0.0)), 0.0)
    } else {
        (-l.dmax, (r - k * l.dmax * l.dmax) / l.dmax)
    };
    let mut segs = Vec::with_capacity(8);
    push_up(&mut segs, s.a, a1, l);
    push_hold(&mut segs, a1, h1);
    push_down(&mut segs, a1, a2, l);
    push_hold(&mut segs, a2, h2);
    push_up(&mut segs, a2, 0.0, l);
    Some(segs)
}

/// UDU candidates from `s` to `(pf, vf, 0)`.
fn udu(s: &State, pf: f64, vf: f64, l: &FourJerkLimits) -> Vec<Candidate> {
    let up = l.amax - s.a;
    // Velocity after ramping to AMAX, and the hold times where A2 reaches DMAX and where
    // the peak velocity reaches VMAX: the family's structural knots.
    let v_ramp = s.v + l.gu(l.amax) - l.gu(s.a);
    let h_dmax = (l.k_dec() * l.dmax * l.dmax - l.gd(l.amax) + vf - v_ramp) / l.amax;
    let h_vmax = (l.vmax - v_ramp - l.gd(l.amax)) / l.amax;
    // Beyond the hold where the peak reaches VMAX no member is valid; allow margin for the
    // braking starts (whose peak is the start itself) with the time scale of the move.
    let h_end = h_vmax.max(h_dmax).max(0.0) + 1e-9 * (1.0 + up / l.jerk[0]);
    let mut knots = vec![0.0, up, up + h_end];
    if s.a < 0.0 {
        knots.push(-s.a);
    }
    for h in [h_dmax, h_vmax] {
        if h > 0.0 && h < h_end {
            knots.push(up + h);
        }
    }
    knots.sort_by(f64::total_cmp);
    knots.dedup();
    let g = |x: f64| {
        let segs = udu_at(s, vf, l, x)?;
        Some(run(*s, &segs).p - pf)
    };
    roots(&g, &knots)
        .into_iter()
        .filter_map(|x| udu_at(s, vf, l, x))
        .map(|segs| (duration(&segs), segs))
        .collect()
}

/// The cruise candidate at `+vmax`, if its cruise is non-negative.
fn cruise(s: &State, pf: f64, vf: f64, l: &FourJerkLimits) -> Option<Candidate> {
    let mut segs = change_to_zero(s.v, s.a, l.vmax, l);
    let mid = run(*s, &segs);
    let second = change_to_zero(l.vmax, 0.0, vf, l);
    let end = run(
        State {
            p: mid.p,
            v: l.vmax,
            a: 0.0,
        },
        &second,
    );
    let c = (pf - end.p) / l.vmax;
    if !(c >= 0.0 && c.is_finite()) {
        return None;
    }
    segs.push(Segment::Accel {
        duration_s: c,
        accel: 0.0,
    });
    segs.extend(second);
    Some((duration(&segs), segs))
}

/// Every candidate from `s` (acceleration within the limits) to `(pf, vf, 0)`, both senses.
pub(crate) fn candidates(s: &State, pf: f64, vf: f64, l: &FourJerkLimits) -> Vec<Candidate> {
    let mut out = udu(s, pf, vf, l);
    out.extend(cruise(s, pf, vf, l));
    let m = State {
        p: -s.p,
        v: -s.v,
        a: -s.a,
    };
    let lm = l.mirrored();
    let mut mirrored = udu(&m, -pf, -vf, &lm);
    mirrored.extend(cruise(&m, -pf, -vf, &lm));
    for (_, segs) in &mut mirrored {
        mirror(segs);
    }
    out.extend(mirrored);
    out
}

/// Every root of `g` on `[first, last]` of the sorted `knots`: a grid refined in each
/// knot interval, the edges of `g`'s domain located by bisection, close root pairs found
/// by golden-section search on `|g|`, each bracket bisected to full precision.
fn roots(g: &dyn Fn(f64) -> Option<f64>, knots: &[f64]) -> Vec<f64> {
    const SUB: usize = 24;
    let mut pts: Vec<(f64, Option<f64>)> = Vec::with_capacity(knots.len() * SUB + 1);
    let push = |pts: &mut Vec<(f64, Option<f64>)>, x: f64| {
        let gx = g(x);
        if let Some(&(xp, gp)) = pts.last()
            && gp.is_some() != gx.is_some()
        {
            let (mut valid, mut invalid) = if gp.is_some() { (xp, x) } else { (x, xp) };
            loop {
                let mid = 0.5 * (valid + invalid);
                if mid == valid || mid == invalid {
                    break;
                }
                if g(mid).is_some() {
                    valid = mid;
                } else {
                    invalid = mid;
                }
            }
            if valid != xp && valid != x {
                pts.push((valid, g(valid)));
            }
        }
        pts.push((x, gx));
    };
    for w in knots.windows(2) {
        for k in 0..SUB {
            push(&mut pts, w[0] + (w[1] - w[0]) * k as f64 / SUB as f64);
        }
    }
    if let Some(&last) = knots.last() {
        push(&mut pts, last);
    }
    // Close root pairs: |g| dips between samples without a sign change.
    let mut extra = Vec::new();
    for w in pts.windows(3) {
        if let ((xa, Some(ga)), (_, Some(gb)), (xc, Some(gc))) = (w[0], w[1], w[2])
            && ga.signum() == gb.signum()
            && gc.signum() == gb.signum()
            && gb.abs() <= ga.abs()
            && gb.abs() <= gc.abs()
        {
            let sg = gb.signum();
            let h = |x: f64| g(x).map(|v| v * sg);
            if let Some((xm, hm)) = golden_min(&h, xa, xc)
                && hm < 0.0
            {
                extra.push((xm, Some(hm * sg)));
            }
        }
    }
    pts.extend(extra);
    pts.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut out = Vec::new();
    for w in pts.windows(2) {
        let ((xa, ga), (xb, gb)) = (w[0], w[1]);
        let (Some(ga), Some(gb)) = (ga, gb) else {
            continue;
        };
        if ga == 0.0 {
            out.push(xa);
            continue;
        }
        if ga.signum() == gb.signum() || gb == 0.0 {
            continue;
        }
        let (mut lo, mut hi, glo) = (xa, xb, ga);
        loop {
            let mid = 0.5 * (lo + hi);
            if mid == lo || mid == hi {
                break;
            }
            match g(mid) {
                Some(gm) if gm.signum() == glo.signum() => lo = mid,
                Some(_) => hi = mid,
                None => break,
            }
        }
        out.push(if g(lo).map(f64::abs) <= g(hi).map(f64::abs) {
            lo
        } else {
            hi
        });
    }
    if let Some(&(xl, Some(gl))) = pts.last()
        && gl == 0.0
    {
        out.push(xl);
    }
    out
}

/// Minimum of `h` on `[a, b]` by golden-section search (`None` if `h` is undefined there).
fn golden_min(h: &dyn Fn(f64) -> Option<f64>, a: f64, b: f64) -> Option<(f64, f64)> {
    let r = 0.5 * (5f64.sqrt() - 1.0);
    let (mut a, mut b) = (a, b);
    let (mut c, mut d) = (b - r * (b - a), a + r * (b - a));
    let (mut hc, mut hd) = (h(c)?, h(d)?);
    for _ in 0..100 {
        if hc < 0.0 || hd < 0.0 {
            break;
        }
        if hc < hd {
            b = d;
            d = c;
            hd = hc;
            c = b - r * (b - a);
            hc = h(c)?;
        } else {
            a = c;
            c = d;
            hc = hd;
            d = a + r * (b - a);
            hd = h(d)?;
        }
        if b - a <= 1e-15 * (a.abs() + b.abs()) {
            break;
        }
    }
    Some(if hc < hd { (c, hc) } else { (d, hd) })
}
