//! `settle sweep`: run every point of a scenario's sweep (or one shard of it) and write the
//! output folder. Every finished run's row goes to the journal at once, so an interruption
//! (or a crash) loses nothing: `resume` runs only what is missing (see
//! [`crate::workflows::journal`]). A run that fails is a row with its reason; the sweep
//! goes on and reports the failures at the end.

use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::error::Error;
use crate::execute::pool::{Progress, run_each_errors};
use crate::input::runs_columns::RunsColumns;
use crate::measure::metrics::Metrics;
use crate::output::atomic::{create_dir, create_subdir, write_atomic};
use crate::output::report::ScenarioFile;
use crate::output::runs_csv::RunsCsv;
use crate::output::sink::{Provenance, Recorder};
use crate::output::sweep_files::{PLOTS, RECORDINGS, write_sweep};
use crate::spec::backend::Backend;
use crate::spec::run_spec::RunSpec;
use crate::spec::runs::RunList;
use crate::workflows::journal::{self, Journal};
use crate::workflows::lock::FolderLock;
use crate::workflows::shard::{self, Manifest, Shard};
use crate::workflows::{Exit, Report};

/// What to sweep and how.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepOptions {
    /// The scenario file.
    pub scenario: PathBuf,
    /// Output folder (default: `results/<name>/`, `results/<name>/shard-K-of-N/` for a
    /// shard).
    pub out: Option<PathBuf>,
    /// Worker threads [default: all cores].
    pub jobs: Option<usize>,
    /// The backend.
    pub backend: Backend,
    /// Write an MCAP recording per run.
    pub mcap: bool,
    /// Write a rerun recording per run (needs the `rerun` feature).
    pub rerun: bool,
    /// Run only this shard.
    pub shard: Option<Shard>,
    /// Continue an interrupted sweep from its journal.
    pub resume: bool,
    /// Overwrite the results of an earlier sweep in the output folder (without it, a folder
    /// holding `runs.csv`, `summary.md`, `report.html` or a journal is refused).
    pub force: bool,
}

impl SweepOptions {
    /// Sweep `scenario` on `backend` with every other option at its default.
    pub fn new(scenario: impl Into<PathBuf>, backend: Backend) -> Self {
        Self {
            scenario: scenario.into(),
            out: None,
            jobs: None,
            backend,
            mcap: false,
            rerun: false,
            shard: None,
            resume: false,
            force: false,
        }
    }
}

/// A failed run (from runs.csv's `status` and `reason`).
#[derive(Debug, Clone, PartialEq)]
pub struct FailedRun {
    /// Its id.
    pub id: usize,
    /// `profile, distance` as in the listing (`scurve, 5 mm`).
    pub what: String,
    /// `lost_steps` or `fault`.
    pub status: String,
    /// Why.
    pub reason: String,
}

/// What a sweep did.
#[derive(Debug, Clone)]
pub struct SweepOutcome {
    /// The scenario file.
    pub scenario: PathBuf,
    /// The output folder.
    pub out: PathBuf,
    /// The runs of this sweep (or shard).
    pub runs: usize,
    /// The shard, if one.
    pub shard: Option<Shard>,
    /// The failed runs (empty when all ran).
    pub failed: Vec<FailedRun>,
    /// Runs finished and kept in the journal when the sweep was interrupted, else `None`.
    pub interrupted: Option<usize>,
    /// Where the recordings are, when asked for.
    pub recordings: Option<PathBuf>,
    /// Wall-clock time (s).
    pub elapsed_s: f64,
    /// The options it ran with (for the command that resumes it).
    pub options: SweepOptions,
}

/// The recorder the flags ask for, checked before any work (a missing feature costs no
/// simulation).
pub fn recorder(
    mcap: bool,
    rerun: bool,
    dir: PathBuf,
    scenario: &Path,
    name: &str,
) -> Result<Option<Recorder>, Error> {
    if rerun && !crate::output::sink::rerun::AVAILABLE {
        return Err(Error::input(
            "--rerun",
            crate::output::sink::rerun::UNAVAILABLE,
        ));
    }
    if !(mcap || rerun) {
        return Ok(None);
    }
    Ok(Some(Recorder {
        dir,
        mcap,
        rerun,
        provenance: Provenance::load(scenario, name)?,
    }))
}

