//! Input shaping in sweeps: the scenario's `[shaper]` table, its sweepable keys
//! (`shaper.type`, `shaper.frequency_hz`, `shaper.damping_ratio`), applying the shaper to a
//! run's commanded motion and its runs.csv columns.
//!
//! Design: the shaper is a table of its own, orthogonal to the profile kind, rather than
//! compound kinds such as `trapezoid+mzv`. A shaper needs a frequency and a damping ratio
//! besides its type; as separate keys all three can be swept, and a sweep over
//! `profile x shaper.type x shaper.frequency_hz` is the plain cartesian product every other
//! sweep is. `type = "none"` switches shaping off inside a sweep (the unshaped reference).

use std::fmt::Write as _;

use serde::Deserialize;
use settle_planner::shaper::{Shaper, ShaperKind};
use settle_planner::{PlanError, Profile, Trajectory};

use crate::expand::RunSpec;

/// Klipper's default damping ratio of its shapers (`damping_ratio_x`), 0.1: a shaper
/// designed for 10% damping still works on the lightly damped modes of a real frame.
pub const DEFAULT_DAMPING_RATIO: f64 = 0.1;

/// Klipper reports a shaper's smoothing at a square-corner velocity of 5 mm/s (its default
/// `square_corner_velocity`); runs.csv uses the same, at the run's own acceleration.
pub const SMOOTHING_SCV_MM_S: f64 = 5.0;

/// The `[shaper]` table of a scenario.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ShaperSpec {
    /// Klipper's shaper name (`zv`, `mzv`, `zvd`, `ei`, `2hump_ei`, `3hump_ei`) or `none`.
    #[serde(rename = "type")]
    pub type_: String,
    /// The frequency the shaper is tuned to (Hz).
    pub frequency_hz: f64,
    /// The damping ratio it is designed for (default [`DEFAULT_DAMPING_RATIO`]).
    #[serde(default = "default_damping")]
    pub damping_ratio: f64,
}

fn default_damping() -> f64 {
    DEFAULT_DAMPING_RATIO
}

/// A run's shaper setting (resolved): `kind` is `None` for `type = "none"`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShaperSetting {
    /// The family, or `None` (no shaping).
    pub kind: Option<ShaperKind>,
    /// Frequency (Hz).
    pub frequency_hz: f64,
    /// Damping ratio the shaper is designed for.
    pub damping_ratio: f64,
}

/// Names `shaper.type` accepts.
pub const ALLOWED_TYPES: &str = "none, zv, mzv, zvd, ei, 2hump_ei, 3hump_ei";

/// Parse a shaper type name (`none` is no shaping).
pub fn parse_type(name: &str) -> Result<Option<ShaperKind>, String> {
    if name.eq_ignore_ascii_case("none") {
        return Ok(None);
    }
    ShaperKind::parse(name)
        .map(Some)
        .map_err(|_| format!("unknown shaper type `{name}`; allowed: {ALLOWED_TYPES}"))
}

impl ShaperSetting {
    /// Resolve the `[shaper]` table; errors name the key (`shaper.type`, ...).
    pub fn from_spec(spec: &ShaperSpec) -> Result<Self, (&'static str, String)> {
        let kind = parse_type(&spec.type_).map_err(|m| ("shaper.type", m))?;
        Ok(Self {
            kind,
            frequency_hz: spec.frequency_hz,
            damping_ratio: spec.damping_ratio,
        })
    }

    /// The shaper, or `None` for no shaping. Errors for a bad frequency or damping ratio.
    pub fn shaper(&self) -> Result<Option<Shaper>, PlanError> {
        self.kind
            .map(|k| Shaper::new(k, self.frequency_hz, self.damping_ratio))
            .transpose()
    }

    /// Set a swept key (`type`, `frequency_hz`, `damping_ratio`).
    pub fn set(&mut self, key: &str, value: &crate::expand::Value) -> Result<(), String> {
        use crate::expand::Value;
        match (key, value) {
            ("type", Value::Text(t)) => self.kind = parse_type(t)?,
            ("frequency_hz", Value::Number(x)) => self.frequency_hz = *x,
            ("damping_ratio", Value::Number(x)) => self.damping_ratio = *x,
            ("type", _) => return Err(format!("`shaper.type` takes names: {ALLOWED_TYPES}")),
            ("frequency_hz" | "damping_ratio", _) => {
                return Err(format!("`shaper.{key}` takes numbers"));
            }
            _ => {
                return Err(format!(
                    "`shaper.{key}` cannot be swept; allowed: shaper.type, shaper.frequency_hz, shaper.damping_ratio"
                ));
            }
        }
        Ok(())
    }

    /// Check the setting: `(key, message)` on error.
    pub fn validate(&self) -> Result<(), (&'static str, String)> {
        if !(self.frequency_hz.is_finite() && self.frequency_hz > 0.0) {
            return Err((
                "shaper.frequency_hz",
                format!(
                    "must be a finite number > 0 (Hz), got {}",
                    self.frequency_hz
                ),
            ));
        }
        if !(0.0..1.0).contains(&self.damping_ratio) {
            return Err((
                "shaper.damping_ratio",
                format!("must be in [0, 1), got {}", self.damping_ratio),
            ));
        }
        Ok(())
    }
}

