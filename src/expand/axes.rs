//! Sweep axes: `[sweep]` keys and their values, a list or a range table, read into
//! [`Value`]s. Numbers stay numbers, strings become names (a study's state checks its
//! names, e.g. `corner.strategy`, when the axis is read), `profile` takes profile kinds.

use settle_planner::ProfileKind;

use crate::error::Error;
use crate::input::scenario::Scenario;
use crate::input::source::Source;
use crate::spec::run_spec::RunSpec;
use crate::spec::value::Value;

/// Upper bound on the number of runs one scenario may expand to: ten times the largest
/// sweep `scripts/scale.sh` checks (100,000 runs), a few hundred MB of run specs.
pub const MAX_RUNS: usize = 1_000_000;

/// One sweep axis: a parameter and its values.
#[derive(Debug, Clone, PartialEq)]
pub struct Axis {
    /// Parameter name as written (`profile`, `move.distance_mm`, ...).
    pub param: String,
    /// Values in order.
    pub values: Vec<Value>,
}

/// Read the sweep axes of a scenario whose runs start from `base`. A key of a study
/// (`corner.angle_deg`) is checked against the base's state of that study: the study must be
/// in the scenario and take every value.
pub fn axes(sc: &Scenario, src: &Source, base: &RunSpec) -> Result<Vec<Axis>, Error> {
    let mut out = Vec::new();
    // Runs so far (the product of the axes read): each axis may multiply it up to
    // MAX_RUNS, checked before its values are made.
    let mut runs = 1usize;
    for (param, raw) in &sc.sweep {
        let key = format!("sweep.{param}");
        let err = |m: String| src.error_at(&key, m);
        let values = if param == "profile" {
            let list = raw.as_array().ok_or_else(|| {
                err("`profile` takes a list of kind names, e.g. [\"trapezoid\", \"scurve\"]".into())
            })?;
            list.iter()
                .map(|v| {
                    let name = v.as_str().ok_or_else(|| {
                        err(format!(
                            "profile kinds are strings; allowed: {}",
                            ProfileKind::ALLOWED
                        ))
                    })?;
                    ProfileKind::parse(name)
                        .map(Value::Study)
                        .map_err(|e| err(e.to_string()))
                })
                .collect::<Result<Vec<_>, _>>()?
        } else if param == "machine.preset" {
            let list = raw.as_array().ok_or_else(|| {
                err("`machine.preset` takes a list of preset names or machine files".into())
            })?;
            list.iter()
                .map(|v| {
                    v.as_str()
                        .map(|s| Value::Text(s.to_string()))
                        .ok_or_else(|| {
                            err("machine presets are strings, e.g. \"printer_xy\"".into())
                        })
                })
                .collect::<Result<Vec<_>, _>>()?
        } else if let Some(list) = raw
            .as_array()
            .filter(|l| !l.is_empty() && l.iter().all(toml::Value::is_str))
        {
            list.iter()
                .filter_map(|v| v.as_str().map(|s| Value::Text(s.to_string())))
                .collect()
        } else {
            numbers(raw, MAX_RUNS / runs)
                .map_err(err)?
                .into_iter()
                .map(Value::Number)
                .collect()
        };
        if values.is_empty() {
            return Err(err("empty sweep axis: give at least one value".into()));
        }
        runs = runs
            .checked_mul(values.len())
            .filter(|&n| n <= MAX_RUNS)
            .ok_or_else(|| {
                err(format!(
                    "the sweep expands to more than {MAX_RUNS} runs ({} values here, {runs} runs from the axes before)",
                    values.len()
                ))
            })?;
        check_study_values(param, &values, base).map_err(err)?;
        out.push(Axis {
            param: param.clone(),
            values,
        });
    }
    Ok(out)
}

