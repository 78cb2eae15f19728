//! `settle tune SCENARIO.toml`: the search grid ([`grid`], candidates and scores in
//! [`search`], restricted to what a [`firmware`] can express, [`target`]), evaluated and
//! refined ([`rank`]), per axis; the axes made to share one acceleration where the
//! firmware has one ([`joint`]); Klipper's own choice on the same machine
//! ([`klipper_choice`]); optionally re-checked on a second backend; the outputs (the
//! report: [`head`], [`report`], [`changes`]; [`candidates`]; the figures, [`figure`];
//! report.html, [`html`]; the firmware configurations, [`export`]); and Klipper's own
//! choice on a resonance CSV ([`klipper_criterion`]).

pub mod candidates;
pub mod cells;
pub mod changes;
pub mod checks;
pub mod export;
pub mod figure;
pub mod firmware;
pub mod grid;
pub mod head;
pub mod html;
pub mod joint;
pub mod klipper_choice;
pub mod klipper_criterion;
pub mod klipper_section;
pub mod rank;
pub mod report;
pub mod scan_figures;
pub mod search;
pub mod target;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::error::Error;
use crate::execute::pool::{Progress, quiet};
use crate::input::scenario::Scenario;
use crate::input::source::Source;
use crate::output::atomic::{create_dir, write_atomic};
use crate::spec::backend::Backend;
use crate::workflows::{Exit, Report};
use search::{Plan, Score};

/// What a tuning found.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// The resolved search.
    pub plan: Plan,
    /// Every candidate's score; index 0 is the scenario's own point (the user's current settings).
    pub scores: Vec<Score>,
    /// Index of the winner in `scores` (after refinement).
    pub winner: usize,
    /// Index of the best grid candidate (the refinement started from it).
    pub grid_winner: usize,
    /// Indices of the Pareto front.
    pub front: Vec<usize>,
    /// `(backend, current, winner)` re-run on a second backend, if asked.
    pub check: Option<(Backend, Score, Score)>,
    /// The axis's own best, where sharing one acceleration with the other axes moved the
    /// recommendation ([`joint::share_acceleration`]).
    pub alone: Option<usize>,
    /// Klipper's choice on the same machine, scored by settle (Klipper or unrestricted
    /// searches of shapers: [`klipper_choice::applies`]).
    pub klipper: Option<klipper_choice::KlipperChoice>,
}

/// How `settle tune` runs: the backends, the workers, and what the command line sets over
/// the scenario's `[tune]` table.
#[derive(Debug, Clone)]
pub struct Options {
    /// Backend of the search.
    pub backend: Backend,
    /// Re-run the current and the winner on this backend.
    pub check_on: Option<Backend>,
    /// Worker threads (`None`: all cores).
    pub jobs: Option<usize>,
    /// `--firmware`: over `[tune] firmware`.
    pub firmware: Option<String>,
    /// `--frequency-tolerance PCT`: over `[tune] frequency_tolerance_pct`.
    pub frequency_tolerance_pct: Option<f64>,
    /// Overwrite the results of an earlier tuning in the output folder (refused without
    /// it).
    pub force: bool,
}

impl Options {
    /// Search on `backend`, nothing else set.
    pub fn new(backend: Backend) -> Self {
        Self {
            backend,
            check_on: None,
            jobs: None,
            firmware: None,
            frequency_tolerance_pct: None,
            force: false,
        }
    }
}

/// Load `path`, search on `backend`, and re-check on `check_on` if given (the move's axis,
/// or the first of `[tune] axes`).
pub fn tune(
    path: &Path,
    backend: Backend,
    check_on: Option<Backend>,
    jobs: Option<usize>,
    progress: Progress,
) -> Result<Outcome, Error> {
    let opts = Options {
        check_on,
        jobs,
        ..Options::new(backend)
    };
    tune_axis(path, None, &opts, progress)
}