/// Run the sweep. `note` gets the lines worth showing as they happen (what runs where,
/// resuming); `progress` the finished runs.
pub fn sweep(
    opts: &SweepOptions,
    note: &dyn Fn(&str),
    progress: Progress,
) -> Result<SweepOutcome, Error> {
    let started = Instant::now();
    let path = &opts.scenario;
    let (sc, src) = crate::expand::load(path)?;
    // Made on demand from their ids: a sweep holds no run spec per run.
    let mut all_runs = crate::expand::sweep_runs(&sc, &src)?;
    let inputs = crate::expand::machine::inputs_identity(&sc, &src)?;
    crate::execute::check_backend(path, &all_runs, opts.backend)?;
    all_runs.set_backend(opts.backend);
    let base = PathBuf::from("results").join(&sc.name);
    let out = opts.out.clone().unwrap_or_else(|| match opts.shard {
        Some(s) => base.join(s.folder()),
        None => base,
    });
    if let Some(s) = opts.shard.filter(|s| s.n > all_runs.len()) {
        return Err(Error::input(
            "--shard",
            format!(
                "{s}: the scenario has {} runs, so at most {} shards",
                all_runs.len(),
                all_runs.len()
            ),
        ));
    }
    let rec = recorder(opts.mcap, opts.rerun, out.join(RECORDINGS), path, &sc.name)?;
    let total_runs = all_runs.len();
    let runs = match opts.shard {
        Some(s) => all_runs.every(s.k - 1, s.n),
        None => all_runs,
    };
    // A recorded run keeps its whole trace: each is checked for it before any starts.
    if rec.is_some() {
        for i in 0..runs.len() {
            crate::expand::validate::validate_recorded(&(&runs as &dyn RunList).at(i), &src)?;
        }
    }
    // Never onto the scenario or a file it reads, nor through a link out of the folder.
    let read = crate::expand::machine::input_files(&sc, &src);
    crate::output::folder::check(&out, &NO_RESULTS, true, &read, writes)?;
    for sub in [PLOTS, RECORDINGS] {
        if std::fs::symlink_metadata(out.join(sub)).is_ok() {
            create_subdir(&out.join(sub))?;
        }
    }
    create_dir(&out)?;
    // The lock first: a folder another sweep is writing is refused as such.
    let _lock = FolderLock::take(&out)?;
    if !opts.resume && !opts.force {
        refuse_overwrite(&out)?;
    }
    // What a killed sweep was writing (`.NAME.tmpPID` beside NAME): nobody else writes here.
    for dir in [out.clone(), out.join(PLOTS), out.join(RECORDINGS)] {
        remove_stale_temps(&dir)?;
    }
    if let Some(r) = &rec {
        create_subdir(&r.dir)?;
    }
    note(&format!(
        "{}: {} runs on {}{} -> {}",
        path.display(),
        runs.len(),
        opts.backend,
        opts.shard.map_or(String::new(), |s| format!(
            " (shard {s} of {} runs)",
            total_runs
        )),
        out.display()
    ));
    let layout = RunsCsv::new(&runs);
    let header = layout.header();
    let scenario_text = src.text().to_string();
    let key = journal::key_line(
        &scenario_text,
        &inputs,
        &sc.name,
        opts.backend.name(),
        &opts.shard.map_or(String::new(), |s| s.to_string()),
    );
    // The leading cells of each run's row: its parameters, up to its status.
    let n_params = layout
        .columns()
        .iter()
        .position(|c| c == "status")
        .unwrap_or(0);
    let params = |id: usize| {
        let spec = runs.get(runs.position(id)?)?;
        let cells = layout.cells(&spec, &Metrics::failed(&spec.bands_um, String::new()));
        let mut prefix = crate::input::runs_table::record(&cells[..n_params]);
        prefix.pop();
        prefix.push(',');
        Some(prefix)
    };
    let resuming = opts.resume && journal::existing(&out).is_some();
    let (journal, done) = match journal::existing(&out) {
        Some(_) if opts.resume => {
            let (j, done, notes) = Journal::resume(&out, &key, &header, &params)?;
            for n in notes {
                note(&format!("{}: {n}", out.join(journal::FILE).display()));
            }
            (j, done)
        }
        Some(p) if !opts.force => {
            return Err(Error::input(
                "--resume",
                format!(
                    "{} holds an interrupted sweep: continue it with --resume, or delete the file to start over",
                    p.display()
                ),
            ));
        }
        _ => (Journal::start(&out, &key, &header)?, Default::default()),
    };
    // The finished runs' ids (their rows stay in the journal).
    let done: std::collections::HashSet<usize> = done.into_keys().collect();
    if resuming {
        note(&format!(
            "resuming: {} of {} runs already finished",
            done.len(),
            runs.len()
        ));
    } else if opts.resume {
        note("--resume: no journal here, so a new sweep");
    }
    // What is left to run (positions among the runs).
    let todo: Vec<u32> = (0..runs.len())
        .filter(|&i| runs.id(i).is_some_and(|id| !done.contains(&id)))
        .map(|i| i as u32)
        .collect();
    // An output that cannot be written (a full disk) is not a result of a run: the sweep
    // stops, the journal keeps what finished, and `--resume` completes it.
    let write_failed = std::sync::atomic::AtomicBool::new(false);
    let run_one = |k: usize| -> Result<(), Error> {
        let spec = (&runs as &dyn RunList).at(todo[k] as usize);
        let spec: &RunSpec = &spec;
        if write_failed.load(std::sync::atomic::Ordering::SeqCst) {
            return Err(Error::Interrupted { run: spec.id });
        }
        let m = match match &rec {
            Some(r) => r.run(spec).map_err(Error::as_write_failure),
            None => crate::execute::execute(spec, None),
        } {
            Ok(m) => m,
            // Not a result of the run: nothing goes to the journal.
            Err(e @ Error::Interrupted { .. }) => return Err(e),
            Err(e @ Error::Write { .. }) => {
                write_failed.store(true, std::sync::atomic::Ordering::SeqCst);
                return Err(e);
            }
            Err(e) => Metrics::failed(&spec.bands_um, format!("{e}")),
        };
        let row = layout.row(spec, &m);
        if let Err(e) = journal.append(&row) {
            write_failed.store(true, std::sync::atomic::Ordering::SeqCst);
            return Err(e);
        }
        Ok(())
    };
    let errors = run_each_errors(todo.len(), opts.jobs, progress, run_one)?;
    let finished = done.len() + todo.len() - errors.len();
    drop((todo, done));
    let mut interrupted = 0usize;
    let mut write_error = None;
    for (_, e) in errors {
        match e {
            Error::Interrupted { .. } => interrupted += 1,
            e => {
                write_error.get_or_insert(e);
            }
        }
    }
    if let Some(e) = write_error {
        return Err(e);
    }
    let mut outcome = SweepOutcome {
        scenario: path.clone(),
        out: out.clone(),
        runs: runs.len(),
        shard: opts.shard,
        failed: Vec::new(),
        interrupted: None,
        recordings: rec.as_ref().map(|r| r.dir.clone()),
        elapsed_s: 0.0,
        options: opts.clone(),
    };
    if interrupted > 0 || crate::execute::interrupt::requested() {
        outcome.interrupted = Some(finished);
        outcome.elapsed_s = started.elapsed().as_secs_f64();
        return Ok(outcome);
    }
    // The rows in run order, read back from the journal.
    let csv = journal.runs_csv(&header, runs.len(), &|id| runs.position(id))?;
    let ids = || (0..runs.len()).filter_map(|i| runs.id(i));
    match opts.shard {
        Some(s) => {
            write_atomic(&out.join("runs.csv"), csv.as_bytes())?;
            shard::write_manifest(
                &out,
                &Manifest {
                    format: shard::FORMAT.to_string(),
                    settle_version: env!("CARGO_PKG_VERSION").to_string(),
                    scenario_name: sc.name.clone(),
                    scenario_file: path.display().to_string(),
                    shard: s.k,
                    shards: s.n,
                    total_runs,
                    runs: ids().collect(),
                    settings: [("backend".to_string(), opts.backend.name().to_string())]
                        .into_iter()
                        .collect(),
                    inputs: inputs.clone(),
                    runs_digest: shard::runs_digest(&csv),
                    recordings: match &rec {
                        Some(r) => ids()
                            .flat_map(|id| {
                                [(r.mcap, "mcap"), (r.rerun, "rrd")]
                                    .into_iter()
                                    .filter(|(on, _)| *on)
                                    .map(move |(_, ext)| format!("run-{id}.{ext}"))
                            })
                            .collect(),
                        None => Vec::new(),
                    },
                    scenario: scenario_text,
                },
            )?;
        }
        None => {
            let file = ScenarioFile {
                path,
                text: &scenario_text,
            };
            write_sweep(&out, &sc, file, &runs, &csv)?
        }
    }
    outcome.elapsed_s = started.elapsed().as_secs_f64();
    journal.finish()?;
    outcome.failed = failures(&runs, &csv);
    Ok(outcome)
}

