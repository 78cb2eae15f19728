//! `settle check SCENARIO --baseline FILE`: rerun a scenario and compare every cell of
//! every run with a committed baseline ([`compare`]); `update` rewrites the baseline on
//! purpose.

pub mod compare;

use std::path::{Path, PathBuf};

use crate::error::Error;
use crate::execute::pool::{Progress, run_all};
use crate::input::runs_table::RunsTable;
use crate::output::atomic::{create_dir, write_atomic};
use crate::output::runs_csv::runs_csv;
use crate::spec::backend::Backend;
use crate::workflows::{Exit, Report};

pub use compare::{Comparison, DEFAULT_FLOOR_UM, DEFAULT_TOLERANCE_PCT, Verdict};

/// What to check against what.
#[derive(Debug, Clone, PartialEq)]
pub struct CheckOptions {
    /// The scenario file.
    pub scenario: PathBuf,
    /// The baseline (a runs.csv written by settle).
    pub baseline: PathBuf,
    /// Relative tolerance (percent).
    pub tolerance_pct: f64,
    /// Absolute floor of length columns (um): changes smaller than it are no change.
    pub floor_um: f64,
    /// Rewrite the baseline with this run's values.
    pub update: bool,
    /// Pass when every change is an improvement of a settling metric.
    pub allow_improvements: bool,
    /// The backend [default: the baseline's own, rapier for a new baseline].
    pub backend: Option<Backend>,
    /// Worker threads [default: all cores].
    pub jobs: Option<usize>,
}

impl CheckOptions {
    /// Check `scenario` against `baseline` at the default tolerance.
    pub fn new(scenario: impl Into<PathBuf>, baseline: impl Into<PathBuf>) -> Self {
        Self {
            scenario: scenario.into(),
            baseline: baseline.into(),
            tolerance_pct: DEFAULT_TOLERANCE_PCT,
            floor_um: DEFAULT_FLOOR_UM,
            update: false,
            allow_improvements: false,
            backend: None,
            jobs: None,
        }
    }
}

/// How a check ended.
#[derive(Debug, Clone, PartialEq)]
pub enum CheckOutcome {
    /// `update` wrote the baseline: `None` for a new one, else the comparison with the old
    /// one (an error when it had another shape).
    Updated {
        /// Runs written.
        runs: usize,
        /// The comparison with the old baseline, if there was one.
        comparison: Option<Result<Comparison, String>>,
    },
    /// The comparison (passed or failed, see [`Checked::passed`]).
    Compared(Comparison),
    /// The baseline does not describe this scenario (columns or runs added or missing).
    Shape(String),
}

/// A check's outcome with what it needs to say it.
#[derive(Debug, Clone, PartialEq)]
pub struct Checked {
    /// The scenario's name.
    pub name: String,
    /// The options it ran with.
    pub opts: CheckOptions,
    /// How it ended.
    pub outcome: CheckOutcome,
}

fn baseline_error(baseline: &Path, message: impl Into<String>) -> Error {
    Error::input(baseline, message)
}

