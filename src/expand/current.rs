//! `[current]`: the user's current settings, one value per swept key. Checked here, where
//! the sweep's axes are known: every key must be a swept setting (not the workload, such
//! as the move length: the settings are compared at every point of it) and every value one
//! of that key's swept values, so that exactly one candidate per swept point is "current".

use settle_planner::ProfileKind;

use crate::error::Error;
use crate::expand::axes::Axis;
use crate::input::scenario::Scenario;
use crate::input::source::Source;
use crate::spec::groups::is_setting;
use crate::spec::value::Value;

/// Whether the TOML value `v` (from `[current]`) is the swept value `swept`. Numbers
/// compare as numbers (`52` is `52.0`), profile kinds by kind (`S-curve` is `scurve`).
pub fn same(v: &toml::Value, swept: &Value) -> bool {
    match (v, swept) {
        (toml::Value::Float(x), Value::Number(y)) => x == y,
        (toml::Value::Integer(x), Value::Number(y)) => (*x as f64) == *y,
        (toml::Value::String(s), Value::Study(k)) => ProfileKind::parse(s).is_ok_and(|p| p == *k),
        (toml::Value::String(s), Value::Text(t)) => s == t,
        _ => false,
    }
}

/// Check `sc.current` against the sweep `axes`; the error names the file, line and key and
/// what is allowed.
pub fn check(sc: &Scenario, src: &Source, axes: &[Axis]) -> Result<(), Error> {
    for (key, v) in &sc.current {
        let at = format!("current.{key}");
        let Some(axis) = axes.iter().find(|a| a.param == *key) else {
            let swept: Vec<String> = axes.iter().map(|a| format!("`{}`", a.param)).collect();
            return Err(src.error_at(
                &at,
                format!(
                    "`{key}` is not swept; [current] takes the swept keys: {}",
                    if swept.is_empty() {
                        "none (the scenario sweeps nothing)".to_string()
                    } else {
                        swept.join(", ")
                    }
                ),
            ));
        };
        if !is_setting(key) {
            let settings: Vec<String> = axes
                .iter()
                .filter(|a| is_setting(&a.param))
                .map(|a| format!("`{}`", a.param))
                .collect();
            return Err(src.error_at(
                &at,
                format!(
                    "`{key}` is part of the workload the settings are compared on (every value of it is a point of the ranking, each with its own gain against the current settings), not a setting; [current] takes the swept settings: {}",
                    if settings.is_empty() {
                        "none (the scenario sweeps only the workload)".to_string()
                    } else {
                        settings.join(", ")
                    }
                ),
            ));
        }
        if !axis.values.iter().any(|s| same(v, s)) {
            let values: Vec<String> = axis.values.iter().map(|s| format!("{s}")).collect();
            return Err(src.error_at(
                &at,
                format!(
                    "{v} is not among the swept values of `{key}`; allowed: {}",
                    values.join(", ")
                ),
            ));
        }
    }
    Ok(())
}
