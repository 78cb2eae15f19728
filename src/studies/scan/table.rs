//! The `[scan]` table: the fly axis of a raster scan whose step is the scenario's move. It
//! is also the study's per-run state, set by the sweep through `scan.<key>`.

use serde::Deserialize;
use settle_planner::raster::StepPlacement;

use crate::spec::run_spec::StudyState;
use crate::spec::value::Value;

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

/// The most lines a scan may have: each line is a turnaround and a step of the planned
/// raster, held in memory; a wafer or a print bed is scanned in thousands.
pub const MAX_LINES: usize = 100_000;

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

impl ScanSpec {
    /// Set a swept numeric key (`field` without the `scan.` prefix).
    pub fn set_number(&mut self, field: &str, x: f64) -> Result<(), String> {
        match field {
            "v_scan_mm_s" => self.v_scan_mm_s = x,
            "fly_amax_mm_s2" => self.fly_amax_mm_s2 = x,
            "fly_jmax_mm_s3" => self.fly_jmax_mm_s3 = Some(x),
            "width_mm" => self.width_mm = x,
            "settle_margin_s" => self.settle_margin_s = x,
            _ => {
                return Err(format!(
                    "`scan.{field}` cannot be swept; allowed: {}",
                    super::SWEEPABLE
                ));
            }
        }
        Ok(())
    }

    /// Check the values: `(key inside [scan], message)` for the first bad one.
    pub fn validate(&self) -> Result<(), (&'static str, String)> {
        use crate::spec::Quantity::{Acceleration, Jerk, Speed};
        let limits = [
            ("v_scan_mm_s", Some(self.v_scan_mm_s), Speed),
            ("fly_amax_mm_s2", Some(self.fly_amax_mm_s2), Acceleration),
            ("fly_jmax_mm_s3", self.fly_jmax_mm_s3, Jerk),
        ];
        for (key, v, quantity) in limits {
            if let Some(Err(m)) = v.map(|v| crate::spec::check_limit(v, quantity)) {
                return Err((key, m));
            }
        }
        crate::spec::check_length(self.width_mm, false).map_err(|m| ("width_mm", m))?;
        if !(self.settle_margin_s.is_finite()
            && (0.0..=crate::spec::MAX_MARGIN_S).contains(&self.settle_margin_s))
        {
            return Err((
                "settle_margin_s",
                format!(
                    "must be a finite number from 0 to {:e} (s), got {}",
                    crate::spec::MAX_MARGIN_S,
                    self.settle_margin_s
                ),
            ));
        }
        if !(2..=MAX_LINES).contains(&self.lines) {
            return Err((
                "lines",
                format!(
                    "a scan needs 2 to {MAX_LINES} lines (one step per turnaround), got {}",
                    self.lines
                ),
            ));
        }
        let name_ok = !self.fly_axis.is_empty()
            && self.fly_axis.len() <= 32
            && self
                .fly_axis
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '_');
        if !name_ok {
            return Err((
                "fly_axis",
                "an axis name: letters, digits and `_`, as the machine's axes are named (x, y, z)"
                    .into(),
            ));
        }
        self.placement()?;
        Ok(())
    }

    /// Where the step sits in the window.
    pub fn placement(&self) -> Result<StepPlacement, (&'static str, String)> {
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

impl StudyState for ScanSpec {
    fn table(&self) -> &'static str {
        "scan"
    }

    fn set(&mut self, key: &str, value: &Value) -> Result<(), String> {
        let x = value
            .number()
            .ok_or_else(|| format!("`scan.{key}` takes numbers"))?;
        self.set_number(key, x)
    }
}
