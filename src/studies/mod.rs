//! Studies: what one run of a sweep does with the machine. A point-to-point move, a
//! corner path, a raster scan's step, input shaping of the commanded motion, a G-code
//! job: each is a [`Study`], one module of this folder, and the expander (`crate::expand`), the runner
//! (`crate::execute`), runs.csv and the summary (`crate::output`) go through [`all`], the
//! registered studies, without naming one.
//!
//! A study
//! - claims a table of the scenario file ([`Study::table`]: `[corner]`, `[scan]`,
//!   `[shaper]`, `[gcode]`; the point move claims none: it is the study of a run no other
//!   motion study claims) and parses it into the per-run state every run of the sweep
//!   starts from
//!   ([`Study::parse`], a [`StudyState`] that the sweep then sets through its keys,
//!   `corner.angle_deg`, ...),
//! - checks each run ([`Study::validate`]),
//! - plans the run's motion ([`Study::plan`], [`Role::Move`] and [`Role::Path`] studies), or
//!   transforms the motion another study plans ([`Study::shaper`], [`Role::Modifier`]),
//! - may measure more than the common metrics from the run's series ([`Planned::probe`]),
//!   or, for a motion too long to plan whole, along its chunks ([`Motion::Stream`]),
//! - names its extra runs.csv columns and fills their cells ([`Study::columns`],
//!   [`Study::cells`]), and adds its section to the summary and its panels to the figures
//!   ([`Study::summary`], [`Study::figures`]).
//!
//! # Adding a study
//!
//! One file and one line:
//! 1. `src/studies/<name>.rs`: the table as a `#[derive(Deserialize)]
//!    #[serde(deny_unknown_fields)]` struct; the per-run state (`Clone + PartialEq + Debug`)
//!    implementing [`StudyState`] (`table` returns the table's name, `set` takes its swept
//!    keys); a unit struct implementing [`Study`]: `table` and `role`, `parse` (read the
//!    table with [`Source::table`], so errors name the file, line and key), `plan` for a
//!    motion study, and whichever of `validate`, `columns`/`cells`, `summary`, `figures` it
//!    needs (each has a default that adds nothing).
//! 2. `<name>::<Study>,` in the `register!` list below (it declares the module and puts the
//!    study in [`STUDIES`]), at the place its runs.csv columns and summary section belong
//!    (registration order is their order).
//!
//! `src/studies/toy.rs` (compiled for the unit tests only, registered by its line in the
//! list) is such a study; `src/workflows/toy_pipeline.rs` runs it through the whole
//! pipeline: parse, sweep, run, runs.csv, summary, figures.

use settle_planner::shaper::Shaper;
use settle_planner::{PlanError, Profile, State, Trajectory};

use crate::error::Error;
use crate::input::runs_columns::RunsColumns;
use crate::input::source::Source;
use crate::measure::metrics::Metrics;
use crate::measure::series::Series;
use crate::spec::run_spec::RunSpec;
pub use crate::spec::run_spec::StudyState;
use crate::spec::runs::RunList;

