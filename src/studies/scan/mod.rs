//! Raster scan steps: a scenario with a `[scan]` table
//! runs its move as the step-over of a raster scan instead of a lone point-to-point move.
//!
//! **What the scenario's keys mean in a scan.** `[move]` is the step: `axis` is the step
//! axis, `distance_mm` the step-over, `profile` the step's kind (any kind; sweep `profile`
//! and `move.distance_mm` like in any scenario); `[limits]` are the step axis's limits.
//! `[scan]` adds the fly axis: scan speed, acceleration (and jerk) limit, region width,
//! number of lines. The planner ([`settle_planner::raster`]) puts the step inside each
//! turnaround, in the window between the fly axis leaving the scan region and re-entering
//! it, which is the longer of the fastest fly turnaround and the step (plus a margin).
//!
//! **Fly axis.** When the machine has the axis named `fly_axis`, it is simulated on that
//! axis; otherwise the fly axis is ideal (kinematic only). The machines' axes are not
//! coupled in the plant models, so the step axis's response, and every scan metric below,
//! depends on the fly axis only through the timing (exit and re-entry).
//!
//! **Metrics** (extra columns of `runs.csv`, worst case over the turnarounds; the error is
//! the step axis's toolhead position minus the step's target):
//! - `scan_step_s`: the step's duration; `scan_window_s`: the time between leaving and
//!   re-entering the region (overhead per line).
//! - `scan_reentry_error_um`: |error| at the moment the fly axis re-enters the region.
//! - `scan_line_residual_peak_um`: peak |error| while the fly axis scans the next line
//!   (from re-entry to its next exit).
//! - `scan_settled_<band>um`: 1 when the error stays within the band over that whole line
//!   (settled at re-entry and stays settled), else 0.
//! - `scan_step_settle_time_s_<band>um`: time after the step's end until the error enters
//!   the band and stays in it until the next exit; `inf` when it is outside at that exit.
//!   Settled at re-entry means this is at most `scan_window_s - scan_step_s` (placement
//!   `exit`).
//!
//! The usual columns (move time, settle time, residual, ...) keep their meaning for the
//! whole raster: they measure the stop after the run-out.

pub mod step_metrics;
mod summary;
pub mod table;

use settle_planner::raster::{self, Raster, RasterSpec};
use settle_planner::shaper::Shaper;
use settle_planner::{PlanError, Profile, State, Trajectory};

use crate::error::Error;
use crate::input::runs_columns::RunsColumns;
use crate::input::source::Source;
use crate::studies::{
    Motion, PlanContext, Planned, PlotColumn, Role, Study, StudyState, jerk_unused,
};
use crate::measure::metrics::Metrics;
use crate::spec::run_spec::RunSpec;
use crate::spec::runs::RunList;
use crate::spec::{MAX_POSITION_MM, beyond_positions};

pub use step_metrics::{StepProbe, step_metrics};
pub use table::ScanSpec;

/// Keys of `[scan]` that can be swept.
pub const SWEEPABLE: &str = "scan.v_scan_mm_s, scan.fly_amax_mm_s2, scan.fly_jmax_mm_s3, \
scan.width_mm, scan.settle_margin_s";

/// Plan the raster of a scan run: X fly, Y step, from the step axis's start position 0.
///
/// With a `shaper` (the run's modifiers', e.g. `[shaper]`), the step axis's motion is
/// input-shaped: the shaped step lasts the
/// shaper's duration longer, so the raster is planned with that much more settle margin
/// (the window is then `max(fastest turnaround, shaped step + settle_margin_s)`, and a
/// centred step is the shaped one centred), and each turnaround's `step_end_s` and
/// `overhead.step_s` are those of the shaped step.
pub fn plan_raster(
    spec: &RunSpec,
    scan: &ScanSpec,
    shaper: Option<&Shaper>,
) -> Result<Raster, PlanError> {
    let placement = scan.placement().map_err(|_| PlanError::InvalidInput {
        reason: "unknown scan placement",
    })?;
    let t_shaper_s = shaper.as_ref().map_or(0.0, |s| s.duration_s());
    let mut r = raster::plan(&RasterSpec {
        lines: scan.lines,
        width: scan.width_mm * 1e-3,
        step: spec.distance_mm * 1e-3,
        v_scan: scan.v_scan_mm_s * 1e-3,
        fly_amax: scan.fly_amax_mm_s2 * 1e-3,
        fly_jmax: scan.fly_jmax_mm_s3.map(|j| j * 1e-3),
        step_kind: spec.profile,
        step_limits: spec.limits_si()?,
        step_params: spec.profile_params,
        placement,
        settle_margin_s: scan.settle_margin_s + t_shaper_s,
    })?;
    if let Some(s) = shaper {
        let axes = r.trajectory.axes();
        let step_axis = s.apply(&axes[1])?;
        r.trajectory = Trajectory::new(vec![axes[0].clone(), step_axis])?;
        for tr in &mut r.turnarounds {
            tr.step_end_s += t_shaper_s;
        }
        r.overhead.step_s += t_shaper_s;
    }
    Ok(r)
}

