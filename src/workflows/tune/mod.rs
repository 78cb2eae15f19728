//! `settle tune SCENARIO.toml`: the search grid ([`grid`], candidates and scores in
//! [`search`], restricted to a [`firmware`]), evaluated and refined ([`rank`]), optionally
//! re-checked on a second backend, per axis; the outputs ([`report`], the firmware
//! configurations in [`export`]); and Klipper's own choice on a resonance CSV
//! ([`klipper_criterion`]).

pub mod export;
pub mod firmware;
pub mod grid;
pub mod klipper_criterion;
pub mod rank;
pub mod report;
pub mod scan_figures;
pub mod search;

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
        firmware::Firmware::parse(f).map_err(|m| Error::input_key(path, "--firmware", m))?;
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

/// Tune one axis of `path` (`None`: the move's axis).
pub fn tune_axis(
    path: &Path,
    axis: Option<&str>,
    opts: &Options,
    progress: Progress,
) -> Result<Outcome, Error> {
    let (sc, src) = load(path, opts)?;
    let (backend, check_on, jobs) = (opts.backend, opts.check_on, opts.jobs);
    // An imported scenario's [sweep] is for `settle sweep`; the search starts from the
    // scenario's own point, the user's current settings (its [current] marks a point of
    // that sweep, so it goes with it).
    let mut point = sc.clone();
    point.sweep.clear();
    point.current.clear();
    let mut runs = crate::expand::expand(&point, &src)?;
    crate::execute::set_backend(path, &mut runs, backend)?;
    let plan = grid::plan(&sc, &src, &runs, axis)?;
    let mut scores = rank::evaluate(&plan, &plan.candidates, jobs, progress)?;
    let grid_winner = rank::best(&scores).ok_or_else(|| {
        Error::input_key(
            path,
            "observe.window_s",
            "no candidate settles within the observation window; lengthen window_s or widen the band",
        )
    })?;
    let winner = rank::refine(&plan, &mut scores, grid_winner, jobs)?;
    let front = rank::pareto(&scores);
    let check = match check_on {
        None => None,
        Some(b) => {
            let mut other = plan.clone();
            let mut base = vec![other.base.clone()];
            crate::execute::set_backend(path, &mut base, b)?;
            other.base.backend = b;
            let pair = [scores[0].candidate, scores[winner].candidate];
            let s = rank::evaluate(&other, &pair, jobs, &quiet)?;
            Some((b, s[0].clone(), s[1].clone()))
        }
    };
    Ok(Outcome {
        plan,
        scores,
        winner,
        grid_winner,
        front,
        check,
    })
}

/// The refinement paragraph of the report: the grid winner, how many candidates the
/// refinement evaluated, and what it gained.
pub fn refine_text(o: &Outcome) -> String {
    let extra = o.scores.len() - o.plan.candidates.len();
    if o.plan
        .spec
        .refine_rounds
        .unwrap_or(rank::DEFAULT_REFINE_ROUNDS)
        == 0
    {
        return String::new();
    }
    let (g, w) = (&o.scores[o.grid_winner], &o.scores[o.winner]);
    let [_, _, h_score] = report::headings(&o.plan);
    let mut out = format!(
        "\n## Refinement around the grid winner\n\n{} grid candidates, then {} rounds around the grid winner ({extra} more candidates). ",
        o.plan.candidates.len(),
        o.plan
            .spec
            .refine_rounds
            .unwrap_or(rank::DEFAULT_REFINE_ROUNDS),
    );
    if o.winner == o.grid_winner {
        let _ = writeln!(
            out,
            "The grid winner {} stays the winner.",
            g.candidate.label()
        );
    } else {
        let _ = writeln!(
            out,
            "Grid winner {}: {} {:.2} ms; refined {}: {:.2} ms ({:.2} ms better).",
            g.candidate.label(),
            h_score.trim_end_matches(" (ms)"),
            g.move_and_settle_s * 1e3,
            w.candidate.label(),
            w.move_and_settle_s * 1e3,
            (g.move_and_settle_s - w.move_and_settle_s) * 1e3
        );
    }
    out
}

