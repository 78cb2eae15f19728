//! Input shaping in sweeps, a modifier kind: the scenario's `[shaper]` table, its sweepable
//! keys (`shaper.type`, `shaper.frequency_hz`, `shaper.damping_ratio`), the shaper it
//! hands the run's motion study (which applies it where it belongs: every axis of a path,
//! the step of a raster) and its runs.csv columns.
//!
//! Design: the shaper is a table of its own, orthogonal to the profile kind, rather than
//! compound kinds such as `trapezoid+mzv`. A shaper needs a frequency and a damping ratio
//! besides its type; as separate keys all three can be swept, and a sweep over
//! `profile x shaper.type x shaper.frequency_hz` is the plain cartesian product every other
//! sweep is. `type = "none"` switches shaping off inside a sweep (the unshaped reference).

use serde::Deserialize;
use settle_planner::PlanError;
use settle_planner::shaper::{Shaper, ShaperType};

use crate::error::Error;
use crate::input::scenario::ModeSpec;
use crate::input::source::Source;
use crate::studies::{Study, StudyState, Role, any_has};
use crate::measure::metrics::Metrics;
use crate::spec::run_spec::RunSpec;
use crate::spec::runs::RunList;
use crate::spec::value::Value;

/// Klipper's default damping ratio of its shapers (`damping_ratio_x`), 0.1: a shaper
/// designed for 10% damping still works on the lightly damped modes of a real frame.
pub const DEFAULT_DAMPING_RATIO: f64 = 0.1;

/// Klipper reports a shaper's smoothing at a square-corner velocity of 5 mm/s (its default
/// `square_corner_velocity`); runs.csv uses the same, at the run's own acceleration.
pub const SMOOTHING_SCV_MM_S: f64 = 5.0;

/// The largest acceleration (mm/s^2) at which `shaper` smooths at most `max_smoothing_mm`
/// at [`SMOOTHING_SCV_MM_S`]: Klipper's suggested `max_accel` (with its 0.12 mm target,
/// settle-planner's `TARGET_SMOOTHING_MM`).
pub fn max_accel_mm_s2(shaper: &Shaper, max_smoothing_mm: f64) -> f64 {
    settle_planner::shaper_select::max_accel_mm_s2(
        shaper.amplitudes(),
        shaper.times_s(),
        SMOOTHING_SCV_MM_S,
        max_smoothing_mm,
    )
}

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

/// A run's shaper setting (resolved): `shaper_type` is `None` for `type = "none"`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShaperSetting {
    /// The family, or `None` (no shaping).
    pub shaper_type: Option<ShaperType>,
    /// Frequency (Hz).
    pub frequency_hz: f64,
    /// Damping ratio the shaper is designed for.
    pub damping_ratio: f64,
}

/// Names `shaper.type` accepts.
pub const ALLOWED_TYPES: &str = "none, zv, mzv, zvd, ei, 2hump_ei, 3hump_ei";

/// Parse a shaper type name (`none` is no shaping).
pub fn parse_type(name: &str) -> Result<Option<ShaperType>, String> {
    if name.eq_ignore_ascii_case("none") {
        return Ok(None);
    }
    ShaperType::parse(name)
        .map(Some)
        .map_err(|_| format!("unknown shaper type `{name}`; allowed: {ALLOWED_TYPES}"))
}

impl ShaperSetting {
    /// Resolve the `[shaper]` table; errors name the key (`shaper.type`, ...).
    pub fn from_spec(spec: &ShaperSpec) -> Result<Self, (&'static str, String)> {
        let kind = parse_type(&spec.type_).map_err(|m| ("shaper.type", m))?;
        Ok(Self {
            shaper_type: kind,
            frequency_hz: spec.frequency_hz,
            damping_ratio: spec.damping_ratio,
        })
    }

