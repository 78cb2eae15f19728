//! Corner paths: a scenario's `[corner]` table describes two straight segments meeting at
//! a corner, how the corner is passed (the strategy) and which machine axes carry the
//! path ([`geometry`]); the sweep can vary every one of its fields
//! (`corner.angle_deg = { from = 0, to = 180, step = 15 }`, `corner.strategy = [...]`).
//!
//! The path is planned by `settle_planner::path` (look-ahead over the two segments with the
//! run's profile kind as the speed law) on a machine with 2 or 3 axes: path coordinate `i`
//! is machine axis `i`, so the trajectory, the toolhead and the path geometry share one
//! coordinate system and the runner measures contour error directly
//! ([`crate::measure::path_metrics`]). runs.csv gets the corner's parameters and the path
//! metrics; the summary a table of corner speed, rounding and contour error.

pub mod geometry;

use std::fmt::Write as _;

use settle_planner::path::{PathOptions, plan_path};
use settle_planner::{PlanError, Trajectory};

use crate::error::Error;
use crate::input::runs_columns::RunsColumns;
use crate::input::source::Source;
use crate::studies::{Motion, Study, StudyState, PathMove, PlanContext, Planned, PlotColumn, Role, any_has};
use crate::measure::metrics::Metrics;
use crate::measure::path_metrics::columns as col;
use crate::spec::run_spec::RunSpec;
use crate::spec::runs::RunList;

pub use geometry::{Corner, CornerSpec, Strategy};

/// Parameters of `[corner]` that can be swept.
pub const SWEEPABLE: &str = "corner.angle_deg, corner.leg_in_mm, corner.leg_out_mm, \
corner.strategy, corner.junction_deviation_mm, corner.square_corner_velocity_mm_s, \
corner.blend_deviation_mm";

/// Parameter columns of a corner sweep (before the path metrics).
pub const PARAM_COLUMNS: [&str; 7] = [
    "corner_angle_deg",
    "corner_leg_in_mm",
    "corner_leg_out_mm",
    "corner_strategy",
    "junction_deviation_mm",
    "square_corner_velocity_mm_s",
    "blend_deviation_mm",
];

/// The corner-path study.
#[derive(Debug, Clone, Copy)]
pub struct CornerPath;

/// Plan the run's corner path: one profile per machine axis (in machine order, `names`),
/// with the path geometry attached.
pub fn trajectory(
    spec: &RunSpec,
    corner: &Corner,
    names: &[String],
) -> Result<Trajectory, PlanError> {
    let path = corner.path(names)?;
    let opts = PathOptions::new(spec.limits_si()?, spec.profile, corner.strategy_si())?;
    plan_path(&path, &opts)
}