/// The files of an earlier sweep that `settle sweep` refuses to overwrite without `--force`.
pub const KEPT: [&str; 4] = [
    "runs.csv",
    "summary.md",
    crate::output::sweep_files::REPORT,
    journal::FILE,
];

/// The results-folder check without earlier results to find (a sweep finds them itself,
/// after taking the folder's lock: [`refuse_overwrite`]).
const NO_RESULTS: crate::output::folder::Results<'static> = crate::output::folder::Results {
    what: "a sweep",
    marks: &[],
};

/// Whether a sweep (or a shard) writes `rel` in its output folder.
pub fn writes(rel: &Path) -> bool {
    crate::output::folder::written(
        rel,
        &[
            "runs.csv",
            "summary.md",
            crate::output::sweep_files::REPORT,
            journal::FILE,
            crate::workflows::lock::FILE,
            shard::MANIFEST,
        ],
        &[PLOTS, RECORDINGS],
        &[],
    )
}

/// An error when `out` holds the results of an earlier sweep ([`KEPT`]).
fn refuse_overwrite(out: &Path) -> Result<(), Error> {
    let found: Vec<&str> = KEPT
        .iter()
        .copied()
        .filter(|f| out.join(f).exists())
        .collect();
    if found.is_empty() {
        return Ok(());
    }
    let interrupted = found.contains(&journal::FILE);
    Err(Error::input(
        "--force",
        format!(
            "{} already holds {}: pass --force to overwrite it, --out DIR to write elsewhere{}",
            out.display(),
            if interrupted {
                "an interrupted sweep"
            } else {
                "the results of a sweep"
            },
            if interrupted {
                ", or --resume to continue it"
            } else {
                ""
            }
        ),
    ))
}

