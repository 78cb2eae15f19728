//! Step 1 from a safe state: every locally fastest profile (the cruises at `vmax` and
//! `vmin`, the UDU and DUD families of `udu`), the fastest of them, and their segments.
//!
//! A cruise profile is the time-optimal velocity change to `(vlim, 0)`, a cruise at
//! `vlim`, and the time-optimal change to `(vf, af)`; it exists when the two changes leave
//! a non-negative distance to cruise. The fastest-profile search evaluates the cruises
//! first: their duration bounds the search in the three-arc cases, which then often have
//! nothing left to solve.

use crate::Segment;
use crate::jerk_arcs::{Arcs, Sink};
use crate::ramp::Ramp;
use crate::segs::Push;
use crate::udu::family;
use crate::unit::{Scale, Unit};
use crate::velocity::{Bounds, change};

/// A candidate profile from a safe state, in normalised units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Cand {
    /// Three arcs (see `udu`) or, from an unsafe state, four (see `udud`).
    Arcs(Arcs),
    /// Change to `(vlim, 0)`, cruise, change to the target.
    Cruise {
        /// The cruise velocity (`vmax` or `vmin`, normalised).
        v: f64,
        /// The first velocity change.
        c1: Ramp,
        /// Cruise duration (normalised time).
        cruise: f64,
        /// The second velocity change.
        c2: Ramp,
    },
}

impl Cand {
    /// Duration (normalised time).
    pub(crate) fn duration(&self) -> f64 {
        match self {
            Cand::Arcs(a) => a.duration(),
            Cand::Cruise { c1, cruise, c2, .. } => c1.duration() + cruise + c2.duration(),
        }
    }

    /// Distance covered from the start of `u` (normalised).
    pub(crate) fn end_p(&self, u: &Unit) -> f64 {
        match self {
            Cand::Arcs(a) => a.end_p(u),
            Cand::Cruise { v, c1, cruise, c2 } => c1.dist + cruise * v + c2.dist,
        }
    }

    /// Append the profile's segments in physical units (zero-duration jerk segments left
    /// out). Holds are zero-jerk segments; the cruise is a constant-acceleration segment at
    /// exactly zero.
    pub(crate) fn segments(&self, sc: &Scale, out: &mut impl Push) {
        match self {
            Cand::Arcs(a) => {
                for (t, j) in a.t.iter().zip(a.jerks()) {
                    out.push_jerk(t * sc.t, j * a.sign * sc.j);
                }
            }
            Cand::Cruise { c1, cruise, c2, .. } => {
                c1.segments(sc, out);
                // The cruise holds the acceleration at exactly zero: the change before ends
                // there only up to rounding, and a cruise can be long enough to matter.
                out.push_seg(Segment::Accel {
                    duration_s: cruise * sc.t,
                    accel: 0.0,
                });
                c2.segments(sc, out);
            }
        }
    }
}

/// The time-optimal velocity changes to `(vlim, 0)` and from there to the target, with
/// their durations' sum and distance. From a safe state toward a limit the first is an
/// up-down change (down-up toward `vmin`) and the second the mirror, in closed form (see
/// `ramp`); otherwise `velocity::change` picks the fastest shape.
fn cruise_changes(u: &Unit, vlim: f64) -> Option<(Ramp, Ramp)> {
    if u.safe() {
        let s = vlim.signum();
        let (amax, amin) = if s > 0.0 {
            (u.amax, u.amin)
        } else {
            (-u.amin, -u.amax)
        };
        if let (Some(r1), Some(r2)) = (
            Ramp::up_down(s * u.v0, s * u.a0, s * vlim, 0.0, amax),
            Ramp::up_down(-s * vlim, 0.0, -s * u.vf, -s * u.af, -amin),
        ) {
            return Some(if s > 0.0 {
                (r1, r2.mirrored())
            } else {
                (r1.mirrored(), r2)
            });
        }
    }
    let b = Bounds {
        amax: u.amax,
        amin: u.amin,
        jmax: 1.0,
    };
    let c1 = change(u.v0, u.a0, vlim, 0.0, &b)?;
    let c2 = change(vlim, 0.0, u.vf, u.af, &b)?;
    Some((
        Ramp::from_change(&c1, u.v0, u.a0),
        Ramp::from_change(&c2, vlim, 0.0),
    ))
}

