//! Sweeping a physical machine's fields: `machine.axis.<axis>.<field>` (one axis),
//! `machine.motor.<field>` and `machine.driver.<field>` (every axis), with the keys of
//! machine files. The keys are settle-sim's own (`settle_sim::machine`, through serde): an
//! axis is written as its machine-file table, the number set at the key, and the table
//! read back, so no key is spelled here.

use settle_sim::machine::{AxisMachine, Machine};
use toml::Value;

/// Set a numeric field of an axis by its key path inside the axis (as in machine files:
/// `mount.stiffness_n_per_m`, `belt.pulley_teeth`, ...). A field that holds whole numbers
/// takes only whole numbers.
pub fn set_axis_field(a: &mut AxisMachine, field: &str, x: f64) -> Result<(), String> {
    let mut table = Value::try_from(&*a).map_err(|e| e.to_string())?;
    let mut slot = &mut table;
    let mut path = field.split('.').peekable();
    while let Some(key) = path.next() {
        let last = path.peek().is_none();
        slot = match slot.get_mut(key) {
            Some(v) => v,
            // An optional part the axis does not have (`belt.*` on a screw axis,
            // `frame.*` without a frame mode).
            None if !last => return Err(format!("axis `{}` has no `{key}`", a.name)),
            None => return Err(no_field(a, field)),
        };
    }
    match slot {
        Value::Float(f) => *f = x,
        Value::Integer(i) => {
            if !(x.fract() == 0.0 && (0.0..=f64::from(u32::MAX)).contains(&x)) {
                return Err(format!("`{field}` takes whole numbers, got {x}"));
            }
            *i = x as i64;
        }
        _ => return Err(no_field(a, field)),
    }
    *a = table
        .try_into()
        .map_err(|e: toml::de::Error| e.to_string())?;
    Ok(())
}

/// The error for a key that is not a numeric field of axis `a`: its numeric keys.
fn no_field(a: &AxisMachine, field: &str) -> String {
    let mut keys = Vec::new();
    if let Ok(Value::Table(t)) = Value::try_from(a) {
        for (k, v) in &t {
            match v {
                Value::Float(_) | Value::Integer(_) => keys.push(k.clone()),
                Value::Table(_) => keys.push(format!("{k}.*")),
                _ => {}
            }
        }
    }
    format!(
        "axis `{}` has no numeric field `{field}`; allowed: {} (the machine-file keys)",
        a.name,
        keys.join(", ")
    )
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

#[cfg(test)]
mod tests {
    use super::*;

    fn printer() -> Machine {
        let (_, path, text) = crate::input::machine_file::PRESETS[0];
        crate::input::machine_file::parse(text, std::path::Path::new(path))
            .expect("preset")
            .0
    }

    #[test]
    fn fields_are_set_by_their_machine_file_keys() {
        let mut m = printer();
        let before = m.clone();
        set_machine_field(&mut m, "p", "axis.x.mount.stiffness_n_per_m", 1.5e5).expect("set");
        set_machine_field(&mut m, "p", "axis.y.carriage_kg", 0.25).expect("set");
        set_machine_field(&mut m, "p", "driver.microsteps", 32.0).expect("set");
        set_machine_field(&mut m, "p", "axis.x.belt.pulley_teeth", 16.0).expect("set");
        let (x, y) = (&m.axes[0], &m.axes[1]);
        assert_eq!(x.mount.stiffness_n_per_m, 1.5e5);
        assert_eq!(y.carriage_kg, 0.25);
        assert!(m.axes.iter().all(|a| a.driver.microsteps == 32));
        let settle_sim::machine::Transmission::Belt(b) = &x.transmission else {
            panic!("a belt axis");
        };
        assert_eq!(b.pulley_teeth, 16);
        // Nothing else moved, bit for bit.
        let mut back = m.clone();
        back.axes[0].mount = before.axes[0].mount.clone();
        back.axes[0].transmission = before.axes[0].transmission.clone();
        back.axes[1].carriage_kg = before.axes[1].carriage_kg;
        for (a, b) in back.axes.iter_mut().zip(&before.axes) {
            a.driver = b.driver.clone();
        }
        assert_eq!(back, before);
    }

    #[test]
    fn bad_keys_and_values_say_what_is_allowed() {
        let mut m = printer();
        let a = &mut m.axes[0];
        let e = set_axis_field(a, "belt.colour", 1.0).expect_err("no such key");
        assert!(
            e.contains("no numeric field `belt.colour`") && e.contains("mount.*"),
            "{e}"
        );
        let e = set_axis_field(a, "screw.lead_mm", 5.0).expect_err("a belt axis");
        assert_eq!(e, "axis `x` has no `screw`");
        let e = set_axis_field(a, "driver.microsteps", 12.5).expect_err("whole numbers");
        assert_eq!(e, "`driver.microsteps` takes whole numbers, got 12.5");
        assert!(set_axis_field(a, "name", 1.0).is_err(), "not a number");
    }
}
