//! Sweep expansion: a scenario becomes a list of fully resolved, validated runs. The same
//! file always gives the same runs in the same order (the only I/O is reading a machine
//! file the scenario names by path).

use settle_planner::{Limits, ProfileKind};
use settle_sim::machine::{AxisMachine, Machine, Transmission};
use settle_sim::{DriverMode, Mode};

use crate::error::Error;
use crate::execute::run::Backend;
use crate::input::scenario::{ModeSpec, Scenario, Source};

/// A value of a swept parameter.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    /// A number (in the parameter's unit).
    Number(f64),
    /// A profile kind.
    Kind(ProfileKind),
    /// A name (a corner strategy, `machine.preset`).
    Text(String),
}

impl std::fmt::Display for Value {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Value::Number(x) => write!(f, "{x}"),
            Value::Kind(k) => write!(f, "{k}"),
            Value::Text(t) => f.write_str(t),
        }
    }
}

/// One sweep axis: a parameter and its values.
#[derive(Debug, Clone, PartialEq)]
pub struct Axis {
    /// Parameter name as written (`profile`, `move.distance_mm`, ...).
    pub param: String,
    /// Values in order.
    pub values: Vec<Value>,
}

/// One point of a sweep, fully resolved (scenario units: mm, s, Hz).
#[derive(Debug, Clone, PartialEq)]
pub struct RunSpec {
    /// Index in the sweep (0-based, in expansion order).
    pub id: usize,
    /// Profile kind.
    pub profile: ProfileKind,
    /// Start position (mm).
    pub start_mm: f64,
    /// Signed move length (mm).
    pub distance_mm: f64,
    /// Maximum speed (mm/s).
    pub vmax_mm_s: f64,
    /// Maximum acceleration (mm/s^2).
    pub amax_mm_s2: f64,
    /// Maximum jerk (mm/s^3), if given.
    pub jmax_mm_s3: Option<f64>,
    /// The machine's modes (modes form; empty for a physical machine).
    pub modes: Vec<ModeSpec>,
    /// The physical machine (preset, machine file or inline), if not given by modes.
    pub machine: Option<Machine>,
    /// The machine's name (the preset's, or `modes`).
    pub machine_name: String,
    /// How the motors are driven (physical machines; `linear` for the modes form).
    pub driver: DriverMode,
    /// The axis that moves.
    pub axis: String,
    /// The backend that simulates the run (set from the command line).
    pub backend: Backend,
    /// Observation window after the move (s).
    pub window_s: f64,
    /// Sample rate (Hz).
    pub sample_rate_hz: f64,
    /// Settling bands (um).
    pub bands_um: Vec<f64>,
    /// `[sim] max_step_s`: forced integration step of rapier and MuJoCo (s).
    pub max_step_s: Option<f64>,
    /// The swept parameters' values of this run, in axis order.
    pub swept: Vec<(String, Value)>,
    /// The corner path the run follows instead of its point-to-point move, if any.
    pub corner: Option<crate::kinds::corner::Corner>,
    /// The raster scan the move is the step of, if the scenario has `[scan]`.
    pub scan: Option<crate::kinds::scan::ScanSpec>,
    /// The input shaper applied to the commanded motion, if the scenario has `[shaper]`.
    pub shaper: Option<crate::kinds::shaping::ShaperSetting>,
    /// Parameters of the kinds that take any (PVT asymmetry, four-jerk BOW1..4 scales);
    /// the planner's defaults unless `settle tune` searches them.
    pub kind_params: settle_planner::KindParams,
}

