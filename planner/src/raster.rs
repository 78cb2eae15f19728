//! Raster scan kinematics: the fly axis X scans lines at `v_scan` across the
//! scan region `[0, width]`, alternating direction; between lines it turns around outside
//! the region while the step axis Y moves one step-over. The output is a 2-axis
//! [`Trajectory`] (X, Y) and, per turnaround, when and where the fly axis re-enters the
//! region: the moment the step must be settled.
//!
//! **Fly axis.** Run-in from rest to `v_scan` (a two-segment PVT with a triangular
//! acceleration), lines at constant velocity, symmetric 2-segment PVT turnarounds
//! ([`crate::pvt::turnaround`]), a mirrored run-out. A turnaround of `2 t_out` with apex
//! acceleration `4 v/(2 t_out)` overtravels `v (2 t_out)/3`; the fastest uses the fly
//! axis's acceleration limit (and its jerk limit, `a^2/(2 v) <= jmax`).
//!
//! **Overhead per line** (per half-turn `t_out + t_edge/2 + t_add`): the time between
//! leaving and re-entering the region, `2 t_out + t_edge`. The step move (any
//! point-to-point [`ProfileKind`]) must fit in that window, with the settling margin
//! after it. The window is the shorter possible: `max(2 t_out_min, T_step + margin)`. When
//! the step is the longer, the fly axis could stop and wait at the apex (for `t_edge`,
//! with acceleration jumps at both ends of the wait); here the turnaround is stretched to
//! the window instead (lower apex acceleration, continuous acceleration, the same
//! overhead), and `t_edge_s` reports the time the step adds. The other lever, slowing the
//! fly axis by `v_diff` before the edge, is not used: it trades scan speed inside the
//! region (`t_add = t_ln v_diff/(3 v_scan)`) for a shorter turnaround, and where the step
//! axis limits the overhead, the overhead grows with `v_diff`; see
//! [`slowdown_fly_overhead_s`] and its test in `planner/tests/all/raster.rs`.

use crate::kind::{ProfileKind, ProfileParams};
use crate::pvt::turnaround::TwoSegment;
use crate::pvt::{Knot, Pvt};
use crate::{Limits, PlanError, Profile, Segment, State, Trajectory};

/// Where the step sits in the window between exit and re-entry.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StepPlacement {
    /// The step starts when the fly axis leaves the region (most time to settle).
    AtExit,
    /// The step is centred in the window.
    Centered,
}

/// A raster scan.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RasterSpec {
    /// Number of lines (>= 1).
    pub lines: usize,
    /// Length of the scan region along X (u, > 0); line 0 runs from 0 to `width`.
    pub width: f64,
    /// Step-over along Y between lines (u, nonzero; its sign is the scan direction in Y).
    pub step: f64,
    /// Fly-axis scan speed (u/s, > 0).
    pub v_scan: f64,
    /// Fly-axis acceleration limit (u/s^2, > 0).
    pub fly_amax: f64,
    /// Fly-axis jerk limit (u/s^3), if any.
    pub fly_jmax: Option<f64>,
    /// The step move's kind.
    pub step_kind: ProfileKind,
    /// The step axis's limits.
    pub step_limits: Limits,
    /// Parameters of the step kind.
    pub step_params: ProfileParams,
    /// Where the step sits in the window.
    pub placement: StepPlacement,
    /// Time the step must be finished before re-entry (s, >= 0).
    pub settle_margin_s: f64,
}

/// The overhead of one turnaround.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Overhead {
    /// Fastest fly half-turn at the limits (s): `2 v/a_apex`.
    pub t_out_min_s: f64,
    /// Fly half-turn actually used (s): half the window.
    pub t_out_s: f64,
    /// Time the step adds to the fastest turnaround (s): `t_edge`.
    pub t_edge_s: f64,
    /// The step move's duration (s).
    pub step_s: f64,
    /// Window between leaving and re-entering the region (s): the overhead per line.
    pub per_line_s: f64,
    /// Scan time per line (s): `width / v_scan`.
    pub line_s: f64,
}

/// One turnaround: when the fly axis leaves and re-enters the region, and the step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Turnaround {
    /// The line the fly axis enters (1 ..= lines - 1).
    pub line: usize,
    /// Time the fly axis leaves the region (s).
    pub exit_s: f64,
    /// Time it re-enters (s): where "settled at re-entry" is measured.
    pub reentry_s: f64,
    /// The edge it re-enters at (u): 0 or `width`.
    pub x_edge: f64,
    /// Step start and end times (s).
    pub step_start_s: f64,
    /// Step end time (s).
    pub step_end_s: f64,
    /// Y before and after the step (u).
    pub y_from: f64,
    /// Y target.
    pub y_to: f64,
}

/// A planned raster.
#[derive(Debug, Clone, PartialEq)]
pub struct Raster {
    /// Axes X (fly) and Y (step), starting at rest at `t = 0`.
    pub trajectory: Trajectory,
    /// The fly axis as PVT knots (continuity and limits can be checked with
    /// [`crate::pvt::check()`]).
    pub fly: Pvt,
    /// One entry per turnaround.
    pub turnarounds: Vec<Turnaround>,
    /// The turnaround actually used.
    pub turn: TwoSegment,
    /// Overhead per line.
    pub overhead: Overhead,
}

fn positive(name: &'static str, value: f64) -> Result<f64, PlanError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(PlanError::InvalidLimit { name, value })
    }
}

/// The fastest apex acceleration of the fly turnaround (u/s^2): the acceleration limit,
/// or less where the jerk `a^2/(2 v)` would exceed the jerk limit.
fn apex_max(s: &RasterSpec) -> f64 {
    match s.fly_jmax {
        Some(j) => s.fly_amax.min((2.0 * s.v_scan * j).sqrt()),
        None => s.fly_amax,
    }
}