/// Shape one profile with the run's shaper (unchanged without one).
pub fn shape_profile(spec: &RunSpec, profile: Profile) -> Result<Profile, PlanError> {
    match spec
        .shaper
        .as_ref()
        .map(ShaperSetting::shaper)
        .transpose()?
    {
        Some(Some(s)) => s.apply(&profile),
        _ => Ok(profile),
    }
}

/// Shape every axis of a trajectory (Klipper shapes each axis independently), keeping
/// the path geometry it follows.
pub fn shape_trajectory(spec: &RunSpec, traj: Trajectory) -> Result<Trajectory, PlanError> {
    match spec
        .shaper
        .as_ref()
        .map(ShaperSetting::shaper)
        .transpose()?
    {
        Some(Some(s)) => {
            let shaped = Trajectory::new(
                traj.axes()
                    .iter()
                    .map(|p| s.apply(p))
                    .collect::<Result<Vec<_>, _>>()?,
            )?;
            // The path stays the reference of the contour error: the shaper's smoothing of
            // the corner counts against the shaped run.
            Ok(match traj.path() {
                Some(g) => shaped.with_path(g.clone()),
                None => shaped,
            })
        }
        _ => Ok(traj),
    }
}

/// The mode the `remaining_vibration_pct` column is computed for: `(frequency Hz, damping
/// ratio)`. The modes form: the mode of largest weight (the first among equals). A physical
/// machine: the strongest mode of the moving axis's (a corner path: its first axis's)
/// linearised response to the run's unshaped move (from the closed form).
pub fn dominant_mode(spec: &RunSpec) -> Option<(f64, f64)> {
    if spec.machine.is_none() {
        let mut best: Option<&crate::input::scenario::ModeSpec> = None;
        for m in &spec.modes {
            if best.is_none_or(|b| m.weight.abs() > b.weight.abs()) {
                best = Some(m);
            }
        }
        return best.map(|m| (m.frequency_hz, m.damping_ratio));
    }
    let machine = spec.machine.as_ref()?;
    let axes = machine.compile(settle_sim::DriverMode::Linear).ok()?;
    // A corner path (`x+y`): its first axis, the one the path starts along.
    let name = spec.axis.split('+').next()?;
    let axis = axes.iter().find(|a| a.name == name)?;
    let limits = spec.limits_si().ok()?;
    let profile = spec
        .profile
        .rest_to_rest(spec.start_mm * 1e-3, spec.distance_mm * 1e-3, &limits)
        .ok()?;
    let lr = settle_sim::closed_form::LinearResponse::new(axis, &profile).ok()?;
    lr.modes()
        .into_iter()
        .find(|(f, _, _)| *f > 0.0)
        .map(|(f, z, _)| (f, z))
}

/// runs.csv columns of shaping (empty when no run has a `[shaper]` table).
pub const COLUMNS: [&str; 6] = [
    "shaper_type",
    "shaper_frequency_hz",
    "shaper_damping_ratio",
    "shaper_duration_s",
    "remaining_vibration_pct",
    "smoothing_mm",
];

/// `,name` for every shaping column (empty when no run has a shaper).
pub fn csv_header(runs: &[RunSpec]) -> String {
    if runs.iter().all(|r| r.shaper.is_none()) {
        return String::new();
    }
    COLUMNS.iter().map(|c| format!(",{c}")).collect()
}

/// The shaping cells of `run`. `remaining_vibration_pct` is Klipper's figure for the
/// [`dominant_mode`] (100 = no reduction; 100 for `none`), `smoothing_mm` Klipper's at the
/// run's acceleration and [`SMOOTHING_SCV_MM_S`] (0 for `none`).
pub fn csv_cells(runs: &[RunSpec], run: &RunSpec) -> String {
    if runs.iter().all(|r| r.shaper.is_none()) {
        return String::new();
    }
    let Some(setting) = &run.shaper else {
        return ",".repeat(COLUMNS.len());
    };
    let mut s = String::new();
    let name = setting.kind.map_or("none", ShaperKind::name);
    let _ = write!(
        s,
        ",{name},{},{}",
        setting.frequency_hz, setting.damping_ratio
    );
    match setting.shaper() {
        Ok(Some(sh)) => {
            let rv = dominant_mode(run)
                .map(|(f, z)| (100.0 * sh.remaining_vibration(f, z)).to_string())
                .unwrap_or_default();
            let _ = write!(
                s,
                ",{},{rv},{}",
                sh.duration_s(),
                sh.smoothing_mm(run.amax_mm_s2, SMOOTHING_SCV_MM_S)
            );
        }
        _ => s.push_str(",0,100,0"),
    }
    s
}
