//! `settle validate`: every backend against the closed form, and the engines against each
//! other, on standard cases (each preset and the quickstart's 40 Hz mode; trapezoid and
//! S-curve; three distances).
//!
//! Per case and backend (linear driver, belt stiffness frozen at the start: the model the
//! closed form solves):
//! - **frequency**: the dominant mode measured from the simulated free response after the
//!   move (matrix pencil, [`settle_identify::fit::pencil`]) against the analytic eigenvalue;
//! - **numerical damping**: the measured damping ratio of that mode against the analytic
//!   one, as a share of the physical damping;
//! - **residual**: the peak residual vibration against the closed form
//!   ([`settle_sim::closed_form::LinearResponse`]) at the same sample times;
//! - **settle**: the settle time (first band) against the modal backend's;
//! - **engines**: residual and settle time of each engine against the first engine.
//!
//! A second table shows what the linear model leaves out (information, no thresholds):
//! the real belt's position-dependent stiffness (on the first engine), and the full
//! stepper driver (on every engine, so rapier's and MuJoCo's can be compared).
//! Adding a backend is one line in [`ENGINES`].

mod markdown;

use std::path::Path;

use settle_planner::{Limits, Profile, ProfileKind, State, Trajectory};
use settle_sim::closed_form::LinearResponse;
use settle_sim::machine::Machine;
use settle_sim::{AxisModel, BeltModel, DriverMode, Mode};

use crate::error::Error;
use crate::execute::{Observe, SimOptions, run_trajectory};
use crate::measure::metrics::Metrics;
use crate::measure::series::Series;
use crate::output::atomic::write_atomic;
use crate::spec::backend::{Backend, NO_MUJOCO};

pub use markdown::markdown;

/// The time-stepping engines validate compares (the modal backend is the reference).
/// Adding a backend here adds it to the table and to the engine comparison.
pub const ENGINES: &[Backend] = &[Backend::Rapier, Backend::Mujoco];

/// Largest frequency error of the dominant mode (%).
pub const FREQUENCY_PCT: f64 = 0.5;
/// Largest residual error against the closed form (%).
pub const RESIDUAL_PCT: f64 = 2.0;
/// Largest difference between engines, and of settle times against the modal backend (%).
pub const ENGINES_PCT: f64 = 3.0;
/// Largest numerical damping, as a share of the physical damping (%).
pub const DAMPING_PCT: f64 = 10.0;
/// Residuals below this (um) are compared in absolute terms (a cancelling move's residual
/// is all rounding; 2 % of 0.1 um is 2 nm).
pub const RESIDUAL_FLOOR_UM: f64 = 0.1;

/// One standard case.
#[derive(Debug, Clone)]
pub struct Case {
    /// Label, e.g. `printer_xy/x scurve 10 mm`.
    pub name: String,
    axes: Vec<AxisModel>,
    /// Physical machine (for the model-effects table).
    machine: Option<Machine>,
    axis: usize,
    profile: Profile,
    /// Whether the model-effects table shows this case (the middle distance).
    effects: bool,
}

/// One row: a case on a backend.
#[derive(Debug, Clone)]
pub struct Row {
    /// Case label.
    pub case: String,
    /// Backend.
    pub backend: Backend,
    /// Dominant mode: analytic natural frequency (Hz).
    pub f_analytic_hz: f64,
    /// Measured (Hz).
    pub f_measured_hz: f64,
    /// Analytic damping ratio of the dominant mode.
    pub zeta_analytic: f64,
    /// Measured.
    pub zeta_measured: f64,
    /// Residual peak, closed form (um).
    pub residual_closed_um: f64,
    /// Residual peak, simulated (um).
    pub residual_um: f64,
    /// Settle time per band of the modal backend (s).
    pub settle_modal_s: Vec<Option<f64>>,
    /// Settle time per band of this backend (s).
    pub settle_s: Vec<Option<f64>>,
    /// Residual and settle-time difference to the first engine (%), for other engines.
    pub engine_pct: Option<f64>,
    /// Which checks failed (empty = pass).
    pub failures: Vec<String>,
}

impl Row {
    /// Frequency error (%).
    pub fn f_err_pct(&self) -> f64 {
        (self.f_measured_hz / self.f_analytic_hz - 1.0) * 100.0
    }
    /// Numerical damping: measured minus analytic damping ratio, as % of the analytic.
    pub fn damping_pct(&self) -> f64 {
        (self.zeta_measured / self.zeta_analytic - 1.0) * 100.0
    }
    /// Residual error against the closed form (%, with the floor).
    pub fn residual_err_pct(&self) -> f64 {
        (self.residual_um - self.residual_closed_um)
            / self.residual_closed_um.max(RESIDUAL_FLOOR_UM)
            * 100.0
    }
}

