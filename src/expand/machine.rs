//! Machines resolved: a scenario's `[machine]` (its modes per axis, a preset or machine
//! file, or inline axes; [`resolve_machine`]) and a machine named by `preset = "..."`,
//! `--machine` or `settle machine FILE` ([`named`], the one resolver of such names).

use std::path::{Path, PathBuf};

use settle_sim::DriverMode;

use crate::error::Error;
use crate::input::machine_file::{PRESETS, parse_any};
use crate::input::machine_form::MachineForm;
use crate::input::modes::AxisModes;
use crate::input::scenario::Scenario;
use crate::input::source::Source;

/// The scenario's machine, resolved.
#[derive(Debug, Clone)]
pub struct Resolved {
    /// The machine.
    pub form: MachineForm,
    /// Its name (the preset's or machine file's, the inline machine's, or `modes`).
    pub name: String,
    /// How the motors are driven (`linear` for the modes form).
    pub driver: DriverMode,
}

/// A machine named by `preset = "..."`, `--machine` or `settle machine FILE`.
#[derive(Debug, Clone, PartialEq)]
pub struct Named {
    /// Its name (a machine file's `name`, a scenario's machine's name).
    pub name: String,
    /// A machine file's `description` (empty for a scenario).
    pub description: String,
    /// The machine.
    pub form: MachineForm,
    /// The file it came from (a preset's: its repository path).
    pub source: PathBuf,
}

/// The machine `value` names: a built-in preset ([`PRESETS`]), a machine file of either
/// form at a path relative to the folder `base`, or (when `scenarios`) a scenario file:
/// its `[machine]`. A value that is neither a preset's name nor a path (with a `/` or
/// ending in `.toml`), or a file that cannot be read, is the error `err` makes of the
/// message. `preset = "..."` is resolved relative to its scenario's folder, without
/// scenarios; `--machine` and `settle machine FILE` relative to the working folder (`""`).
pub fn named(
    value: &str,
    base: &Path,
    scenarios: bool,
    err: &dyn Fn(String) -> Error,
) -> Result<Named, Error> {
    if let Some((_, path, text)) = PRESETS.iter().find(|(n, _, _)| *n == value) {
        let source = PathBuf::from(path);
        let d = parse_any(text, &source)?;
        return Ok(Named {
            name: d.name,
            description: d.description,
            form: d.form,
            source,
        });
    }
    let looks_like_path = value.contains('/') || value.ends_with(".toml");
    let names: Vec<&str> = PRESETS.iter().map(|(n, _, _)| *n).collect();
    let or_scenario = if scenarios { " or a scenario" } else { "" };
    // A file of another kind (a printer.cfg, a G-code job, a model) named where a machine
    // goes: named as what it is, with the command that reads it.
    let foreign = |file: &Path| -> Option<Error> {
        use settle_files::looks::Looks;
        let l = settle_files::looks::file(file, crate::input::file::limit::SETTINGS)?;
        if matches!(l, Looks::MachineFile | Looks::Packed(_)) || (scenarios && l == Looks::Scenario)
        {
            return None;
        }
        Some(err(format!(
            "{} is {}, not a machine: {}; a machine is a preset ({}), a machine file (ending in .toml){or_scenario}",
            file.display(),
            l.what(),
            l.then(),
            names.join(", "),
        )))
    };
    if !looks_like_path {
        let file = base.join(value);
        if let Some(e) = file.is_file().then(|| foreign(&file)).flatten() {
            return Err(e);
        }
        return Err(err(format!(
            "unknown preset `{value}`; built in: {}, or give a path to a machine file (ending in .toml){or_scenario}",
            names.join(", "),
        )));
    }
    let source = base.join(value);
    let text = crate::input::file::read_text(&source, crate::input::file::limit::SETTINGS)
        .map_err(|e| {
            if let Some(named) = foreign(&source) {
                return named;
            }
            let why = match e {
                Error::Read { source, .. } => source.to_string(),
                Error::Input { message, .. } => message,
                other => other.to_string(),
            };
            err(format!(
                "cannot read machine file {}: {why}",
                source.display()
            ))
        })?;
    let named = |e: Error| foreign(&source).unwrap_or(e);
    if scenarios
        && text
            .parse::<toml::Table>()
            .is_ok_and(|t| t.contains_key("machine"))
    {
        let (sc, src) = crate::expand::parse(&text, &source).map_err(named)?;
        let r = resolve_machine(&sc, &src)?;
        return Ok(Named {
            name: r.name,
            description: String::new(),
            form: r.form,
            source,
        });
    }
    let d = parse_any(&text, &source).map_err(named)?;
    Ok(Named {
        name: d.name,
        description: d.description,
        form: d.form,
        source,
    })
}

