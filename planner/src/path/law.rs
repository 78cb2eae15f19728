//! How a path segment changes its speed between corners: attack (accelerate), sustain
//! (cruise) and release (decelerate), with the speed-change law pluggable.
//!
//! A [`SpeedLaw`] answers one question: the fastest change of the path speed from `v0` to
//! `v1`, starting and ending with zero path acceleration, as profile segments of the path
//! coordinate. Everything else is derived from it: the distance a change needs (the
//! *minimum segment length*: a segment entered at `v0 > 0` needs at least the distance of
//! the change to its exit speed), the highest speed reachable within a length, and the
//! segment profile (attack to a peak speed, sustain, release; the peak is `vmax` when the
//! segment is long enough, else the highest peak whose attack and release fit).
//!
//! Laws here: [`TrapezoidLaw`] (acceleration steps), [`SCurveLaw`] (symmetric jerk) and
//! [`FourJerkLaw`] (the TMC4361A's four independent jerks: `j1` raises and `j2` lowers the
//! acceleration of an attack, `j3` raises and `j4` lowers the deceleration of a release).
//! Another planner (e.g. a Trinamic register-level ramp) plugs in by implementing the
//! trait.

use std::sync::Arc;

use crate::{Limits, PlanError, ProfileKind, Segment, State};

/// A speed change: its segments (of the path coordinate), duration and distance.
#[derive(Debug, Clone, PartialEq)]
pub struct SpeedChange {
    /// Segments, starting from acceleration zero; they end at acceleration zero.
    pub segments: Vec<Segment>,
    /// Duration (s).
    pub duration_s: f64,
    /// Distance travelled (m).
    pub distance_m: f64,
}

impl SpeedChange {
    /// A change from `v0` made of `segments` (duration and distance integrated exactly).
    pub fn from_segments(v0: f64, segments: Vec<Segment>) -> Self {
        let mut s = State {
            p: 0.0,
            v: v0,
            a: 0.0,
        };
        let mut t = 0.0;
        for seg in &segments {
            s = seg.end_state(&s);
            t += seg.duration_s();
        }
        Self {
            segments,
            duration_s: t,
            distance_m: s.p,
        }
    }
}

/// The per-segment speed-change law (the extension point for other ramp generators).
pub trait SpeedLaw: std::fmt::Debug + Send + Sync {
    /// Name for tables (`trapezoid`, `scurve`, `fourjerk`, ...).
    fn name(&self) -> &'static str;

    /// The fastest change of the path speed from `v0 >= 0` to `v1 >= 0` with zero
    /// acceleration at both ends. The distance must grow with `max(v0, v1)` for a fixed
    /// other end (true of every time-optimal law).
    fn change(&self, v0: f64, v1: f64) -> SpeedChange;

    /// The largest jerk magnitude the law uses (m/s^3; infinite for acceleration steps).
    fn max_jerk(&self) -> f64;

    /// The largest acceleration magnitude the law uses (m/s^2).
    fn max_accel(&self) -> f64;
}

/// Acceleration steps (velocity trapezoid) at `amax`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrapezoidLaw {
    /// Acceleration (m/s^2).
    pub amax: f64,
}

impl SpeedLaw for TrapezoidLaw {
    fn name(&self) -> &'static str {
        "trapezoid"
    }

    fn change(&self, v0: f64, v1: f64) -> SpeedChange {
        let dv = v1 - v0;
        if dv == 0.0 {
            return SpeedChange::from_segments(v0, Vec::new());
        }
        let a = self.amax.copysign(dv);
        SpeedChange::from_segments(
            v0,
            vec![
                Segment::Accel {
                    duration_s: dv / a,
                    accel: a,
                },
                Segment::Accel {
                    duration_s: 0.0,
                    accel: 0.0,
                },
            ],
        )
    }

    fn max_jerk(&self) -> f64 {
        f64::INFINITY
    }

    fn max_accel(&self) -> f64 {
        self.amax
    }
}

