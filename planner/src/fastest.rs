//! Step 1 from a safe state: every locally fastest profile (the cruises at `vmax` and
//! `vmin`, the UDU and DUD families of `arcs`), the fastest of them, and their segments.
//!
//! A cruise profile is the time-optimal velocity change to `(vlim, 0)`, a cruise at
//! `vlim`, and the time-optimal change to `(vf, af)`; it exists when the two changes leave
//! a non-negative distance to cruise. The fastest-profile search evaluates the cruises
//! first: their duration bounds the search in the three-arc cases, which then often have
//! nothing left to solve.

use crate::Segment;
use crate::arcs::{Arcs, Sink, family};
use crate::segs::Segs;
use crate::unit::{Scale, Unit};
use crate::velocity::{Bounds, Change, change};

/// A candidate profile from a safe state, in normalised units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Cand {
    /// Three arcs (see `arcs`).
    Arcs(Arcs),
    /// Change to `(vlim, 0)`, cruise, change to the target.
    Cruise {
        /// The cruise velocity (`vmax` or `vmin`, normalised).
        v: f64,
        /// The first velocity change.
        c1: Change,
        /// Cruise duration (normalised time).
        cruise: f64,
        /// The second velocity change.
        c2: Change,
    },
}

impl Cand {
    /// Duration (normalised time).
    pub(crate) fn duration(&self) -> f64 {
        match self {
            Cand::Arcs(a) => a.duration(),
            Cand::Cruise { c1, cruise, c2, .. } => c1.duration_s() + cruise + c2.duration_s(),
        }
    }

    /// Distance covered from the start of `u` (normalised).
    pub(crate) fn end_p(&self, u: &Unit) -> f64 {
        match self {
            Cand::Arcs(a) => {
                let (mut p, mut v, mut acc) = (0.0, a.sign * u.v0, a.sign * u.a0);
                for (t, j) in a.t.iter().zip(a.jerks()) {
                    p += t * (v + t * (acc / 2.0 + t * j / 6.0));
                    v += t * (acc + t * j / 2.0);
                    acc += t * j;
                }
                a.sign * p
            }
            Cand::Cruise { v, c1, cruise, c2 } => {
                c1.end(u.v0, u.a0).p + cruise * v + c2.end(*v, 0.0).p
            }
        }
    }

    /// Append the profile's segments in physical units (zero-duration ones included). Holds
    /// are zero-jerk segments; the cruise is a constant-acceleration segment at exactly
    /// zero.
    pub(crate) fn segments(&self, sc: &Scale, out: &mut Segs) {
        match self {
            Cand::Arcs(a) => {
                for (t, j) in a.t.iter().zip(a.jerks()) {
                    out.push(Segment::Jerk {
                        duration_s: t * sc.t,
                        jerk: j * a.sign * sc.j,
                    });
                }
            }
            Cand::Cruise { c1, cruise, c2, .. } => {
                push_change(c1, sc, out);
                // The cruise holds the acceleration at exactly zero: the change before ends
                // there only up to rounding, and a cruise can be long enough to matter.
                out.push(Segment::Accel {
                    duration_s: cruise * sc.t,
                    accel: 0.0,
                });
                push_change(c2, sc, out);
            }
        }
    }
}

fn push_change(c: &Change, sc: &Scale, out: &mut Segs) {
    for seg in &c.segments {
        if let Segment::Jerk { duration_s, jerk } = *seg {
            out.push(Segment::Jerk {
                duration_s: duration_s * sc.t,
                jerk: jerk * sc.j,
            });
        }
    }
}

/// The time-optimal velocity changes to `(vlim, 0)` and from there to the target, with
/// their durations' sum and distance.
fn cruise_changes(u: &Unit, vlim: f64) -> Option<(Change, Change, f64, f64)> {
    let b = Bounds {
        amax: u.amax,
        amin: u.amin,
        jmax: 1.0,
    };
    let c1 = change(u.v0, u.a0, vlim, 0.0, &b)?;
    let c2 = change(vlim, 0.0, u.vf, u.af, &b)?;
    let d = c1.end(u.v0, u.a0).p + c2.end(vlim, 0.0).p;
    Some((c1, c2, c1.duration_s() + c2.duration_s(), d))
}

/// The cruise profile at `vlim` (`vmax` or `vmin`), if the distance leaves room for it.
fn cruise(u: &Unit, vlim: f64) -> Option<Cand> {
    let (c1, c2, _, d) = cruise_changes(u, vlim)?;
    let cruise = (u.dp - d) / vlim;
    (cruise >= 0.0 && cruise.is_finite()).then_some(Cand::Cruise {
        v: vlim,
        c1,
        cruise,
        c2,
    })
}

/// The cruise profile at `vlim` lasting `t` (normalised), whatever its distance.
pub(crate) fn cruise_lasting(u: &Unit, vlim: f64, t: f64) -> Option<Cand> {
    let (c1, c2, t12, _) = cruise_changes(u, vlim)?;
    let cruise = t - t12;
    (cruise >= -1e-12 * (1.0 + t) && cruise.is_finite()).then_some(Cand::Cruise {
        v: vlim,
        c1,
        cruise: cruise.max(0.0),
        c2,
    })
}

/// The fastest profile of `u` shorter than `t_max` (normalised time), if any.
pub(crate) fn fastest(u: &Unit, t_max: f64) -> Option<Cand> {
    let mut s = Fastest { t_max, best: None };
    for vlim in [u.vmax, u.vmin] {
        if let Some(c) = cruise(u, vlim) {
            s.offer(c);
        }
    }
    family(u, 1.0, &mut s);
    family(&u.mirror(), -1.0, &mut s);
    if !u.safe() {
        crate::four_arcs::family(u, 1.0, &mut s);
        crate::four_arcs::family(&u.mirror(), -1.0, &mut s);
    }
    s.best
}

/// Calls `f` with the duration (normalised) of every locally fastest profile of `u`.
pub(crate) fn each_duration(u: &Unit, f: impl FnMut(f64)) {
    let mut s = Every(f);
    for vlim in [u.vmax, u.vmin] {
        if let Some(c) = cruise(u, vlim) {
            (s.0)(c.duration());
        }
    }
    family(u, 1.0, &mut s);
    family(&u.mirror(), -1.0, &mut s);
    if !u.safe() {
        crate::four_arcs::family(u, 1.0, &mut s);
        crate::four_arcs::family(&u.mirror(), -1.0, &mut s);
    }
}

struct Fastest {
    t_max: f64,
    best: Option<Cand>,
}

impl Fastest {
    fn offer(&mut self, c: Cand) -> bool {
        let t = c.duration();
        if t < self.t_max {
            self.t_max = t;
            self.best = Some(c);
            true
        } else {
            false
        }
    }
}

impl Sink for Fastest {
    fn t_max(&self) -> f64 {
        self.t_max
    }
    fn offer_arcs(&mut self, arcs: Arcs) -> bool {
        // Within a case the roots come in order of duration: the first valid one is the
        // case's fastest, whether or not it beats the best so far.
        self.offer(Cand::Arcs(arcs));
        true
    }
}

struct Every<F>(F);

impl<F: FnMut(f64)> Sink for Every<F> {
    fn t_max(&self) -> f64 {
        f64::INFINITY
    }
    fn offer_arcs(&mut self, arcs: Arcs) -> bool {
        (self.0)(arcs.duration());
        false
    }
}