/// The velocity changes of the cruises at `vmax` and `vmin` of one problem, computed when
/// first needed (often only the one at `vmax` is) and kept for step 2.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct Cruises {
    /// `[vmax, vmin]`: `None` until computed.
    changes: [Option<Option<(Ramp, Ramp)>>; 2],
}

impl Cruises {
    /// The cruise at `vmax` (`k = 0`) or `vmin` (`k = 1`), if the distance leaves room.
    fn cruise(&mut self, u: &Unit, k: usize) -> Option<Cand> {
        let (v, (c1, c2)) = self.get(u, k)?;
        let rest = u.dp - c1.dist - c2.dist;
        // Room to cruise when the rest of the distance lies in the cruise's direction.
        if rest * v < 0.0 {
            return None;
        }
        let cruise = rest / v;
        (cruise >= 0.0 && cruise.is_finite()).then_some(Cand::Cruise { v, c1, cruise, c2 })
    }

    /// The cruise at `vmax` (`k = 0`) or `vmin` (`k = 1`) lasting `t` (normalised),
    /// whatever its distance.
    pub(crate) fn lasting(&mut self, u: &Unit, k: usize, t: f64) -> Option<Cand> {
        let (v, (c1, c2)) = self.get(u, k)?;
        lasting_with(v, c1, c2, t)
    }

    fn get(&mut self, u: &Unit, k: usize) -> Option<(f64, (Ramp, Ramp))> {
        let v = if k == 0 { u.vmax } else { u.vmin };
        let r = *self.changes[k].get_or_insert_with(|| cruise_changes(u, v));
        r.map(|r| (v, r))
    }
}

/// The cruise profile at `vlim` lasting `t` (normalised), whatever its distance.
pub(crate) fn cruise_lasting(u: &Unit, vlim: f64, t: f64) -> Option<Cand> {
    let (c1, c2) = cruise_changes(u, vlim)?;
    lasting_with(vlim, c1, c2, t)
}

fn lasting_with(v: f64, c1: Ramp, c2: Ramp, t: f64) -> Option<Cand> {
    let cruise = t - c1.duration() - c2.duration();
    (cruise >= -1e-12 * (1.0 + t) && cruise.is_finite()).then_some(Cand::Cruise {
        v,
        c1,
        cruise: cruise.max(0.0),
        c2,
    })
}

/// The fastest profile of `u` shorter than `t_max` (normalised time), if any.
///
/// Shortcuts, both exact:
/// - A cruise at `vmax` that [`cruise_is_optimal`] proves fastest ends the search (and the
///   mirror for `vmin`).
/// - The family that moves the other way is skipped when a velocity bound shows it cannot
///   cover the distance faster than the best so far: every DUD profile stays below
///   `V = max(v0, vf, v0 + a0^2/2 if a0 > 0, vf + af^2/2 if af < 0)` (its velocity maxima
///   sit where its acceleration falls through zero, in the first or last arc), so it
///   covers at most `max(V, 0) t_max` in less than `t_max`; UDU mirrored.
pub(crate) fn fastest(u: &Unit, t_max: f64, cruises: &mut Cruises) -> Option<Cand> {
    let mut s = Fastest { t_max, best: None };
    if !u.safe() {
        for k in 0..2 {
            if let Some(c) = cruises.cruise(u, k) {
                s.offer(c);
            }
        }
        family(u, 1.0, &mut s);
        family(&u.mirror(), -1.0, &mut s);
        crate::udud::family(u, 1.0, &mut s);
        crate::udud::family(&u.mirror(), -1.0, &mut s);
        return s.best;
    }
    // The cruise towards the target first (often proven fastest), the one away from it
    // last (rarely a candidate).
    let (toward, away) = if u.dp >= 0.0 { (0, 1) } else { (1, 0) };
    if let Some(c) = cruises.cruise(u, toward) {
        if cruise_is_optimal(u, if toward == 0 { u.vmax } else { u.vmin }) {
            return (c.duration() < t_max).then_some(c);
        }
        s.offer(c);
    }
    let (a0, af) = (u.a0, u.af);
    let v_hi =
        u.v0.max(u.vf)
            .max(u.v0 + 0.5 * a0.max(0.0).powi(2))
            .max(u.vf + 0.5 * af.min(0.0).powi(2));
    let v_lo =
        u.v0.min(u.vf)
            .min(u.v0 - 0.5 * a0.min(0.0).powi(2))
            .min(u.vf - 0.5 * af.max(0.0).powi(2));
    let udu = |s: &mut Fastest| {
        // (0 times an infinite bound is NaN: no bound, search.)
        let beyond = u.dp <= v_lo.min(0.0) * s.t_max;
        if !beyond {
            family(u, 1.0, s);
        }
    };
    let dud = |s: &mut Fastest| {
        let beyond = u.dp >= v_hi.max(0.0) * s.t_max;
        if !beyond {
            family(&u.mirror(), -1.0, s);
        }
    };
    if u.dp >= 0.0 {
        udu(&mut s);
        dud(&mut s);
    } else {
        dud(&mut s);
        udu(&mut s);
    }
    // The cruise away from the target changes the velocity to the far limit and back,
    // which takes at least |dv| / a_limit each way: skip it if that alone is too slow.
    let (amax, amin) = (u.amax, -u.amin);
    let slow = if away == 1 {
        (u.v0 - u.vmin) * amax + (u.vf - u.vmin) * amin >= s.t_max * amax * amin
    } else {
        (u.vmax - u.v0) * amin + (u.vmax - u.vf) * amax >= s.t_max * amax * amin
    };
    if !slow && let Some(c) = cruises.cruise(u, away) {
        s.offer(c);
    }
    s.best
}

