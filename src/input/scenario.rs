//! Scenario files: what a user writes. Parsed strictly (unknown keys are errors) and
//! reported with file, line and key. The studies' tables (`[corner]`, `[scan]`,
//! `[shaper]`, ...) are read by the studies themselves (`crate::studies`); this is the rest.

use std::collections::BTreeMap;
use std::path::Path;

use serde::Deserialize;
use settle_sim::machine::{Driver, Motor};

use crate::error::Error;
use crate::input::machine_file::AxisSpec;
pub use crate::input::modes::ModeSpec;
use crate::input::source::Source;
use crate::input::tune_spec::TuneSpec;

/// A scenario file as written (mm, s; converted to SI when runs are built).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// Name; also the default output folder `results/<name>/`. Letters, digits, `-`, `_`.
    pub name: String,
    /// Free text shown in the summary.
    #[serde(default)]
    pub description: String,
    /// The machine the moves run on.
    pub machine: MachineSpec,
    /// The base move (sweeps override its fields): a point-to-point move, or the move a
    /// study builds on (the step of a `[scan]`). A study with a path of its own (`[corner]`)
    /// replaces it.
    #[serde(rename = "move")]
    pub move_: Option<MoveSpec>,
    /// Kinematic limits (sweeps override them).
    pub limits: LimitsSpec,
    /// How and how long the result is observed.
    #[serde(default)]
    pub observe: ObserveSpec,
    /// The search of `settle tune` (see `crate::workflows::tune`).
    #[serde(default)]
    pub tune: Option<TuneSpec>,
    /// Sweep axes: `parameter = [list]` or `parameter = { from, to, steps | step, scale }`.
    /// The cartesian product of all axes, in the order written, gives the runs.
    #[serde(default)]
    pub sweep: toml::Table,
    /// `[current]`: the user's current settings among the swept ones (one value per swept
    /// key, the keys as in `[sweep]`), e.g. written by `settle import`. The summary and
    /// report.html give every gain against the runs with these values; without it, against
    /// the slowest. Checked against the sweep when it is expanded (`crate::expand`).
    #[serde(default)]
    pub current: toml::Table,
    /// Numerical settings of the simulation (expert; the defaults are the validated ones).
    #[serde(default)]
    pub sim: SimSpec,
}

/// `[sim]`: numerical settings of the time-stepping backends.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SimSpec {
    /// Integration step of rapier and MuJoCo (s), instead of the one each picks from the
    /// machine's fastest mode (the step `settle validate` checks). A larger step runs
    /// faster, loses accuracy, and past the integrator's stability limit blows up: such
    /// a run is reported as a failed run (`status = fault`). Steps never exceed one
    /// sample interval. No effect on the modal backend (exact at any step).
    pub max_step_s: Option<f64>,
}

/// The machine, in one of three forms: its modes (`[machine.axis.<name>] modes = [...]`
/// per axis; `modes = [...]` here is the shorthand for axis `x`), a preset or machine file
/// (`preset = "printer_xy"` or a path), or inline axes (`[machine.axis.x]` ... with the
/// machine-file schema, see [`crate::input::machine_file`]).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MachineSpec {
    /// One or more lightly damped modes between command and toolhead of axis `x` (the
    /// shorthand for `[machine.axis.x] modes`).
    #[serde(default)]
    pub modes: Vec<ModeSpec>,
    /// A built-in preset name, or a path to a machine file relative to the scenario.
    pub preset: Option<String>,
    /// Name of an inline machine (default: the scenario's name).
    pub name: Option<String>,
    /// Inline machine: motor of every axis that does not name its own.
    pub motor: Option<Motor>,
    /// Inline machine: driver of every axis that does not name its own.
    pub driver: Option<Driver>,
    /// Inline machine: the axes, by name (physical axes, or `modes = [...]` each).
    #[serde(default)]
    pub axis: BTreeMap<String, AxisSpec>,
    /// How the motors are driven: `full` (stepper driver model, the default), `spring`
    /// (a linear spring to the microstep-quantised command) or `linear` (a linear spring
    /// to the continuous command: the modal backend's model). Physical machines only.
    pub driver_model: Option<String>,
}

