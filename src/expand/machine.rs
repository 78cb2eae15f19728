//! The scenario's machine: its modes, a preset or machine file, or inline axes.

use settle_sim::DriverMode;
use settle_sim::machine::Machine;

use crate::error::Error;
use crate::input::scenario::Scenario;
use crate::input::source::Source;

/// The scenario's machine: `(physical machine or None for the modes form, name, driver
/// model)`.
pub fn resolve_machine(
    sc: &Scenario,
    src: &Source,
) -> Result<(Option<Machine>, String, DriverMode), Error> {
    let m = &sc.machine;
    let inline = !m.axis.is_empty() || m.motor.is_some() || m.driver.is_some();
    let physical = inline || m.preset.is_some();
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
    if !m.modes.is_empty() {
        if driver.is_some_and(|d| d != DriverMode::Linear) {
            return Err(src.error_at(
                "machine.driver_model",
                "a machine given by its modes has no motor: driver_model applies to physical machines only",
            ));
        }
        return Ok((None, "modes".into(), DriverMode::Linear));
    }
    let driver = driver.unwrap_or(DriverMode::Full);
    if let Some(preset) = &m.preset {
        let (machine, _, _) = crate::input::machine_file::load_preset(preset, &src.path, src)?;
        let name = machine.name.clone();
        return Ok((Some(machine), name, driver));
    }
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
        return Ok((Some(machine), name, driver));
    }
    Err(src.error_at(
        "machine",
        "give the machine: `modes = [{ frequency_hz, damping_ratio }]`, `preset = \"printer_xy\"` (or a machine file path), or [machine.axis.<name>] tables",
    ))
}

/// The identity of the files a scenario reads besides itself (its machine files, given by
/// `preset` in `[machine]` or swept as `machine.preset`), by content: one `path=digest` per
/// file, in the order named, empty when it reads none. A sweep's journal and a shard's
/// manifest carry it, so that a machine file edited between an interruption and
/// `--resume`, or between two shards, is noticed.
pub fn inputs_identity(sc: &Scenario, src: &Source) -> Result<String, Error> {
    let mut values: Vec<&str> = sc.machine.preset.iter().map(String::as_str).collect();
    if let Some(list) = sc.sweep.get("machine.preset").and_then(|v| v.as_array()) {
        values.extend(list.iter().filter_map(|v| v.as_str()));
    }
    let mut out = Vec::new();
    for v in values {
        let Some(path) = crate::input::machine_file::preset_file(v, &src.path) else {
            continue;
        };
        let bytes = crate::input::file::read_bytes(&path)?;
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
