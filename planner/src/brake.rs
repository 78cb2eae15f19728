//! Brake pre-trajectories: bring a start state that violates, or must violate, the limits
//! back inside them before the time-optimal profile begins: first the acceleration, then
//! the velocity, as in Haschke, Weitnauer, Ritter, "On-Line Planning of Time-Optimal,
//! Jerk-Limited Trajectories" (IROS 2008).
//!
//! The brake law:
//! 1. `a` beyond its limit: jerk towards the limit until it is reached.
//! 2. Velocity overshoot: the velocity reached by ramping the acceleration to zero at full
//!    jerk, `vz = v + a|a|/(2j)`, is above `vmax` (below `vmin`). Jerk `-j` (`+j`) keeps
//!    `vz` constant while `a` returns to zero and lowers it afterwards (`d vz/dt = 2a`);
//!    hold `amin` (`amax`) once reached.
//!
//! Along this law, braking may stop anywhere from the moment `vz` is back on the limit (the
//! shortest brake; the profile that follows then meets the limit exactly) to the moment
//! the velocity itself is back inside (where Ruckig's brake stops). The planner tries
//! several stopping times and keeps the fastest total.

use crate::segs::Segs;
use crate::{Limits, Segment, State};

/// The brake control law from one start state, as segments up to the latest stopping
/// time, with the range of stopping times.
#[derive(Debug, Clone)]
pub struct BrakeLaw {
    start: State,
    segs: Segs<4>,
    earliest_s: f64,
    latest_s: f64,
}

impl BrakeLaw {
    /// The law for `start` under `lim` with jerk limit `j`.
    pub fn new(start: State, lim: &Limits, j: f64) -> Self {
        let mut segs = Segs::<4>::default();
        let mut s = start;
        let mut t = 0.0;
        let mut push = |seg: Segment, s: &mut State, t: &mut f64| {
            if seg.duration_s() > 0.0 {
                *s = seg.end_state(s);
                *t += seg.duration_s();
                segs.push(seg);
            }
        };
        if s.a > lim.amax() {
            push(
                Segment::Jerk {
                    duration_s: (s.a - lim.amax()) / j,
                    jerk: -j,
                },
                &mut s,
                &mut t,
            );
            s.a = lim.amax();
        } else if s.a < lim.amin() {
            push(
                Segment::Jerk {
                    duration_s: (lim.amin() - s.a) / j,
                    jerk: j,
                },
                &mut s,
                &mut t,
            );
            s.a = lim.amin();
        }
        let after_accel = t;
        let vz = s.v + s.a * s.a.abs() / (2.0 * j);
        // Brake when vz is beyond a limit, or when v is (then, with vz inside, the earliest
        // stop is immediate and the latest is where v is back inside).
        // The direction is where the velocity is heading: vz decides; only with vz inside
        // does an excess of v itself (which the acceleration is already correcting).
        let up = (1.0, lim.vmax(), lim.amin(), lim.vmin());
        let down = (-1.0, lim.vmin(), lim.amax(), lim.vmax());
        let (dir, vlim, alim, vopp) = if vz > lim.vmax() {
            up
        } else if vz < lim.vmin() {
            down
        } else if s.v > lim.vmax() {
            up
        } else if s.v < lim.vmin() {
            down
        } else {
            return Self {
                start,
                segs,
                earliest_s: t,
                latest_s: t,
            };
        };
        // Mirrored frame: the overshoot is upwards, the floor acceleration negative.
        let a = dir * s.a;
        let excess = (dir * (vz - vlim)).max(0.0);
        let a_floor = dir * alim;
        let tau_floor = -a_floor / j;
        let tau0 = if a < 0.0 { -a / j } else { 0.0 };
        let ramp = a.max(0.0) / j;
        // vz = vz0 - j tau^2 on the descent past a = 0.
        let tau_vz = (tau0 * tau0 + excess / j).sqrt();
        // v = vz0 - j tau^2 / 2 on the descent: v back on the limit.
        let vz0 = dir * vz + j * tau0 * tau0;
        let tau_v = (2.0 * (vz0 - dir * vlim) / j).max(0.0).sqrt();
        let jerk_len = |tau: f64| ramp + tau.min(tau_floor) - tau0;
        let earliest = if tau_vz <= tau_floor {
            after_accel + jerk_len(tau_vz)
        } else {
            // Hold at the floor: vz falls at |a_floor| per second.
            let vz_at_floor = vz0 - j * tau_floor * tau_floor;
            after_accel + jerk_len(tau_floor) + (vz_at_floor - dir * vlim) / (-a_floor)
        };
        // The latest stop is where v is back inside, but no later than where vz reaches the
        // opposite limit (braking on from there, the velocity must overshoot that limit).
        let vz_opp = -dir * vopp;
        let tau_opp = ((vz0 + vz_opp) / j).max(0.0).sqrt();
        let doomed = if tau_opp <= tau_floor {
            after_accel + jerk_len(tau_opp)
        } else {
            let vz_at_floor = vz0 - j * tau_floor * tau_floor;
            after_accel + jerk_len(tau_floor) + (vz_at_floor + vz_opp) / (-a_floor)
        };
        let tau_v = if tau_opp < tau_v { tau_opp } else { tau_v };
        let latest;
        if tau_v <= tau_floor {
            latest = after_accel + jerk_len(tau_v);
            push(
                Segment::Jerk {
                    duration_s: jerk_len(tau_v),
                    jerk: -dir * j,
                },
                &mut s,
                &mut t,
            );
        } else {
            push(
                Segment::Jerk {
                    duration_s: jerk_len(tau_floor),
                    jerk: -dir * j,
                },
                &mut s,
                &mut t,
            );
            s.a = alim;
            let v_at_floor = dir * s.v;
            let hold = ((v_at_floor - dir * vlim) / (-a_floor)).max(0.0);
            latest = (t + hold).min(doomed);
            push(
                Segment::Accel {
                    duration_s: hold,
                    accel: alim,
                },
                &mut s,
                &mut t,
            );
        }
        Self {
            start,
            segs,
            earliest_s: earliest.min(latest),
            latest_s: latest,
        }
    }

