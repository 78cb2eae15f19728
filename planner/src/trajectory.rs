//! `Trajectory`: several axes in time, one [`Profile`] each, all starting at `t = 0`.
//!
//! A multi-axis move (a synchronised point-to-point move, a path through corners, a raster
//! scan line with its step-over) is a trajectory. Each axis is evaluated by its own profile;
//! an axis that finishes early holds its end state until the longest one ends.
//!
//! A trajectory planned along a path also carries the path's geometry
//! ([`Trajectory::path`]), so contour error and corner rounding can be measured.

use std::sync::Arc;

use crate::path::PathGeometry;
use crate::runs::RunSort;
use crate::{PlanError, Profile, Sample};

/// Several axes in time (axis 0 = X, 1 = Y, 2 = Z by convention).
#[derive(Debug, Clone, PartialEq)]
pub struct Trajectory {
    axes: Vec<Profile>,
    duration_s: f64,
    path: Option<Arc<PathGeometry>>,
}

impl Trajectory {
    /// A trajectory from one profile per axis (at least one).
    pub fn new(axes: Vec<Profile>) -> Result<Self, PlanError> {
        if axes.is_empty() {
            return Err(PlanError::InvalidInput {
                reason: "a trajectory needs at least one axis",
            });
        }
        let duration_s = axes.iter().map(Profile::duration_s).fold(0.0, f64::max);
        Ok(Self {
            axes,
            duration_s,
            path: None,
        })
    }

    /// A single-axis trajectory.
    pub fn single(profile: Profile) -> Self {
        let duration_s = profile.duration_s();
        Self {
            axes: vec![profile],
            duration_s,
            path: None,
        }
    }

    /// Attach the geometry of the path this trajectory follows.
    pub fn with_path(mut self, path: PathGeometry) -> Self {
        self.path = Some(Arc::new(path));
        self
    }

    /// The geometry of the path this trajectory follows, if it was planned along one.
    pub fn path(&self) -> Option<&PathGeometry> {
        self.path.as_deref()
    }

    /// The per-axis profiles.
    pub fn axes(&self) -> &[Profile] {
        &self.axes
    }

    /// Number of axes.
    pub fn dof(&self) -> usize {
        self.axes.len()
    }

    /// Duration: the longest axis (s).
    pub fn duration_s(&self) -> f64 {
        self.duration_s
    }

    /// Every axis at time `t` (s), written into `out` (one sample per axis; `out` must be
    /// at least [`Self::dof`] long). Allocation free.
    pub fn state_at(&self, t: f64, out: &mut [Sample]) {
        for (o, p) in out.iter_mut().zip(&self.axes) {
            *o = p.state_at(t);
        }
    }

    /// Every segment boundary of every axis, sorted and deduplicated (s): the instants
    /// where some axis changes its jerk, so a simulation can split its steps there.
    pub fn breakpoints(&self) -> Vec<f64> {
        // Each axis's segment ends are in order (each is the next segment's start): sorted
        // by merging them, with a run of each axis's 0.
        let n = self.axes.iter().map(|p| p.segments().len()).sum::<usize>() + self.axes.len();
        let mut ts = Vec::with_capacity(n);
        let mut runs = RunSort::default();
        for p in &self.axes {
            runs.mark(ts.len());
            ts.extend(p.iter().map(|(t0, _, seg)| t0 + seg.duration_s()));
        }
        runs.mark(ts.len());
        ts.extend(self.axes.iter().map(|_| 0.0));
        runs.sort(&mut ts);
        ts.dedup();
        ts
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Segment, State};

    #[test]
    fn axes_hold_their_end_until_the_longest_finishes() {
        let a = Profile::new(
            State::default(),
            vec![Segment::Jerk {
                duration_s: 1.0,
                jerk: 6.0,
            }],
        )
        .expect("profile");
        let b = Profile::new(
            State::default(),
            vec![Segment::Accel {
                duration_s: 2.0,
                accel: 1.0,
            }],
        )
        .expect("profile");
        let tr = Trajectory::new(vec![a, b]).expect("trajectory");
        assert_eq!(tr.duration_s(), 2.0);
        let mut out = [Sample::default(); 2];
        tr.state_at(1.5, &mut out);
        // Axis 0 ended at t = 1 with p = j t^3/6 = 1, v = 3, a = 6 and holds that state.
        assert_eq!(
            (out[0].p, out[0].v, out[0].a, out[0].j),
            (1.0, 3.0, 6.0, 0.0)
        );
        // Axis 1: p = t^2/2.
        assert_eq!(out[1].p, 1.125);
        assert_eq!(tr.breakpoints(), vec![0.0, 1.0, 2.0]);
        assert!(Trajectory::new(Vec::new()).is_err());
    }
}