/// Declares each study's module and lists it in [`STUDIES`]: one line per kind.
macro_rules! register {
    ($($(#[$attr:meta])* $module:ident :: $study:ident),* $(,)?) => {
        $($(#[$attr])* pub mod $module;)*

        /// Every study, in registration order: runs.csv's study columns, the summary's
        /// study sections and the figures' study panels follow it.
        pub static STUDIES: &[&dyn Study] = &[$($(#[$attr])* &$module::$study),*];
    };
}

register! {
    point::PointMove,
    corner::CornerPath,
    shaping::Shaping,
    scan::ScanStep,
    gcode::GcodeRun,
    #[cfg(test)]
    toy::Toy,
}

/// The registered studies ([`STUDIES`]).
pub fn all() -> &'static [&'static dyn Study] {
    STUDIES
}

/// What a study does with the run's motion.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    /// Plans the motion from `[move]` (the point-to-point move, which claims no table; a
    /// raster scan, whose step is the move).
    Move,
    /// Plans a motion of its own instead of `[move]` (a corner path).
    Path,
    /// Transforms the motion the run's motion study plans (an input shaper).
    Modifier,
}

/// What a path study stands in for `[move]` with.
#[derive(Debug, Clone, PartialEq)]
pub struct PathMove {
    /// The profile kind named in its table (the speed law of the path).
    pub profile: String,
    /// The key of that name (`corner.profile`), for errors.
    pub profile_key: &'static str,
    /// The machine axes it moves, joined by `+` (runs.csv's `axis`, e.g. `x+y`: no machine
    /// axis has this name, so the point move's travel check leaves the path to its study).
    pub axis: String,
}

/// What a motion study plans with.
#[derive(Debug, Clone)]
pub struct PlanContext<'a> {
    /// The machine's axes, in order: the trajectory has one profile per axis.
    pub axes: &'a [String],
    /// The input shaper of the run's modifier studies, if any: the motion study applies it
    /// where it belongs (every axis of a path, the step of a raster).
    pub shaper: Option<Shaper>,
}

/// Figures of a run beyond the common metrics, measured from its full series.
pub trait Probe: std::fmt::Debug + Send {
    /// Add them to `m` (as [`Metrics::extra`]) from `series`, the run's recording.
    fn measure(&self, run: &RunSpec, series: &Series, m: &mut Metrics) -> Result<(), Error>;
}

/// A planned run's motion.
#[derive(Debug)]
pub enum Motion {
    /// One profile per machine axis (with the path geometry, when it follows a path).
    Whole(Trajectory),
    /// A motion too long to hold planned whole (a G-code job): its chunks one after the
    /// other, measured as they are simulated.
    Stream(Streamed),
}

impl Motion {
    /// The trajectory of a motion planned whole; `None` for a streamed one.
    pub fn whole(&self) -> Option<&Trajectory> {
        match self {
            Motion::Whole(t) => Some(t),
            Motion::Stream(_) => None,
        }
    }

    /// The motion's duration (s).
    pub fn duration_s(&self) -> f64 {
        match self {
            Motion::Whole(t) => t.duration_s(),
            Motion::Stream(s) => s.duration_s,
        }
    }
}

/// A motion simulated chunk by chunk ([`Motion::Stream`]): where it starts and ends and
/// how long it takes (what the common metrics measure against, as for a whole
/// trajectory), and its chunks with what the study measures along them.
pub struct Streamed {
    /// The start, per machine axis.
    pub start: Vec<State>,
    /// The end, per machine axis.
    pub end: Vec<State>,
    /// The duration (s): the sum of the chunks' durations, in order.
    pub duration_s: f64,
    /// The chunks and the study's measurement.
    pub chunks: Box<dyn MotionStream>,
}

impl std::fmt::Debug for Streamed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Streamed")
            .field("start", &self.start)
            .field("end", &self.end)
            .field("duration_s", &self.duration_s)
            .finish_non_exhaustive()
    }
}

/// The chunks of a [`Streamed`] motion and what the study measures along them.
pub trait MotionStream: Send {
    /// The next chunk, one profile per machine axis, and its time 0 on the run's clock
    /// (s): it starts where the one before ended, its time 0 the sum of the durations
    /// before, in order; `None` after the last.
    fn next_chunk(&mut self) -> Result<Option<(f64, Trajectory)>, PlanError>;

    /// Samples `k0, k0 + 1, ...` of a clock whose sample `k` is at `origin_s + k dt_s` (s,
    /// the run's clock; `clock` is `[origin_s, dt_s]`), with the toolhead at `toolhead_m`
    /// (`axes` values a sample, one per machine axis, sample after sample): every sample,
    /// in order, the observation window's too.
    fn samples(&mut self, clock: [f64; 2], k0: u64, toolhead_m: &[f64], axes: usize);

    /// Add its figures to an ok run's metrics.
    fn measure(&mut self, m: &mut Metrics);
}

/// A planned run.
#[derive(Debug)]
pub struct Planned {
    /// The motion.
    pub motion: Motion,
    /// What the study measures beyond the common metrics from a whole motion's series:
    /// the runner then records the run's series for it.
    pub probe: Option<Box<dyn Probe>>,
    /// Where the modal backend linearises the machine (m per machine axis); `None`: at
    /// the trajectory's start (see [`crate::execute::SimOptions::linearise_at_m`]).
    pub linearise_at_m: Option<Vec<f64>>,
    /// Where rapier sizes its integration step (m per machine axis); `None`: at the
    /// trajectory's start (see [`crate::execute::SimOptions::step_at_m`]).
    pub step_at_m: Option<Vec<f64>>,
}

/// A runs.csv column a study plots against each swept parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct PlotColumn {
    /// The column.
    pub column: String,
    /// The panel's title.
    pub title: String,
    /// The y axis's quantity (`settle time`, `|error|`).
    pub quantity: &'static str,
    /// The y axis's unit after `scale` (`ms`, `um`).
    pub unit: &'static str,
    /// Factor from the column's unit to `unit`.
    pub scale: f64,
    /// Whether a logarithmic y axis suits it (when it spans more than a factor of 20).
    pub log_ok: bool,
}

impl PlotColumn {
    /// The panel of `column`, titled `title`, its y axis `quantity (unit)` after `scale`.
    pub fn new(
        column: impl Into<String>,
        title: impl Into<String>,
        quantity: &'static str,
        unit: &'static str,
        scale: f64,
        log_ok: bool,
    ) -> Self {
        Self {
            column: column.into(),
            title: title.into(),
            quantity,
            unit,
            scale,
            log_ok,
        }
    }
}

/// A trajectory with `profile` on machine axis `axis`, every other axis of `axes` holding
/// at 0 (a move on one axis).
pub fn on_axis(axes: &[String], axis: &str, profile: &Profile) -> Result<Trajectory, PlanError> {
    Trajectory::new(
        axes.iter()
            .map(|a| {
                if a == axis {
                    profile.clone()
                } else {
                    Profile::empty(State::default())
                }
            })
            .collect(),
    )
}

/// A study (see the module documentation).
pub trait Study: std::fmt::Debug + Sync {
    /// What it is, in messages (`corner path`).
    fn name(&self) -> &'static str;

    /// The scenario table it claims (`corner` for `[corner]`); `None` for the point move.
    fn table(&self) -> Option<&'static str>;

    /// What it does with the run's motion.
    fn role(&self) -> Role;

    /// Its swept keys, for messages (`corner.angle_deg, corner.strategy`).
    fn sweepable(&self) -> &'static str {
        ""
    }

    /// Parse its table from the scenario: the state every run starts from, `None` when the
    /// scenario has no such table.
    fn parse(&self, src: &Source) -> Result<Option<Box<dyn StudyState>>, Error> {
        let _ = src;
        Ok(None)
    }

    /// A path study's stand-in for `[move]` (from its state in the scenario).
    fn path_move(&self, state: &dyn StudyState) -> Option<PathMove> {
        let _ = state;
        None
    }

    /// A path study's move length (mm) for `run` (runs.csv's `distance_mm`).
    fn path_length_mm(&self, run: &RunSpec) -> Option<f64> {
        let _ = run;
        None
    }

    /// Check a run that has this study's state: `(key to blame, message)` for the first
    /// problem.
    fn validate(&self, run: &RunSpec) -> Result<(), (String, String)> {
        let _ = run;
        Ok(())
    }

    /// The input shaper a modifier applies to the commanded motion, if any.
    fn shaper(&self, run: &RunSpec) -> Result<Option<Shaper>, PlanError> {
        let _ = run;
        Ok(None)
    }

    /// The machine axes a motion study's run moves, whose vibration its samples must
    /// resolve (see [`moved_axes`]): by default the move's axis, or a path's two (`x+y`).
    fn moved_axes(&self, run: &RunSpec) -> Vec<String> {
        run.axis.split('+').map(str::to_string).collect()
    }

    /// Plan the run's motion (motion studies: [`Role::Move`], [`Role::Path`]).
    fn plan(&self, run: &RunSpec, ctx: &PlanContext) -> Result<Planned, PlanError> {
        let _ = (run, ctx);
        Err(PlanError::InvalidInput {
            reason: "this study plans no motion",
        })
    }

    /// Its extra runs.csv columns, named from the runs alone (never from results, so that
    /// the header is the same whatever the results: the sweep journal relies on it).
    fn columns(&self, runs: &dyn RunList) -> Vec<String> {
        let _ = runs;
        Vec::new()
    }

    /// The cells of [`Study::columns`] for `run` with metrics `m`, in column order; asked
    /// only when the sweep has the columns (missing cells are left empty, e.g. all of
    /// them for a run without this study's state). A failed run's metrics are not numbers:
    /// leave their cells empty.
    fn cells(&self, run: &RunSpec, m: &Metrics) -> Vec<String> {
        let _ = (run, m);
        Vec::new()
    }

    /// Its summary section, read from the runs table (row `i` = `runs[i]`) so that a
    /// merged sweep's summary is the same; `None` when it has nothing to show. `current`
    /// tells the scenario's `[current]` runs (the user's settings today) from the others.
    fn summary(
        &self,
        runs: &dyn RunList,
        table: &RunsColumns,
        current: &dyn Fn(&RunSpec) -> bool,
    ) -> Option<String> {
        let _ = (runs, table, current);
        None
    }

    /// Its panels in the sweep figures (shown when their column is in the table).
    fn figures(&self, bands_um: &[f64]) -> Vec<PlotColumn> {
        let _ = bands_um;
        Vec::new()
    }

    /// Whether its summary section and panels replace the common move-and-settle ones
    /// (which would not measure what the study is about: a raster's run-out, not its step).
    fn replaces_move_tables(&self) -> bool {
        false
    }

    /// Why swept key `key` does not change a run that does this study (`a trapezoid has no
    /// jerk limit`), or `None` when it does: runs that differ only in such values are the
    /// same run, ranked once ([`unused`]).
    fn unused(&self, run: &RunSpec, key: &str) -> Option<&'static str> {
        let _ = (run, key);
        None
    }
}