/// Remove the temporary files of atomic writes ([`crate::output::atomic::tmp_path`]) left
/// in `dir` by a sweep that was killed while writing.
fn remove_stale_temps(dir: &Path) -> Result<(), Error> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Ok(()); // no such folder yet
    };
    for e in entries.flatten() {
        let name = e.file_name();
        let name = name.to_string_lossy();
        if name.starts_with('.') && name.contains(".tmp") && e.path().is_file() {
            std::fs::remove_file(e.path()).map_err(|err| Error::write(e.path(), err))?;
        }
    }
    Ok(())
}

/// The failed runs, from runs.csv's `status` and `reason` columns.
pub fn failures(runs: &dyn RunList, csv: &str) -> Vec<FailedRun> {
    let Ok(table) = RunsColumns::parse(csv) else {
        return Vec::new();
    };
    (0..runs.len())
        .filter(|&i| table.cell(i, "status").is_some_and(|s| s != "ok"))
        .map(|i| FailedRun {
            id: runs.at(i).id,
            what: format!("{}, {} mm", runs.at(i).profile, runs.at(i).distance_mm),
            status: table.cell(i, "status").unwrap_or_default().to_string(),
            reason: table.cell(i, "reason").unwrap_or_default().to_string(),
        })
        .collect()
}

