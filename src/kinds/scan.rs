//! Raster scan steps in the harness (issue 6, seed 003): a scenario with a `[scan]` table
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

use serde::Deserialize;
use settle_planner::raster::{self, Raster, RasterSpec, StepPlacement};
use settle_planner::{Profile, State, Trajectory};

use crate::error::Error;
use crate::execute::run::{Observe, SimOptions};
use crate::expand::RunSpec;
use crate::measure::metrics::Metrics;
use crate::measure::series::Series;

/// The `[scan]` table of a scenario (mm, s).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScanSpec {
    /// Fly-axis scan speed inside the region (mm/s).
    pub v_scan_mm_s: f64,
    /// Fly-axis acceleration limit (mm/s^2): sets the fastest turnaround, `4 v / a`.
    pub fly_amax_mm_s2: f64,
    /// Fly-axis jerk limit (mm/s^3), if any.
    pub fly_jmax_mm_s3: Option<f64>,
    /// Width of the scan region along the fly axis (mm). Default 20 mm: a line of 200 ms
    /// at 100 mm/s, long enough to see the step settle (or not) during the next line.
    #[serde(default = "default_width")]
    pub width_mm: f64,
    /// Number of lines (>= 2: one step per turnaround). Default 2: one step.
    #[serde(default = "default_lines")]
    pub lines: usize,
    /// Where the step sits in the window: `exit` (starts when the fly axis leaves the
    /// region: most time to settle, the default) or `centered`.
    #[serde(default = "default_placement")]
    pub placement: String,
    /// Time the step must end before re-entry (s), which lengthens the window when the
    /// step sets it. Default 0: the planner's fastest window.
    #[serde(default)]
    pub settle_margin_s: f64,
    /// The machine axis that flies, simulated when the machine has it (default `y`).
    #[serde(default = "default_fly_axis")]
    pub fly_axis: String,
}

fn default_width() -> f64 {
    20.0
}
fn default_lines() -> usize {
    2
}
fn default_placement() -> String {
    "exit".into()
}
fn default_fly_axis() -> String {
    "y".into()
}

/// Keys of `[scan]` that can be swept (`"scan.<key>"`).
pub const SWEEPABLE: &str = "scan.v_scan_mm_s, scan.fly_amax_mm_s2, scan.fly_jmax_mm_s3, \
scan.width_mm, scan.settle_margin_s";

impl ScanSpec {
    /// Set a swept numeric key (`field` without the `scan.` prefix).
    pub fn set(&mut self, field: &str, x: f64) -> Result<(), String> {
        match field {
            "v_scan_mm_s" => self.v_scan_mm_s = x,
            "fly_amax_mm_s2" => self.fly_amax_mm_s2 = x,
            "fly_jmax_mm_s3" => self.fly_jmax_mm_s3 = Some(x),
            "width_mm" => self.width_mm = x,
            "settle_margin_s" => self.settle_margin_s = x,
            _ => {
                return Err(format!(
                    "`scan.{field}` cannot be swept; allowed: {SWEEPABLE}"
                ));
            }
        }
        Ok(())
    }

    /// Check the values: `(key inside [scan], message)` for the first bad one.
    pub fn validate(&self) -> Result<(), (&'static str, String)> {
        let positive = [
            ("v_scan_mm_s", Some(self.v_scan_mm_s), "mm/s"),
            ("fly_amax_mm_s2", Some(self.fly_amax_mm_s2), "mm/s^2"),
            ("fly_jmax_mm_s3", self.fly_jmax_mm_s3, "mm/s^3"),
            ("width_mm", Some(self.width_mm), "mm"),
        ];
        for (key, v, unit) in positive {
            if let Some(v) = v.filter(|v| !(v.is_finite() && *v > 0.0)) {
                return Err((
                    key,
                    format!("must be a finite number > 0 ({unit}), got {v}"),
                ));
            }
        }
        if !(self.settle_margin_s.is_finite() && self.settle_margin_s >= 0.0) {
            return Err((
                "settle_margin_s",
                format!(
                    "must be a finite number >= 0 (s), got {}",
                    self.settle_margin_s
                ),
            ));
        }
        if self.lines < 2 {
            return Err((
                "lines",
                format!(
                    "a scan needs at least 2 lines (one step), got {}",
                    self.lines
                ),
            ));
        }
        self.placement()?;
        Ok(())
    }

    fn placement(&self) -> Result<StepPlacement, (&'static str, String)> {
        match self.placement.as_str() {
            "exit" => Ok(StepPlacement::AtExit),
            "centered" => Ok(StepPlacement::Centered),
            other => Err((
                "placement",
                format!("unknown placement `{other}`; allowed: exit, centered"),
            )),
        }
    }
}

