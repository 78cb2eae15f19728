//! Sweeping a physical machine's fields: `machine.axis.<axis>.<field>` (one axis),
//! `machine.motor.<field>` and `machine.driver.<field>` (every axis), with the keys of
//! machine files (`crate::input::machine_file`).

use settle_sim::machine::{AxisMachine, Machine, Transmission};

/// Set a numeric field of an axis by its key path inside the axis (as in machine files).
pub fn set_axis_field(a: &mut AxisMachine, field: &str, x: f64) -> Result<(), String> {
    let int = |x: f64| {
        if x.fract() == 0.0 && (0.0..=u32::MAX as f64).contains(&x) {
            Ok(x as u32)
        } else {
            Err(format!("`{field}` takes whole numbers, got {x}"))
        }
    };
    let no_field = || {
        Err(format!(
            "axis `{}` has no numeric field `{field}`; allowed: carriage_kg, toolhead_kg, beam_kg, \
belt.*, screw.*, mount.*, frame.*, motor.*, driver.* (the machine-file keys)",
            a.name
        ))
    };
    match field {
        "carriage_kg" => a.carriage_kg = x,
        "toolhead_kg" => a.toolhead_kg = x,
        "beam_kg" => a.beam_kg = x,
        "mount.stiffness_n_per_m" => a.mount.stiffness_n_per_m = x,
        "mount.damping_ratio" => a.mount.damping_ratio = x,
        f if f.starts_with("belt.") => {
            let Transmission::Belt(b) = &mut a.transmission else {
                return Err(format!("axis `{}` has no belt", a.name));
            };
            match f {
                "belt.ea_n" => b.ea_n = x,
                "belt.span_mm" => b.span_mm = x,
                "belt.pulley_teeth" => b.pulley_teeth = int(x)?,
                "belt.pitch_mm" => b.pitch_mm = x,
                "belt.carriage_at_zero_mm" => b.carriage_at_zero_mm = x,
                "belt.damping_ratio" => b.damping_ratio = x,
                _ => return no_field(),
            }
        }
        f if f.starts_with("screw.") => {
            let Transmission::Screw(sc) = &mut a.transmission else {
                return Err(format!("axis `{}` has no screw", a.name));
            };
            match f {
                "screw.lead_mm" => sc.lead_mm = x,
                "screw.stiffness_n_per_m" => sc.stiffness_n_per_m = x,
                "screw.damping_ratio" => sc.damping_ratio = x,
                _ => return no_field(),
            }
        }
        f if f.starts_with("frame.") => {
            let Some(fr) = a.frame.as_mut() else {
                return Err(format!("axis `{}` has no frame mode", a.name));
            };
            match f {
                "frame.mass_kg" => fr.mass_kg = x,
                "frame.stiffness_n_per_m" => fr.stiffness_n_per_m = x,
                "frame.damping_ratio" => fr.damping_ratio = x,
                _ => return no_field(),
            }
        }
        "motor.holding_torque_n_m" => a.motor.holding_torque_n_m = x,
        "motor.rated_current_a" => a.motor.rated_current_a = x,
        "motor.resistance_ohm" => a.motor.resistance_ohm = x,
        "motor.inductance_mh" => a.motor.inductance_mh = x,
        "motor.rotor_inertia_g_cm2" => a.motor.rotor_inertia_g_cm2 = x,
        "motor.rotor_teeth" => a.motor.rotor_teeth = int(x)?,
        "motor.detent_torque_n_m" => a.motor.detent_torque_n_m = x,
        "motor.damping_ratio" => a.motor.damping_ratio = x,
        "driver.microsteps" => a.driver.microsteps = int(x)?,
        "driver.run_current_a_rms" => a.driver.run_current_a_rms = x,
        "driver.supply_v" => a.driver.supply_v = x,
        "driver.current_loop_bandwidth_hz" => a.driver.current_loop_bandwidth_hz = x,
        _ => return no_field(),
    }
    Ok(())
}

/// Set `machine.<rest>` = `x` on `m`: `rest` is `axis.<axis>.<field>`, `motor.<field>` or
/// `driver.<field>`.
pub fn set_machine_field(m: &mut Machine, param: &str, rest: &str, x: f64) -> Result<(), String> {
    if let Some(rest) = rest.strip_prefix("axis.") {
        let (axis, field) = rest
            .split_once('.')
            .ok_or_else(|| format!("`{param}`: expected machine.axis.<axis>.<field>"))?;
        let names: Vec<String> = m.axes.iter().map(|a| a.name.clone()).collect();
        let a = m
            .axes
            .iter_mut()
            .find(|a| a.name == axis)
            .ok_or_else(|| format!("no axis `{axis}`; the machine has {}", names.join(", ")))?;
        set_axis_field(a, field, x)
    } else {
        for a in &mut m.axes {
            set_axis_field(a, rest, x)?;
        }
        Ok(())
    }
}
