//! `settle tune SCENARIO.toml`: the search grid ([`grid`], candidates and scores in
//! [`search`]), evaluated and refined ([`rank`]), optionally re-checked on a second backend,
//! and the outputs ([`report`]).

pub mod grid;
pub mod rank;
pub mod report;
pub mod scan_figures;
pub mod search;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::error::Error;
use crate::execute::pool::{Progress, quiet};
use crate::output::atomic::{create_dir, write_atomic};
use crate::spec::backend::Backend;
use crate::workflows::{Exit, Report};
use search::{Plan, Score};

/// What a tuning found.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// The resolved search.
    pub plan: Plan,
    /// Every candidate's score; index 0 is the untuned default.
    pub scores: Vec<Score>,
    /// Index of the winner in `scores` (after refinement).
    pub winner: usize,
    /// Index of the best grid candidate (the refinement started from it).
    pub grid_winner: usize,
    /// Indices of the Pareto front.
    pub front: Vec<usize>,
    /// `(backend, default, winner)` re-run on a second backend, if asked.
    pub check: Option<(Backend, Score, Score)>,
}

/// Load `path`, search on `backend`, and re-check on `check_on` if given.
pub fn tune(
    path: &Path,
    backend: Backend,
    check_on: Option<Backend>,
    jobs: Option<usize>,
    progress: Progress,
) -> Result<Outcome, Error> {
    let (sc, src) = crate::expand::load(path)?;
    let mut runs = crate::expand::expand(&sc, &src)?;
    crate::execute::set_backend(path, &mut runs, backend)?;
    let plan = grid::plan(&sc, &src, &runs)?;
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
    let verdict = if w.move_and_settle_s < d.move_and_settle_s {
        format!(
            "the winner still beats the default on {b}: {:.1}% better",
            100.0 * (1.0 - w.move_and_settle_s / d.move_and_settle_s)
        )
    } else {
        format!("the winner does NOT beat the default on {b}")
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
    /// The search and its result.
    pub outcome: Outcome,
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

/// Tune `path` on `backend` (re-checked on `check_on`), and write `OUT/tune.md`,
/// `candidates.csv`, `pareto.svg/png`, `klipper.cfg` and `tmc5160.txt` into `out`
/// (default: `results/<name>-tune/`).
pub fn tune_to(
    path: &Path,
    out: Option<PathBuf>,
    backend: Backend,
    check_on: Option<Backend>,
    jobs: Option<usize>,
    progress: Progress,
) -> Result<Tuned, Error> {
    let (sc, _) = crate::expand::load(path)?;
    let o = tune(path, backend, check_on, jobs, progress)?;
    let out = out.unwrap_or_else(|| PathBuf::from("results").join(format!("{}-tune", sc.name)));
    create_dir(&out)?;
    let mut md = report::markdown(&sc.name, &o.plan, &o.scores, o.winner, &o.front);
    md.push_str(&refine_text(&o));
    md.push_str(&check_text(&o));
    let w = &o.scores[o.winner];
    let klipper = report::klipper(&o.plan, w);
    let tmc = report::tmc(&o.plan, w);
    let _ = write!(
        md,
        "\n## Export\n\nKlipper (`klipper.cfg`):\n\n```ini\n{klipper}```\n\nTrinamic TMC5160 (`tmc5160.txt`):\n\n```\n{tmc}```\n\n![Pareto front](pareto.svg)\n"
    );
    let write = |name: &str, text: &str| write_atomic(&out.join(name), text.as_bytes());
    write("tune.md", &md)?;
    write("candidates.csv", &report::candidates_csv(&o.scores))?;
    write("klipper.cfg", &klipper)?;
    write("tmc5160.txt", &tmc)?;
    let fig = report::pareto_figure(&sc.name, &o.plan, &o.scores, o.winner, &o.front);
    crate::output::plot::write(&fig, &out, "pareto")?;
    // report.html: tune.md's tables, every candidate, the Pareto figure, the provenance.
    let text = std::fs::read_to_string(path).map_err(|e| Error::read(path, e))?;
    let file = crate::output::report::ScenarioFile { path, text: &text };
    let svg_path = out.join("pareto.svg");
    let svg = std::fs::read_to_string(&svg_path).map_err(|e| Error::read(&svg_path, e))?;
    let html = crate::output::report::markdown_report(
        &format!("{} (tune)", sc.name),
        &md,
        &report::candidates_csv(&o.scores),
        &[("Pareto front".to_string(), svg)],
        crate::output::report::provenance(
            file,
            backend.name(),
            format!("settle tune {}", path.display()),
        ),
    );
    write(
        crate::output::sweep_files::REPORT,
        &crate::output::html::render(&html),
    )?;
    Ok(Tuned {
        outcome: o,
        markdown: md,
        out,
    })
}
