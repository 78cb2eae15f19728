//! G-code jobs in sweeps, a path study: the scenario's `[gcode]` table names a G-code file
//! (relative to the scenario), the firmware whose planner runs it and the layers to
//! simulate; the sweep varies `gcode.firmware`, the existing `shaper.*` keys (the shaper
//! goes into the job, on X and Y, as the firmware shapes) and the `[limits]` keys (the
//! firmware's velocity and acceleration limits; settle's planner also takes the jerk and
//! the profile kind).
//!
//! ```toml
//! [gcode]
//! file = "../gcode/prints/cube_layer.gcode"
//! firmware = "klipper"
//! layers = "0..0"
//! ```
//!
//! `layer_source` says where the file's layers come from, as `settle gcode
//! --layer-source` does: `auto` (slicer markers, else changes of Z), `markers`, `z`.
//!
//! The run's motion is the job's shaped X and Y (and Z), one trajectory. Without
//! `layers` it runs from the job's first move to its end. With `layers` it starts from
//! the whole job's state, as `settle gcode --layers` does: the job's chunks start a
//! pre-roll ([`preroll`]) of at least `ln(1e6) / sigma` before the range's first move
//! (`sigma` the slowest decay rate of the machine's linearised modes; no earlier than the
//! file's first move), so the vibration the layers before leave is in the range's
//! samples. `t = 0` is on the print clock's sample grid (`k / sample_rate_hz`, the grid
//! of `settle gcode`) so that both sample the same instants: the pre-roll's start moved
//! to the next instant of the grid, or, where the run starts with the job (at rest; a
//! shaped job starts before the first move, by half the shaper's duration), the instant
//! of the grid before, standing still until the job starts. The common metrics are those
//! of any run over that
//! trajectory: `move_time_s` is the pre-roll plus the range, the residual and the settle
//! time are measured after the range's last move. The study's probe measures the contour
//! error against the G-code's own geometry ([`contour`]) and adds to runs.csv
//! `print_time_s` (the whole file's, by the firmware's planner), `contour_worst_um`,
//! `contour_p95_um` (working samples of the range's moves, during the job; never the
//! pre-roll's), `contour_worst_line`, and the largest of each of the error's two parts
//! over the same samples ([`stats::Split`]): `smoothing_worst_um` and
//! `vibration_worst_um`. Bad G-code is reported when the sweep is
//! checked, with the file and line.
//!
//! A physical machine on the modal backend is linearised where the print is
//! ([`linpoint`]: the centre of the file's working moves), the point `settle gcode`
//! uses, for the whole file and for any layer range of it: a range gives the numbers of
//! the same layers in the whole job, and the study the numbers of `settle gcode`.
//!
//! A range that ends before the file does: the contour columns count the range's samples
//! up to its last command, as `settle gcode --layers` does (the whole job's samples after
//! it belong to the next layer's moves). The common metrics (`residual_*`, settle times)
//! are defined as for any run: the command then stands at the range's last point for the
//! observation window, as if the job stopped dead there (a range can end moving, and the
//! real job goes on); they measure that stop, not the print, and `settle gcode --layers`
//! reports no such ringing for a range that ends before the file.

pub mod box2;
pub mod command_path;
pub mod contour;
pub mod features;
pub mod fly;
pub mod linpoint;
pub mod position;
pub mod preroll;
pub mod stats;
pub mod stream;
pub mod work;

use std::collections::{BTreeMap, BTreeSet};
use std::path::PathBuf;
use std::sync::Mutex;

use serde::Deserialize;
use settle_gcode::job::{Job, JobConfig, PlannerConfig, ShaperSetting, parse_firmware};
use settle_gcode::{LayerMode, Reader};
use settle_planner::PlanError;
use settle_planner::firmware::Firmware;
use settle_planner::path::CornerStrategy;
use settle_planner::path::junction::Junction;
use settle_sim::{AxisModel, DriverMode};

use crate::error::Error;
use crate::input::source::Source;
use crate::measure::metrics::Metrics;
use crate::spec::backend::Backend;
use crate::spec::run_spec::RunSpec;
use crate::spec::runs::RunList;
use crate::spec::value::Value;
use crate::studies::{
    Motion, PathMove, PlanContext, Planned, Role, Streamed, Study, StudyState, any_has,
};

