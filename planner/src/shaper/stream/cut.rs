//! Cutting a profile between two instants: how a stream's chunks are made from a longer
//! motion, and where a shaper change splits one.

use crate::{PlanError, Profile, Segment, State};

/// The part of `profile` from `from_s` to `to_s` (s, profile time) as a profile starting
/// at `from_s` in the exact state there: the segments that overlap, shortened to the
/// interval, and the zero-length acceleration steps inside it.
pub fn cut(profile: &Profile, from_s: f64, to_s: f64) -> Result<Profile, PlanError> {
    let s = profile.state_at(from_s);
    let mut segs = Vec::new();
    for (ts, _, seg) in profile.iter() {
        let te = ts + seg.duration_s();
        let (a, b) = (ts.max(from_s), te.min(to_s));
        if b < a || (b == a && !(ts >= from_s && ts < to_s)) {
            continue;
        }
        let duration_s = b - a;
        segs.push(match *seg {
            Segment::Jerk { jerk, .. } => Segment::Jerk { duration_s, jerk },
            Segment::Accel { accel, .. } => Segment::Accel { duration_s, accel },
        });
    }
    Profile::new(
        State {
            p: s.p,
            v: s.v,
            a: s.a,
        },
        segs,
    )
}
