//! The breakpoints of each axis's command inside the steps of a batch, with the jumps of
//! the command there: what a plant that steps across breakpoints
//! ([`settle_sim::Plant::step_samples_across`]) takes instead of steps split at them.
//!
//! An axis's breakpoints are the starts of its profile's segments after the first, and
//! its end when the trajectory goes on after it. At each the command's velocity,
//! acceleration and jerk jump from the continuation of the segment before (its own
//! polynomial, evaluated at its end) to the next segment's start (or, at the end, to the
//! end state held with zero jerk, as [`settle_planner::Profile::state_at`] reports it). A
//! breakpoint on a step's end is none of the step's: the next step's command starts from
//! it, as the cursor gives it (right-continuous).

use settle_planner::{Profile, Sample, Trajectory};
use settle_sim::InnerBreak;

/// Walks each axis's breakpoints along a trajectory (module doc).
#[derive(Debug)]
pub struct AxisBreaks<'a> {
    axes: &'a [Profile],
    /// The trajectory's duration (s): an axis's end at or after it is no breakpoint.
    t1: f64,
    /// Per axis, the next breakpoint to look at: segment `i` starts at breakpoint `i`
    /// (`1 <= i < len`), breakpoint `len` is the axis's end.
    next: Vec<usize>,
}

impl<'a> AxisBreaks<'a> {
    /// At the start of `traj`.
    pub fn new(traj: &'a Trajectory) -> Self {
        Self {
            axes: traj.axes(),
            t1: traj.duration_s(),
            next: vec![1; traj.dof()],
        }
    }

    /// The breakpoints inside steps `0..m`, step `i` from `t(i)` to `t(i + 1)` (the
    /// trajectory's own time, increasing), into `out` (one list per axis, cleared first).
    /// Breakpoints at or before `t(0)` are passed over.
    pub fn fill(&mut self, m: usize, t: impl Fn(usize) -> f64, out: &mut [Vec<InnerBreak>]) {
        let (lo, hi) = (t(0), t(m));
        for ((p, next), list) in self.axes.iter().zip(&mut self.next).zip(out.iter_mut()) {
            list.clear();
            let n = p.segments().len();
            let mut step = 0;
            while *next <= n {
                let b = if *next < n {
                    p.segment_start(*next).0
                } else {
                    p.duration_s()
                };
                if *next == n && b >= self.t1 {
                    // The axis ends with the trajectory: no breakpoint.
                    *next += 1;
                    continue;
                }
                if b <= lo {
                    *next += 1;
                    continue;
                }
                if b >= hi {
                    break;
                }
                while t(step + 1) <= b {
                    step += 1;
                }
                // `t(step) < b <= t(step + 1)`: inside the step unless on its end.
                if b < t(step + 1) {
                    let (before, after) = jump(p, *next);
                    list.push(InnerBreak {
                        step,
                        before_end_s: t(step + 1) - b,
                        dv: after.v - before.v,
                        da: after.a - before.a,
                        dj: after.j - before.j,
                    });
                }
                *next += 1;
            }
        }
    }
}

/// The command at breakpoint `i` of profile `p` (module doc): the continuation of the
/// segment before, and what follows.
fn jump(p: &Profile, i: usize) -> (Sample, Sample) {
    let segments = p.segments();
    let (_, s) = p.segment_start(i - 1);
    let prev = &segments[i - 1];
    let before = prev.sample(&s, prev.duration_s());
    let after = match segments.get(i) {
        Some(seg) => seg.sample(&p.segment_start(i).1, 0.0),
        None => p.state_at(p.duration_s()),
    };
    (before, after)
}

#[cfg(test)]
mod tests {
    use super::*;
    use settle_planner::{Segment, State};

    /// A profile with a jerk change, an acceleration step and two segments at one instant;
    /// steps of 1 ms. The jumps are the segments' own values, and breakpoints on a step's
    /// end are left to the next step.
    #[test]
    fn breakpoints_inside_steps_with_their_jumps() {
        let p = Profile::new(
            State::default(),
            vec![
                Segment::Jerk {
                    duration_s: 0.0025,
                    jerk: 100.0,
                },
                Segment::Accel {
                    duration_s: 0.002,
                    accel: -1.0,
                },
                Segment::Jerk {
                    duration_s: 0.0,
                    jerk: 7.0,
                },
                Segment::Jerk {
                    duration_s: 0.0013,
                    jerk: -50.0,
                },
            ],
        )
        .expect("profile");
        let longer = Profile::new(
            State::default(),
            vec![Segment::Jerk {
                duration_s: 0.01,
                jerk: 1.0,
            }],
        )
        .expect("profile");
        let traj = Trajectory::new(vec![p, longer]).expect("trajectory");
        let mut walk = AxisBreaks::new(&traj);
        let mut out = vec![Vec::new(); 2];
        walk.fill(8, |i| i as f64 * 1e-3, &mut out);
        let got: Vec<(usize, f64, f64, f64)> = out[0]
            .iter()
            .map(|b| (b.step, b.before_end_s, b.da, b.dj))
            .collect();
        let a1 = 100.0 * 0.0025;
        // 2.5 ms: the acceleration steps from 0.25 to -1 and the jerk from 100 to 0;
        // 4.5 ms (two segments at once: to jerk 7, then to -50, the acceleration staying
        // -1); 5.8 ms: the end, the jerk back to 0.
        let want = [
            (2, 0.0005, -1.0 - a1, -100.0),
            (4, 0.0005, 0.0, 7.0),
            (4, 0.0005, 0.0, -57.0),
            (5, 0.0002, 0.0, 50.0),
        ];
        assert_eq!(got.len(), want.len(), "{got:?}");
        for (g, w) in got.iter().zip(&want) {
            assert_eq!(g.0, w.0, "{got:?}");
            assert!((g.1 - w.1).abs() < 1e-15, "{got:?}");
            assert!(
                (g.2 - w.2).abs() < 1e-12 && (g.3 - w.3).abs() < 1e-12,
                "{got:?}"
            );
        }
        // The longer axis has no breakpoint inside: its end is the trajectory's.
        assert!(out[1].is_empty());
        // A second batch goes on from where the first stopped.
        walk.fill(2, |i| (8 + i) as f64 * 1e-3, &mut out);
        assert!(out[0].is_empty() && out[1].is_empty());
    }
}