/// The folder a scenario's relative paths start from.
fn folder(src: &Source) -> &Path {
    src.path.parent().unwrap_or(Path::new("."))
}

/// `preset = "<value>"` of the scenario `src` for a machine to sweep through
/// `machine.preset`: a physical one (errors keyed at `machine.preset`).
pub fn swept_preset(value: &str, src: &Source) -> Result<Named, Error> {
    let n = named(value, folder(src), false, &|m| {
        src.error_at("machine.preset", m)
    })?;
    match n.form {
        MachineForm::Physical(_) => Ok(n),
        MachineForm::Modes(_) => Err(src.error_at(
            "machine.preset",
            format!(
                "{} gives the machine by its modes; only physical machines (motor, belts, masses) can be swept as presets",
                n.source.display()
            ),
        )),
    }
}

/// The scenario's machine.
pub fn resolve_machine(sc: &Scenario, src: &Source) -> Result<Resolved, Error> {
    let m = &sc.machine;
    let axis_modes = m.axis.values().any(|a| a.modes.is_some());
    let modes_form = !m.modes.is_empty() || axis_modes;
    let inline = !m.axis.is_empty() || m.motor.is_some() || m.driver.is_some();
    let physical = (inline && !axis_modes) || m.preset.is_some();
    if !m.modes.is_empty() && physical {
        return Err(src.error_at(
            "machine",
            "give either `modes = [...]` or a physical machine (`preset` or [machine.axis.<name>] tables), not both",
        ));
    }
    if m.preset.is_some() && inline {
        return Err(src.error_at(
            "machine.preset",
            "a preset cannot be combined with inline [machine.axis/motor/driver] tables; copy the preset's file, edit it and give its path",
        ));
    }
    let driver = match m.driver_model.as_deref() {
        None => None,
        Some(name) => Some(DriverMode::parse(name).ok_or_else(|| {
            src.error_at(
                "machine.driver_model",
                format!(
                    "unknown driver model `{name}`; allowed: {}",
                    DriverMode::ALLOWED
                ),
            )
        })?),
    };
    let no_motor = |driver: Option<DriverMode>| {
        if driver.is_some_and(|d| d != DriverMode::Linear) {
            return Err(src.error_at(
                "machine.driver_model",
                "a machine given by its modes has no motor: driver_model applies to physical machines only",
            ));
        }
        Ok(DriverMode::Linear)
    };
    let modes_machine = |modes: Vec<AxisModes>, name: String| -> Result<Resolved, Error> {
        Ok(Resolved {
            form: MachineForm::Modes(modes),
            name,
            driver: no_motor(driver)?,
        })
    };
    if modes_form {
        let mut modes = Vec::new();
        if !m.modes.is_empty() {
            if m.axis.get("x").is_some_and(|a| a.modes.is_some()) {
                return Err(src.error_at(
                    "machine.modes",
                    "axis x's modes are given twice: `modes` in [machine] is the shorthand for [machine.axis.x] modes; keep one",
                ));
            }
            modes = crate::input::modes::to_axis_modes(
                [("x".to_string(), "machine.modes".to_string(), &m.modes[..])],
                src,
            )?;
        }
        if axis_modes {
            let MachineForm::Modes(axes) = crate::input::machine_file::to_form(
                "modes",
                m.motor.as_ref(),
                m.driver.as_ref(),
                &m.axis,
                src,
                "machine.",
            )?
            else {
                return Err(src.error_at("machine.axis", "expected every axis given by modes"));
            };
            modes.extend(axes);
            modes.sort_by(|a, b| a.axis.cmp(&b.axis));
        }
        // The shorthand alone keeps the name every modes scenario had: `modes`.
        let name = match (&m.name, axis_modes) {
            (Some(n), true) => n.clone(),
            _ => "modes".to_string(),
        };
        return modes_machine(modes, name);
    }
    if let Some(preset) = &m.preset {
        let n = named(preset, folder(src), false, &|m| {
            src.error_at("machine.preset", m)
        })?;
        return match n.form {
            MachineForm::Physical(machine) => Ok(Resolved {
                name: machine.name.clone(),
                form: MachineForm::Physical(machine),
                driver: driver.unwrap_or(DriverMode::Full),
            }),
            MachineForm::Modes(modes) => modes_machine(modes, n.name),
        };
    }
    let driver = driver.unwrap_or(DriverMode::Full);
    if inline {
        let name = m.name.clone().unwrap_or_else(|| sc.name.clone());
        let machine = crate::input::machine_file::to_machine(
            &name,
            m.motor.as_ref(),
            m.driver.as_ref(),
            &m.axis,
            src,
            "machine.",
        )?;
        return Ok(Resolved {
            form: MachineForm::Physical(machine),
            name,
            driver,
        });
    }
    Err(src.error_at(
        "machine",
        "give the machine: `modes = [{ frequency_hz, damping_ratio }]` (axis x) or [machine.axis.<name>] modes = [...] per axis, `preset = \"printer_xy\"` (or a machine file path), or [machine.axis.<name>] tables",
    ))
}