    /// Stopping times to try: the earliest, the latest and evenly spaced ones between
    /// (one time when the brake has no freedom).
    pub fn candidate_times(&self) -> impl Iterator<Item = f64> + use<> {
        const N: usize = 8;
        let (e, l) = (self.earliest_s, self.latest_s);
        let n = if l <= e { 0 } else { N };
        (0..=n).map(move |k| {
            if n == 0 {
                e
            } else {
                e + (l - e) * k as f64 / N as f64
            }
        })
    }

    /// The state after braking until `tau`, its acceleration snapped onto the limits (the
    /// brake ends on them up to rounding).
    pub(crate) fn state_at(&self, tau: f64, lim: &Limits) -> State {
        let (_, mut s) = self.until(tau);
        s.a = s.a.clamp(lim.amin(), lim.amax());
        s
    }

    /// The brake segments up to time `tau` and the state there.
    pub(crate) fn until(&self, tau: f64) -> (Segs<4>, State) {
        let mut out = Segs::<4>::default();
        let mut s = self.start;
        let mut t = 0.0;
        for seg in self.segs.as_slice() {
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
        }
        (out, s)
    }
}

/// Does `start` need a brake: acceleration beyond its limits, velocity beyond them, or
/// bound to overshoot them (`v + a|a|/(2j)` beyond)?
pub(crate) fn needed(start: &State, lim: &Limits, j: f64) -> bool {
    let vz = start.v + start.a * start.a.abs() / (2.0 * j);
    !(start.a <= lim.amax()
        && start.a >= lim.amin()
        && start.v <= lim.vmax()
        && start.v >= lim.vmin()
        && vz <= lim.vmax()
        && vz >= lim.vmin())
}

/// The shortest brake (stop as soon as `vz` is back on the limit).
pub(crate) fn brake(start: State, lim: &Limits, j: f64) -> (Segs<4>, State) {
    let law = BrakeLaw::new(start, lim, j);
    law.until(law.earliest_s)
}