/// One row of the model-effects table.
#[derive(Debug, Clone)]
pub struct Effect {
    /// Case label.
    pub case: String,
    /// Residual peak and settle time (first band) of the linear model on rapier (frozen belt).
    pub linear: (f64, Option<f64>),
    /// The same with the belt's stiffness varying with position.
    pub varying_belt: (f64, Option<f64>),
    /// The same with the full stepper driver (and the varying belt), per engine: the
    /// first engine, then every other engine validated (MuJoCo when built): residual peak
    /// (um), settle time (s) and lost steps.
    pub full_driver: Vec<(Backend, f64, Option<f64>, u32)>,
}

/// Everything validate measured.
#[derive(Debug, Clone)]
pub struct Validation {
    /// Bands (um) of the settle times.
    pub bands_um: Vec<f64>,
    /// Per case and backend.
    pub rows: Vec<Row>,
    /// Model effects (information).
    pub effects: Vec<Effect>,
}

impl Validation {
    /// True when every row passes.
    pub fn pass(&self) -> bool {
        self.rows.iter().all(|r| r.failures.is_empty())
    }
}

fn preset(name: &str) -> Machine {
    let (_, path, text) = crate::input::machine_file::PRESETS
        .iter()
        .find(|(n, _, _)| *n == name)
        .copied()
        .unwrap_or(crate::input::machine_file::PRESETS[0]);
    match crate::input::machine_file::parse(text, Path::new(path)) {
        Ok((m, _)) => m,
        // The presets are parsed by a test; a broken one is a build bug.
        Err(e) => panic!("built-in preset {name} does not parse: {e}"),
    }
}

/// The standard cases.
pub fn cases() -> Vec<Case> {
    let mut out = Vec::new();
    let mut add = |label: &str,
                   axes: Vec<AxisModel>,
                   machine: Option<Machine>,
                   axis: usize,
                   lim: Limits,
                   dists: &[f64]| {
        for kind in [ProfileKind::Trapezoid, ProfileKind::SCurve] {
            for (i, &d) in dists.iter().enumerate() {
                let Ok(profile) = kind.rest_to_rest(0.0, d * 1e-3, &lim) else {
                    continue;
                };
                out.push(Case {
                    name: format!("{label} {kind} {d} mm"),
                    axes: axes.clone(),
                    machine: machine.clone(),
                    axis,
                    profile,
                    effects: i == 1,
                });
            }
        }
    };
    let printer = Limits::new(0.3, 3.0, Some(100.0));
    let stage = Limits::new(0.05, 2.0, Some(200.0));
    if let (Ok(printer), Ok(stage)) = (printer, stage) {
        if let Ok(modes) = Mode::new(40.0, 0.05, 1.0).and_then(|m| AxisModel::from_modes("x", &[m]))
        {
            add(
                "modes 40 Hz",
                vec![modes],
                None,
                0,
                printer,
                &[2.0, 10.0, 50.0],
            );
        }
        let p = preset("printer_xy");
        if let Ok(axes) = p.compile(DriverMode::Linear) {
            for i in 0..axes.len() {
                let label = format!("printer_xy/{}", axes[i].name);
                add(
                    &label,
                    axes.clone(),
                    Some(p.clone()),
                    i,
                    printer,
                    &[2.0, 10.0, 50.0],
                );
            }
        }
        let s = preset("leadscrew_stage");
        if let Ok(axes) = s.compile(DriverMode::Linear) {
            add(
                "leadscrew_stage/x",
                axes,
                Some(s.clone()),
                0,
                stage,
                &[1.0, 5.0, 20.0],
            );
        }
    }
    out
}

fn trajectory(case: &Case) -> Trajectory {
    let profiles = (0..case.axes.len())
        .map(|i| {
            if i == case.axis {
                case.profile.clone()
            } else {
                Profile::empty(State::default())
            }
        })
        .collect();
    Trajectory::new(profiles).unwrap_or_else(|_| Trajectory::single(case.profile.clone()))
}

fn observe() -> Observe {
    Observe {
        window_s: 0.5,
        sample_rate_hz: 10_000.0,
        bands_um: vec![10.0, 1.0],
    }
}