/// The second-backend paragraph of the report.
pub fn check_text(o: &Outcome) -> String {
    let Some((b, d, w)) = &o.check else {
        return String::new();
    };
    let plan = &o.plan;
    let band = plan.base.bands_um[plan.band_index];
    let [h_move, h_res, h_score] = report::headings(plan);
    let mut out = String::new();
    let _ = writeln!(
        out,
        "\n## Checked on a second backend: {b}\n\n| | candidate | {h_move} | {h_res} | {h_score} | into {band} um (ms) |\n|---|---|---:|---:|---:|---:|"
    );
    report::default_and_winner_rows(&mut out, d, w, "winner");
    let verdict = if w.move_and_settle_s < d.simulated_move_and_settle_s {
        format!(
            "the winner still beats the current settings on {b}: {:.1}% better",
            100.0 * (1.0 - w.move_and_settle_s / d.simulated_move_and_settle_s)
        )
    } else {
        format!("the winner does NOT beat the current settings on {b}")
    };
    let _ = writeln!(out, "\nVerdict: {verdict}.");
    let searched = &o.scores[o.winner];
    let _ = writeln!(
        out,
        "Into the {band} um band the winner takes {} ms on {b} ({} ms on {}, {}).",
        report::ms(w.at_band_s),
        report::ms(searched.at_band_s),
        plan.base.backend,
        if w.at_band_s <= searched.at_band_s + 1.0 / plan.base.sample_rate_hz {
            "confirmed within one sample"
        } else {
            "later than predicted: consider a smaller [tune] margin"
        }
    );
    out
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

/// The files `settle tune` writes in its output folder.
const FILES: [&str; 8] = [
    "tune.md",
    "candidates.csv",
    "klipper.cfg",
    "rrf.g",
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

/// Tune every axis of `[tune] axes` (default: the move's axis) of `path`, and write into
/// `out` (default: `results/<name>-tune/`): `tune.md` (your current settings ->
/// recommended per axis, then each axis's search), `candidates.csv` (every candidate of
/// every axis with its smoothing and max_accel), `pareto.svg/png` (the first axis),
/// `klipper.cfg`, `rrf.g` and `tmc4361a.txt` (see [`export`]).
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
    let writes = |rel: &Path| crate::output::folder::written(rel, &FILES, &[], &[]);
    crate::output::folder::check(&out, &RESULTS, opts.force, &inputs, writes)?;
    let mut done: Vec<(String, Outcome)> = Vec::new();
    for axis in axes(&sc) {
        let o = tune_axis(path, axis.as_deref(), opts, progress)?;
        done.push((o.plan.base.axis.clone(), o));
    }
    create_dir(&out)?;
    let mut md = format!("# settle tune: {}\n\n", sc.name);
    md.push_str(&report::current_to_recommended(&done));
    let several = done.len() > 1;
    for (axis, o) in &done {
        let mut body = report::markdown(&sc.name, &o.plan, &o.scores, o.winner, &o.front);
        body.push_str(&refine_text(o));
        body.push_str(&check_text(o));
        let body = body
            .split_once('\n')
            .map_or(body.as_str(), |(_, rest)| rest)
            .to_string();
        if several {
            let _ = write!(md, "\n## Axis {axis}\n{}", report::demote(&body));
        } else {
            md.push_str(&body);
        }
    }
    let produced_by = format!("settle tune {}", path.display());
    let klipper = export::klipper(&done, &produced_by);
    let rrf = export::rrf(&done, &produced_by);
    let tmc = export::tmc4361a(&done);
    let _ = write!(
        md,
        "\n## Export\n\nKlipper (`klipper.cfg`; paste at the end of printer.cfg, above any SAVE_CONFIG block):\n\n```ini\n{klipper}```\n\nRepRapFirmware (`rrf.g`; config.g lines):\n\n```\n{rrf}```\n\nTMC4361A ramp registers (`tmc4361a.txt`):\n\n```\n{tmc}```\n\n![Pareto front](pareto.svg)\n"
    );
    let write = |name: &str, text: &str| write_atomic(&out.join(name), text.as_bytes());
    write("tune.md", &md)?;
    write("candidates.csv", &report::candidates_csv(&done))?;
    write("klipper.cfg", &klipper)?;
    write("rrf.g", &rrf)?;
    write("tmc4361a.txt", &tmc)?;
    let o = &done[0].1;
    let fig = report::pareto_figure(&sc.name, &o.plan, &o.scores, o.winner, &o.front);
    crate::output::plot::write(&fig, &out, "pareto")?;
    // report.html: tune.md's tables, every candidate, the Pareto figure, the provenance.
    let text = crate::input::file::read_text(path, crate::input::file::limit::SETTINGS)?;
    let file = crate::output::report::ScenarioFile { path, text: &text };
    let svg_path = out.join("pareto.svg");
    let svg = crate::input::file::read_text(&svg_path, crate::input::file::limit::RESULTS)?;
    let html = crate::output::report::markdown_report(
        &format!("{} (tune)", sc.name),
        &md,
        &report::candidates_csv(&done),
        &[("Pareto front".to_string(), svg)],
        crate::output::report::provenance(
            file,
            opts.backend.name(),
            format!("settle tune {}", path.display()),
        ),
    );
    write(
        crate::output::sweep_files::REPORT,
        &crate::output::html::render(&html),
    )?;
    let outcome = o.clone();
    Ok(Tuned {
        outcome,
        axes: done,
        markdown: md,
        out,
    })
}