/// The scenario with the command line's settings over its `[tune]` table.
fn load(path: &Path, opts: &Options) -> Result<(Scenario, Source), Error> {
    let (mut sc, src) = crate::expand::load(path)?;
    let mut t = sc.tune.take().unwrap_or_default();
    if let Some(f) = &opts.firmware {
        firmware::Candidates::parse(f).map_err(|m| Error::input_key(path, "--firmware", m))?;
        t.firmware = Some(f.clone());
    }
    if let Some(p) = opts.frequency_tolerance_pct {
        if !(p.is_finite() && (0.0..50.0).contains(&p)) {
            return Err(Error::input_key(
                path,
                "--frequency-tolerance",
                format!("must be 0 to under 50 (percent), got {p}"),
            ));
        }
        t.frequency_tolerance_pct = Some(p);
    }
    sc.tune = Some(t);
    Ok((sc, src))
}

/// The axes `[tune] axes` names (`[None]`: the move's axis).
fn axes(sc: &Scenario) -> Vec<Option<String>> {
    match sc.tune.as_ref().and_then(|t| t.axes.clone()) {
        Some(list) if !list.is_empty() => list.into_iter().map(Some).collect(),
        _ => vec![None],
    }
}

/// Tune one axis of `path` (`None`: the move's axis): search, compare with Klipper's
/// choice, and re-check on the second backend if asked.
pub fn tune_axis(
    path: &Path,
    axis: Option<&str>,
    opts: &Options,
    progress: Progress,
) -> Result<Outcome, Error> {
    let mut o = search_axis(path, axis, opts, progress)?;
    finish(path, &mut o, opts)?;
    Ok(o)
}

/// Why no candidate is feasible, counted by reason.
fn none_feasible(path: &Path, scores: &[Score]) -> Error {
    let mut groups: Vec<(&str, usize, String)> = Vec::new();
    for s in scores {
        if let Some(why) = &s.infeasible {
            match groups.iter_mut().find(|g| g.0 == why.group()) {
                Some(g) => g.1 += 1,
                None => groups.push((why.group(), 1, why.short())),
            }
        }
    }
    let list: Vec<String> = groups
        .iter()
        .map(|(g, n, e)| format!("{n} {} (e.g. {e})", g.trim_start_matches("out: ")))
        .collect();
    Error::input_key(
        path,
        "observe.window_s",
        format!(
            "no candidate is feasible: {}; lengthen window_s, widen the band or raise max_smoothing_mm",
            list.join(", ")
        ),
    )
}

/// The search of one axis, refined, without the second backend or Klipper's choice.
pub fn search_axis(
    path: &Path,
    axis: Option<&str>,
    opts: &Options,
    progress: Progress,
) -> Result<Outcome, Error> {
    let (sc, src) = load(path, opts)?;
    // An imported scenario's [sweep] is for `settle sweep`; the search starts from the
    // scenario's own point, the user's current settings (its [current] marks a point of
    // that sweep, so it goes with it).
    let mut point = sc.clone();
    point.sweep.clear();
    point.current.clear();
    let mut runs = crate::expand::expand(&point, &src)?;
    crate::execute::set_backend(path, &mut runs, opts.backend)?;
    let plan = grid::plan(&sc, &src, &runs, axis)?;
    let mut scores = rank::evaluate(&plan, &plan.candidates, opts.jobs, progress)?;
    let grid_winner = rank::best(&scores).ok_or_else(|| none_feasible(path, &scores))?;
    let winner = rank::refine(&plan, &mut scores, grid_winner, opts.jobs)?;
    let front = rank::pareto(&scores);
    Ok(Outcome {
        plan,
        scores,
        winner,
        grid_winner,
        front,
        check: None,
        alone: None,
        klipper: None,
    })
}

/// Klipper's choice on the axis's machine, and the re-check of the current settings and
/// the recommendation on `opts.check_on`.
fn finish(path: &Path, o: &mut Outcome, opts: &Options) -> Result<(), Error> {
    o.klipper = klipper_choice::compare(&o.plan, &o.scores[o.winner], opts.jobs)?;
    o.check = match opts.check_on {
        None => None,
        Some(b) => {
            let mut other = o.plan.clone();
            let mut base = vec![other.base.clone()];
            crate::execute::set_backend(path, &mut base, b)?;
            other.base.backend = b;
            let pair = [o.scores[0].candidate, o.scores[o.winner].candidate];
            let s = rank::evaluate(&other, &pair, opts.jobs, &quiet)?;
            Some((b, s[0].clone(), s[1].clone()))
        }
    };
    Ok(())
}