/// Why swept key `key` does not change `run` (see [`Study::unused`]), asking the studies
/// it does; `None` when it does.
pub fn unused(run: &RunSpec, key: &str) -> Option<&'static str> {
    of(run).find_map(|k| k.unused(run, key))
}

/// Why the jerk limit does not change a move of `run`'s profile kind: a trapezoid steps
/// its acceleration (the point move's and a scan step's rule).
pub fn jerk_unused(run: &RunSpec, key: &str) -> Option<&'static str> {
    (key == "limits.jmax_mm_s3" && !crate::spec::run_spec::needs_jerk(run.profile))
        .then_some("a trapezoid has no jerk limit")
}

/// The tables the studies claim (left out of the scenario's strict parse).
pub fn tables() -> Vec<&'static str> {
    all().iter().filter_map(|k| k.table()).collect()
}

/// The study whose table is `table`.
pub fn by_table(table: &str) -> Option<&'static dyn Study> {
    all().iter().copied().find(|k| k.table() == Some(table))
}

/// Whether `run` has `study`: its state (a study with a table), or no other motion study (the
/// point move).
pub fn has(run: &RunSpec, study: &dyn Study) -> bool {
    match study.table() {
        Some(t) => run.state_of(t).is_some(),
        None => study.role() != Role::Modifier && motion(run).table().is_none(),
    }
}