/// Jerk `+-j` up to a peak acceleration (held at `amax` if reached) and back to zero,
/// with separate jerks for raising (`j_rise`) and lowering (`j_fall`) the acceleration
/// magnitude. Velocity gained: `A^2/(2 j_rise) + A^2/(2 j_fall) [+ amax hold]`.
fn two_jerk(v0: f64, v1: f64, amax: f64, j_rise: f64, j_fall: f64) -> SpeedChange {
    let dv = v1 - v0;
    if dv == 0.0 {
        return SpeedChange::from_segments(v0, Vec::new());
    }
    let sign = dv.signum();
    let m = dv.abs();
    let k = 0.5 * (1.0 / j_rise + 1.0 / j_fall);
    let peak = (m / k).sqrt();
    let (a, hold) = if peak <= amax {
        (peak, 0.0)
    } else {
        (amax, (m - amax * amax * k) / amax)
    };
    let mut segs = vec![Segment::Jerk {
        duration_s: a / j_rise,
        jerk: sign * j_rise,
    }];
    if hold > 0.0 {
        segs.push(Segment::Jerk {
            duration_s: hold,
            jerk: 0.0,
        });
    }
    segs.push(Segment::Jerk {
        duration_s: a / j_fall,
        jerk: -sign * j_fall,
    });
    SpeedChange::from_segments(v0, segs)
}

/// Symmetric jerk-limited S-curve changes (`jmax`, `amax`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SCurveLaw {
    /// Acceleration limit (m/s^2).
    pub amax: f64,
    /// Jerk (m/s^3).
    pub jmax: f64,
}

impl SpeedLaw for SCurveLaw {
    fn name(&self) -> &'static str {
        "scurve"
    }

    fn change(&self, v0: f64, v1: f64) -> SpeedChange {
        two_jerk(v0, v1, self.amax, self.jmax, self.jmax)
    }

    fn max_jerk(&self) -> f64 {
        self.jmax
    }

    fn max_accel(&self) -> f64 {
        self.amax
    }
}

/// The TMC4361A's four-jerk ramp as a speed law: an attack raises the acceleration with `j1`
/// to at most `amax` and lowers it with `j2`; a release raises the deceleration with `j3`
/// to at most `dmax` and lowers it with `j4` (Trinamic's BOW1..BOW4, AMAX, DMAX).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FourJerkLaw {
    /// Acceleration limit of attacks (m/s^2).
    pub amax: f64,
    /// Deceleration limit of releases (m/s^2, > 0).
    pub dmax: f64,
    /// Jerks (m/s^3, > 0): attack rise, attack fall, release rise, release fall.
    pub jerks: [f64; 4],
}

impl SpeedLaw for FourJerkLaw {
    fn name(&self) -> &'static str {
        "fourjerk"
    }

    fn change(&self, v0: f64, v1: f64) -> SpeedChange {
        let [j1, j2, j3, j4] = self.jerks;
        if v1 >= v0 {
            two_jerk(v0, v1, self.amax, j1, j2)
        } else {
            two_jerk(v0, v1, self.dmax, j3, j4)
        }
    }

    fn max_jerk(&self) -> f64 {
        self.jerks.iter().copied().fold(0.0, f64::max)
    }

    fn max_accel(&self) -> f64 {
        self.amax.max(self.dmax)
    }
}

/// The law for a profile kind at the path limits (`SCurve` and `FourJerk` need `jmax`;
/// `FourJerk` here uses its default parameters, all four jerks `jmax` and `dmax = amax`:
/// build a [`FourJerkLaw`] directly for others). The PVT step kinds are point-to-point
/// moves of fixed shape, not speed-change laws: they are refused.
pub fn for_kind(kind: ProfileKind, limits: &Limits) -> Result<Arc<dyn SpeedLaw>, PlanError> {
    let jmax = || {
        limits
            .jmax()
            .ok_or(PlanError::MissingJerkLimit { kind: kind.name() })
    };
    Ok(match kind {
        ProfileKind::FourJerk => Arc::new(FourJerkLaw {
            amax: limits.amax(),
            dmax: limits.amax(),
            jerks: [jmax()?; 4],
        }),
        ProfileKind::PvtSym | ProfileKind::PvtAsym => {
            return Err(PlanError::InvalidInput {
                reason: "the PVT step kinds (pvt_sym, pvt_asym) are point-to-point moves, not path speed laws; use trapezoid, scurve or fourjerk on paths",
            });
        }
        ProfileKind::Trapezoid => Arc::new(TrapezoidLaw {
            amax: limits.amax(),
        }),
        ProfileKind::SCurve => Arc::new(SCurveLaw {
            amax: limits.amax(),
            jmax: limits
                .jmax()
                .ok_or(PlanError::MissingJerkLimit { kind: "scurve" })?,
        }),
    })
}