/// Parameters that can be swept, for error messages.
pub const SWEEPABLE: &str = "profile, move.distance_mm, move.start_mm, limits.vmax_mm_s, \
limits.amax_mm_s2, limits.jmax_mm_s3, machine.modes.N.frequency_hz, machine.modes.N.damping_ratio, \
machine.modes.N.weight (N = 0-based mode index), and for physical machines \
machine.axis.<axis>.<field> (e.g. machine.axis.x.mount.stiffness_n_per_m), machine.motor.<field> \
and machine.driver.<field> (every axis), machine.preset (preset names or machine files); \
with a [corner] table: corner.angle_deg, corner.leg_in_mm, corner.leg_out_mm, corner.strategy, \
corner.junction_deviation_mm, corner.square_corner_velocity_mm_s, corner.blend_deviation_mm; \
with a [scan] table: scan.v_scan_mm_s, scan.fly_amax_mm_s2, scan.fly_jmax_mm_s3, scan.width_mm, \
scan.settle_margin_s; with a [shaper] table: shaper.type, shaper.frequency_hz, shaper.damping_ratio";

/// Set a numeric field of an axis by its key path inside the axis (as in machine files).
fn set_axis_field(a: &mut AxisMachine, field: &str, x: f64) -> Result<(), String> {
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

/// Upper bound on the number of runs one scenario may expand to.
pub const MAX_RUNS: usize = 10_000_000;

impl RunSpec {
    /// Kinematic limits in SI units (m, s).
    pub fn limits_si(&self) -> Result<Limits, settle_planner::PlanError> {
        Limits::new(
            self.vmax_mm_s * 1e-3,
            self.amax_mm_s2 * 1e-3,
            self.jmax_mm_s3.map(|j| j * 1e-3),
        )
    }

    /// The modes as sim types.
    pub fn modes_sim(&self) -> Result<Vec<Mode>, settle_sim::SimError> {
        self.modes
            .iter()
            .map(|m| Mode::new(m.frequency_hz, m.damping_ratio, m.weight))
            .collect()
    }

    fn set(&mut self, param: &str, value: &Value) -> Result<(), String> {
        let num = |v: &Value| match v {
            Value::Number(x) => Ok(*x),
            _ => Err(format!("`{param}` takes numbers")),
        };
        match param {
            "profile" => match value {
                Value::Kind(k) => self.profile = *k,
                _ => return Err("`profile` takes profile kind names".into()),
            },
            other if other.starts_with("shaper.") => match self.shaper.as_mut() {
                Some(sh) => sh.set(&other["shaper.".len()..], value)?,
                None => return Err(format!("`{other}` needs a [shaper] table")),
            },
            other if other.starts_with("corner.") => match self.corner.as_mut() {
                Some(c) => c.set(&other["corner.".len()..], value)?,
                None => return Err(format!("`{other}` needs a [corner] table")),
            },
            "move.distance_mm" => self.distance_mm = num(value)?,
            "move.start_mm" => self.start_mm = num(value)?,
            "limits.vmax_mm_s" => self.vmax_mm_s = num(value)?,
            "limits.amax_mm_s2" => self.amax_mm_s2 = num(value)?,
            "limits.jmax_mm_s3" => self.jmax_mm_s3 = Some(num(value)?),
            // Resolved in `expand` (it reads the preset); nothing to set here.
            "machine.preset" => {}
            other if other.starts_with("scan.") => {
                let x = num(value)?;
                let scan = self
                    .scan
                    .as_mut()
                    .ok_or_else(|| format!("`{other}` needs a [scan] table in the scenario"))?;
                scan.set(&other["scan.".len()..], x)?;
            }
            other
                if other.starts_with("machine.axis.")
                    || other.starts_with("machine.motor.")
                    || other.starts_with("machine.driver.") =>
            {
                let x = num(value)?;
                let Some(m) = self.machine.as_mut() else {
                    return Err(format!(
                        "`{other}` needs a physical machine (preset or [machine.axis.*]), not modes"
                    ));
                };
                if let Some(rest) = other.strip_prefix("machine.axis.") {
                    let (axis, field) = rest.split_once('.').ok_or_else(|| {
                        format!("`{other}`: expected machine.axis.<axis>.<field>")
                    })?;
                    let names: Vec<String> = m.axes.iter().map(|a| a.name.clone()).collect();
                    let a = m.axes.iter_mut().find(|a| a.name == axis).ok_or_else(|| {
                        format!("no axis `{axis}`; the machine has {}", names.join(", "))
                    })?;
                    set_axis_field(a, field, x)?;
                } else {
                    let field = &other["machine.".len()..];
                    for a in &mut m.axes {
                        set_axis_field(a, field, x)?;
                    }
                }
            }
            other => {
                let mode_param = other
                    .strip_prefix("machine.modes.")
                    .and_then(|rest| rest.split_once('.'))
                    .and_then(|(i, field)| Some((i.parse::<usize>().ok()?, field)));
                let Some((i, field)) = mode_param else {
                    return Err(format!("`{other}` cannot be swept; allowed: {SWEEPABLE}"));
                };
                let n = self.modes.len();
                let mode = self.modes.get_mut(i).ok_or_else(|| {
                    format!("mode index {i} out of range: the machine has {n} mode(s)")
                })?;
                let x = num(value)?;
                match field {
                    "frequency_hz" => mode.frequency_hz = x,
                    "damping_ratio" => mode.damping_ratio = x,
                    "weight" => mode.weight = x,
                    _ => return Err(format!("`{other}` cannot be swept; allowed: {SWEEPABLE}")),
                }
            }
        }
        Ok(())
    }
}

/// Read the sweep axes of a scenario.
pub fn axes(sc: &Scenario, src: &Source) -> Result<Vec<Axis>, Error> {
    let mut out = Vec::new();
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
                        .map(Value::Kind)
                        .map_err(|e| err(e.to_string()))
                })
                .collect::<Result<Vec<_>, _>>()?
        } else if param == "shaper.type" {
            let list = raw
                .as_array()
                .ok_or_else(|| err(format!("`{param}` takes a list of shaper names")))?;
            list.iter()
                .map(|v| {
                    let name = v.as_str().ok_or_else(|| {
                        err(format!(
                            "shaper types are strings; allowed: {}",
                            crate::kinds::shaping::ALLOWED_TYPES
                        ))
                    })?;
                    crate::kinds::shaping::parse_type(name).map_err(&err)?;
                    Ok(Value::Text(name.to_string()))
                })
                .collect::<Result<Vec<_>, Error>>()?
        } else if crate::kinds::corner::is_text_param(param) {
            let list = raw
                .as_array()
                .ok_or_else(|| err(format!("`{param}` takes a list of names")))?;
            list.iter()
                .map(|v| {
                    let name = v.as_str().ok_or_else(|| {
                        err(format!("`{param}` takes names (strings), got `{v}`"))
                    })?;
                    crate::kinds::corner::check_text(param, name).map_err(&err)?;
                    Ok(Value::Text(name.to_string()))
                })
                .collect::<Result<Vec<_>, Error>>()?
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
        } else {
            numbers(raw)
                .map_err(err)?
                .into_iter()
                .map(Value::Number)
                .collect()
        };
        if values.is_empty() {
            return Err(err("empty sweep axis: give at least one value".into()));
        }
        out.push(Axis {
            param: param.clone(),
            values,
        });
    }
    Ok(out)
}

