//! A cursor into a trajectory's command: [`Trajectory::state_at`] for times that mostly
//! increase (the harness's sample clock), without its per-call binary search.

use settle_planner::{Profile, Sample, Trajectory};

/// Where each axis's command is: the index of the segment the last query fell in.
#[derive(Debug, Clone)]
pub struct Cursor<'a> {
    axes: &'a [Profile],
    seg: Vec<usize>,
    /// The command of an axis without segments: the same at every time.
    fixed: Vec<Option<Sample>>,
}

impl<'a> Cursor<'a> {
    /// A cursor at the start of `traj`.
    pub fn new(traj: &'a Trajectory) -> Self {
        Self {
            axes: traj.axes(),
            seg: vec![0; traj.dof()],
            fixed: traj
                .axes()
                .iter()
                .map(|p| p.segments().is_empty().then(|| p.state_at(0.0)))
                .collect(),
        }
    }

    /// Every axis at time `t` (s), written into `out`: bit for bit what
    /// [`Trajectory::state_at`] writes (the same segment, found by walking forward from
    /// the last one instead of searching, and the same evaluation). Any `t` is allowed; a
    /// `t` before the last one restarts the walk from the first segment.
    pub fn at(&mut self, t: f64, out: &mut [Sample]) {
        let axes = out.iter_mut().zip(self.axes).zip(&mut self.seg);
        for (((o, p), i), fixed) in axes.zip(&self.fixed) {
            // Each case writes its own sample (not one value merged from the three): the
            // walk's sample is then written from registers, not through the return slot
            // of `state_at`, which a whole copy would read back in wider pieces than it
            // was written (a stall per axis per sample). Inside the profile
            // `state_at_from` walks (its own test for the ends is the same and so never
            // holds).
            let outside = p.segments().is_empty() || t < 0.0 || t >= p.duration_s();
            match fixed {
                Some(s) => *o = *s,
                None if outside => *o = p.state_at(t),
                None => *o = p.state_at_from(i, t),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use settle_planner::{Limits, ProfileKind, Segment, State};

    fn bits(s: &[Sample]) -> Vec<[u64; 4]> {
        s.iter()
            .map(|s| [s.p.to_bits(), s.v.to_bits(), s.a.to_bits(), s.j.to_bits()])
            .collect()
    }

    #[test]
    fn the_cursor_equals_state_at_bit_for_bit() {
        let lim = Limits::new(0.3, 3.0, Some(100.0)).expect("limits");
        let y = ProfileKind::SCurve
            .rest_to_rest(0.0, 0.01, &lim)
            .expect("plan");
        // Zero-length segments and an acceleration jump (several segments start at once).
        let x = Profile::new(
            State {
                p: 0.002,
                v: 0.0,
                a: 0.0,
            },
            vec![
                Segment::Accel {
                    duration_s: 0.0,
                    accel: 2.0,
                },
                Segment::Jerk {
                    duration_s: 0.0,
                    jerk: 5.0,
                },
                Segment::Accel {
                    duration_s: 0.05,
                    accel: 2.0,
                },
                Segment::Jerk {
                    duration_s: 0.03,
                    jerk: -40.0,
                },
            ],
        )
        .expect("profile");
        let traj =
            Trajectory::new(vec![x, Profile::empty(State::default()), y]).expect("trajectory");
        let mut cursor = Cursor::new(&traj);
        let (mut a, mut b) = ([Sample::default(); 3], [Sample::default(); 3]);
        // Sample instants, every breakpoint, and times before 0 and past the end.
        let mut ts: Vec<f64> = (0..2000).map(|k| k as f64 * 1e-4).collect();
        ts.extend(traj.breakpoints());
        ts.extend([-1.0, 0.0, traj.duration_s(), 1.0]);
        ts.sort_by(f64::total_cmp);
        for &t in &ts {
            traj.state_at(t, &mut a);
            cursor.at(t, &mut b);
            assert_eq!(bits(&a), bits(&b), "t = {t}");
        }
        // Going back restarts the walk.
        for &t in ts.iter().rev().step_by(7) {
            traj.state_at(t, &mut a);
            cursor.at(t, &mut b);
            assert_eq!(bits(&a), bits(&b), "t = {t} (backwards)");
        }
    }
}
