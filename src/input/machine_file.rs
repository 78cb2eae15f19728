//! Machine files (TOML): what a user writes to describe a gantry, parsed strictly and
//! reported with file, line and key, then converted to [`settle_sim::machine::Machine`].
//!
//! A machine file has a `name`, an optional `description` and one `[axis.<name>]` table
//! per axis (`x`, `y`, ...; axes are ordered by name), in one of two forms:
//!
//! - physical: machine-wide `[motor]` and `[driver]` tables (defaults for every axis) and
//!   per axis `carriage_kg`, `toolhead_kg`, optional `beam_kg`, exactly one of
//!   `[axis.<name>.belt]` or `[axis.<name>.screw]`, a `[axis.<name>.mount]`, an optional
//!   `[axis.<name>.frame]` and optional `motor` / `driver` overrides;
//! - modes: per axis only `modes = [{ frequency_hz, damping_ratio, weight }, ...]`
//!   ([`crate::input::modes`]; what `settle identify` writes).
//!
//! The same tables can be written inline in a scenario under `[machine]`. Built-in
//! presets (`scenarios/machines/*.toml`) are compiled into the binary.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::Deserialize;
use settle_sim::SimError;
use settle_sim::machine::{
    AxisMachine, Belt, Driver, Frame, Machine, Motor, Mount, Screw, Transmission,
};

// The tables of an axis's parts (`belt`, `screw`, `mount`, `frame`, `motor`, `driver`)
// are settle-sim's types, which carry the machine-file keys (`settle_sim::machine`).

use crate::error::Error;
use crate::input::machine_form::MachineForm;
use crate::input::modes::ModeSpec;
use crate::input::source::Source;

/// The built-in presets: name, repository path, text.
pub const PRESETS: [(&str, &str, &str); 2] = [
    (
        "printer_xy",
        "scenarios/machines/printer_xy.toml",
        include_str!("../../scenarios/machines/printer_xy.toml"),
    ),
    (
        "leadscrew_stage",
        "scenarios/machines/leadscrew_stage.toml",
        include_str!("../../scenarios/machines/leadscrew_stage.toml"),
    ),
];

/// A machine file as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MachineFile {
    /// Name, for reports.
    pub name: String,
    /// Free text.
    #[serde(default)]
    pub description: String,
    /// Motor of every axis that does not name its own.
    pub motor: Option<Motor>,
    /// Driver of every axis that does not name its own.
    pub driver: Option<Driver>,
    /// The axes, by name.
    pub axis: BTreeMap<String, AxisSpec>,
}

/// One axis as written: its modes, or its parts (a physical axis: `carriage_kg`,
/// `toolhead_kg`, the transmission and the mount are then required).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AxisSpec {
    /// The axis's modes (the modes form: no other key).
    pub modes: Option<Vec<ModeSpec>>,
    /// Carriage mass (kg).
    pub carriage_kg: Option<f64>,
    /// Toolhead mass (kg).
    pub toolhead_kg: Option<f64>,
    /// Mass carried rigidly with the carriage (kg), e.g. the X beam on a Y axis. Default 0.
    pub beam_kg: Option<f64>,
    /// A belt drive.
    pub belt: Option<Belt>,
    /// A screw drive.
    pub screw: Option<Screw>,
    /// Toolhead mount.
    pub mount: Option<Mount>,
    /// Optional frame mode.
    pub frame: Option<Frame>,
    /// Motor (else the machine-wide one).
    pub motor: Option<Motor>,
    /// Driver (else the machine-wide one).
    pub driver: Option<Driver>,
}

/// The most axes a machine may have: a gantry has two or three, a machine with its
/// extruder and rotary axes a few more.
pub const MAX_AXES: usize = 8;

/// Convert parsed axes into a validated machine. `prefix` is the key path of the tables
/// in `src` (`""` in a machine file, `"machine."` inline in a scenario), for errors.
pub fn to_machine(
    name: &str,
    motor: Option<&Motor>,
    driver: Option<&Driver>,
    axes: &BTreeMap<String, AxisSpec>,
    src: &Source,
    prefix: &str,
) -> Result<Machine, Error> {
    if axes.is_empty() || axes.len() > MAX_AXES {
        return Err(src.error_at(
            &format!("{prefix}axis"),
            format!(
                "a machine needs one to {MAX_AXES} [axis.<name>] tables, got {}",
                axes.len()
            ),
        ));
    }
    let mut out = Vec::new();
    for (axis, a) in axes {
        let key = |k: &str| format!("{prefix}axis.{axis}.{k}");
        let missing = |k: &str, what: &str| {
            src.error_at(
                &key(k),
                format!(
                    "missing `{k}` ({what}): a physical axis needs carriage_kg, toolhead_kg, [belt] or [screw] and [mount]; or give the axis by its `modes = [...]`"
                ),
            )
        };
        let carriage_kg = a.carriage_kg.ok_or_else(|| missing("carriage_kg", "kg"))?;
        let toolhead_kg = a.toolhead_kg.ok_or_else(|| missing("toolhead_kg", "kg"))?;
        let mount = a
            .mount
            .as_ref()
            .ok_or_else(|| missing("mount", "a table"))?;
        let transmission = match (&a.belt, &a.screw) {
            (Some(b), None) => Transmission::Belt(b.clone()),
            (None, Some(s)) => Transmission::Screw(s.clone()),
            _ => {
                return Err(src.error_at(
                    &format!("{prefix}axis.{axis}"),
                    "give exactly one of [belt] or [screw] for this axis",
                ));
            }
        };
        let (m, motor_key) = match (&a.motor, motor) {
            (Some(m), _) => (m, key("motor")),
            (None, Some(m)) => (m, format!("{prefix}motor")),
            (None, None) => {
                return Err(src.error_at(
                    &format!("{prefix}axis.{axis}"),
                    "no motor: give [motor] (for every axis) or [axis.<name>.motor]",
                ));
            }
        };
        let (d, driver_key) = match (&a.driver, driver) {
            (Some(d), _) => (d, key("driver")),
            (None, Some(d)) => (d, format!("{prefix}driver")),
            (None, None) => {
                return Err(src.error_at(
                    &format!("{prefix}axis.{axis}"),
                    "no driver: give [driver] (for every axis) or [axis.<name>.driver]",
                ));
            }
        };
        let machine_axis = AxisMachine {
            name: axis.clone(),
            carriage_kg,
            toolhead_kg,
            beam_kg: a.beam_kg.unwrap_or(0.0),
            transmission,
            mount: mount.clone(),
            frame: a.frame.clone(),
            motor: m.clone(),
            driver: d.clone(),
        };
        if let Err(e) = machine_axis.validate() {
            return Err(match e {
                SimError::InvalidMachine {
                    field,
                    value,
                    allowed,
                    ..
                } => {
                    let k = if let Some(f) = field.strip_prefix("motor.") {
                        format!("{motor_key}.{f}")
                    } else if let Some(f) = field.strip_prefix("driver.") {
                        format!("{driver_key}.{f}")
                    } else {
                        key(&field)
                    };
                    src.error_at(&k, format!("must be {allowed}, got {value}"))
                }
                other => src.error_at(&format!("{prefix}axis.{axis}"), other.to_string()),
            });
        }
        out.push(machine_axis);
    }
    let machine = Machine {
        name: name.to_string(),
        axes: out,
    };
    machine
        .validate()
        .map_err(|e| src.error_at(&format!("{prefix}axis"), e.to_string()))?;
    Ok(machine)
}

