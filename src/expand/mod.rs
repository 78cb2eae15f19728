//! Sweep expansion: a scenario becomes a list of fully resolved, validated runs. The same
//! file always gives the same runs in the same order (the only I/O is reading a machine
//! file the scenario names by path).
//!
//! The base run comes from the scenario's core tables and the studies' tables (each
//! registered study parses its own, `crate::studies`); the sweep axes ([`axes`]) then vary it,
//! the last axis fastest, and every run is checked ([`validate`]).

pub mod axes;
pub mod current;
pub mod machine;
pub mod validate;

use std::path::Path;

use crate::input::machine_form::MachineForm;
use settle_planner::ProfileKind;

use crate::error::Error;
use crate::input::scenario::{MoveSpec, Scenario};
use crate::input::source::Source;
use crate::spec::backend::Backend;
use crate::spec::run_spec::{RunSpec, SWEEPABLE};
use crate::spec::value::Value;
use crate::studies::{self, Role, Study, StudyState};

pub use axes::{Axis, MAX_RUNS};

/// Read a scenario file (its core and every study's table).
pub fn load(path: &Path) -> Result<(Scenario, Source), Error> {
    crate::input::scenario::load(path, &studies::tables())
}

/// Parse scenario text (see [`load`]); `path` is used in error messages.
pub fn parse(text: &str, path: &Path) -> Result<(Scenario, Source), Error> {
    crate::input::scenario::parse(text, path, &studies::tables())
}

/// Load a scenario file and expand it into validated runs.
pub fn load_runs(path: &Path) -> Result<(Scenario, Vec<RunSpec>), Error> {
    let (sc, src) = load(path)?;
    let runs = expand(&sc, &src)?;
    Ok((sc, runs))
}

/// Parse scenario text and expand it into validated runs.
pub fn parse_runs(text: &str, path: &Path) -> Result<(Scenario, Vec<RunSpec>), Error> {
    let (sc, src) = parse(text, path)?;
    let runs = expand(&sc, &src)?;
    Ok((sc, runs))
}

/// Everything that can be swept, for messages: the keys of every run, then each study's.
pub fn sweepable() -> String {
    let mut out = SWEEPABLE.to_string();
    for k in studies::all() {
        if let (Some(t), s) = (k.table(), k.sweepable())
            && !s.is_empty()
        {
            out.push_str(&format!("; with a [{t}] table: {s}"));
        }
    }
    out
}

/// How a study is given in a scenario, for messages: `[corner] (a corner path)`.
fn given_as(k: &dyn Study) -> String {
    format!("[{}] (a {})", k.table().unwrap_or("move"), k.name())
}