/// The studies `run` has, in registration order.
pub fn of(run: &RunSpec) -> impl Iterator<Item = &'static dyn Study> + '_ {
    all().iter().copied().filter(move |k| has(run, *k))
}

/// The study that plans `run`'s motion: the first motion study whose state it has, else the
/// point move (the motion study without a table).
pub fn motion(run: &RunSpec) -> &'static dyn Study {
    let is_motion = |k: &&dyn Study| k.role() != Role::Modifier;
    all()
        .iter()
        .copied()
        .filter(is_motion)
        .find(|k| k.table().is_some_and(|t| run.state_of(t).is_some()))
        .or_else(|| {
            all()
                .iter()
                .copied()
                .filter(is_motion)
                .find(|k| k.table().is_none())
        })
        .unwrap_or(&point::PointMove)
}

/// The input shaper `run`'s modifier studies apply (the last one that has one).
pub fn shaper(run: &RunSpec) -> Result<Option<Shaper>, PlanError> {
    let mut shaper = None;
    for k in of(run).filter(|k| k.role() == Role::Modifier) {
        if let Some(s) = k.shaper(run)? {
            shaper = Some(s);
        }
    }
    Ok(shaper)
}

/// The machine axes `run`'s motion moves (its motion study's [`Study::moved_axes`]): the
/// axes whose modes its sample rate must resolve and its window must show.
pub fn moved_axes(run: &RunSpec) -> Vec<String> {
    motion(run).moved_axes(run)
}

/// Plan `run` on a machine with axes `axes`: its motion study, with its modifiers' shaper.
pub fn plan(run: &RunSpec, axes: &[String]) -> Result<Planned, PlanError> {
    let shaper = shaper(run)?;
    motion(run).plan(run, &PlanContext { axes, shaper })
}

/// Whether `runs` share a study state of type `T` (any of them has one).
pub fn any_has<T: StudyState>(runs: &dyn RunList) -> bool {
    runs.iter().any(|r| r.state::<T>().is_some())
}
