//! The brake law under four jerks (the velocity brake of `crate::brake`, each arc at its
//! own jerk): a start whose velocity is, or must become, beyond VMAX lowers its
//! acceleration at full jerk (`j2` while positive, `j3` once negative) and holds DMAX once
//! there, until it may stop braking.
//!
//! While `a > 0` this keeps `vz = v + a^2/(2 j2)` (the velocity after ramping the
//! acceleration to zero at once) constant; once `a < 0`, `vz = v - a^2/(2 j4)` falls. Braking
//! may stop anywhere from the moment `vz` is back on the limit (the earliest: the profile
//! that follows then meets VMAX exactly) to the moment the velocity itself is (the
//! latest), but not after `vz` has fallen below -VMAX (from there the velocity must
//! overshoot the other way). The total time over that range is not monotone: the planner
//! samples it and refines the best sample. A negative overshoot is the mirror image.

use super::arc_algebra::{mirror, push_down, push_hold, run, v_zero};
use super::limits::FourJerkLimits;
use crate::{Segment, State};

/// The brake law from one start (acceleration within the limits).
#[derive(Debug, Clone)]
pub(crate) struct BrakeLaw {
    start: State,
    segs: Vec<Segment>,
    /// Earliest and latest stopping times (s).
    pub earliest_s: f64,
    pub latest_s: f64,
}

impl BrakeLaw {
    pub(crate) fn new(start: State, l: &FourJerkLimits) -> Self {
        let vl = l.vmax;
        let vz = v_zero(start.v, start.a, l);
        // Brake towards where the velocity is heading: vz decides; only with vz inside
        // does an excess of v itself (which the acceleration is already correcting).
        let dir = if vz > vl {
            1.0
        } else if vz < -vl {
            -1.0
        } else if start.v > vl {
            1.0
        } else if start.v < -vl {
            -1.0
        } else {
            0.0
        };
        let lim = if dir > 0.0 { *l } else { l.mirrored() };
        if dir == 0.0 {
            return Self {
                start,
                segs: Vec::new(),
                earliest_s: 0.0,
                latest_s: 0.0,
            };
        };
        // Work in the frame where the overshoot is positive.
        let s = State {
            p: dir * start.p,
            v: dir * start.v,
            a: dir * start.a,
        };
        let mut segs = Vec::with_capacity(3);
        push_down(&mut segs, s.a, -lim.dmax, &lim);
        let at_floor = run(s, &segs);
        // Hold at DMAX until the velocity is back on the limit (if it is not already).
        push_hold(&mut segs, -lim.dmax, (at_floor.v - vl) / lim.dmax);
        let total: f64 = segs.iter().map(Segment::duration_s).sum();
        let state_at = |tau: f64| {
            let (_, st) = until_in(s, &segs, tau);
            st
        };
        // vz is non-increasing along the law, and so is v once a <= 0: bisect both.
        let first_at_or_below = |f: &dyn Fn(&State) -> f64| {
            if f(&s) <= vl {
                return 0.0;
            }
            if f(&state_at(total)) > vl {
                return total;
            }
            let (mut lo, mut hi) = (0.0, total);
            loop {
                let mid = 0.5 * (lo + hi);
                if mid <= lo || mid >= hi {
                    break hi;
                }
                if f(&state_at(mid)) <= vl {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
        };
        let earliest = first_at_or_below(&|st: &State| v_zero(st.v, st.a, &lim));
        // The latest stop: v back inside while the acceleration is negative, but not so
        // late that vz has passed -VMAX (the velocity would then overshoot the other way).
        let v_in = first_at_or_below(&|st: &State| if st.a > 0.0 { f64::INFINITY } else { st.v });
        let doomed = first_at_or_below(&|st: &State| v_zero(st.v, st.a, &lim) + 2.0 * vl);
        let latest = v_in.min(doomed);
        if dir < 0.0 {
            mirror(&mut segs);
        }
        Self {
            start,
            segs,
            earliest_s: earliest.min(latest),
            latest_s: latest.max(earliest),
        }
    }

    /// Stopping times to try: the earliest, the latest and evenly spaced ones between.
    pub(crate) fn samples(&self) -> Vec<f64> {
        const N: usize = 8;
        if self.latest_s <= self.earliest_s {
            return vec![self.earliest_s];
        }
        (0..=N)
            .map(|k| self.earliest_s + (self.latest_s - self.earliest_s) * k as f64 / N as f64)
            .collect()
    }

    /// The brake segments up to time `tau` and the state there.
    pub(crate) fn until(&self, tau: f64) -> (Vec<Segment>, State) {
        until_in(self.start, &self.segs, tau)
    }
}

fn until_in(start: State, segs: &[Segment], tau: f64) -> (Vec<Segment>, State) {
    let mut out = Vec::with_capacity(segs.len());
    let mut s = start;
    let mut t = 0.0;
    for seg in segs {
        let d = seg.duration_s().min(tau - t);
        if d <= 0.0 {
            break;
        }
        let part = match *seg {
            Segment::Jerk { jerk, .. } => Segment::Jerk {
                duration_s: d,
                jerk,
            },
            Segment::Accel { accel, .. } => Segment::Accel {
                duration_s: d,
                accel,
            },
        };
        s = part.end_state(&s);
        t += d;
        out.push(part);
        if d < seg.duration_s() {
            // Cut here: rounding of `t` must not start the next segment.
            break;
        }
    }
    (out, s)
}