    /// The shaper, or `None` for no shaping. Errors for a bad frequency or damping ratio.
    pub fn shaper(&self) -> Result<Option<Shaper>, PlanError> {
        self.shaper_type
            .map(|k| Shaper::new(k, self.frequency_hz, self.damping_ratio))
            .transpose()
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
        let min = settle_planner::shaper::MIN_FREQUENCY_HZ;
        if self.shaper_type.is_some() && self.frequency_hz < min {
            return Err((
                "shaper.frequency_hz",
                format!(
                    "{} Hz is below {min} Hz, the lowest shaper frequency settle runs (a shaper lasts about one period)",
                    self.frequency_hz
                ),
            ));
        }
        let max = crate::input::modes::MAX_FREQUENCY_HZ;
        if self.shaper_type.is_some() && self.frequency_hz > max {
            return Err((
                "shaper.frequency_hz",
                format!(
                    "{} Hz is above {max} Hz, the fastest mode a machine may have (a shaper is tuned to a mode; one far above every mode shapes nothing)",
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
        // What the firmware itself refuses (Klipper's damping ratio up to 0.99, 0.4 for ei,
        // 0.3 for 2hump_ei, 0.2 for 3hump_ei; RepRapFirmware's and Marlin's ranges) is bad
        // input too, found before any run, not a run that fails.
        if let Err(e) = self.shaper() {
            let m = e.to_string();
            let key = if m.contains("damping_ratio") {
                "shaper.damping_ratio"
            } else if m.contains("frequency_hz") {
                "shaper.frequency_hz"
            } else {
                "shaper.type"
            };
            return Err((key, m));
        }
        Ok(())
    }
}

impl StudyState for ShaperSetting {
    fn table(&self) -> &'static str {
        "shaper"
    }

    fn set(&mut self, key: &str, value: &Value) -> Result<(), String> {
        match (key, value) {
            ("type", Value::Text(t)) => self.shaper_type = parse_type(t)?,
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
}

/// The mode the `remaining_vibration_pct` column is computed for: `(frequency Hz, damping
/// ratio)`. The modes form: the moving axis's (a corner path: its first axis's) mode of
/// largest weight (the first among equals). A physical machine: the strongest mode of the
/// moving axis's linearised response to the run's unshaped move (from the closed form).
pub fn dominant_mode(spec: &RunSpec) -> Option<(f64, f64)> {
    // A corner path (`x+y`): its first axis, the one the path starts along.
    let name = spec.axis.split('+').next()?;
    let Some(machine) = spec.machine.physical() else {
        let mut best: Option<&ModeSpec> = None;
        for m in spec.machine.modes_of(name) {
            if best.is_none_or(|b| m.weight.abs() > b.weight.abs()) {
                best = Some(m);
            }
        }
        return best.map(|m| (m.frequency_hz, m.damping_ratio));
    };
    let axes = machine.compile(settle_sim::DriverMode::Linear).ok()?;
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

/// Input shaping of the commanded motion.
#[derive(Debug, Clone, Copy)]
pub struct Shaping;

impl Study for Shaping {
    fn name(&self) -> &'static str {
        "input shaper"
    }

    fn table(&self) -> Option<&'static str> {
        Some("shaper")
    }

    fn role(&self) -> Role {
        Role::Modifier
    }

    fn sweepable(&self) -> &'static str {
        "shaper.type, shaper.frequency_hz, shaper.damping_ratio"
    }

    fn parse(&self, src: &Source) -> Result<Option<Box<dyn StudyState>>, Error> {
        let Some(spec) = src.table::<ShaperSpec>("shaper")? else {
            return Ok(None);
        };
        let setting = ShaperSetting::from_spec(&spec).map_err(|(key, m)| src.error_at(key, m))?;
        Ok(Some(Box::new(setting)))
    }

    fn validate(&self, run: &RunSpec) -> Result<(), (String, String)> {
        match run.state::<ShaperSetting>().map(ShaperSetting::validate) {
            Some(Err((key, message))) => Err((run.blame(key), message)),
            _ => Ok(()),
        }
    }

    fn shaper(&self, run: &RunSpec) -> Result<Option<Shaper>, PlanError> {
        Ok(run
            .state::<ShaperSetting>()
            .map(ShaperSetting::shaper)
            .transpose()?
            .flatten())
    }

    fn columns(&self, runs: &dyn RunList) -> Vec<String> {
        if !any_has::<ShaperSetting>(runs) {
            return Vec::new();
        }
        COLUMNS.iter().map(|c| c.to_string()).collect()
    }

    /// A shaper's frequency and damping ratio with no shaper.
    fn unused(&self, run: &RunSpec, key: &str) -> Option<&'static str> {
        let s = run.state::<ShaperSetting>()?;
        (s.shaper_type.is_none() && matches!(key, "shaper.frequency_hz" | "shaper.damping_ratio"))
            .then_some("no shaper (`none`) has a frequency or damping ratio")
    }

    /// `remaining_vibration_pct` is Klipper's figure for the [`dominant_mode`] (100 = no
    /// reduction; 100 for `none`), `smoothing_mm` Klipper's at the run's acceleration and
    /// [`SMOOTHING_SCV_MM_S`] (0 for `none`).
    fn cells(&self, run: &RunSpec, _m: &Metrics) -> Vec<String> {
        let Some(setting) = run.state::<ShaperSetting>() else {
            return Vec::new();
        };
        let name = setting
            .shaper_type
            .map_or_else(|| "none".to_string(), |k| k.name().to_string());
        let mut out = vec![
            name.to_string(),
            setting.frequency_hz.to_string(),
            setting.damping_ratio.to_string(),
        ];
        match setting.shaper() {
            Ok(Some(sh)) => {
                let rv = dominant_mode(run)
                    .map(|(f, z)| (100.0 * sh.remaining_vibration(f, z)).to_string())
                    .unwrap_or_default();
                out.extend([
                    sh.duration_s().to_string(),
                    rv,
                    sh.smoothing_mm(run.amax_mm_s2, SMOOTHING_SCV_MM_S)
                        .to_string(),
                ]);
            }
            _ => out.extend(["0", "100", "0"].map(String::from)),
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::{ShaperSetting, parse_type};

    fn setting(name: &str, frequency_hz: f64, damping_ratio: f64) -> ShaperSetting {
        ShaperSetting {
            shaper_type: parse_type(name).expect("type"),
            frequency_hz,
            damping_ratio,
        }
    }

    /// A damping ratio the firmware refuses is bad input before any run (it was a run that
    /// failed with the planner's reason, and the sweep exited 0).
    #[test]
    fn a_damping_ratio_the_firmware_refuses_is_bad_input() {
        assert_eq!(setting("mzv", 50.0, 0.1).validate(), Ok(()));
        assert_eq!(setting("none", 50.0, 0.995).validate(), Ok(()));
        for (name, zeta) in [("mzv", 0.995), ("ei", 0.5), ("2hump_ei", 0.35), ("3hump_ei", 0.25)] {
            let e = setting(name, 50.0, zeta).validate();
            assert!(
                e.as_ref()
                    .is_err_and(|(key, m)| *key == "shaper.damping_ratio" && m.contains(&zeta.to_string())),
                "{name} at {zeta}: {e:?}"
            );
        }
    }
}