/// runs.csv columns of a G-code run.
pub const COLUMNS: [&str; 8] = [
    "gcode_file",
    "firmware",
    "print_time_s",
    "contour_worst_um",
    "contour_p95_um",
    "contour_worst_line",
    "smoothing_worst_um",
    "vibration_worst_um",
];

/// The `[gcode]` table.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct GcodeSpec {
    /// The G-code file, relative to the scenario.
    pub file: String,
    /// `klipper`, `marlin`, `rrf` or `settle`.
    pub firmware: String,
    /// Layers to simulate, `A..B` or `A` (default: all).
    pub layers: Option<String>,
    /// Where layers come from: `auto` (default), `markers` or `z`
    /// ([`settle_gcode::LayerMode::parse`]).
    pub layer_source: Option<String>,
    /// The speed law of settle's planner (`scurve`, `trapezoid`, ...; default `scurve`).
    #[serde(default = "default_profile")]
    pub profile: String,
    /// settle's planner: Klipper's corner rule at this speed (mm/s; default 5, Klipper's
    /// `square_corner_velocity`); 0 stops at every corner.
    #[serde(default = "default_scv")]
    pub square_corner_velocity_mm_s: f64,
}

fn default_profile() -> String {
    "scurve".into()
}

fn default_scv() -> f64 {
    5.0
}

/// A run's G-code job.
#[derive(Debug, Clone, PartialEq)]
pub struct GcodeJob {
    /// The file (resolved against the scenario's folder).
    pub file: PathBuf,
    /// The planner.
    pub firmware: Firmware,
    /// Layer range (inclusive).
    pub layers: Option<(u32, u32)>,
    /// Where layers come from.
    pub layer_mode: LayerMode,
    /// Profile name (settle's planner), as written.
    pub profile: String,
    /// settle's planner: square-corner velocity (mm/s).
    pub square_corner_velocity_mm_s: f64,
}

impl StudyState for GcodeJob {
    fn table(&self) -> &'static str {
        "gcode"
    }

    fn set(&mut self, key: &str, value: &Value) -> Result<(), String> {
        match (key, value) {
            ("firmware", Value::Text(t)) => {
                self.firmware = parse_firmware(t).map_err(|e| e.to_string())?;
            }
            ("firmware", _) => {
                return Err(format!(
                    "`gcode.firmware` takes names: {}",
                    Firmware::names(&Firmware::GCODE)
                ));
            }
            _ => {
                return Err(format!(
                    "`gcode.{key}` cannot be swept; allowed: gcode.firmware"
                ));
            }
        }
        Ok(())
    }
}

/// The layer range syntax of `[gcode] layers` and `--layers`: `A..B` (both included) or
/// `A`.
pub fn parse_layers(s: &str) -> Result<(u32, u32), String> {
    let num = |t: &str| {
        t.trim()
            .parse::<u32>()
            .map_err(|_| format!("`{s}`: layers are `A..B` or `A` with whole numbers >= 0"))
    };
    let (a, b) = match s.split_once("..") {
        Some((a, b)) => (num(a)?, num(b.trim_start_matches('='))?),
        None => (num(s)?, num(s)?),
    };
    if a > b {
        return Err(format!("`{s}`: the first layer is after the last"));
    }
    Ok((a, b))
}

/// The job configuration of `run`: its firmware's defaults for the job's file (for Prusa,
/// the printer the file names, [`JobConfig::for_file`]), the run's limits, `shaper` on X
/// and Y, and the job's layer source.
pub fn job_config(run: &RunSpec, job: &GcodeJob, shaper: Option<ShaperSetting>) -> Result<JobConfig, String> {
    let mut cfg = JobConfig::for_file(job.firmware, &job.file).map_err(|e| e.to_string())?;
    let (v, a) = (run.vmax_mm_s * 1e-3, run.amax_mm_s2 * 1e-3);
    match &mut cfg.planner {
        PlannerConfig::Klipper(c) => {
            c.max_velocity_m_s = v;
            c.max_accel_m_s2 = a;
        }
        PlannerConfig::Marlin(c) | PlannerConfig::Prusa(c) => {
            for i in 0..3 {
                c.max_feedrate_m_s[i] = v;
                c.max_accel_m_s2[i] = a;
            }
            c.print_accel_m_s2 = a;
            c.travel_accel_m_s2 = a;
            c.retract_accel_m_s2 = c.retract_accel_m_s2.min(a);
        }
        PlannerConfig::Rrf(c) => {
            for i in 0..3 {
                c.max_feedrate_m_s[i] = v;
                c.max_accel_m_s2[i] = a;
            }
            c.print_accel_m_s2 = a;
            c.travel_accel_m_s2 = a;
        }
        PlannerConfig::Grbl(g) => {
            g.max_rate_mm_min = [run.vmax_mm_s * 60.0; 3];
            g.accel_mm_s2 = [run.amax_mm_s2; 3];
        }
        PlannerConfig::Settle(c) => {
            c.limits = run.limits_si().map_err(|e| e.to_string())?;
            c.kind = settle_planner::ProfileKind::parse(&job.profile).map_err(|e| e.to_string())?;
            c.corners = if job.square_corner_velocity_mm_s > 0.0 {
                CornerStrategy::Junction(Junction::Klipper {
                    square_corner_velocity: job.square_corner_velocity_mm_s * 1e-3,
                })
            } else {
                CornerStrategy::ExactStop
            };
        }
    }
    cfg.shapers[0] = shaper;
    cfg.shapers[1] = shaper;
    cfg.layer_mode = job.layer_mode;
    Ok(cfg)
}