/// The studies' states from their tables, and the move every run starts from: `[move]`
/// (`None`), or a path study's stand-in for it (with the key its profile kind is blamed on).
type BaseMotion = (Vec<Box<dyn StudyState>>, MoveSpec, Option<&'static str>);

fn base_motion(sc: &Scenario, src: &Source) -> Result<BaseMotion, Error> {
    let mut states = Vec::new();
    let mut motion: Option<&dyn Study> = None;
    for k in studies::all() {
        let Some(state) = k.parse(src)? else {
            continue;
        };
        if k.role() != Role::Modifier {
            if let Some(m) = motion {
                return Err(src.error_at(
                    k.table().unwrap_or("name"),
                    format!(
                        "{} cannot be combined with {}: give one motion",
                        given_as(*k),
                        given_as(m)
                    ),
                ));
            }
            motion = Some(*k);
        }
        states.push(state);
    }
    let paths: Vec<String> = studies::all()
        .iter()
        .filter(|k| k.role() == Role::Path)
        .map(|k| given_as(*k))
        .collect();
    let path = motion.filter(|k| k.role() == Role::Path).and_then(|k| {
        let state = states.iter().find(|s| Some(s.table()) == k.table())?;
        Some((k, k.path_move(&**state)?))
    });
    match (&sc.move_, path) {
        (Some(m), None) => Ok((states, m.clone(), None)),
        (None, Some((_, p))) => Ok((
            states,
            MoveSpec {
                distance_mm: 0.0,
                start_mm: 0.0,
                profile: p.profile,
                axis: p.axis,
            },
            Some(p.profile_key),
        )),
        (Some(_), Some((k, _))) => Err(src.error_at(
            k.table().unwrap_or("move"),
            format!(
                "give either [move] (a point-to-point move) or {}, not both",
                given_as(k)
            ),
        )),
        (None, None) => Err(src.error_at(
            "name",
            format!(
                "missing the motion: give [move] (a point-to-point move) or {}",
                paths.join(" or ")
            ),
        )),
    }
}

/// A scenario's sweep before expansion: the base run and the axes.
#[derive(Debug, Clone)]
pub struct Sweep {
    /// The run every point starts from.
    pub base: RunSpec,
    /// The sweep axes, in the order written.
    pub axes: Vec<Axis>,
    /// The number of runs (the product of the axes' lengths).
    pub total: usize,
}

/// The base run and the sweep axes of a scenario (checked, not yet expanded).
pub fn sweep_of(sc: &Scenario, src: &Source) -> Result<Sweep, Error> {
    let (states, mv, path_profile_key) = base_motion(sc, src)?;
    let is_path = path_profile_key.is_some();
    let profile_key = path_profile_key.unwrap_or("move.profile");
    let base_profile =
        ProfileKind::parse(&mv.profile).map_err(|e| src.error_at(profile_key, e.to_string()))?;
    let machine::Resolved {
        form: machine,
        name: machine_name,
        driver,
    } = machine::resolve_machine(sc, src)?;
    let axis_names = machine.axis_names();
    if !is_path && !axis_names.contains(&mv.axis) {
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
        profile_params: settle_planner::ProfileParams::default(),
        studies: states,
    };
    validate::validate_observe(&base, src)?;
    if sc.sweep.len() > validate::MAX_SWEEP_AXES {
        return Err(src.error_at(
            "sweep",
            format!(
                "{} sweep axes; at most {}",
                sc.sweep.len(),
                validate::MAX_SWEEP_AXES
            ),
        ));
    }
    let axes = axes::axes(sc, src, &base)?;
    current::check(sc, src, &axes)?;
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
    if axes.iter().any(|a| a.param == "machine.preset") && base.machine.physical().is_none() {
        return Err(src.error_at(
            "sweep.machine.preset",
            "sweeping presets needs a physical machine: give `preset` in [machine], not `modes`",
        ));
    }
    Ok(Sweep { base, axes, total })
}

/// Expand a scenario into validated runs: the base run, then the cartesian product of the
/// sweep axes in the order written (the last axis varies fastest).
pub fn expand(sc: &Scenario, src: &Source) -> Result<Vec<RunSpec>, Error> {
    let runs = sweep_runs(sc, src)?;
    let runs: &dyn crate::spec::runs::RunList = &runs;
    Ok(runs.iter().map(std::borrow::Cow::into_owned).collect())
}

/// The runs of a sweep, made on demand from their ids: [`Sweep`]'s base and axes, with the
/// machines of a swept preset loaded once.
#[derive(Debug, Clone)]
struct SweepRuns {
    base: RunSpec,
    axes: Vec<Axis>,
    total: usize,
    /// Swept presets: (name as written, machine, machine name).
    presets: Vec<(String, MachineForm, String)>,
}

/// What makes run `id` fail: the key to blame and the message.
type Blame = (String, String);

impl SweepRuns {
    /// The axes' value indices of run `id` (the last axis varies fastest).
    fn picks(&self, id: usize) -> Vec<usize> {
        let mut rest = id;
        let mut picks = vec![0; self.axes.len()];
        for (i, axis) in self.axes.iter().enumerate().rev() {
            picks[i] = rest % axis.values.len();
            rest /= axis.values.len();
        }
        picks
    }

    /// The swept preset of run `id`, if presets are swept.
    fn preset_of(&self, picks: &[usize]) -> Option<&str> {
        self.axes.iter().zip(picks).find_map(|(axis, &k)| {
            match (axis.param == "machine.preset", &axis.values[k]) {
                (true, Value::Text(name)) => Some(name.as_str()),
                _ => None,
            }
        })
    }

    /// Run `id`, with its presets loaded into `self.presets`.
    fn build(&self, id: usize) -> Result<RunSpec, Blame> {
        let mut run = self.base.clone();
        run.id = id;
        let picks = self.picks(id);
        // A swept preset replaces the machine first; other machine keys then edit it.
        for (axis, &k) in self.axes.iter().zip(&picks) {
            if let (true, Value::Text(name)) = (axis.param == "machine.preset", &axis.values[k]) {
                if let Some((_, m, mname)) = self.presets.iter().find(|(n, _, _)| n == name) {
                    run.machine = m.clone();
                    run.machine_name = mname.clone();
                }
                if run.machine.physical().is_some() && !run.machine.has_axis(&run.axis) {
                    return Err((
                        "sweep.machine.preset".to_string(),
                        format!("machine `{name}` has no axis `{}` (move.axis)", run.axis),
                    ));
                }
            }
        }
        for (axis, &k) in self.axes.iter().zip(&picks) {
            let v = &axis.values[k];
            let key = format!("sweep.{}", axis.param);
            let known = run.set(&axis.param, v).map_err(|m| (key.clone(), m))?;
            if !known {
                return Err((
                    key,
                    format!("`{}` cannot be swept; allowed: {}", axis.param, sweepable()),
                ));
            }
            run.swept.push((axis.param.clone(), v.clone()));
        }
        // A path study's move length is its path length.
        if let Some(d) = studies::motion(&run).path_length_mm(&run) {
            run.distance_mm = d;
        }
        Ok(run)
    }
}

impl crate::spec::runs::MakeRun for SweepRuns {
    fn total(&self) -> usize {
        self.total
    }

    fn make(&self, id: usize) -> RunSpec {
        match self.build(id) {
            Ok(run) => run,
            // Every run was built and checked when the sweep was expanded.
            Err((key, message)) => panic!("run {id} of a checked sweep: {key}: {message}"),
        }
    }

    fn set_backend(&mut self, backend: Backend) {
        self.base.backend = backend;
    }
}

/// Expand a scenario into validated runs made on demand ([`expand`] as a
/// [`crate::spec::runs::Runs`]: every run is made and checked here, none is kept).
pub fn sweep_runs(sc: &Scenario, src: &Source) -> Result<crate::spec::runs::Runs, Error> {
    let Sweep { base, axes, total } = sweep_of(sc, src)?;
    let mut runs = SweepRuns {
        base,
        axes,
        total,
        presets: Vec::new(),
    };
    type ModesKey = (MachineForm, f64, String);
    let mut last_modes: Option<(ModesKey, Option<(f64, f64)>)> = None;
    for id in 0..total {
        let picks = runs.picks(id);
        if let Some(name) = runs.preset_of(&picks)
            && !runs.presets.iter().any(|(n, _, _)| n == name)
        {
            let name = name.to_string();
            let m = machine::swept_preset(&name, src)?.form;
            let mname = m.physical().map(|m| m.name.clone()).unwrap_or_default();
            runs.presets.push((name, m, mname));
        }
        let run = runs.build(id).map_err(|(key, m)| src.error_at(&key, m))?;
        validate::validate_run(&run, src)?;
        // The modes change only with the machine, its modes, the moved axis or where the
        // move starts: most sweeps linearise the machine once.
        let range = match &last_modes {
            Some(((m, start, axis), r))
                if *m == run.machine && *start == run.start_mm && *axis == run.axis =>
            {
                *r
            }
            _ => {
                let r = validate::mode_range_hz(&run);
                let key = (run.machine.clone(), run.start_mm, run.axis.clone());
                last_modes = Some((key, r));
                r
            }
        };
        validate::validate_sampling(&run, range, src)?;
    }
    // The values as written, which the sweep may have overridden in every run (checked
    // after the runs, whose errors name the sweep axis to blame).
    validate::validate_base(&runs.base, src)?;
    Ok(crate::spec::runs::Runs::new(Box::new(runs)))
}
