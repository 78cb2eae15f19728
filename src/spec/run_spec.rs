//! One point of a sweep, fully resolved: [`RunSpec`], and [`StudyState`], the per-run state
//! of a study (`crate::studies`) that a `RunSpec` carries without knowing the study.

use std::any::Any;

use settle_planner::{Limits, ProfileKind};
use settle_sim::DriverMode;

use crate::input::machine_form::MachineForm;
use crate::spec::backend::Backend;
use crate::spec::value::Value;

/// The per-run state of a study: its scenario table, resolved (e.g. the corner of a
/// corner run), set by the sweep through its keys (`corner.angle_deg`).
///
/// Implement [`StudyState::table`] and [`StudyState::set`] on a type that is `Clone`,
/// `PartialEq` and `Debug`; cloning and comparing come with it ([`StateBox`]). The study
/// reads its state back with [`RunSpec::state`].
pub trait StudyState: StateBox + std::fmt::Debug + Send + Sync {
    /// The scenario table the state comes from (`corner` for `[corner]`): swept keys
    /// `<table>.<key>` are set on it.
    fn table(&self) -> &'static str;

    /// Set swept key `key` (without the `<table>.` prefix) to `value`; the error says what
    /// the key takes.
    fn set(&mut self, key: &str, value: &Value) -> Result<(), String>;
}

/// Cloning and comparing a boxed [`StudyState`] (implemented for every `Clone + PartialEq`
/// state).
pub trait StateBox: Any {
    /// A boxed copy.
    fn clone_box(&self) -> Box<dyn StudyState>;
    /// Whether `other` is the same type with the same value.
    fn eq_box(&self, other: &dyn StudyState) -> bool;
}

impl<T: StudyState + Clone + PartialEq> StateBox for T {
    fn clone_box(&self) -> Box<dyn StudyState> {
        Box::new(self.clone())
    }

    fn eq_box(&self, other: &dyn StudyState) -> bool {
        (other as &dyn Any)
            .downcast_ref::<T>()
            .is_some_and(|o| o == self)
    }
}

impl Clone for Box<dyn StudyState> {
    fn clone(&self) -> Self {
        self.clone_box()
    }
}

impl PartialEq for Box<dyn StudyState> {
    fn eq(&self, other: &Self) -> bool {
        self.eq_box(&**other)
    }
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
    /// Signed move length (mm); a path study's path length.
    pub distance_mm: f64,
    /// Maximum speed (mm/s).
    pub vmax_mm_s: f64,
    /// Maximum acceleration (mm/s^2).
    pub amax_mm_s2: f64,
    /// Maximum jerk (mm/s^3), if given.
    pub jmax_mm_s3: Option<f64>,
    /// The machine: physical (preset, machine file or inline) or its modes per axis.
    pub machine: MachineForm,
    /// The machine's name (the preset's, or `modes`).
    pub machine_name: String,
    /// How the motors are driven (physical machines; `linear` for the modes form).
    pub driver: DriverMode,
    /// The axis that moves (a path study's axes joined by `+`, e.g. `x+y`).
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
    /// Parameters of the profile kinds that take any (PVT asymmetry, four-jerk BOW1..4
    /// scales); the planner's defaults unless `settle tune` searches them.
    pub profile_params: settle_planner::ProfileParams,
    /// The states of the studies whose tables the scenario has (at most one each).
    pub studies: Vec<Box<dyn StudyState>>,
}

/// The parameters every scenario can sweep, for messages (the studies add theirs).
pub const SWEEPABLE: &str = "profile, move.distance_mm, move.start_mm, limits.vmax_mm_s, \
limits.amax_mm_s2, limits.jmax_mm_s3, machine.modes.N.frequency_hz, machine.modes.N.damping_ratio, \
machine.modes.N.weight (N = 0-based mode index of axis x), machine.axis.<axis>.modes.N.<field> \
(the same for any axis), and for physical machines \
machine.axis.<axis>.<field> (e.g. machine.axis.x.mount.stiffness_n_per_m), machine.motor.<field> \
and machine.driver.<field> (every axis), machine.preset (preset names or machine files)";

/// Whether `kind` needs a jerk limit: every kind but the trapezoid.
pub fn needs_jerk(kind: ProfileKind) -> bool {
    kind != ProfileKind::Trapezoid
}

impl RunSpec {
    /// Kinematic limits in SI units (m, s).
    pub fn limits_si(&self) -> Result<Limits, settle_planner::PlanError> {
        Limits::new(
            self.vmax_mm_s * 1e-3,
            self.amax_mm_s2 * 1e-3,
            self.jmax_mm_s3.map(|j| j * 1e-3),
        )
    }

    /// The names of the machine's axes (physical or modes form), in order.
    pub fn axis_names(&self) -> Vec<String> {
        self.machine.axis_names()
    }

    /// The run's state of type `T` (a study's), if it has one.
    pub fn state<T: StudyState>(&self) -> Option<&T> {
        self.studies
            .iter()
            .find_map(|s| (&**s as &dyn Any).downcast_ref::<T>())
    }