/// The shaper the run's `[shaper]` sets, as a job setting.
fn shaper_setting(s: Option<&settle_planner::shaper::Shaper>) -> Option<ShaperSetting> {
    s.map(|s| ShaperSetting {
        shaper_type: s.shaper_type(),
        frequency_hz: s.frequency_hz(),
        damping_ratio: s.damping_ratio(),
    })
}

/// The machine's axes with the linear driver (the modes form as it is): where the
/// pre-roll's decay rate is read.
fn linear_axes(run: &RunSpec) -> Result<Vec<AxisModel>, String> {
    run.machine
        .axes(DriverMode::Linear)
        .map_err(|e| e.to_string())
}

/// The pre-roll of `run`'s layer range (s; 0 without one): [`preroll::preroll_s`] of the
/// machine's slowest decay rate, plus two sample periods, so that moving the start to the
/// sample grid leaves at least [`preroll::preroll_s`].
fn preroll_of(run: &RunSpec, job: &GcodeJob) -> Result<f64, String> {
    if job.layers.is_none() {
        return Ok(0.0);
    }
    let sigma = preroll::slowest_decay_per_s(&linear_axes(run)?).map_err(|m| {
        format!(
            "{m}: a layer range cannot start from the state the layers before leave; simulate the whole file (no `layers`)"
        )
    })?;
    Ok(preroll::preroll_s(sigma) + 2.0 / run.sample_rate_hz)
}

/// Where the modal backend linearises `run`'s machine ([`linpoint`]), one position (m)
/// per machine axis in `axes`' order: `None` on the other backends and on a machine whose
/// stiffness does not depend on position (the modes form).
fn linearise_at(run: &RunSpec, job: &GcodeJob, axes: &[String]) -> Result<Option<Vec<f64>>, String> {
    if run.backend != Backend::Modal || !linpoint::depends_on_position(&linear_axes(run)?) {
        return Ok(None);
    }
    let mut cfg = JobConfig::defaults(job.firmware).map_err(|e| e.to_string())?;
    cfg.layer_mode = job.layer_mode;
    let options = cfg.reader_options();
    // Runs of a sweep over one file (its shaper, its limits) share the point: read once.
    let key = format!("{}|{options:?}", file_key(job)?);
    let known = LINEARISED.lock().ok().and_then(|m| m.get(&key).copied());
    let point = match known {
        Some(p) => p,
        None => {
            let reader = Reader::open(&job.file, options).map_err(|e| e.to_string())?;
            let p = linpoint::linearisation_point(reader).map_err(|e| e.to_string())?;
            if let Ok(mut m) = LINEARISED.lock() {
                m.insert(key, p);
            }
            p
        }
    };
    Ok(Some(point.on_axes(axes)))
}

/// The linearisation points found so far ([`linearise_at`]), by file (its path, size and
/// modification time) and reader options.
static LINEARISED: Mutex<BTreeMap<String, linpoint::LinPoint>> = Mutex::new(BTreeMap::new());