/// A run's post-move toolhead error of the moving axis (m), from its series.
fn post_move_error(series: &Series, axis: &str, t_end: f64, target: f64) -> Vec<f64> {
    let Some(ch) = series.channel(&format!("toolhead_{axis}")) else {
        return Vec::new();
    };
    series
        .t_s
        .iter()
        .zip(&ch.data)
        .filter(|(t, _)| **t >= t_end)
        .map(|(_, x)| x - target)
        .collect()
}

fn simulate(
    case: &Case,
    backend: Backend,
    options: &SimOptions,
    axes: Vec<AxisModel>,
) -> Result<(Metrics, Series), String> {
    let mut series = Series::default();
    let m = run_trajectory(
        axes,
        backend,
        options,
        &trajectory(case),
        &observe(),
        Some(&mut series),
    )
    .map_err(|e| e.to_string())?;
    Ok((m, series))
}

/// Validate `backends` (the modal reference always runs). Errors only for a backend this
/// build does not have.
pub fn run(backends: &[Backend]) -> Result<Validation, String> {
    for b in backends {
        if !b.available() {
            return Err(format!("{b}: {}", NO_MUJOCO));
        }
    }
    let obs = observe();
    let dt = 1.0 / obs.sample_rate_hz;
    let frozen = SimOptions {
        belt: BeltModel::Frozen,
        max_step_s: None,
        linearise_at_m: None,
        step_at_m: None,
    };
    let mut rows = Vec::new();
    let mut effects = Vec::new();
    let engines: Vec<Backend> = ENGINES
        .iter()
        .copied()
        .filter(|b| backends.contains(b))
        .collect();
    for case in cases() {
        let axis = &case.axes[case.axis];
        let t_end = case.profile.duration_s();
        let target = case.profile.end().p;
        let closed = LinearResponse::new(axis, &case.profile).map_err(|e| e.to_string())?;
        let n = (obs.window_s * obs.sample_rate_hz).ceil() as usize;
        let closed_peak = (0..=n)
            .map(|i| closed.error_at(t_end + i as f64 * dt).abs())
            .fold(0.0, f64::max)
            * 1e6;
        let analytic = closed.modes();
        let (f_an, z_an, _) = analytic
            .first()
            .copied()
            .unwrap_or((f64::NAN, f64::NAN, 0.0));
        let f_max = analytic.iter().map(|m| m.0).fold(0.0, f64::max);
        let decimate = ((obs.sample_rate_hz / (5.0 * f_max)).floor() as usize).clamp(1, 10);
        let order = 2 * axis.lumped.dof();
        let mut modal_settle = Vec::new();
        let mut first_engine: Option<(f64, Vec<Option<f64>>)> = None;
        let mut list = vec![Backend::Modal];
        list.extend(backends.iter().copied().filter(|b| *b != Backend::Modal));
        for backend in list {
            let (m, series) = simulate(&case, backend, &frozen, case.axes.clone())?;
            let e = post_move_error(&series, &axis.name, t_end, target);
            let ys: Vec<f64> = e.iter().step_by(decimate).take(400).copied().collect();
            let fit = settle_identify::fit::pencil::fit(&ys, dt * decimate as f64, order)
                .unwrap_or_default();
            // The measured mode nearest the analytic dominant one.
            let measured = fit.iter().min_by(|a, b| {
                (a.frequency_hz - f_an)
                    .abs()
                    .total_cmp(&(b.frequency_hz - f_an).abs())
            });
            let (f_me, z_me) =
                measured.map_or((f64::NAN, f64::NAN), |m| (m.frequency_hz, m.damping_ratio));
            let settle = m.settle_time_s.clone();
            if backend == Backend::Modal {
                modal_settle = settle.clone();
            }
            let mut row = Row {
                case: case.name.clone(),
                backend,
                f_analytic_hz: f_an,
                f_measured_hz: f_me,
                zeta_analytic: z_an,
                zeta_measured: z_me,
                residual_closed_um: closed_peak,
                residual_um: m.residual_peak_um,
                settle_modal_s: modal_settle.clone(),
                settle_s: settle.clone(),
                engine_pct: None,
                failures: Vec::new(),
            };
            if !within(row.f_err_pct(), FREQUENCY_PCT) {
                row.failures
                    .push(format!("frequency {:+.3} %", row.f_err_pct()));
            }
            if !within(row.damping_pct(), DAMPING_PCT) {
                row.failures
                    .push(format!("numerical damping {:+.2} %", row.damping_pct()));
            }
            if !within(row.residual_err_pct(), RESIDUAL_PCT) {
                row.failures
                    .push(format!("residual {:+.3} %", row.residual_err_pct()));
            }
            if !settles_agree(&modal_settle, &settle, dt) {
                row.failures.push("settle time vs modal".into());
            }
            if engines.contains(&backend) {
                match &first_engine {
                    None => first_engine = Some((m.residual_peak_um, settle)),
                    Some((r0, s0)) => {
                        let r0 = *r0;
                        let d = (m.residual_peak_um - r0) / r0.max(RESIDUAL_FLOOR_UM) * 100.0;
                        row.engine_pct = Some(d);
                        if !within(d, ENGINES_PCT) || !settles_agree(s0, &settle, dt) {
                            row.failures.push(format!("engines {d:+.2} %"));
                        }
                    }
                }
            }
            rows.push(row);
        }
        // Model effects: the middle distance of physical machines, on the first engine
        // (rapier); the full driver on every engine.
        if let (Some(machine), Some(&engine)) = (&case.machine, engines.first())
            && case.effects
        {
            let lin = simulate(&case, engine, &frozen, case.axes.clone())?.0;
            let var = simulate(&case, engine, &SimOptions::default(), case.axes.clone())?.0;
            let full_axes = machine
                .compile(DriverMode::Full)
                .map_err(|e| e.to_string())?;
            let mut full_driver = Vec::new();
            for &b in &engines {
                let full = simulate(&case, b, &SimOptions::default(), full_axes.clone())?.0;
                full_driver.push((
                    b,
                    full.residual_peak_um,
                    full.settle_time_s[0],
                    full.status.lost_steps(),
                ));
            }
            effects.push(Effect {
                case: case.name.clone(),
                linear: (lin.residual_peak_um, lin.settle_time_s[0]),
                varying_belt: (var.residual_peak_um, var.settle_time_s[0]),
                full_driver,
            });
        }
    }
    Ok(Validation {
        bands_um: obs.bands_um.clone(),
        rows,
        effects,
    })
}