    /// The run's state of type `T`, to change it.
    pub fn state_mut<T: StudyState>(&mut self) -> Option<&mut T> {
        self.studies
            .iter_mut()
            .find_map(|s| (&mut **s as &mut dyn Any).downcast_mut::<T>())
    }

    /// The state of the study whose table is `table`.
    pub fn state_of(&self, table: &str) -> Option<&dyn StudyState> {
        self.studies
            .iter()
            .find(|s| s.table() == table)
            .map(|s| &**s)
    }

    /// Give the run `state`, replacing its state of the same table.
    pub fn put_state(&mut self, state: Box<dyn StudyState>) {
        match self.studies.iter_mut().find(|s| s.table() == state.table()) {
            Some(s) => *s = state,
            None => self.studies.push(state),
        }
    }

    /// Remove the state of the study whose table is `table`.
    pub fn remove_state(&mut self, table: &str) {
        self.studies.retain(|s| s.table() != table);
    }

    /// The swept values as `key = value`, joined by `sep`.
    pub fn swept_text(&self, sep: &str) -> String {
        let parts: Vec<String> = self
            .swept
            .iter()
            .map(|(k, v)| format!("{k} = {v}"))
            .collect();
        parts.join(sep)
    }

    /// The key to blame for parameter `param`: the sweep axis if it is swept.
    pub fn blame(&self, param: &str) -> String {
        if self.swept.iter().any(|(p, _)| p == param) {
            format!("sweep.{param}")
        } else {
            param.to_string()
        }
    }

    /// Set swept parameter `param` to `value`: a key of every run, or `<table>.<key>` of a
    /// study state the run has. `Ok(false)`: no such parameter (the caller names the
    /// allowed ones).
    pub fn set(&mut self, param: &str, value: &Value) -> Result<bool, String> {
        let num = |v: &Value| v.number().ok_or_else(|| format!("`{param}` takes numbers"));
        if let Some((table, key)) = param.split_once('.')
            && let Some(state) = self.studies.iter_mut().find(|s| s.table() == table)
        {
            state.set(key, value)?;
            return Ok(true);
        }
        match param {
            "profile" => match value {
                Value::Study(k) => self.profile = *k,
                _ => return Err("`profile` takes profile kind names".into()),
            },
            "move.distance_mm" => self.distance_mm = num(value)?,
            "move.start_mm" => self.start_mm = num(value)?,
            "limits.vmax_mm_s" => self.vmax_mm_s = num(value)?,
            "limits.amax_mm_s2" => self.amax_mm_s2 = num(value)?,
            "limits.jmax_mm_s3" => self.jmax_mm_s3 = Some(num(value)?),
            // Resolved by the expander (it reads the preset); nothing to set here.
            "machine.preset" => {}
            other => {
                if let Some((axis, i, field)) = mode_param(other) {
                    let x = num(value)?;
                    let names = self.axis_names().join(", ");
                    let physical = self.machine.physical().is_some();
                    let modes = match &mut self.machine {
                        MachineForm::Modes(axes) => axes.as_mut_slice(),
                        MachineForm::Physical(_) => &mut [],
                    };
                    let Some(a) = modes.iter_mut().find(|a| a.axis == axis) else {
                        return Err(if physical {
                            format!(
                                "`{other}` needs a machine given by its modes, not a physical one"
                            )
                        } else {
                            format!("no axis `{axis}` with modes; the machine has {names}")
                        });
                    };
                    let n = a.modes.len();
                    let mode = a.modes.get_mut(i).ok_or_else(|| {
                        format!("mode index {i} out of range: axis `{axis}` has {n} mode(s)")
                    })?;
                    match field {
                        "frequency_hz" => mode.frequency_hz = x,
                        "damping_ratio" => mode.damping_ratio = x,
                        "weight" => mode.weight = x,
                        _ => return Ok(false),
                    }
                    return Ok(true);
                }
                if let Some(rest) = ["axis.", "motor.", "driver."]
                    .iter()
                    .find_map(|p| other.strip_prefix("machine.").filter(|r| r.starts_with(p)))
                {
                    let x = num(value)?;
                    let MachineForm::Physical(m) = &mut self.machine else {
                        return Err(format!(
                            "`{other}` needs a physical machine (preset or [machine.axis.*]), not modes"
                        ));
                    };
                    crate::spec::machine::set_machine_field(m, other, rest, x)?;
                    return Ok(true);
                }
                return Ok(false);
            }
        }
        Ok(true)
    }
}

/// A swept mode key: `machine.modes.N.<field>` (axis `x`) or
/// `machine.axis.<axis>.modes.N.<field>`, as `(axis, N, field)`.
pub fn mode_param(param: &str) -> Option<(&str, usize, &str)> {
    let (axis, rest) = match param.strip_prefix("machine.modes.") {
        Some(rest) => ("x", rest),
        None => {
            let rest = param.strip_prefix("machine.axis.")?;
            let (axis, rest) = rest.split_once('.')?;
            (axis, rest.strip_prefix("modes.")?)
        }
    };
    let (i, field) = rest.split_once('.')?;
    Some((axis, i.parse().ok()?, field))
}
