//! Cutting a trajectory at an instant (where a shaper change takes effect).

use settle_planner::{PlanError, Profile, Segment, State, Trajectory};

/// The part of `p` from `t0` to `t1` (s, profile time), starting at `t0`.
fn slice(p: &Profile, t0: f64, t1: f64) -> Result<Profile, PlanError> {
    let s = p.state_at(t0);
    let mut segs = Vec::new();
    for (ts, _, seg) in p.iter() {
        let te = ts + seg.duration_s();
        let (a, b) = (ts.max(t0), te.min(t1));
        // Keep what overlaps, and zero-length segments (acceleration steps) inside.
        if b < a || (b == a && !(ts >= t0 && ts < t1)) {
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

/// A part of a cut trajectory with its start time (`None`: empty).
pub(crate) type Part = Option<(f64, Trajectory)>;

/// Cut `tr`, which starts at `start_s`, at `at_s`: the parts before and after.
pub(crate) fn split(start_s: f64, tr: &Trajectory, at_s: f64) -> Result<(Part, Part), PlanError> {
    let d = tr.duration_s();
    let cut = at_s - start_s;
    if cut <= 0.0 {
        return Ok((None, Some((start_s, tr.clone()))));
    }
    if cut >= d {
        return Ok((Some((start_s, tr.clone())), None));
    }
    let part = |a: f64, b: f64| -> Result<Trajectory, PlanError> {
        Trajectory::new(
            tr.axes()
                .iter()
                .map(|p| slice(p, a, b))
                .collect::<Result<Vec<_>, _>>()?,
        )
    };
    Ok((
        Some((start_s, part(0.0, cut)?)),
        Some((start_s + cut, part(cut, d)?)),
    ))
}