/// What `settle tune` found and wrote.
#[derive(Debug, Clone)]
pub struct Tuned {
    /// The search and its result, per axis (the first: the move's axis or the first of
    /// `[tune] axes`).
    pub outcome: Outcome,
    /// Every tuned axis's outcome, with the axis name, in order.
    pub axes: Vec<(String, Outcome)>,
    /// The report (`tune.md`).
    pub markdown: String,
    /// The output folder.
    pub out: PathBuf,
}

impl Tuned {
    /// What `settle tune` prints: the report.
    pub fn report(&self) -> Report {
        Report {
            stdout: self.markdown.clone(),
            stderr: String::new(),
            exit: Exit::Ok,
        }
    }
}

/// Tune `path` on `backend` (re-checked on `check_on`), and write its outputs into `out`
/// (default: `results/<name>-tune/`); see [`tune_with`].
pub fn tune_to(
    path: &Path,
    out: Option<PathBuf>,
    backend: Backend,
    check_on: Option<Backend>,
    jobs: Option<usize>,
    progress: Progress,
) -> Result<Tuned, Error> {
    let opts = Options {
        check_on,
        jobs,
        ..Options::new(backend)
    };
    tune_with(path, out, &opts, progress)
}

/// The files `settle tune` writes in its output folder (with `pareto-<axis>.svg/png`
/// for several axes: [`PATTERNS`]).
const FILES: [&str; 10] = [
    "tune.md",
    "candidates.csv",
    "klipper.cfg",
    "rrf.g",
    "marlin.gcode",
    "prusa.gcode",
    "tmc4361a.txt",
    "pareto.svg",
    "pareto.png",
    crate::output::sweep_files::REPORT,
];

/// An earlier tuning's results, which `--force` overwrites.
const RESULTS: crate::output::folder::Results<'static> = crate::output::folder::Results {
    what: "settle tune",
    marks: &FILES,
};

/// The per-axis Pareto figures of a tuning of several axes ([`figure_name`]).
const PATTERNS: [(&str, &str); 2] = [("pareto-", ".svg"), ("pareto-", ".png")];