/// The job of `run` opened, limited to its layers with their pre-roll ([`preroll_of`]).
fn open(run: &RunSpec, job: &GcodeJob) -> Result<Job<settle_gcode::FileInput>, String> {
    let shaper = crate::studies::shaper(run).map_err(|e| e.to_string())?;
    let cfg = job_config(run, job, shaper_setting(shaper.as_ref()))?;
    let j = Job::open(&job.file, cfg).map_err(|e| e.to_string())?;
    match job.layers {
        Some((a, b)) => j
            .with_layers(a..=b)
            .and_then(|j| j.with_preroll_s(preroll_of(run, job).unwrap_or(0.0)))
            .map_err(|e| e.to_string()),
        None => Ok(j),
    }
}

/// The jobs [`Study::validate`] has planned whole without an error, by
/// [`validation_key`].
static VALIDATED: Mutex<BTreeSet<String>> = Mutex::new(BTreeSet::new());

/// What the validity of `run`'s job depends on: the file (its path, size and modification
/// time), the planner's settings without the shapers, and the layer range with its
/// pre-roll. (A shaper only shapes the planned moves.)
fn validation_key(run: &RunSpec, job: &GcodeJob) -> Result<String, String> {
    let mut cfg = job_config(run, job, None)?;
    cfg.shapers = [None; 3];
    Ok(format!(
        "{}|{cfg:?}|{:?}|{:?}",
        file_key(job)?,
        job.layers,
        preroll_of(run, job)?
    ))
}

/// `job`'s file as the sweep's caches know it: its path, size and modification time.
fn file_key(job: &GcodeJob) -> Result<String, String> {
    let meta = std::fs::metadata(&job.file).map_err(|e| format!("{}: {e}", job.file.display()))?;
    Ok(format!(
        "{}|{}|{:?}",
        job.file.display(),
        meta.len(),
        meta.modified().ok()
    ))
}

/// The G-code job study.
#[derive(Debug, Clone, Copy)]
pub struct GcodeRun;