/// The machine files a scenario names (`preset` in `[machine]`, or swept as
/// `machine.preset`), in the order named.
fn machine_files(sc: &Scenario, src: &Source) -> Vec<std::path::PathBuf> {
    let mut values: Vec<&str> = sc.machine.preset.iter().map(String::as_str).collect();
    if let Some(list) = sc.sweep.get("machine.preset").and_then(|v| v.as_array()) {
        values.extend(list.iter().filter_map(|v| v.as_str()));
    }
    values
        .into_iter()
        .filter_map(|v| crate::input::machine_file::preset_file(v, &src.path))
        .collect()
}

/// Every file a scenario reads: itself, its machine files and its G-code file (`[gcode]
/// file`), for the output rule (no output is one of them).
pub fn input_files(sc: &Scenario, src: &Source) -> settle_files::write::Inputs {
    let mut inputs = settle_files::write::Inputs::of(machine_files(sc, src));
    inputs.add(&src.path);
    if let Ok(Some(t)) = src.table::<toml::Table>("gcode")
        && let Some(file) = t.get("file").and_then(|v| v.as_str())
    {
        inputs.add(
            &src.path
                .parent()
                .unwrap_or(std::path::Path::new("."))
                .join(file),
        );
    }
    inputs
}

/// The identity of the files a scenario reads besides itself (its machine files, given by
/// `preset` in `[machine]` or swept as `machine.preset`), by content: one `path=digest` per
/// file, in the order named, empty when it reads none. A sweep's journal and a shard's
/// manifest carry it, so that a machine file edited between an interruption and
/// `--resume`, or between two shards, is noticed.
pub fn inputs_identity(sc: &Scenario, src: &Source) -> Result<String, Error> {
    let mut out = Vec::new();
    for path in machine_files(sc, src) {
        let bytes = crate::input::file::read_bytes(&path, crate::input::file::limit::SETTINGS)?;
        let entry = format!(
            "{}={:016x}",
            path.display(),
            crate::input::file::digest(&[&bytes])
        );
        if !out.contains(&entry) {
            out.push(entry);
        }
    }
    Ok(out.join(";"))
}