/// A machine file, read: its name, description and machine.
#[derive(Debug, Clone, PartialEq)]
pub struct Described {
    /// `name`.
    pub name: String,
    /// `description`.
    pub description: String,
    /// The machine.
    pub form: MachineForm,
}

/// Convert parsed axes into a validated machine of either form: every axis given by its
/// `modes`, or every axis by its parts ([`to_machine`]). Keys as in [`to_machine`].
pub fn to_form(
    name: &str,
    motor: Option<&Motor>,
    driver: Option<&Driver>,
    axes: &BTreeMap<String, AxisSpec>,
    src: &Source,
    prefix: &str,
) -> Result<MachineForm, Error> {
    let with_modes: Vec<&String> = axes
        .iter()
        .filter(|(_, a)| a.modes.is_some())
        .map(|(n, _)| n)
        .collect();
    if with_modes.is_empty() {
        return to_machine(name, motor, driver, axes, src, prefix).map(MachineForm::Physical);
    }
    for (axis, a) in axes {
        let parts = a.carriage_kg.is_some()
            || a.toolhead_kg.is_some()
            || a.beam_kg.is_some()
            || a.belt.is_some()
            || a.screw.is_some()
            || a.mount.is_some()
            || a.frame.is_some()
            || a.motor.is_some()
            || a.driver.is_some();
        match (&a.modes, parts) {
            (Some(_), true) => {
                return Err(src.error_at(
                    &format!("{prefix}axis.{axis}.modes"),
                    "an axis is given either by its modes or by its parts (carriage_kg, belt, mount, ...), not both",
                ));
            }
            (None, _) => {
                return Err(src.error_at(
                    &format!("{prefix}axis.{axis}"),
                    format!(
                        "axis `{}` has modes, this one has none: give every axis by its `modes = [...]`, or every axis by its parts",
                        with_modes[0]
                    ),
                ));
            }
            (Some(_), false) => {}
        }
    }
    if motor.is_some() || driver.is_some() {
        let k = if motor.is_some() { "motor" } else { "driver" };
        return Err(src.error_at(
            &format!("{prefix}{k}"),
            "a machine given by its modes has no motor or driver: remove [motor] and [driver]",
        ));
    }
    crate::input::modes::to_axis_modes(
        axes.iter().map(|(n, a)| {
            (
                n.clone(),
                format!("{prefix}axis.{n}.modes"),
                a.modes.as_deref().unwrap_or_default(),
            )
        }),
        src,
    )
    .map(MachineForm::Modes)
}

/// Parse a machine file's text (either form); `path` names it in errors.
pub fn parse_any(text: &str, path: &Path) -> Result<Described, Error> {
    let src = Source::new(text, path);
    let file: MachineFile = src.document(&[])?;
    let form = to_form(
        &file.name,
        file.motor.as_ref(),
        file.driver.as_ref(),
        &file.axis,
        &src,
        "",
    )?;
    Ok(Described {
        name: file.name,
        description: file.description,
        form,
    })
}

/// Parse a physical machine file's text; `path` names it in errors.
pub fn parse(text: &str, path: &Path) -> Result<(Machine, String), Error> {
    let d = parse_any(text, path)?;
    match d.form {
        MachineForm::Physical(m) => Ok((m, d.description)),
        MachineForm::Modes(_) => Err(Error::input_key(
            path,
            "axis",
            "this machine is given by its modes; a physical machine (motor, belts, masses) is needed here",
        )),
    }
}

/// The machine file `preset = "<value>"` of a scenario at `scenario_path` names, `None`
/// for a built-in preset (or a value that is neither; `crate::expand::machine::named`
/// says why).
pub fn preset_file(value: &str, scenario_path: &Path) -> Option<PathBuf> {
    if PRESETS.iter().any(|(n, _, _)| *n == value)
        || !(value.contains('/') || value.ends_with(".toml"))
    {
        return None;
    }
    Some(scenario_path.parent().unwrap_or(Path::new(".")).join(value))
}