/// A list of numbers, or a range table `{ from, to, steps | step, scale = "linear" | "log" }`.
fn numbers(raw: &toml::Value) -> Result<Vec<f64>, String> {
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
            let count = match (get("steps")?, get("step")?) {
                (Some(n), None) if n >= 1.0 && n.fract() == 0.0 && n <= MAX_RUNS as f64 => {
                    n as usize
                }
                (None, Some(s)) if !log && s > 0.0 && s.is_finite() => {
                    let n = ((to - from).abs() / s + 1e-9).floor() + 1.0;
                    if n > MAX_RUNS as f64 {
                        return Err(format!("range has {n} values; at most {MAX_RUNS}"));
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

/// Expand a scenario into validated runs: the base run, then the cartesian product of the
/// sweep axes in the order written (the last axis varies fastest).
pub fn expand(sc: &Scenario, src: &Source) -> Result<Vec<RunSpec>, Error> {
    let (mv, corner) = match (&sc.move_, &sc.corner) {
        (Some(m), None) => (m.clone(), None),
        (None, Some(c)) => (
            crate::input::scenario::MoveSpec {
                distance_mm: 0.0,
                start_mm: 0.0,
                profile: c.profile.clone(),
                // Both path axes, e.g. `x+y` (no machine axis has this name, so the
                // point-to-point travel check leaves the corner to its own).
                axis: format!("{}+{}", c.axes[0], c.axes[1]),
            },
            Some(crate::kinds::corner::Corner::from_spec(c, src)?),
        ),
        (Some(_), Some(_)) => {
            return Err(src.error_at(
                "corner",
                "give either [move] (a point-to-point move) or [corner] (a corner path), not both",
            ));
        }
        (None, None) => {
            return Err(src.error_at(
                "name",
                "missing the motion: give [move] (a point-to-point move) or [corner] (a corner path)",
            ));
        }
    };
    let profile_key = if corner.is_some() {
        "corner.profile"
    } else {
        "move.profile"
    };
    let base_profile =
        ProfileKind::parse(&mv.profile).map_err(|e| src.error_at(profile_key, e.to_string()))?;
    let (machine, machine_name, driver) = resolve_machine(sc, src)?;
    let axis_names: Vec<String> = match &machine {
        Some(m) => m.axes.iter().map(|a| a.name.clone()).collect(),
        None => vec!["x".to_string()],
    };
    if corner.is_none() && !axis_names.contains(&mv.axis) {
        return Err(src.error_at(
            "move.axis",
            format!(
                "no axis `{}`; the machine has {}",
                mv.axis,
                axis_names.join(", ")
            ),
        ));
    }
    let base = RunSpec {
        id: 0,
        profile: base_profile,
        start_mm: mv.start_mm,
        distance_mm: mv.distance_mm,
        vmax_mm_s: sc.limits.vmax_mm_s,
        amax_mm_s2: sc.limits.amax_mm_s2,
        jmax_mm_s3: sc.limits.jmax_mm_s3,
        modes: sc.machine.modes.clone(),
        machine,
        machine_name,
        driver,
        axis: mv.axis.clone(),
        backend: Backend::default(),
        window_s: sc.observe.window_s,
        sample_rate_hz: sc.observe.sample_rate_hz,
        bands_um: sc.observe.bands_um.clone(),
        max_step_s: sc.sim.max_step_s,
        swept: Vec::new(),
        corner,
        scan: sc.scan.clone(),
        shaper: match &sc.shaper {
            None => None,
            Some(spec) => Some(
                crate::kinds::shaping::ShaperSetting::from_spec(spec)
                    .map_err(|(key, m)| src.error_at(key, m))?,
            ),
        },
        kind_params: settle_planner::KindParams::default(),
    };
    validate_observe(&base, src)?;
    let axes = axes(sc, src)?;
    let total = axes
        .iter()
        .try_fold(1usize, |acc, a| acc.checked_mul(a.values.len()))
        .filter(|&n| n <= MAX_RUNS)
        .ok_or_else(|| {
            src.error_at(
                "sweep",
                format!("the sweep expands to more than {MAX_RUNS} runs"),
            )
        })?;
    if axes.iter().any(|a| a.param == "machine.preset") && base.machine.is_none() {
        return Err(src.error_at(
            "sweep.machine.preset",
            "sweeping presets needs a physical machine: give `preset` in [machine], not `modes`",
        ));
    }
    let mut presets: Vec<(String, Machine, String)> = Vec::new();
    let mut runs = Vec::with_capacity(total);
    for id in 0..total {
        let mut run = base.clone();
        run.id = id;
        let mut rest = id;
        let mut picks = vec![0; axes.len()];
        for (i, axis) in axes.iter().enumerate().rev() {
            picks[i] = rest % axis.values.len();
            rest /= axis.values.len();
        }
        // A swept preset replaces the machine first; other machine keys then edit it.
        for (axis, &k) in axes.iter().zip(&picks) {
            if let (true, Value::Text(name)) = (axis.param == "machine.preset", &axis.values[k]) {
                if !presets.iter().any(|(n, _, _)| n == name) {
                    let (m, _, _) = crate::input::machine_file::load_preset(name, &src.path, src)?;
                    let mname = m.name.clone();
                    presets.push((name.clone(), m, mname));
                }
                if let Some((_, m, mname)) = presets.iter().find(|(n, _, _)| n == name) {
                    run.machine = Some(m.clone());
                    run.machine_name = mname.clone();
                }
                if run
                    .machine
                    .as_ref()
                    .is_some_and(|m| m.axis(&run.axis).is_none())
                {
                    return Err(src.error_at(
                        "sweep.machine.preset",
                        format!("machine `{name}` has no axis `{}` (move.axis)", run.axis),
                    ));
                }
            }
        }
        for (axis, &k) in axes.iter().zip(&picks) {
            let v = &axis.values[k];
            run.set(&axis.param, v)
                .map_err(|m| src.error_at(&format!("sweep.{}", axis.param), m))?;
            run.swept.push((axis.param.clone(), v.clone()));
        }
        if let Some(c) = &run.corner {
            // A corner run's move length is its path length.
            run.distance_mm = c.leg_in_mm + c.leg_out_mm;
        }
        validate_run(&run, src)?;
        runs.push(run);
    }
    Ok(runs)
}

/// The key to blame for parameter `param` of `run`: the sweep axis if it is swept.
fn blame(run: &RunSpec, param: &str) -> String {
    if run.swept.iter().any(|(p, _)| p == param) {
        format!("sweep.{param}")
    } else {
        param.to_string()
    }
}

fn validate_observe(run: &RunSpec, src: &Source) -> Result<(), Error> {
    if !(run.window_s.is_finite() && run.window_s > 0.0) {
        return Err(src.error_at(
            "observe.window_s",
            format!("must be a finite number > 0 (s), got {}", run.window_s),
        ));
    }
    if !(run.sample_rate_hz.is_finite() && run.sample_rate_hz > 0.0) {
        return Err(src.error_at(
            "observe.sample_rate_hz",
            format!(
                "must be a finite number > 0 (Hz), got {}",
                run.sample_rate_hz
            ),
        ));
    }
    if run.window_s * run.sample_rate_hz > 1e8 {
        return Err(src.error_at(
            "observe.sample_rate_hz",
            "window_s * sample_rate_hz exceeds 1e8 samples; lower one of them",
        ));
    }
    if let Some(h) = run.max_step_s
        && !(h.is_finite() && h > 0.0)
    {
        return Err(src.error_at(
            "sim.max_step_s",
            format!("must be a finite number > 0 (s), got {h}"),
        ));
    }
    if run.bands_um.is_empty() || run.bands_um.iter().any(|b| !(b.is_finite() && *b > 0.0)) {
        return Err(src.error_at(
            "observe.bands_um",
            "give one or more bands, each a finite number > 0 (um)",
        ));
    }
    Ok(())
}

/// The scenario's machine: `(physical machine or None for the modes form, name, driver
/// model)`.
fn resolve_machine(
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

/// Whether `kind` needs a jerk limit: every kind but the trapezoid.
pub fn needs_jerk(kind: ProfileKind) -> bool {
    kind != ProfileKind::Trapezoid
}

fn validate_run(run: &RunSpec, src: &Source) -> Result<(), Error> {
    if let Some(c) = &run.corner {
        c.validate(run).map_err(|(key, m)| src.error_at(&key, m))?;
    }
    for (name, value) in [
        ("move.distance_mm", run.distance_mm),
        ("move.start_mm", run.start_mm),
    ] {
        if !value.is_finite() {
            return Err(src.error_at(&blame(run, name), format!("must be finite, got {value}")));
        }
    }
    let limits = [
        ("limits.vmax_mm_s", Some(run.vmax_mm_s), "mm/s"),
        ("limits.amax_mm_s2", Some(run.amax_mm_s2), "mm/s^2"),
        ("limits.jmax_mm_s3", run.jmax_mm_s3, "mm/s^3"),
    ];
    for (key, value, unit) in limits {
        if let Some(v) = value.filter(|v| !(v.is_finite() && *v > 0.0)) {
            return Err(src.error_at(
                &blame(run, key),
                format!("must be a finite number > 0 ({unit}), got {v}"),
            ));
        }
    }
    if needs_jerk(run.profile) && run.jmax_mm_s3.is_none() {
        return Err(src.error_at(
            "limits",
            format!(
                "profile kind `{}` needs `jmax_mm_s3` in [limits] (every kind but `trapezoid` is jerk-limited: scurve, fourjerk, pvt_sym, pvt_asym)",
                run.profile
            ),
        ));
    }
    if let Some(sh) = &run.shaper
        && let Err((key, message)) = sh.validate()
    {
        return Err(src.error_at(&blame(run, key), message));
    }
    if let Some(scan) = &run.scan
        && let Err((key, message)) = scan.validate()
    {
        return Err(src.error_at(&blame(run, &format!("scan.{key}")), message));
    }
    if let Some(machine) = &run.machine {
        let machine_swept = || {
            run.swept
                .iter()
                .find(|(p, _)| p.starts_with("machine."))
                .map_or("machine".to_string(), |(p, _)| format!("sweep.{p}"))
        };
        if let Err(e) = machine.validate() {
            return Err(src.error_at(&machine_swept(), e.to_string()));
        }
        if let Some(a) = machine.axis(&run.axis)
            && let Some((lo, hi)) = a.travel_m()
        {
            let (lo_mm, hi_mm) = (lo * 1e3, hi * 1e3);
            for (name, x) in [
                ("move.start_mm", run.start_mm),
                ("move.distance_mm", run.start_mm + run.distance_mm),
            ] {
                if !(lo_mm..=hi_mm).contains(&x) {
                    return Err(src.error_at(
                        &blame(run, name),
                        format!(
                            "the move reaches {x} mm, outside the belt travel of axis `{}`: {lo_mm:.1} to {hi_mm:.1} mm (the carriage must stay 5 mm from pulley and idler)",
                            run.axis
                        ),
                    ));
                }
            }
        }
    }
    for (i, m) in run.modes.iter().enumerate() {
        if let Err(e) = Mode::new(m.frequency_hz, m.damping_ratio, m.weight) {
            let field = if !(m.frequency_hz.is_finite() && m.frequency_hz > 0.0) {
                "frequency_hz"
            } else if !(0.0..1.0).contains(&m.damping_ratio) {
                "damping_ratio"
            } else {
                "weight"
            };
            let swept = format!("machine.modes.{i}.{field}");
            let key = if run.swept.iter().any(|(p, _)| *p == swept) {
                format!("sweep.{swept}")
            } else {
                "machine.modes".to_string()
            };
            return Err(src.error_at(&key, format!("mode {i}: {e}")));
        }
    }
    Ok(())
}

/// Load a scenario file and expand it into validated runs.
pub fn load_runs(
    path: &std::path::Path,
) -> Result<(crate::input::scenario::Scenario, Vec<RunSpec>), Error> {
    let (sc, src) = crate::input::scenario::load(path)?;
    let runs = expand(&sc, &src)?;
    Ok((sc, runs))
}