/// Tune every axis of `[tune] axes` (default: the move's axis) of `path`, sharing one
/// acceleration where the firmware has one, and write into `out` (default:
/// `results/<name>-tune/`): `tune.md` (the machine, your current settings ->
/// recommended, what changes in each export, then one section per axis), `candidates.csv`
/// (every candidate of every axis), the Pareto figure of each axis (`pareto.svg/png`, or
/// `pareto-<axis>.svg/png` for several axes), `report.html`, and `klipper.cfg`, `rrf.g`,
/// `marlin.gcode`, `prusa.gcode` and `tmc4361a.txt` (see [`export`]).
pub fn tune_with(
    path: &Path,
    out: Option<PathBuf>,
    opts: &Options,
    progress: Progress,
) -> Result<Tuned, Error> {
    let (sc, src) = load(path, opts)?;
    let out = out.unwrap_or_else(|| PathBuf::from("results").join(format!("{}-tune", sc.name)));
    // The output folder, before the search: never an input, nor earlier results unasked.
    let inputs = crate::expand::machine::input_files(&sc, &src);
    let writes = |rel: &Path| crate::output::folder::written(rel, &FILES, &[], &PATTERNS);
    crate::output::folder::check(&out, &RESULTS, opts.force, &inputs, writes)?;
    let mut done: Vec<(String, Outcome)> = Vec::new();
    for axis in axes(&sc) {
        let o = search_axis(path, axis.as_deref(), opts, progress)?;
        done.push((o.plan.base.axis.clone(), o));
    }
    let shared = if target::one_acceleration(done[0].1.plan.firmware) {
        joint::share_acceleration(&mut done)
    } else {
        None
    };
    for (_, o) in &mut done {
        finish(path, o, opts)?;
    }
    create_dir(&out)?;
    let produced_by = format!("settle tune {}", path.display());
    let klipper = export::klipper(&done, &produced_by);
    let rrf = export::rrf(&done, &produced_by);
    let marlin = export::marlin(&done, &produced_by);
    let prusa = export::prusa(&done, &produced_by);
    let tmc = export::tmc4361a(&done);
    let mut md = format!("# settle tune: {}\n\n", sc.name);
    md.push_str(&head::current_to_recommended(&done, shared.as_deref()));
    if let Some(c) = export::klipper_changes(&done) {
        md.push_str(&changes::table("klipper.cfg", &c));
    }
    if let Some(c) = export::rrf_changes(&done) {
        md.push_str(&changes::table("rrf.g", &c));
    }
    if let Some(c) = export::marlin_changes(&done) {
        md.push_str(&changes::table("marlin.gcode", &c));
    }
    if let Some(c) = export::prusa_changes(&done) {
        md.push_str(&changes::table("prusa.gcode", &c));
    }
    let mut figures = Vec::new();
    for (axis, o) in &done {
        let name = figure_name(axis, done.len());
        let fig = figure::pareto_figure(&sc.name, axis, o);
        crate::output::plot::write(&fig, &out, &name)?;
        md.push_str(&report::axis_section(axis, o, &format!("{name}.svg")));
        md.push_str(&checks::refine_text(o));
        md.push_str(&checks::check_text(o));
        md.push('\n');
        figures.push(out.join(format!("{name}.svg")));
    }
    let marlin_kind = match done[0].1.plan.firmware.marlin_shaping() {
        firmware::MarlinShaping::FtMotion => "Fixed-Time Motion, M493",
        firmware::MarlinShaping::InputShaping => "input shaping, M593",
    };
    let _ = write!(
        md,
        "## Export\n\nKlipper (`klipper.cfg`; paste at the end of printer.cfg, above any SAVE_CONFIG block):\n\n```ini\n{klipper}```\n\nRepRapFirmware (`rrf.g`; config.g lines):\n\n```\n{rrf}```\n\nMarlin (`marlin.gcode`; {marlin_kind}):\n\n```\n{marlin}```\n\nPrusa-Firmware-Buddy (`prusa.gcode`; M593):\n\n```\n{prusa}```\n\nTMC4361A ramp registers (`tmc4361a.txt`):\n\n```\n{tmc}```\n"
    );
    let write = |name: &str, text: &str| write_atomic(&out.join(name), text.as_bytes());
    write("tune.md", &md)?;
    write("candidates.csv", &candidates::csv(&done))?;
    write("klipper.cfg", &klipper)?;
    write("rrf.g", &rrf)?;
    write("marlin.gcode", &marlin)?;
    write("prusa.gcode", &prusa)?;
    write("tmc4361a.txt", &tmc)?;
    let text = crate::input::file::read_text(path, crate::input::file::limit::SETTINGS)?;
    let page = html::page(html::Page {
        name: &sc.name,
        markdown: &md,
        axes: &done,
        figures: &figures,
        exports: [
            ("klipper.cfg", klipper.as_str()),
            ("rrf.g", rrf.as_str()),
            ("marlin.gcode", marlin.as_str()),
            ("prusa.gcode", prusa.as_str()),
            ("tmc4361a.txt", tmc.as_str()),
        ],
        provenance: crate::output::report::provenance(
            crate::output::report::ScenarioFile { path, text: &text },
            opts.backend.name(),
            produced_by.clone(),
        ),
    })?;
    write(crate::output::sweep_files::REPORT, &page)?;
    let outcome = done[0].1.clone();
    Ok(Tuned {
        outcome,
        axes: done,
        markdown: md,
        out,
    })
}

/// The file name (without extension) of axis `axis`'s Pareto figure among `n` axes.
pub fn figure_name(axis: &str, n: usize) -> String {
    if n > 1 {
        format!("pareto-{axis}")
    } else {
        "pareto".into()
    }
}