/// Plan the raster.
pub fn plan(spec: &RasterSpec) -> Result<Raster, PlanError> {
    if spec.lines == 0 {
        return Err(PlanError::InvalidInput {
            reason: "a raster needs at least one line",
        });
    }
    let w = positive("width", spec.width)?;
    let v = positive("v_scan", spec.v_scan)?;
    positive("fly_amax", spec.fly_amax)?;
    if let Some(j) = spec.fly_jmax {
        positive("fly_jmax", j)?;
    }
    if !(spec.step.is_finite() && spec.step != 0.0) {
        return Err(PlanError::InvalidLimit {
            name: "step",
            value: spec.step,
        });
    }
    if !(spec.settle_margin_s.is_finite() && spec.settle_margin_s >= 0.0) {
        return Err(PlanError::InvalidLimit {
            name: "settle_margin_s",
            value: spec.settle_margin_s,
        });
    }
    let step_prof =
        spec.step_kind
            .rest_to_rest_with(0.0, spec.step, &spec.step_limits, &spec.step_params)?;
    let t_step = step_prof.duration_s();
    let a_fast = apex_max(spec);
    let t_out_min = 2.0 * v / a_fast;
    let window = (2.0 * t_out_min).max(t_step + spec.settle_margin_s);
    let turn = crate::pvt::turnaround::two_segment(v, 4.0 * v / window)?;
    // Run-in (and run-out): rest <-> v with a triangular acceleration peaking at the
    // same jerk as the fastest turnaround allows, a^2/v <= a_fast^2/(2 v).
    let a_run = a_fast / 2f64.sqrt();
    let t_run = 2.0 * v / a_run;
    let d_run = v * v / a_run;
    let line_s = w / v;
    let mut knots = Vec::with_capacity(4 * spec.lines + 4);
    knots.push(Knot::new(0.0, -d_run, 0.0));
    knots.push(Knot::new(t_run / 2.0, -d_run + d_run / 6.0, v / 2.0));
    let mut t = t_run;
    let mut turns = Vec::with_capacity(spec.lines - 1);
    for line in 0..spec.lines {
        let dir = if line % 2 == 0 { 1.0 } else { -1.0 };
        let (x0, x1) = if dir > 0.0 { (0.0, w) } else { (w, 0.0) };
        knots.push(Knot::new(t, x0, dir * v));
        t += line_s;
        knots.push(Knot::new(t, x1, dir * v));
        if line + 1 < spec.lines {
            let apex = turn.knots(t, x1, v, dir);
            knots.push(apex[1]);
            let exit_s = t;
            t = apex[2].t_s;
            let offset = match spec.placement {
                StepPlacement::AtExit => 0.0,
                StepPlacement::Centered => 0.5 * (window - t_step - spec.settle_margin_s),
            };
            turns.push(Turnaround {
                line: line + 1,
                exit_s,
                reentry_s: t,
                x_edge: x1,
                step_start_s: exit_s + offset,
                step_end_s: exit_s + offset + t_step,
                y_from: spec.step * line as f64,
                y_to: spec.step * (line + 1) as f64,
            });
        }
    }
    // Run-out: the mirror of the run-in beyond the last edge.
    let dir = if spec.lines % 2 == 1 { 1.0 } else { -1.0 };
    let x_end = if dir > 0.0 { w } else { 0.0 };
    knots.push(Knot::new(
        t + t_run / 2.0,
        x_end + dir * (d_run - d_run / 6.0),
        dir * v / 2.0,
    ));
    knots.push(Knot::new(t + t_run, x_end + dir * d_run, 0.0));
    let total = t + t_run;
    let fly = Pvt::new(knots, 0.0, 0.0)?;
    // The step axis: hold, step, hold, ... hold to the end.
    let mut segs: Vec<Segment> = Vec::with_capacity(turns.len() * 8 + 2);
    let mut now = 0.0;
    for tr in &turns {
        segs.push(Segment::Accel {
            duration_s: tr.step_start_s - now,
            accel: 0.0,
        });
        segs.extend_from_slice(step_prof.segments());
        now = tr.step_start_s + t_step;
    }
    segs.push(Segment::Accel {
        duration_s: (total - now).max(0.0),
        accel: 0.0,
    });
    let y = Profile::new(State::default(), segs)?;
    Ok(Raster {
        trajectory: Trajectory::new(vec![fly.profile.clone(), y])?,
        fly,
        turnarounds: turns,
        turn,
        overhead: Overhead {
            t_out_min_s: t_out_min,
            t_out_s: turn.t_out_s,
            t_edge_s: window - 2.0 * t_out_min,
            step_s: t_step,
            per_line_s: window,
            line_s,
        },
    })
}

/// The fly-axis overhead per half-turn with a slow-down before the edge (and
/// `t_edge = 0`): over `t_ln` before the edge the fly axis slows from `v_scan` by `v_diff`
/// (its acceleration linear from 0), then stops with apex acceleration `a_max`. Returns
/// `(t_out, t_add, t_out + t_add)` (s):
/// `t_out = 2 t_ln (v_scan - v_diff)/(2 v_diff + a_max t_ln)`,
/// `t_add = t_ln v_diff/(3 v_scan)` (the scan time lost inside the region).
pub fn slowdown_fly_overhead_s(v_scan: f64, a_max: f64, t_ln: f64, v_diff: f64) -> (f64, f64, f64) {
    let t_out = 2.0 * t_ln * (v_scan - v_diff) / (2.0 * v_diff + a_max * t_ln);
    let t_add = t_ln * v_diff / (3.0 * v_scan);
    (t_out, t_add, t_out + t_add)
}