/// A study's key (`<table>.<key>` with a registered study's table): the base must have
/// the study, and its state must take every value.
fn check_study_values(param: &str, values: &[Value], base: &RunSpec) -> Result<(), String> {
    let Some((table, key)) = param.split_once('.') else {
        return Ok(());
    };
    if crate::studies::by_table(table).is_none() {
        return Ok(());
    }
    let Some(state) = base.state_of(table) else {
        return Err(format!("`{param}` needs a [{table}] table in the scenario"));
    };
    for v in values {
        state.clone_box().set(key, v)?;
    }
    Ok(())
}

/// A count of values as a message gives it: the integer, or its order of magnitude when
/// it is beyond any sweep (`1e-300` as a step gives some 1e300 values).
fn count_text(n: f64) -> String {
    if n < 1e15 {
        format!("{n:.0}")
    } else {
        format!("about {n:.1e}")
    }
}

/// A list of numbers, or a range table `{ from, to, steps | step, scale = "linear" | "log" }`
/// of at most `max_values` values (checked before the values are made).
fn numbers(raw: &toml::Value, max_values: usize) -> Result<Vec<f64>, String> {
    let as_f64 = |v: &toml::Value| {
        v.as_float()
            .or_else(|| v.as_integer().map(|i| i as f64))
            .ok_or_else(|| format!("expected a number, got `{v}`"))
    };
    match raw {
        toml::Value::Array(list) => list.iter().map(as_f64).collect(),
        toml::Value::Table(t) => {
            for k in t.keys() {
                if !["from", "to", "steps", "step", "scale"].contains(&k.as_str()) {
                    return Err(format!(
                        "unknown range key `{k}`; allowed: from, to, steps, step, scale"
                    ));
                }
            }
            let get = |k: &str| t.get(k).map(as_f64).transpose();
            let (from, to) = match (get("from")?, get("to")?) {
                (Some(f), Some(t)) if f.is_finite() && t.is_finite() => (f, t),
                _ => return Err("a range needs finite `from` and `to`".into()),
            };
            let log = match t.get("scale").map(|s| s.as_str()) {
                None | Some(Some("linear")) => false,
                Some(Some("log")) => true,
                _ => return Err("`scale` must be \"linear\" or \"log\"".into()),
            };
            if log && (from <= 0.0 || to <= 0.0) {
                return Err("a log range needs `from` and `to` > 0".into());
            }
            let too_many = |n: f64| {
                format!(
                    "the range has {} values; the sweep may have at most {MAX_RUNS} runs{}",
                    count_text(n),
                    if max_values < MAX_RUNS {
                        format!(" (at most {max_values} values here, with the axes before it)")
                    } else {
                        String::new()
                    }
                )
            };
            let count = match (get("steps")?, get("step")?) {
                (Some(n), None) if n >= 1.0 && n.fract() == 0.0 => {
                    if n > max_values as f64 {
                        return Err(too_many(n));
                    }
                    n as usize
                }
                (None, Some(s)) if !log && s > 0.0 && s.is_finite() => {
                    // The count is checked as a float first: a tiny step gives a count far
                    // beyond usize, and the values are not made unless it passes.
                    let n = ((to - from).abs() / s + 1e-9).floor() + 1.0;
                    if n > max_values as f64 {
                        return Err(too_many(n));
                    }
                    let dir = if to >= from { 1.0 } else { -1.0 };
                    return Ok((0..n as usize).map(|i| from + dir * s * i as f64).collect());
                }
                _ => {
                    return Err("a range needs either `steps` (an integer >= 1) or `step` (> 0, linear ranges only)".into());
                }
            };
            if count == 1 {
                return Ok(vec![from]);
            }
            Ok((0..count)
                .map(|i| {
                    let f = i as f64 / (count - 1) as f64;
                    if i == count - 1 {
                        to
                    } else if log {
                        (from.ln() + f * (to.ln() - from.ln())).exp()
                    } else {
                        from + f * (to - from)
                    }
                })
                .collect())
        }
        other => Err(format!(
            "expected a list of values or a range table {{ from, to, steps }}, got `{other}`"
        )),
    }
}