impl SweepOutcome {
    /// The command that resumes this sweep: the same scenario, folder, backend, shard and
    /// recordings (everything the journal's key or the outputs depend on), and `--jobs`
    /// when it was given.
    pub fn resume_command(&self) -> String {
        let o = &self.options;
        let quote = |p: &Path| {
            let s = p.display().to_string();
            if s.chars()
                .all(|c| c.is_ascii_alphanumeric() || "/._-+".contains(c))
            {
                s
            } else {
                format!("'{}'", s.replace('\'', "'\\''"))
            }
        };
        let mut cmd = format!(
            "settle sweep {} --out {} --backend {}",
            quote(&self.scenario),
            quote(&self.out),
            o.backend.name()
        );
        if let Some(s) = o.shard {
            cmd.push_str(&format!(" --shard {s}"));
        }
        if let Some(j) = o.jobs {
            cmd.push_str(&format!(" --jobs {j}"));
        }
        if o.mcap {
            cmd.push_str(" --mcap");
        }
        if o.rerun {
            cmd.push_str(" --rerun");
        }
        cmd.push_str(" --resume");
        cmd
    }

    /// What `settle sweep` prints: where the outputs are, and the failed runs (at most 20,
    /// then a count).
    pub fn report(&self) -> Report {
        let out = &self.out;
        if let Some(kept) = self.interrupted {
            let mut r = Report::new(Exit::Interrupted);
            r.err(format!(
                "interrupted: {kept} of {} runs finished and kept in {}; continue with\n  {}",
                self.runs,
                out.join(journal::FILE).display(),
                self.resume_command()
            ));
            return r;
        }
        let mut r = Report::new(if self.failed.is_empty() {
            Exit::Ok
        } else {
            Exit::RunsFailed
        });
        match self.shard {
            Some(s) => r.err(format!(
                "wrote shard {s}: {} and {} ({} runs in {:.2} s); combine all shards with `settle merge`",
                out.join("runs.csv").display(),
                out.join(shard::MANIFEST).display(),
                self.runs,
                self.elapsed_s
            )),
            None => r.err(format!(
                "wrote {}, {}, {} and {}/ ({} runs in {:.2} s){}",
                out.join("runs.csv").display(),
                out.join("summary.md").display(),
                out.join(crate::output::sweep_files::REPORT).display(),
                out.join(PLOTS).display(),
                self.runs,
                self.elapsed_s,
                self.recordings
                    .as_ref()
                    .map_or(String::new(), |d| format!("; recordings in {}", d.display()))
            )),
        }
        list_failures(&mut r, &self.failed, self.runs);
        r
    }
}

/// The failed runs on stderr (at most 20, then a count), as `settle sweep` and `settle
/// merge` print them.
pub fn list_failures(r: &mut Report, failed: &[FailedRun], runs: usize) {
    if failed.is_empty() {
        return;
    }
    r.err(format!(
        "{} of {runs} runs failed (status and reason in runs.csv):",
        failed.len(),
    ));
    const SHOWN: usize = 20;
    for f in failed.iter().take(SHOWN) {
        r.err(format!(
            "  run {} ({}): {}: {}",
            f.id, f.what, f.status, f.reason
        ));
    }
    if failed.len() > SHOWN {
        r.err(format!("  ... and {} more", failed.len() - SHOWN));
    }
}