/// Run the check.
pub fn check(opts: &CheckOptions, progress: Progress) -> Result<Checked, Error> {
    let (path, baseline, tol) = (&opts.scenario, &opts.baseline, opts.tolerance_pct);
    if !(tol.is_finite() && tol >= 0.0) {
        return Err(Error::input(
            "--tolerance",
            format!("must be a finite percentage >= 0, got {tol}"),
        ));
    }
    if !(opts.floor_um.is_finite() && opts.floor_um >= 0.0) {
        return Err(Error::input(
            "--floor-um",
            format!("must be a finite length >= 0 (um), got {}", opts.floor_um),
        ));
    }
    let (sc, src) = crate::expand::load(path)?;
    let mut runs = crate::expand::expand(&sc, &src)?;
    if opts.update {
        // --update rewrites the baseline, and only the baseline: never the scenario or a
        // file it reads, a link or a device.
        crate::expand::machine::input_files(&sc, &src).refuse(baseline)?;
        settle_files::write::check_target(baseline)?;
    }
    let old = match crate::input::file::read_text(baseline, crate::input::file::limit::RESULTS) {
        Ok(text) => Some(text),
        Err(Error::Read { source, .. })
            if source.kind() == std::io::ErrorKind::NotFound && opts.update =>
        {
            None
        }
        Err(Error::Read { source, .. }) if source.kind() == std::io::ErrorKind::NotFound => {
            return Err(baseline_error(
                baseline,
                format!(
                    "no baseline here; create it on purpose with `settle check {} --baseline {} --update`",
                    path.display(),
                    baseline.display()
                ),
            ));
        }
        Err(e) => return Err(e),
    };
    let old_table = old
        .as_deref()
        .map(RunsTable::parse)
        .transpose()
        .map_err(|e| baseline_error(baseline, e))?;
    // A malformed baseline is refused before any run (one being rewritten need not be
    // well formed).
    if let Some(t) = old_table.as_ref().filter(|_| !opts.update) {
        compare::check_baseline(t).map_err(|e| baseline_error(baseline, e))?;
    }
    // The backend: as asked, else the baseline's own; a baseline made on another backend
    // than the one asked for is an error (its numbers are not comparable), unless updating.
    let made_with = old_table
        .as_ref()
        .map(compare::baseline_backend)
        .transpose()
        .map_err(|e| baseline_error(baseline, e))?
        .flatten();
    let backend = match (opts.backend, made_with.as_deref()) {
        (Some(b), Some(m)) if b.name() != m && !opts.update => {
            return Err(baseline_error(
                baseline,
                format!(
                    "this baseline was made on backend `{m}`, not `{b}`: pass --backend {m}, or rewrite it with --update"
                ),
            ));
        }
        (Some(b), _) => b,
        (None, Some(m)) => Backend::parse(m).ok_or_else(|| {
            baseline_error(
                baseline,
                format!(
                    "unknown backend `{m}` in its backend column; allowed: {}",
                    Backend::ALLOWED
                ),
            )
        })?,
        (None, None) => Backend::default(),
    };
    crate::execute::set_backend(path, &mut runs, backend)?;
    let results = run_all(&runs, opts.jobs, progress)?;
    let metrics = results.into_iter().collect::<Result<Vec<_>, _>>()?;
    let csv = runs_csv(&runs, &metrics);
    let now = RunsTable::parse(&csv).map_err(|e| Error::input("runs.csv", e))?;
    let comparison = old_table
        .as_ref()
        .map(|b| compare::compare(b, &now, tol, opts.floor_um));
    let outcome = if opts.update {
        if let Some(dir) = baseline.parent().filter(|d| !d.as_os_str().is_empty()) {
            create_dir(dir)?;
        }
        write_atomic(baseline, csv.as_bytes())?;
        CheckOutcome::Updated {
            runs: runs.len(),
            comparison,
        }
    } else {
        match comparison {
            Some(Ok(c)) => CheckOutcome::Compared(c),
            Some(Err(e)) => CheckOutcome::Shape(e),
            // A missing baseline without `update` returned above.
            None => CheckOutcome::Shape("no baseline".into()),
        }
    };
    Ok(Checked {
        name: sc.name,
        opts: opts.clone(),
        outcome,
    })
}

impl Checked {
    /// Whether the check passed (an update always does).
    pub fn passed(&self) -> bool {
        match &self.outcome {
            CheckOutcome::Updated { .. } => true,
            CheckOutcome::Compared(c) => c.failures(self.opts.allow_improvements) == 0,
            CheckOutcome::Shape(_) => false,
        }
    }

    /// What `settle check` prints: the table of changes and the verdict.
    pub fn report(&self) -> Report {
        let (name, opts) = (&self.name, &self.opts);
        let baseline = opts.baseline.display();
        let tol = format!("{}% (or {} um)", opts.tolerance_pct, opts.floor_um);
        let mut r = Report::new(if self.passed() {
            Exit::Ok
        } else {
            Exit::Failed
        });
        match &self.outcome {
            CheckOutcome::Updated { runs, comparison } => r.out(match comparison {
                Some(Ok(c)) if !c.changes.is_empty() => format!(
                    "updated {baseline}: {} values changed beyond {tol}:\n{}",
                    c.changes.len(),
                    compare::table(&c.changes, usize::MAX)
                ),
                Some(Ok(_)) => {
                    format!("updated {baseline} ({runs} runs; no value changed beyond {tol})")
                }
                Some(Err(e)) => format!("updated {baseline} (it had another shape: {e})"),
                None => format!("created {baseline} ({runs} runs)"),
            }),
            CheckOutcome::Shape(e) => {
                r.err(format!(
                    "settle check {name}: FAILED against {baseline}: {e}"
                ));
            }
            CheckOutcome::Compared(c) => {
                let counts = format!(
                    "{} worse, {} better, {} changed",
                    c.count(Verdict::Worse),
                    c.count(Verdict::Better),
                    c.count(Verdict::Changed)
                );
                if !c.changes.is_empty() {
                    r.out(compare::table(&c.changes, 500));
                }
                if self.passed() {
                    r.out(format!(
                        "settle check {name}: ok: {} values ({} runs) match {baseline} within {tol}{}",
                        c.cells,
                        c.runs,
                        if c.changes.is_empty() {
                            String::new()
                        } else {
                            format!(
                                " except improvements ({counts}), allowed by --allow-improvements"
                            )
                        }
                    ));
                } else {
                    r.err(format!(
                        "settle check {name}: FAILED: {} of {} values ({} runs) differ from {baseline} by more than {tol} ({counts}).\n\
If the change is intended, rewrite the baseline and commit it:\n  settle check {} --baseline {baseline} --update",
                        c.changes.len(),
                        c.cells,
                        c.runs,
                        opts.scenario.display(),
                    ));
                }
            }
        }
        r
    }
}
