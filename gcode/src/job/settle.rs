//! settle's own planner on a G-code stream: [`WindowedPath`] for the toolhead, plus what
//! a path planner does not plan.
//!
//! - Extruder-only moves (retracts, unretracts) stop the toolhead and take the time of a
//!   rest-to-rest move of the filament at the move's feed rate (capped by `vmax`) and
//!   `amax`: a trapezoid, `d/v + v/a`, or a triangle, `2 sqrt(d/a)`.
//! - The extruder axis of the chunks stays at 0: settle's planner plans the toolhead, and
//!   the simulated machine has no extruder.
//! - Limit and shaper commands in the file are for the firmware it was sliced for; settle's
//!   planner runs with the job's settings and counts them as ignored.

use settle_planner::path::window::{PathChunk, WindowedPath};
use settle_planner::{PlanError, Profile, Segment, State, Trajectory};

use super::config::SettleConfig;

/// settle's planner (module doc).
#[derive(Debug)]
pub(crate) struct SettlePlanner {
    path: WindowedPath,
    vmax: f64,
    amax: f64,
}

impl SettlePlanner {
    /// The planner of `cfg`, at rest at the origin.
    pub(crate) fn new(cfg: &SettleConfig) -> Result<Self, PlanError> {
        Ok(Self {
            path: WindowedPath::new(cfg.path_options()?, cfg.window_points, [0.0; 3])?,
            vmax: cfg.limits.vmax(),
            amax: cfg.limits.amax(),
        })
    }

    /// A straight toolhead move to `to_m` at no more than `speed_m_s`, as move `seq`.
    pub(crate) fn push(
        &mut self,
        to_m: [f64; 3],
        speed_m_s: f64,
        seq: u64,
    ) -> Result<(), PlanError> {
        self.path.push(to_m, speed_m_s, seq)
    }

    /// An extruder-only move of `de_m` at `speed_m_s`: the toolhead stops; returns when
    /// the filament move starts and ends (s).
    pub(crate) fn extrude(&mut self, de_m: f64, speed_m_s: f64) -> Result<(f64, f64), PlanError> {
        self.path.stop(0.0)?;
        let d = de_m.abs();
        let v = speed_m_s.min(self.vmax);
        let t = if d >= v * v / self.amax {
            d / v + v / self.amax
        } else {
            2.0 * (d / self.amax).sqrt()
        };
        let t0 = self.path.print_time_s();
        self.path.stop(t)?;
        Ok((t0, t0 + t))
    }

    /// Stop, then stand still for `dwell_s`.
    pub(crate) fn dwell(&mut self, dwell_s: f64) -> Result<(), PlanError> {
        self.path.stop(dwell_s)
    }

    /// The clock at the end of the committed motion (s).
    pub(crate) fn print_time_s(&self) -> f64 {
        self.path.print_time_s()
    }

    /// The next committed chunk, with an extruder axis at 0 (X, Y, Z, E).
    pub(crate) fn pop(&mut self) -> Option<Result<PathChunk, PlanError>> {
        let mut c = self.path.pop()?;
        let d = c.trajectory.duration_s();
        let e = Profile::new(
            State::default(),
            vec![Segment::Accel {
                duration_s: d,
                accel: 0.0,
            }],
        );
        Some(e.and_then(|e| {
            let mut axes = c.trajectory.axes().to_vec();
            axes.push(e);
            c.trajectory = Trajectory::new(axes)?;
            Ok(c)
        }))
    }
}