/// Plan the raster of a scan run: X fly, Y step, from the step axis's start position 0.
///
/// With a `[shaper]`, the step axis's motion is input-shaped: the shaped step lasts the
/// shaper's duration longer, so the raster is planned with that much more settle margin
/// (the window is then `max(fastest turnaround, shaped step + settle_margin_s)`, and a
/// centred step is the shaped one centred), and each turnaround's `step_end_s` and
/// `overhead.step_s` are those of the shaped step.
pub fn plan(spec: &RunSpec, scan: &ScanSpec) -> Result<Raster, settle_planner::PlanError> {
    let placement = scan
        .placement()
        .map_err(|_| settle_planner::PlanError::InvalidInput {
            reason: "unknown scan placement",
        })?;
    let shaper = spec
        .shaper
        .as_ref()
        .map(crate::kinds::shaping::ShaperSetting::shaper)
        .transpose()?
        .flatten();
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
        step_params: spec.kind_params,
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

fn shifted(p: &Profile, dp: f64) -> Result<Profile, settle_planner::PlanError> {
    let s = p.start();
    Profile::new(State { p: s.p + dp, ..s }, p.segments().to_vec())
}

/// Plan and simulate a scan run; the metrics carry the scan columns in
/// [`Metrics::extra`]. When `record` is given it receives the run's series.
pub fn execute(
    spec: &RunSpec,
    scan: &ScanSpec,
    record: Option<&mut Series>,
) -> Result<Metrics, Error> {
    let sim_err = |source| Error::Sim {
        run: spec.id,
        source,
    };
    let plan_err = |source| Error::Plan {
        run: spec.id,
        source,
    };
    let axes = crate::execute::run::axes_of(spec).map_err(sim_err)?;
    let r = plan(spec, scan).map_err(plan_err)?;
    let y0 = spec.start_mm * 1e-3;
    let profiles = axes
        .iter()
        .map(|a| {
            if a.name == spec.axis {
                shifted(&r.trajectory.axes()[1], y0)
            } else if a.name == scan.fly_axis {
                Ok(r.trajectory.axes()[0].clone())
            } else {
                Ok(Profile::empty(State::default()))
            }
        })
        .collect::<Result<Vec<_>, _>>()
        .map_err(plan_err)?;
    let traj = Trajectory::new(profiles).map_err(plan_err)?;
    let observe = Observe {
        window_s: spec.window_s,
        sample_rate_hz: spec.sample_rate_hz,
        bands_um: spec.bands_um.clone(),
    };
    let mut local = Series::default();
    let series = match record {
        Some(s) => s,
        None => &mut local,
    };
    let mut m = crate::execute::run::run_trajectory(
        axes,
        spec.backend,
        &SimOptions::default(),
        &traj,
        &observe,
        Some(series),
    )
    .map_err(sim_err)?;
    let ch = format!("toolhead_{}", spec.axis);
    let y = &series
        .channel(&ch)
        .ok_or_else(|| Error::Sim {
            run: spec.id,
            source: settle_sim::SimError::Unsupported {
                backend: "scan",
                reason: format!("no channel {ch}"),
            },
        })?
        .data;
    m.extra = step_metrics(&series.t_s, y, &r, y0, &spec.bands_um);
    Ok(m)
}

/// The scan columns from the step axis's toolhead positions `y` (m) at times `t` (s,
/// increasing), for the raster `r` whose step axis started at `y0` (m).
pub fn step_metrics(
    t: &[f64],
    y: &[f64],
    r: &Raster,
    y0: f64,
    bands_um: &[f64],
) -> Vec<(String, f64)> {
    let mut reentry_um: f64 = 0.0;
    let mut line_peak_um: f64 = 0.0;
    let mut settle_s = vec![0.0f64; bands_um.len()];
    for tr in &r.turnarounds {
        let target = y0 + tr.y_to;
        let err_um = |i: usize| (y[i] - target).abs() * 1e6;
        let next_exit = tr.reentry_s + r.overhead.line_s;
        // The error at re-entry, interpolated between the samples around it.
        let k = t.partition_point(|&ti| ti < tr.reentry_s).min(t.len() - 1);
        let at = if k > 0 && t[k] > tr.reentry_s {
            let f = (tr.reentry_s - t[k - 1]) / (t[k] - t[k - 1]);
            ((y[k - 1] + f * (y[k] - y[k - 1])) - target).abs() * 1e6
        } else {
            err_um(k)
        };
        reentry_um = reentry_um.max(at);
        let end = t.partition_point(|&ti| ti <= next_exit).max(k);
        let peak = (k..end).map(err_um).fold(at, f64::max);
        line_peak_um = line_peak_um.max(peak);
        // Settle time after the step's end, until the next exit.
        let first = t.partition_point(|&ti| ti < tr.step_end_s);
        let last = t.partition_point(|&ti| ti <= next_exit);
        for (b, s) in bands_um.iter().zip(&mut settle_s) {
            let out = (first..last).rev().find(|&i| err_um(i) > *b);
            let here = match out {
                None => 0.0,
                Some(i) if i + 1 >= last => f64::INFINITY,
                Some(i) => {
                    // Linear crossing between the last sample out and the next one in.
                    let (e0, e1) = (err_um(i), err_um(i + 1));
                    let tc = t[i] + (t[i + 1] - t[i]) * (e0 - b) / (e0 - e1);
                    (tc - tr.step_end_s).max(0.0)
                }
            };
            *s = s.max(here);
        }
    }
    let mut out = vec![
        ("scan_step_s".to_string(), r.overhead.step_s),
        ("scan_window_s".to_string(), r.overhead.per_line_s),
        ("scan_reentry_error_um".to_string(), reentry_um),
        ("scan_line_residual_peak_um".to_string(), line_peak_um),
    ];
    for b in bands_um {
        let settled = if line_peak_um <= *b { 1.0 } else { 0.0 };
        out.push((format!("scan_settled_{b}um"), settled));
    }
    for (b, s) in bands_um.iter().zip(&settle_s) {
        out.push((format!("scan_step_settle_time_s_{b}um"), *s));
    }
    out
}

/// The names of the extra `runs.csv` columns of a scan run (`None` for other runs), from
/// the run alone so the header never depends on results; [`step_metrics`] fills them.
pub fn extra_columns(spec: &RunSpec) -> Option<Vec<String>> {
    spec.scan.as_ref()?;
    let mut out: Vec<String> = [
        "scan_step_s",
        "scan_window_s",
        "scan_reentry_error_um",
        "scan_line_residual_peak_um",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    out.extend(spec.bands_um.iter().map(|b| format!("scan_settled_{b}um")));
    out.extend(
        spec.bands_um
            .iter()
            .map(|b| format!("scan_step_settle_time_s_{b}um")),
    );
    Some(out)
}

/// The summary's scan section (empty when the table has no scan columns): per band, the
/// step-axis error at re-entry for every kind side by side, settled or not, with the
/// window and the step's settle time. Read from the runs table, like the rest of the
/// summary, so a merged sweep's summary is the same.
pub fn summary_section(runs: &[RunSpec], table: &crate::input::runs_table::RunsTable) -> String {
    use std::fmt::Write as _;
    let mut out = String::new();
    if table.column("scan_reentry_error_um").is_none() {
        return out;
    }
    let crate::output::report::SweptGroups {
        kinds,
        groups,
        params,
    } = crate::output::report::SweptGroups::of(runs);
    let bands = runs.first().map(|r| r.bands_um.clone()).unwrap_or_default();
    let _ = writeln!(
        out,
        "## Scan steps: step-axis error when the fly axis re-enters the region\n\n\
Each cell: |error| at re-entry (um), then per band whether the error stays inside the band \
for the whole next line (yes/no), then window = exit to re-entry (ms) and the step's own \
settle time to within {} um after its end (ms, `not settled` = still outside at the next \
exit). The move is the step-over (`move.distance_mm`).\n",
        bands.last().copied().unwrap_or_default()
    );
    let mut header: Vec<String> = params.iter().map(|p| p.to_string()).collect();
    header.extend(kinds.iter().map(|k| k.to_string()));
    let _ = writeln!(out, "| {} |", header.join(" | "));
    let _ = writeln!(out, "|{}", "---:|".repeat(header.len()));
    let last_band = bands.last().copied().unwrap_or_default();
    for (key, idx) in &groups {
        let mut row: Vec<String> = if params.is_empty() {
            Vec::new()
        } else {
            key.split(" | ").map(str::to_string).collect()
        };
        for k in &kinds {
            let cell =
                idx.iter()
                    .copied()
                    .find(|&i| runs[i].profile == *k)
                    .map_or("-".to_string(), |i| {
                        if table.cell(i, "status").is_some_and(|s| s != "ok") {
                            return "lost steps".to_string();
                        }
                        let e = table.num(i, "scan_reentry_error_um").unwrap_or(f64::NAN);
                        let settled: Vec<&str> = bands
                            .iter()
                            .map(|b| match table.num(i, &format!("scan_settled_{b}um")) {
                                Some(1.0) => "yes",
                                _ => "no",
                            })
                            .collect();
                        let w = table.num(i, "scan_window_s").unwrap_or(f64::NAN) * 1e3;
                        let s = table
                            .num(i, &format!("scan_step_settle_time_s_{last_band}um"))
                            .filter(|x| x.is_finite())
                            .map_or("not settled".to_string(), |x| format!("{:.1}", x * 1e3));
                        format!("{e:.2} {} (w {w:.1}, s {s})", settled.join("/"))
                    });
            row.push(cell);
        }
        let _ = writeln!(out, "| {} |", row.join(" | "));
    }
    out.push('\n');
    out
}
