//! Executing runs: the machine's axes compiled for the run, its motion planned by its
//! study, the one [`sim_options`] every study's run is simulated with, the simulation
//! driver every command runs its plants on ([`driver`]), the plant of the chosen backend
//! ([`plant`]), a run as the driver's sink ([`simulate`]), the worker pool with progress
//! reported through a callback ([`pool`]) and interruption ([`interrupt`]).

pub mod cursor;
pub mod driver;
pub mod inner_breaks;
pub mod interrupt;
pub mod plant;
pub mod pool;
pub mod simulate;

use settle_sim::{AxisModel, DriverMode, SimError};

use crate::error::Error;
use crate::measure::metrics::Metrics;
use crate::measure::series::Series;
use crate::spec::backend::{Backend, NO_MUJOCO};
use crate::spec::run_spec::RunSpec;
use crate::spec::runs::RunList;

pub use plant::SimOptions;
pub use simulate::run_motion;

/// How a run is observed.
#[derive(Debug, Clone, PartialEq)]
pub struct Observe {
    /// Observation window after the move (s).
    pub window_s: f64,
    /// Sample rate (Hz).
    pub sample_rate_hz: f64,
    /// Settling bands (um).
    pub bands_um: Vec<f64>,
}

/// How `spec` is observed.
pub fn observe_of(spec: &RunSpec) -> Observe {
    Observe {
        window_s: spec.window_s,
        sample_rate_hz: spec.sample_rate_hz,
        bands_um: spec.bands_um.clone(),
    }
}

/// The simulation options of `spec`: the one place a run's settings (`[sim] max_step_s`)
/// become what the backends honour, whatever the run's kind.
pub fn sim_options(spec: &RunSpec) -> SimOptions {
    SimOptions {
        max_step_s: spec.max_step_s,
        ..SimOptions::default()
    }
}

/// The axes a run simulates: the machine compiled for the run's driver model, or one axis
/// per axis of the modes form.
pub fn axes_of(spec: &RunSpec) -> Result<Vec<AxisModel>, SimError> {
    spec.machine.axes(spec.driver)
}

/// Plan and simulate one run on its backend. When `record` is given, it is replaced by a
/// series with the run's channels ([`simulate::channels`]) and every sample is appended to
/// it. A study that measures more than the common metrics ([`crate::studies::Probe`]) gets
/// the series recorded (into `record`, or a series of its own) and adds its figures to an
/// ok run's metrics.
pub fn execute(spec: &RunSpec, record: Option<&mut Series>) -> Result<Metrics, Error> {
    let sim_err = |source| Error::Sim {
        run: spec.id,
        source,
    };
    let axes = axes_of(spec).map_err(sim_err)?;
    let names: Vec<String> = axes.iter().map(|a| a.name.clone()).collect();
    let planned = crate::studies::plan(spec, &names).map_err(|source| Error::Plan {
        run: spec.id,
        source,
    })?;
    let options = SimOptions {
        linearise_at_m: planned.linearise_at_m.clone(),
        step_at_m: planned.step_at_m.clone(),
        ..sim_options(spec)
    };
    let observe = observe_of(spec);
    // A trace kept in memory (recorded, or measured whole by the run's kind) is bounded;
    // the sweep checked the same before any run ([`crate::expand::validate`]).
    let kept = record.is_some() || planned.probe.is_some();
    let per_sample = simulate::channels(&axes).len() + 1;
    if let Err(m) =
        crate::expand::validate::check_run_size(spec, planned.motion.duration_s(), per_sample, kept)
    {
        return Ok(Metrics::failed(&spec.bands_um, m));
    }
    // A study that measures more than the common metrics gets the series recorded.
    let mut local = Series::default();
    let mut series = match record {
        Some(s) => Some(s),
        None => planned.probe.is_some().then_some(&mut local),
    };
    let mut motion = planned.motion;
    let m = run_motion(
        axes,
        spec.backend,
        &options,
        &mut motion,
        &observe,
        series.as_deref_mut(),
    )
    .map_err(|source| Error::Plan {
        run: spec.id,
        source,
    })?;
    if interrupt::requested() {
        return Err(Error::Interrupted { run: spec.id });
    }
    let mut m = m.map_err(sim_err)?;
    if let (Some(probe), Some(series)) = (planned.probe, series)
        && m.is_ok()
    {
        probe.measure(spec, series, &mut m)?;
    }
    Ok(m)
}

/// Set every run's backend, checking that this build has it and that it can simulate the
/// runs' models (the modal backend: linear driver only). Errors are input errors naming
/// the scenario file.
pub fn set_backend(
    path: &std::path::Path,
    runs: &mut [RunSpec],
    backend: Backend,
) -> Result<(), Error> {
    check_drivers(path, runs.iter().map(|r| r.driver), backend)?;
    for r in runs {
        r.backend = backend;
    }
    Ok(())
}

/// The error of [`set_backend`] when `backend` cannot run `runs`, without setting it.
pub fn check_backend(
    path: &std::path::Path,
    runs: &dyn RunList,
    backend: Backend,
) -> Result<(), Error> {
    check_drivers(path, runs.iter().map(|r| r.driver), backend)
}

/// The error of [`set_backend`] for runs with `drivers`.
fn check_drivers(
    path: &std::path::Path,
    mut drivers: impl Iterator<Item = DriverMode>,
    backend: Backend,
) -> Result<(), Error> {
    let err = |message: String| Error::input_key(path, "--backend", message);
    if !backend.available() {
        return Err(err(NO_MUJOCO.to_string()));
    }
    if backend == Backend::Modal
        && let Some(d) = drivers.find(|d| *d != DriverMode::Linear)
    {
        return Err(err(format!(
            "the modal backend is the exact solution of the linear model: it cannot run the `{d}` driver model; set `driver_model = \"linear\"` in [machine] or use --backend rapier"
        )));
    }
    Ok(())
}