fn shifted(p: &Profile, dp: f64) -> Result<Profile, PlanError> {
    let s = p.start();
    Profile::new(State { p: s.p + dp, ..s }, p.segments().to_vec())
}

/// The raster of a scan run, with the run's own shaper (what the runner plans).
pub fn raster(spec: &RunSpec) -> Result<Raster, PlanError> {
    let scan = spec.state::<ScanSpec>().ok_or(PlanError::InvalidInput {
        reason: "a scan run without its scan",
    })?;
    plan_raster(spec, scan, crate::studies::shaper(spec)?.as_ref())
}

/// The raster-scan-step kind.
#[derive(Debug, Clone, Copy)]
pub struct ScanStep;

/// The names of the scan columns of a sweep with bands `bands_um`, in order.
pub fn column_names(bands_um: &[f64]) -> Vec<String> {
    let mut out: Vec<String> = [
        "scan_step_s",
        "scan_window_s",
        "scan_reentry_error_um",
        "scan_line_residual_peak_um",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    out.extend(bands_um.iter().map(|b| format!("scan_settled_{b}um")));
    out.extend(
        bands_um
            .iter()
            .map(|b| format!("scan_step_settle_time_s_{b}um")),
    );
    out
}

impl Study for ScanStep {
    fn name(&self) -> &'static str {
        "raster scan step"
    }

    fn table(&self) -> Option<&'static str> {
        Some("scan")
    }

    fn role(&self) -> Role {
        Role::Move
    }

    /// The step axis and, when the machine has it, the fly axis (simulated: its modes
    /// ring after every turnaround and are reported per axis).
    fn moved_axes(&self, run: &RunSpec) -> Vec<String> {
        let mut axes: Vec<String> = run.axis.split('+').map(str::to_string).collect();
        if let Some(scan) = run.state::<ScanSpec>()
            && run.axis_names().contains(&scan.fly_axis)
            && !axes.contains(&scan.fly_axis)
        {
            axes.push(scan.fly_axis.clone());
        }
        axes
    }

    fn sweepable(&self) -> &'static str {
        SWEEPABLE
    }

    fn parse(&self, src: &Source) -> Result<Option<Box<dyn StudyState>>, Error> {
        Ok(src
            .table::<ScanSpec>("scan")?
            .map(|s| Box::new(s) as Box<dyn StudyState>))
    }

    fn validate(&self, run: &RunSpec) -> Result<(), (String, String)> {
        let Some(scan) = run.state::<ScanSpec>() else {
            return Ok(());
        };
        scan.validate()
            .map_err(|(key, message)| (run.blame(&format!("scan.{key}")), message))?;
        // The raster within the positions f64 resolves: the fly axis from 0 to the
        // width, the step axis from the start over every line's step.
        let last_mm = run.start_mm + (scan.lines - 1) as f64 * run.distance_mm;
        if scan.width_mm > MAX_POSITION_MM {
            return Err((
                run.blame("scan.width_mm"),
                beyond_positions("the fly axis's far end is", scan.width_mm),
            ));
        }
        if last_mm.abs() > MAX_POSITION_MM {
            return Err((
                run.blame("scan.lines"),
                beyond_positions(
                    &format!("the last of {} lines of the step axis is", scan.lines),
                    last_mm,
                ),
            ));
        }
        // The fly axis: an axis of the machine (simulated), or a gantry axis it does not
        // have (an ideal one); never the stepping axis.
        let axes = run.axis_names();
        let fly = scan.fly_axis.as_str();
        if run.axis.split('+').any(|a| a == fly) {
            return Err((
                run.blame("scan.fly_axis"),
                format!("`{fly}` is the axis that steps (move.axis); the fly axis is the other one"),
            ));
        }
        if !axes.iter().any(|a| a == fly) && !["x", "y", "z"].contains(&fly) {
            return Err((
                run.blame("scan.fly_axis"),
                format!(
                    "`{fly}` is not an axis of the machine ({}) nor a gantry axis x, y or z",
                    axes.join(", ")
                ),
            ));
        }
        Ok(())
    }

    fn plan(&self, run: &RunSpec, ctx: &PlanContext) -> Result<Planned, PlanError> {
        let scan = run.state::<ScanSpec>().ok_or(PlanError::InvalidInput {
            reason: "a scan run without its scan",
        })?;
        let r = plan_raster(run, scan, ctx.shaper.as_ref())?;
        let y0_m = run.start_mm * 1e-3;
        let profiles = ctx
            .axes
            .iter()
            .map(|a| {
                if *a == run.axis {
                    shifted(&r.trajectory.axes()[1], y0_m)
                } else if *a == scan.fly_axis {
                    Ok(r.trajectory.axes()[0].clone())
                } else {
                    Ok(Profile::empty(State::default()))
                }
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Planned {
            motion: Motion::Whole(Trajectory::new(profiles)?),
            probe: Some(Box::new(StepProbe { raster: r, y0_m })),
            linearise_at_m: None,
            step_at_m: None,
        })
    }

    /// The columns, named from the first scan run's bands, so the header never depends on
    /// results; [`step_metrics()`] fills them.
    fn columns(&self, runs: &dyn RunList) -> Vec<String> {
        runs.iter()
            .find(|r| r.state::<ScanSpec>().is_some())
            .map(|r| column_names(&r.bands_um))
            .unwrap_or_default()
    }

    fn cells(&self, run: &RunSpec, m: &Metrics) -> Vec<String> {
        if !m.is_ok() || run.state::<ScanSpec>().is_none() {
            return Vec::new();
        }
        column_names(&run.bands_um)
            .iter()
            .map(|c| {
                m.extra
                    .iter()
                    .find(|(n, _)| n == c)
                    .map_or(String::new(), |(_, x)| x.to_string())
            })
            .collect()
    }

    fn summary(
        &self,
        runs: &dyn RunList,
        table: &RunsColumns,
        current: &dyn Fn(&RunSpec) -> bool,
    ) -> Option<String> {
        table
            .column("scan_reentry_error_um")
            .map(|_| summary::section(runs, table, current))
    }

    fn figures(&self, bands_um: &[f64]) -> Vec<PlotColumn> {
        let mut out = vec![
            PlotColumn::new(
                "scan_reentry_error_um",
                "step axis: |error| when the fly axis re-enters",
                "|error|",
                "um",
                1.0,
                true,
            ),
            PlotColumn::new(
                "scan_line_residual_peak_um",
                "step axis: peak |error| during the next line",
                "|error|",
                "um",
                1.0,
                true,
            ),
        ];
        for b in bands_um {
            out.push(PlotColumn::new(
                format!("scan_step_settle_time_s_{b}um"),
                format!("step axis: settle time to within {b} um after the step"),
                "settle time",
                "ms",
                1e3,
                false,
            ));
        }
        out.push(PlotColumn::new(
            "scan_window_s",
            "window from exit to re-entry (overhead per line)",
            "window",
            "ms",
            1e3,
            false,
        ));
        out
    }

    /// The move-and-settle tables would measure the raster's run-out, not the step.
    fn replaces_move_tables(&self) -> bool {
        true
    }

    fn unused(&self, run: &RunSpec, key: &str) -> Option<&'static str> {
        jerk_unused(run, key)
    }
}
