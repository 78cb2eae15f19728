//! Shaping a profile: the weighted sum of shifted copies, again as a [`Profile`].

use super::{END_ACCEL_ROUND_OFF, Shaper};
use crate::{PlanError, Profile, Sample, Segment, State};

impl Shaper {
    /// Shape a profile: `q(t) = sum_i w_i p(t - T_i)`. Outside its span the profile is
    /// extended by its start state before `t = 0` and its end state after its end, moving on
    /// at constant velocity (so a move that starts and ends at rest is shaped into one that
    /// does too, `duration_s()` longer). The start and end accelerations must be zero (a
    /// move, not a fragment). The weights sum to 1; where they are all positive the shaped
    /// velocity, acceleration and jerk stay within the original's bounds (a negative one,
    /// as RepRapFirmware's `ei2`/`ei3` have at high damping, can take them beyond).
    ///
    /// "Zero" is zero to round-off: within [`END_ACCEL_ROUND_OFF`] of the profile's peak
    /// acceleration (a PVT step's knots sum its segments' jerks to about 1e-16 m/s^2, not
    /// to 0); such a remainder is taken as 0, as the extension outside the span has it.
    pub fn apply(&self, profile: &Profile) -> Result<Profile, PlanError> {
        let (start, end) = (profile.start(), profile.end());
        let peak = profile
            .iter()
            .map(|(_, s, _)| s.a.abs())
            .fold(start.a.abs().max(end.a.abs()), f64::max);
        let round_off = END_ACCEL_ROUND_OFF * peak;
        if start.a.abs() > round_off || end.a.abs() > round_off {
            return Err(PlanError::InvalidInput {
                reason: "input shaping needs a profile that starts and ends with zero acceleration",
            });
        }
        let weights: Vec<f64> = self.weights().collect();
        let t_end = profile.duration_s();
        let eval = |t: f64| -> Sample {
            if t < 0.0 {
                return Sample {
                    p: start.p + start.v * t,
                    v: start.v,
                    a: 0.0,
                    j: 0.0,
                };
            }
            if t >= t_end {
                return Sample {
                    p: end.p + end.v * (t - t_end),
                    v: end.v,
                    a: 0.0,
                    j: 0.0,
                };
            }
            profile.state_at(t)
        };
        let shaped = |t: f64| -> Sample {
            let mut s = Sample::default();
            for (w, ti) in weights.iter().zip(&self.times_s) {
                let x = eval(t - ti);
                s.p += w * x.p;
                s.v += w * x.v;
                s.a += w * x.a;
                s.j += w * x.j;
            }
            s
        };
        // Every breakpoint of every shifted copy.
        let mut knots: Vec<f64> = Vec::new();
        for ti in &self.times_s {
            knots.push(ti + 0.0);
            for (t0, _, seg) in profile.iter() {
                knots.push(t0 + ti);
                knots.push(t0 + seg.duration_s() + ti);
            }
        }
        knots.sort_by(f64::total_cmp);
        knots.dedup();
        let s0 = shaped(0.0);
        let (segments, _) = segments_between(&knots, 0.0, shaped);
        Profile::new(
            State {
                p: s0.p,
                v: s0.v,
                a: 0.0,
            },
            segments,
        )
    }
}

/// The profile segments of a piecewise-polynomial motion `shaped` (right-continuous)
/// between consecutive `knots` (sorted), where it has constant jerk: each interval's jerk
/// and start acceleration are read at its middle; an acceleration that differs from the
/// previous interval's end (`a_now` before the first) by more than rounding starts with
/// an acceleration step. Returns the segments and the acceleration at the end.
pub(super) fn segments_between(
    knots: &[f64],
    mut a_now: f64,
    mut shaped: impl FnMut(f64) -> Sample,
) -> (Vec<Segment>, f64) {
    let mut segments = Vec::with_capacity(knots.len());
    for pair in knots.windows(2) {
        let (ta, tb) = (pair[0], pair[1]);
        let dur = tb - ta;
        if dur <= 0.0 {
            continue;
        }
        // Right limits on the interval: evaluate just inside it.
        let mid = shaped(ta + 0.5 * dur);
        let a_start = mid.a - mid.j * 0.5 * dur;
        let jumps = (a_start - a_now).abs() > 1e-12 * (1.0 + a_start.abs() + a_now.abs());
        if mid.j == 0.0 {
            segments.push(Segment::Accel {
                duration_s: dur,
                accel: a_start,
            });
        } else {
            if jumps {
                segments.push(Segment::Accel {
                    duration_s: 0.0,
                    accel: a_start,
                });
            }
            segments.push(Segment::Jerk {
                duration_s: dur,
                jerk: mid.j,
            });
        }
        a_now = a_start + mid.j * dur;
    }
    (segments, a_now)
}