impl Study for CornerPath {
    fn name(&self) -> &'static str {
        "corner path"
    }

    fn table(&self) -> Option<&'static str> {
        Some("corner")
    }

    fn role(&self) -> Role {
        Role::Path
    }

    fn sweepable(&self) -> &'static str {
        SWEEPABLE
    }

    fn parse(&self, src: &Source) -> Result<Option<Box<dyn StudyState>>, Error> {
        let Some(spec) = src.table::<CornerSpec>("corner")? else {
            return Ok(None);
        };
        Ok(Some(Box::new(Corner::from_spec(&spec, src)?)))
    }

    fn path_move(&self, state: &dyn StudyState) -> Option<PathMove> {
        let c = (state as &dyn std::any::Any).downcast_ref::<Corner>()?;
        Some(PathMove {
            profile: c.profile.clone(),
            profile_key: "corner.profile",
            axis: format!("{}+{}", c.axes[0], c.axes[1]),
        })
    }

    fn path_length_mm(&self, run: &RunSpec) -> Option<f64> {
        run.state::<Corner>().map(|c| c.leg_in_mm + c.leg_out_mm)
    }

    fn validate(&self, run: &RunSpec) -> Result<(), (String, String)> {
        match run.state::<Corner>() {
            Some(c) => c.validate(run),
            None => Ok(()),
        }
    }

    fn plan(&self, run: &RunSpec, ctx: &PlanContext) -> Result<Planned, PlanError> {
        let corner = run.state::<Corner>().ok_or(PlanError::InvalidInput {
            reason: "a corner run without its corner",
        })?;
        let traj = trajectory(run, corner, ctx.axes)?;
        let trajectory = match &ctx.shaper {
            // Klipper shapes each axis independently; the path stays the reference of the
            // contour error: the shaper's smoothing of the corner counts against the run.
            Some(s) => {
                let shaped = Trajectory::new(
                    traj.axes()
                        .iter()
                        .map(|p| s.apply(p))
                        .collect::<Result<Vec<_>, _>>()?,
                )?;
                match traj.path() {
                    Some(g) => shaped.with_path(g.clone()),
                    None => shaped,
                }
            }
            None => traj,
        };
        Ok(Planned {
            motion: Motion::Whole(trajectory),
            probe: None,
            linearise_at_m: None,
            step_at_m: None,
        })
    }

    fn columns(&self, runs: &dyn RunList) -> Vec<String> {
        if !any_has::<Corner>(runs) {
            return Vec::new();
        }
        PARAM_COLUMNS
            .iter()
            .chain(col::ALL.iter())
            .map(|c| c.to_string())
            .collect()
    }

    fn cells(&self, run: &RunSpec, m: &Metrics) -> Vec<String> {
        let Some(c) = run.state::<Corner>() else {
            return Vec::new();
        };
        let mut out = vec![
            c.angle_deg.to_string(),
            c.leg_in_mm.to_string(),
            c.leg_out_mm.to_string(),
            c.strategy.name().to_string(),
            c.junction_deviation_mm.to_string(),
            c.square_corner_velocity_mm_s.to_string(),
            c.blend_deviation_mm.to_string(),
        ];
        if let Some(p) = m.path.as_ref().filter(|_| m.is_ok()) {
            out.extend(p.values().iter().map(f64::to_string));
        }
        out
    }

    fn summary(
        &self,
        runs: &dyn RunList,
        table: &RunsColumns,
        _current: &dyn Fn(&RunSpec) -> bool,
    ) -> Option<String> {
        if !any_has::<Corner>(runs) || table.column(col::MAX_CONTOUR).is_none() {
            return None;
        }
        Some(summary_section(runs, table))
    }

    /// A strategy's parameter under another strategy; the jerk limit of a trapezoid path
    /// that does not blend (only the blend is jerk-limited then).
    fn unused(&self, run: &RunSpec, key: &str) -> Option<&'static str> {
        let c = run.state::<Corner>()?;
        let (used, why) = match key {
            "corner.junction_deviation_mm" => (
                c.strategy == Strategy::JunctionDeviation,
                "only the junction_deviation strategy uses it",
            ),
            "corner.square_corner_velocity_mm_s" => (
                c.strategy == Strategy::SquareCornerVelocity,
                "only the square_corner_velocity strategy uses it",
            ),
            "corner.blend_deviation_mm" => (
                c.strategy == Strategy::Blend,
                "only the blend strategy uses it",
            ),
            "limits.jmax_mm_s3" => (
                run.profile != settle_planner::ProfileKind::Trapezoid
                    || c.strategy == Strategy::Blend,
                "a trapezoid path has no jerk limit unless it blends its corners",
            ),
            _ => return None,
        };
        (!used).then_some(why)
    }

    fn figures(&self, _bands_um: &[f64]) -> Vec<PlotColumn> {
        [
            (col::MAX_CONTOUR, "contour error during the move: max"),
            (col::CONTOUR_AFTER, "contour error after the move: max"),
        ]
        .into_iter()
        .map(|(column, title)| PlotColumn::new(column, title, "contour error", "um", 1.0, true))
        .collect()
    }
}

/// The summary's corner section: per run (angle, strategy, kind, shaper), the planned corner speed,
/// the commanded corner rounding and the toolhead's contour error.
fn summary_section(runs: &dyn RunList, table: &RunsColumns) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "## Corners: speed, rounding and contour error\n\n\
Corner speed: planned speed at the corner. Commanded rounding: distance of the commanded \
path from the sharp corner. Contour error: distance of the toolhead from the commanded path, \
largest during the move and after it. Toolhead rounding: the toolhead's closest approach to \
the corner point.\n"
    );
    let _ = writeln!(
        out,
        "| run | angle (deg) | strategy | kind | shaper | corner speed (mm/s) | commanded rounding (um) | contour error during (um) | contour error after (um) | toolhead rounding (um) |"
    );
    let _ = writeln!(out, "|---:|---:|---|---|---|---:|---:|---:|---:|---:|");
    // The shaper of a run: its type and frequency, `none` without a [shaper] table.
    let shaper = |row: usize| match (
        table.cell(row, "shaper_type").as_deref(),
        table.cell(row, "shaper_frequency_hz").as_deref(),
    ) {
        (Some("none"), _) | (None, _) => "none".to_string(),
        (Some(t), Some(f)) => format!("{t} {f} Hz"),
        (Some(t), None) => t.to_string(),
    };
    let f = |row: usize, c: &str, prec: usize| {
        table
            .num(row, c)
            .map_or_else(|| "-".to_string(), |x| format!("{x:.prec$}"))
    };
    for (i, r) in runs.iter().enumerate() {
        let Some(c) = r.state::<Corner>() else {
            continue;
        };
        if table.cell(i, "status").is_some_and(|s| s != "ok") {
            let _ = writeln!(
                out,
                "| {} | {} | {} | {} | {} | lost steps | - | - | - | - |",
                r.id,
                c.angle_deg,
                c.strategy.name(),
                r.profile,
                shaper(i)
            );
            continue;
        }
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            r.id,
            c.angle_deg,
            c.strategy.name(),
            r.profile,
            shaper(i),
            f(i, col::CORNER_SPEED, 2),
            f(i, col::CORNER_ROUNDING, 3),
            f(i, col::MAX_CONTOUR, 2),
            f(i, col::CONTOUR_AFTER, 2),
            f(i, col::TOOLHEAD_ROUNDING, 2),
        );
    }
    out.push('\n');
    out
}