/// `|x| <= limit`, false for NaN.
fn within(x: f64, limit: f64) -> bool {
    x.abs() <= limit
}

/// Settle times of every band agree.
fn settles_agree(reference: &[Option<f64>], got: &[Option<f64>], dt: f64) -> bool {
    reference.len() == got.len()
        && reference
            .iter()
            .zip(got)
            .all(|(a, b)| settle_agrees(*a, *b, dt))
}

/// Settle times agree within [`ENGINES_PCT`] of the reference or one sample.
fn settle_agrees(reference: Option<f64>, got: Option<f64>, dt: f64) -> bool {
    match (reference, got) {
        (Some(a), Some(b)) => (a - b).abs() <= (ENGINES_PCT / 100.0 * a).max(dt * 1.001),
        (None, None) => true,
        _ => false,
    }
}

/// What `settle validate` found, and how long it took.
#[derive(Debug, Clone)]
pub struct Validated {
    /// The tables.
    pub validation: Validation,
    /// Its Markdown (what is printed, and written to `out` when asked).
    pub markdown: String,
    /// Wall-clock time (s).
    pub elapsed_s: f64,
}

/// `settle validate [--backend B] [--out FILE]`: `backend` and the modal reference, or
/// every backend this build has; the Markdown also written to `out`.
pub fn validate(backend: Option<Backend>, out: Option<&Path>) -> Result<Validated, Error> {
    let backends: Vec<Backend> = match backend {
        Some(b) => vec![b],
        None => Backend::ALL.into_iter().filter(|b| b.available()).collect(),
    };
    if let Some(path) = out {
        // Checked before the work: a link or a device is not written.
        settle_files::write::check_target(path)?;
    }
    let started = std::time::Instant::now();
    let validation = run(&backends).map_err(|e| Error::input("--backend", e))?;
    let markdown = markdown(&validation);
    if let Some(path) = out {
        write_atomic(path, markdown.as_bytes())?;
    }
    Ok(Validated {
        validation,
        markdown,
        elapsed_s: started.elapsed().as_secs_f64(),
    })
}

impl Validated {
    /// What `settle validate` prints: the tables, then a count of the failed rows.
    pub fn report(&self) -> crate::workflows::Report {
        let v = &self.validation;
        let failed = v.rows.iter().filter(|r| !r.failures.is_empty()).count();
        let mut r = crate::workflows::Report::new(if v.pass() {
            crate::workflows::Exit::Ok
        } else {
            crate::workflows::Exit::Failed
        });
        r.stdout = self.markdown.clone();
        r.err(format!(
            "{} rows, {failed} failed ({:.1} s)",
            v.rows.len(),
            self.elapsed_s
        ));
        r
    }
}