impl Study for GcodeRun {
    fn name(&self) -> &'static str {
        "G-code job"
    }

    fn table(&self) -> Option<&'static str> {
        Some("gcode")
    }

    fn role(&self) -> Role {
        Role::Path
    }

    /// Every axis of the machine: a job moves x and y, and z between layers.
    fn moved_axes(&self, run: &RunSpec) -> Vec<String> {
        run.axis_names()
    }

    fn sweepable(&self) -> &'static str {
        "gcode.firmware"
    }

    fn parse(&self, src: &Source) -> Result<Option<Box<dyn StudyState>>, Error> {
        let Some(spec) = src.table::<GcodeSpec>("gcode")? else {
            return Ok(None);
        };
        let firmware = parse_firmware(&spec.firmware)
            .map_err(|e| src.error_at("gcode.firmware", e.to_string()))?;
        // 0 (stop at every corner) or a speed like the limits: Klipper takes any
        // `square_corner_velocity` >= 0 (`ToolHead.__init__`, klippy/toolhead.py).
        let scv = spec.square_corner_velocity_mm_s;
        if scv != 0.0 && crate::spec::check_limit(scv, crate::spec::Quantity::Speed).is_err() {
            let (lo, hi) = crate::spec::SPEED_RANGE_MM_S;
            return Err(src.error_at(
                "gcode.square_corner_velocity_mm_s",
                format!(
                    "must be 0 (stop at every corner) or a finite number from {lo:e} to {hi:e} (mm/s), got {scv}"
                ),
            ));
        }
        let layers = spec
            .layers
            .as_deref()
            .map(parse_layers)
            .transpose()
            .map_err(|m| src.error_at("gcode.layers", m))?;
        settle_planner::ProfileKind::parse(&spec.profile)
            .map_err(|e| src.error_at("gcode.profile", e.to_string()))?;
        let layer_mode = spec
            .layer_source
            .as_deref()
            .map(LayerMode::parse)
            .transpose()
            .map_err(|m| src.error_at("gcode.layer_source", m))?
            .unwrap_or_default();
        let base = src.path.parent().unwrap_or(std::path::Path::new("."));
        Ok(Some(Box::new(GcodeJob {
            file: base.join(&spec.file),
            firmware,
            layers,
            layer_mode,
            profile: spec.profile,
            square_corner_velocity_mm_s: spec.square_corner_velocity_mm_s,
        })))
    }

    fn path_move(&self, state: &dyn StudyState) -> Option<PathMove> {
        let job = (state as &dyn std::any::Any).downcast_ref::<GcodeJob>()?;
        Some(PathMove {
            profile: job.profile.clone(),
            profile_key: "gcode.profile",
            axis: "x+y".into(),
        })
    }

    /// Plans the whole file once: bad G-code is an error naming its file and line.
    fn validate(&self, run: &RunSpec) -> Result<(), (String, String)> {
        let Some(job) = run.state::<GcodeJob>() else {
            return Ok(());
        };
        let names = run.axis_names();
        let has = |a: &str| names.iter().any(|n| n == a);
        if !(has("x") && has("y") && names.iter().all(|n| ["x", "y", "z"].contains(&n.as_str()))) {
            return Err((
                "machine".into(),
                "a G-code job needs a machine with axes x and y (and z), no others: a physical machine (e.g. `preset = \"printer_xy\"`) or modes on `[machine.axis.x]` and `[machine.axis.y]`".into(),
            ));
        }
        preroll_of(run, job).map_err(|m| (run.blame("gcode.layers"), m))?;
        // Runs that differ in their shaper only plan the same moves: planned once.
        let key = validation_key(run, job).map_err(|m| (run.blame("gcode.file"), m))?;
        if VALIDATED.lock().is_ok_and(|v| v.contains(&key)) {
            return Ok(());
        }
        let mut j = open(run, job).map_err(|m| (run.blame("gcode.file"), m))?;
        j.run_to_end()
            .map_err(|e| (run.blame("gcode.file"), e.to_string()))?;
        if let Some(why) =
            work::nothing_to_measure(&j.summary(), j.reader().lines_read(), j.reader().looks())
        {
            return Err((
                run.blame("gcode.file"),
                format!("{}: {why}", job.file.display()),
            ));
        }
        if let Some(why) = job.layers.and_then(|r| work::no_work_in(&j.summary(), r)) {
            return Err((
                run.blame("gcode.layers"),
                format!("{}: {why}", job.file.display()),
            ));
        }
        // Only a job that passed every check is remembered as checked.
        if let Ok(mut v) = VALIDATED.lock() {
            v.insert(key);
        }
        Ok(())
    }

    /// The job streamed chunk by chunk ([`stream`]): an outline pass finds where the run
    /// starts and ends, the run plans the job again as it is simulated.
    fn plan(&self, run: &RunSpec, ctx: &PlanContext) -> Result<Planned, PlanError> {
        let job = run.state::<GcodeJob>().ok_or(PlanError::InvalidInput {
            reason: "not a G-code run",
        })?;
        let failed = |_| PlanError::InvalidInput {
            reason: "the G-code job failed to plan (checked when the sweep was validated)",
        };
        let map = stream::job_axes(ctx.axes)?;
        let dt = 1.0 / run.sample_rate_hz;
        let range = match job.layers {
            Some((a, _)) => Some((a, preroll_of(run, job).map_err(failed)? - 2.0 * dt)),
            None => None,
        };
        let outline = stream::Outline::of(open(run, job).map_err(failed)?, &map, dt, range)?;
        let chunks = stream::JobChunks::new(
            open(run, job).map_err(failed)?,
            map,
            &outline,
            job.layers,
            run.sample_rate_hz,
        )?;
        let linearise_at_m = linearise_at(run, job, ctx.axes).map_err(failed)?;
        Ok(Planned {
            motion: Motion::Stream(Streamed {
                start: outline.start.clone(),
                end: outline.end.clone(),
                duration_s: outline.duration_s,
                chunks: Box::new(chunks),
            }),
            probe: None,
            linearise_at_m,
            // Every planner starts the job at the origin: rapier's step is sized there,
            // as `settle gcode` sizes it, for the whole file and any layer range.
            step_at_m: Some(vec![0.0; ctx.axes.len()]),
        })
    }

    fn columns(&self, runs: &dyn RunList) -> Vec<String> {
        if !any_has::<GcodeJob>(runs) {
            return Vec::new();
        }
        COLUMNS.iter().map(|c| c.to_string()).collect()
    }

    fn cells(&self, run: &RunSpec, m: &Metrics) -> Vec<String> {
        let Some(job) = run.state::<GcodeJob>() else {
            return Vec::new();
        };
        let mut out = vec![job.file.display().to_string(), job.firmware.to_string()];
        if m.is_ok() {
            for c in &COLUMNS[2..] {
                let v = m.extra.iter().find(|(n, _)| n == c).map(|(_, v)| *v);
                out.push(v.map(|v| v.to_string()).unwrap_or_default());
            }
        }
        out
    }
}
