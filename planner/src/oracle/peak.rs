//! Oracle (test only): a bracketing implementation of step 1, independent of the
//! closed-form cases, to check them. Peak-velocity family: an acceleration phase to a peak
//! velocity `vp` (ending with `a = 0`), a cruise at `vp`, and a phase to the target; the
//! no-cruise roots of `D(vp) = dp` are found by bracketing every sign change between the
//! structural breakpoints and bisecting to full precision, plus the three-arc family
//! (`three_arc`) and the cruises at `vmax` and `vmin`; the fastest is kept.

use super::roots::roots;
use crate::brake::BrakeLaw;
use crate::position::{Shape, assemble, bounds, check_target, finite_state, pre, verify};
use crate::velocity::{Bounds, Change, change};
use crate::{Limits, PlanError, Profile, Segment, State};

/// Position interface: the fastest profile from `start` to `target`.
///
/// A start that must violate the limits is braked first. Braking just long enough
/// (`brake::minimal`) is not always fastest overall; braking on along the same control law
/// until the velocity itself is back inside the limits (where Ruckig stops braking) can
/// be faster. Both ends and points between them are tried and the fastest total is kept.
pub fn to_state(
    start: State,
    target: State,
    lim: &Limits,
    shape: Shape,
) -> Result<Profile, PlanError> {
    finite_state("start", &start)?;
    finite_state("target", &target)?;
    let b = bounds(lim, shape)?;
    check_target(&target, lim, &b)?;
    if b.jmax.is_infinite() {
        let (pre_segs, s) = pre(start, lim, &b);
        let (_, segs) = from_safe(&s, &target, lim, &b).ok_or(PlanError::NoSolution {
            reason: "no peak velocity reaches the target",
        })?;
        return verify(
            assemble(start, &[pre_segs.as_slice(), &segs])?,
            &target,
            lim,
            true,
        );
    }
    let law = BrakeLaw::new(start, lim, b.jmax);
    let mut best: Option<(f64, crate::segs::Segs<4>, Vec<Segment>)> = None;
    for tau in law.candidate_times() {
        let (pre_segs, mut s) = law.until(tau);
        // The brake ends on the acceleration limit up to rounding: snap it there.
        s.a = s.a.clamp(lim.amin(), lim.amax());
        if let Some((t, segs)) = from_safe(&s, &target, lim, &b) {
            let total = tau + t;
            if best.as_ref().is_none_or(|(bt, _, _)| total < *bt) {
                best = Some((total, pre_segs, segs));
            }
        }
    }
    let (_, pre_segs, segs) = best.ok_or(PlanError::NoSolution {
        reason: "no peak velocity reaches the target",
    })?;
    verify(
        assemble(start, &[pre_segs.as_slice(), &segs])?,
        &target,
        lim,
        true,
    )
}

/// The peak-velocity family from a safe state `s` to `target`: for a peak velocity `vp`,
/// the two phases, their distance and their duration.
pub(crate) struct PeakFamily<'a> {
    s: State,
    target: State,
    lim: &'a Limits,
    b: Bounds,
}

impl<'a> PeakFamily<'a> {
    pub(crate) fn new(s: State, target: State, lim: &'a Limits, b: Bounds) -> Self {
        Self { s, target, lim, b }
    }

    /// The two phases for peak velocity `vp`, their distance and duration.
    pub(crate) fn phases(&self, vp: f64) -> Option<(Change, Change, f64, f64)> {
        let c1 = change(self.s.v, self.s.a, vp, 0.0, &self.b)?;
        let c2 = change(vp, 0.0, self.target.v, self.target.a, &self.b)?;
        let d = c1.end(self.s.v, self.s.a).p + c2.end(vp, 0.0).p;
        Some((c1, c2, d, c1.duration_s() + c2.duration_s()))
    }

    /// Distance still to cover after the two phases.
    pub(crate) fn dp(&self) -> f64 {
        self.target.p - self.s.p
    }

    /// The profile for peak `vp` with `cruise` seconds at `vp`.
    pub(crate) fn segments(&self, vp: f64, cruise: f64) -> Option<Vec<Segment>> {
        let (c1, c2, _, _) = self.phases(vp)?;
        let mut segs = c1.segments.to_vec();
        // The cruise holds the acceleration at exactly zero: the phase before ends there
        // only up to rounding, and a cruise can be long enough for that to matter.
        segs.push(Segment::Accel {
            duration_s: cruise,
            accel: 0.0,
        });
        segs.extend(c2.segments);
        Some(segs)
    }

    /// Structural breakpoints in `vp` (see [`breakpoints`]).
    pub(crate) fn knots(&self) -> Vec<f64> {
        breakpoints(&self.s, &self.target, self.lim, &self.b)
    }
}

/// Every locally fastest profile from a state inside the limits, as `(duration, segments)`:
/// the cruise at `vmax` and at `vmin`, each no-cruise peak velocity, and the three-arc
/// family's solutions. The fastest of them is the time-optimal profile; the others start
/// the ranges of longer durations that step 2 (time synchronisation) can stretch to.
pub(crate) fn candidates(
    s: &State,
    target: &State,
    lim: &Limits,
    b: &Bounds,
) -> Vec<(f64, Vec<Segment>)> {
    let fam = PeakFamily::new(*s, *target, lim, *b);
    let dp = fam.dp();
    let mut out = Vec::new();
    for vlim in [lim.vmax(), lim.vmin()] {
        if let Some((_, _, d, t)) = fam.phases(vlim) {
            let cruise = (dp - d) / vlim;
            if cruise >= 0.0 && (t + cruise).is_finite() {
                out.extend(fam.segments(vlim, cruise).map(|segs| (t + cruise, segs)));
            }
        }
    }
    for vp in roots(
        &|vp| fam.phases(vp).map(|(_, _, d, _)| d - dp),
        &fam.knots(),
    ) {
        if let Some((_, _, _, t)) = fam.phases(vp) {
            out.extend(fam.segments(vp, 0.0).map(|segs| (t, segs)));
        }
    }
    if b.jmax.is_finite() {
        out.extend(super::three_arc::candidates(s, target, lim, b));
    }
    out
}

/// The fastest profile from a state inside the limits. Returns its duration and segments.
fn from_safe(s: &State, target: &State, lim: &Limits, b: &Bounds) -> Option<(f64, Vec<Segment>)> {
    candidates(s, target, lim, b)
        .into_iter()
        .min_by(|x, y| x.0.total_cmp(&y.0))
}

/// Peak velocities where either phase changes structure, plus the velocity limits.
fn breakpoints(s: &State, t: &State, lim: &Limits, b: &Bounds) -> Vec<f64> {
    let mut v = vec![lim.vmin(), lim.vmax(), 0.0, s.v, t.v];
    if b.jmax.is_finite() {
        let j = b.jmax;
        let (amax2, amin2) = (b.amax * b.amax, b.amin * b.amin);
        v.extend([
            s.v + s.a * s.a.abs() / (2.0 * j),
            s.v + (amax2 - s.a * s.a / 2.0) / j,
            s.v + (s.a * s.a / 2.0 - amin2) / j,
            t.v - t.a * t.a.abs() / (2.0 * j),
            t.v - (amax2 - t.a * t.a / 2.0) / j,
            t.v - (t.a * t.a / 2.0 - amin2) / j,
        ]);
    }
    v.retain(|x| x.is_finite() && *x >= lim.vmin() && *x <= lim.vmax());
    v.sort_by(f64::total_cmp);
    v.dedup();
    v
}