/// Is the cruise at `vlim` (which exists) the fastest profile from the safe state of `u`?
/// Yes if it moves towards the target (`dp > 0` for `vmax`), the target's acceleration
/// does not oppose leaving the cruise (`af <= 0`), and the start is *backward safe*
/// (`v0 - a0|a0|/2 <= vmax`: no past within the limits leads to it from above `vmax`).
/// Mirrored for `vmin`.
///
/// Proof. Every profile from a safe start to a target holdable within the limits stays
/// *forward safe* (`v + a|a|/2 <= vmax`; once above, the velocity must overshoot), so its
/// velocity never exceeds `u(t)`: the time-optimal rise to `(vmax, 0)`, then `vmax` (where
/// `u` is on the boundary `v + a^2/2 = vmax` it cannot be passed without leaving it). By
/// time reversal, with the start backward safe, it never exceeds `w(T - t)`, where `w(tau)`
/// is the velocity `tau` before the end of the time-optimal descent from `(vmax, 0)` to
/// the target (then `vmax`); with `af <= 0` that descent only slows, so `w` is
/// nondecreasing. A profile of duration `T` thus covers at most
/// `F(T) = int_0^T min(u(t), w(T - t)) dt`, and `F(T_c) = dp` for the cruise profile's
/// duration `T_c` (its velocity *is* that minimum). `F` grows with `T` at the rate of the
/// minimum's peak, which rises with `T`: where that peak is positive `F` increases, where
/// it is not `F <= 0 < dp`. Hence `F(T) < dp` for every `T < T_c`: nothing is faster.
/// The property test against the oracle checks this on random problems.
fn cruise_is_optimal(u: &Unit, vlim: f64) -> bool {
    let s = vlim.signum();
    let (dp, af, v0, a0) = (s * u.dp, s * u.af, s * u.v0, s * u.a0);
    dp > 0.0 && af <= 0.0 && v0 - 0.5 * a0 * a0.abs() <= s * vlim
}

/// Calls `f` with the duration (normalised) of every locally fastest profile of `u`.
pub(crate) fn each_duration(u: &Unit, f: impl FnMut(f64)) {
    let mut s = Every(f);
    let mut cruises = Cruises::default();
    for k in 0..2 {
        if let Some(c) = cruises.cruise(u, k) {
            (s.0)(c.duration());
        }
    }
    family(u, 1.0, &mut s);
    family(&u.mirror(), -1.0, &mut s);
    if !u.safe() {
        crate::udud::family(u, 1.0, &mut s);
        crate::udud::family(&u.mirror(), -1.0, &mut s);
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