/// Bisection for the largest `x` in `[lo, hi]` with `ok(x)`, given `ok(lo)` (monotone).
pub(crate) fn largest(lo: f64, hi: f64, ok: impl Fn(f64) -> bool) -> f64 {
    if ok(hi) {
        return hi;
    }
    let (mut lo, mut hi) = (lo, hi);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if ok(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// The minimum segment length: the distance the change `v0 -> v1` needs (m).
pub fn min_length(law: &dyn SpeedLaw, v0: f64, v1: f64) -> f64 {
    law.change(v0, v1).distance_m
}

/// The maximum segment length for a segment of `duration_s` entered at `v0` and
/// left at `v1` under `vmax`: attack to the highest peak whose attack and release fit the
/// time, sustain for the rest (m). `None` if even the direct change takes longer.
pub fn max_length(law: &dyn SpeedLaw, v0: f64, v1: f64, duration_s: f64, vmax: f64) -> Option<f64> {
    let lo = v0.max(v1);
    let time = |vp: f64| law.change(v0, vp).duration_s + law.change(vp, v1).duration_s;
    if time(lo) > duration_s {
        return None;
    }
    let vp = largest(lo, vmax.max(lo), |vp| time(vp) <= duration_s);
    let (c1, c2) = (law.change(v0, vp), law.change(vp, v1));
    let cruise = (duration_s - c1.duration_s - c2.duration_s).max(0.0);
    Some(c1.distance_m + c2.distance_m + vp * cruise)
}

/// The highest speed `<= cap` reachable from `v0` within `len_m` (accelerating), or from
/// which `v0` is reachable (`backward`: decelerating to `v0`).
pub fn reachable(law: &dyn SpeedLaw, v0: f64, len_m: f64, cap: f64, backward: bool) -> f64 {
    if cap <= v0 {
        return cap;
    }
    largest(v0, cap, |v| {
        let c = if backward {
            law.change(v, v0)
        } else {
            law.change(v0, v)
        };
        c.distance_m <= len_m
    })
}

/// The segment profile (path coordinate) from speed `v0` to `v1` over `len_m` under
/// `vmax`: attack to the peak, sustain, release. Requires
/// `len_m >= min_length(v0, v1)` (up to rounding; the look-ahead guarantees it).
pub fn segment(law: &dyn SpeedLaw, v0: f64, v1: f64, len_m: f64, vmax: f64) -> Vec<Segment> {
    let lo = v0.max(v1);
    let dist = |vp: f64| law.change(v0, vp).distance_m + law.change(vp, v1).distance_m;
    let vp = if len_m <= 0.0 {
        lo
    } else {
        largest(lo, vmax.max(lo), |vp| dist(vp) <= len_m)
    };
    let (c1, c2) = (law.change(v0, vp), law.change(vp, v1));
    let mut segs = c1.segments;
    if vp > 0.0 {
        let cruise = (len_m - c1.distance_m - c2.distance_m) / vp;
        if cruise > 0.0 {
            segs.push(Segment::Jerk {
                duration_s: cruise,
                jerk: 0.0,
            });
        }
    }
    segs.extend(c2.segments);
    segs
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::position::{Shape, to_state};

    fn scurve() -> SCurveLaw {
        SCurveLaw {
            amax: 2.0,
            jmax: 10.0,
        }
    }

    #[test]
    fn known_changes() {
        // 0 -> 1 at a 2, j 10: ramps 0.2 s, hold 0.3 s, T = 0.7; distance = mean speed * T.
        let c = scurve().change(0.0, 1.0);
        assert!((c.duration_s - 0.7).abs() < 1e-15 && (c.distance_m - 0.35).abs() < 1e-15);
        // Triangle: 0.5 -> 0.6 (dv 0.1 < a^2/j = 0.4): T = 2 sqrt(0.1/10) = 0.2, d = 0.11.
        let c = scurve().change(0.6, 0.5);
        assert!((c.duration_s - 0.2).abs() < 1e-15 && (c.distance_m - 0.11).abs() < 1e-15);
        let c = TrapezoidLaw { amax: 2.0 }.change(1.0, 0.0);
        assert!((c.duration_s - 0.5).abs() < 1e-15 && (c.distance_m - 0.25).abs() < 1e-15);
        // Four jerks: attack j1 = 10, j2 = 40, amax 2, 0 -> 0.1: peak^2 (1/20 + 1/80) = 0.1,
        // peak = 1.2649 < 2, T = peak (1/10 + 1/40).
        let fj = FourJerkLaw {
            amax: 2.0,
            dmax: 1.0,
            jerks: [10.0, 40.0, 5.0, 20.0],
        };
        let c = fj.change(0.0, 0.1);
        let peak = (0.1_f64 / 0.0625).sqrt();
        assert!((c.duration_s - peak * 0.125).abs() < 1e-15);
        let e = SpeedChange::from_segments(0.0, c.segments.clone());
        assert!((e.distance_m - c.distance_m).abs() < 1e-18);
    }

    #[test]
    fn segment_matches_the_any_state_planner() {
        // The attack/sustain/release segment is time-optimal between (0, v0, 0) and
        // (len, v1, 0): compare with the position-interface planner.
        let lim = Limits::new(1.0, 2.0, Some(10.0)).expect("limits");
        for &(v0, v1, len) in &[
            (0.0, 0.0, 1.7),
            (0.0, 0.0, 0.1),
            (0.3, 0.7, 0.5),
            (0.9, 0.2, 0.4),
            (0.5, 0.5, 0.05),
            (0.0, 1.0, 2.0),
        ] {
            assert!(len >= min_length(&scurve(), v0, v1));
            let segs = segment(&scurve(), v0, v1, len, 1.0);
            let ours = SpeedChange::from_segments(v0, segs);
            let start = State {
                p: 0.0,
                v: v0,
                a: 0.0,
            };
            let target = State {
                p: len,
                v: v1,
                a: 0.0,
            };
            let reference = to_state(start, target, &lim, Shape::JerkLimited).expect("plan");
            assert!(
                (ours.duration_s - reference.duration_s()).abs() < 1e-9,
                "{v0} {v1} {len}: {} vs {}",
                ours.duration_s,
                reference.duration_s()
            );
            assert!((ours.distance_m - len).abs() < 1e-12);
        }
    }

    #[test]
    fn reachable_and_lengths() {
        let law = scurve();
        // From rest within 0.35 m: exactly 1 m/s (the change 0 -> 1 needs 0.35 m).
        let v = reachable(&law, 0.0, 0.35, 5.0, false);
        assert!((v - 1.0).abs() < 1e-12, "{v}");
        assert_eq!(reachable(&law, 0.0, 0.35, 0.5, false), 0.5);
        // Backward: from which speed can one stop within 0.35 m: 1 m/s.
        assert!((reachable(&law, 0.0, 0.35, 5.0, true) - 1.0).abs() < 1e-12);
        assert_eq!(min_length(&law, 0.0, 1.0), 0.35);
        // Max length in 2.4 s from rest to rest under vmax 1: 1.7 m (the known S-curve).
        let l = max_length(&law, 0.0, 0.0, 2.4, 1.0).expect("feasible");
        assert!((l - 1.7).abs() < 1e-12, "{l}");
        assert!(max_length(&law, 0.0, 1.0, 0.5, 1.0).is_none());
    }
}