/// The base move.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MoveSpec {
    /// Signed move length (mm).
    pub distance_mm: f64,
    /// Start position (mm).
    #[serde(default)]
    pub start_mm: f64,
    /// Profile kind (`trapezoid`, `scurve`); sweep `profile` to compare kinds.
    #[serde(default = "default_profile")]
    pub profile: String,
    /// The axis that moves (default `x`); the others hold at 0.
    #[serde(default = "default_axis")]
    pub axis: String,
}

fn default_axis() -> String {
    "x".to_string()
}

fn default_profile() -> String {
    "scurve".to_string()
}

/// Kinematic limits.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LimitsSpec {
    /// Maximum speed (mm/s).
    pub vmax_mm_s: f64,
    /// Maximum acceleration (mm/s^2).
    pub amax_mm_s2: f64,
    /// Maximum jerk (mm/s^3); required by jerk-limited kinds (`scurve`).
    pub jmax_mm_s3: Option<f64>,
}

/// Observation: how long after the move, how finely, and which settling bands.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObserveSpec {
    /// Observation window after the commanded move ends (s). Default 0.5 s: ten decay time
    /// constants of a 40 Hz, zeta 0.05 mode.
    #[serde(default = "default_window")]
    pub window_s: f64,
    /// Sample rate of the simulation output (Hz). Default 10 kHz: 0.1 ms settle-time
    /// resolution, 250 samples per period of a 40 Hz mode.
    #[serde(default = "default_rate")]
    pub sample_rate_hz: f64,
    /// Settling bands (um), absolute error around the commanded end point.
    #[serde(default = "default_bands")]
    pub bands_um: Vec<f64>,
}

fn default_window() -> f64 {
    0.5
}
fn default_rate() -> f64 {
    10_000.0
}
fn default_bands() -> Vec<f64> {
    vec![10.0, 50.0]
}

impl Default for ObserveSpec {
    fn default() -> Self {
        Self {
            window_s: default_window(),
            sample_rate_hz: default_rate(),
            bands_um: default_bands(),
        }
    }
}

/// Read and parse a scenario file; `claimed` are the top-level tables others read (the
/// studies' tables: `crate::studies::tables`), left out of the strict parse.
pub fn load(path: &Path, claimed: &[&str]) -> Result<(Scenario, Source), Error> {
    let read = || {
        let source = Source::load(path)?;
        let scenario = parse_source(&source, claimed)?;
        Ok((scenario, source))
    };
    // A G-code job, a printer.cfg or a machine file given in a scenario's place is named,
    // with the command that reads it.
    read().map_err(|e| {
        use settle_files::looks::Looks;
        crate::input::file::name_foreign(
            path,
            e,
            crate::input::file::limit::SETTINGS,
            "a scenario (TOML)",
            &[Looks::Scenario],
        )
    })
}

/// Parse scenario text (see [`load`]); `path` is used in error messages.
pub fn parse(text: &str, path: &Path, claimed: &[&str]) -> Result<(Scenario, Source), Error> {
    let source = Source::new(text, path);
    let scenario = parse_source(&source, claimed)?;
    Ok((scenario, source))
}

/// The longest scenario name: it names the output folder, and file systems allow 255
/// bytes per name (a shard folder adds its `shard-K-of-N` beside it).
pub const MAX_NAME_CHARS: usize = 64;

fn parse_source(source: &Source, claimed: &[&str]) -> Result<Scenario, Error> {
    let scenario: Scenario = source.document(claimed).map_err(|e| match e {
        // The strict parse names the core keys; the claimed tables are allowed too.
        Error::Input { at, message }
            if message.starts_with("unknown field") && !claimed.is_empty() =>
        {
            let tables: Vec<String> = claimed.iter().map(|t| format!("`{t}`")).collect();
            Error::Input {
                at,
                message: format!("{message}, or a study's table: {}", tables.join(", ")),
            }
        }
        other => other,
    })?;
    if scenario.name.is_empty()
        || scenario.name.len() > MAX_NAME_CHARS
        || !scenario
            .name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
    {
        return Err(source.error_at(
            "name",
            format!(
                "`{}` is not a valid scenario name; allowed: 1 to {MAX_NAME_CHARS} letters, digits, `-` and `_` (it names the output folder)",
                crate::error::echo(&scenario.name)
            ),
        ));
    }
    Ok(scenario)
}
