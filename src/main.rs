//! The `settle` command.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::Context;
use clap::{Parser, Subcommand};

use settle::Error;
use settle::execute::run::Backend;
use settle::output::report;

fn parse_backend(s: &str) -> Result<Backend, String> {
    Backend::parse(s).ok_or_else(|| format!("unknown backend `{s}`; allowed: {}", Backend::ALLOWED))
}

#[derive(Parser, Debug)]
#[command(
    name = "settle",
    version,
    about = "Which motion profile makes my machine settle fastest, and by how much?",
    after_help = "Example:\n  settle sweep scenarios/quickstart.toml\n  (writes results/quickstart/runs.csv and summary.md)"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Run every point of a scenario's sweep and write runs.csv, summary.md and plots.
    #[command(
        after_help = "Example:\n  settle sweep scenarios/quickstart.toml --out /tmp/qs --jobs 2"
    )]
    Sweep {
        /// The scenario file (TOML).
        scenario: PathBuf,
        /// Output folder [default: results/<scenario name>/].
        #[arg(long)]
        out: Option<PathBuf>,
        /// Worker threads [default: all cores].
        #[arg(long, value_parser = clap::value_parser!(u16).range(1..))]
        jobs: Option<u16>,
        /// Simulation backend: modal (exact, linear driver only), rapier, mujoco.
        #[arg(long, default_value = "rapier", value_parser = parse_backend)]
        backend: Backend,
        #[command(flatten)]
        outputs: OutputFlags,
        /// Run only shard K of N (1-based: runs i with i % N == K-1) into
        /// DIR [default: results/<scenario name>/shard-K-of-N/]; combine with `settle merge`.
        #[arg(long, value_name = "K/N")]
        shard: Option<settle::workflows::shard::Shard>,
        /// Continue an interrupted sweep: keep the runs in OUT/journal.csv, run the rest.
        #[arg(long)]
        resume: bool,
    },
    /// Check every backend against the closed form and against each other; print a table.
    #[command(
        after_help = "Example:\n  settle validate\n  settle validate --backend rapier --out validate.md\n\nExit code 1 when a check is past its threshold (frequency 0.5 %, residual 2 %,\nengines 3 %, numerical damping 10 % of the physical)."
    )]
    Validate {
        /// Only this backend (with the modal reference) [default: every available one].
        #[arg(long, value_parser = parse_backend)]
        backend: Option<Backend>,
        /// Also write the table as Markdown to this file.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Rerun a scenario and compare every metric of every run with a committed baseline.
    #[command(
        after_help = "Exit status: 0 when every value is within the tolerance, 1 (with a table of run,\nmetric, baseline, now, delta%) when any is not, 2 on bad input.\n\nAny change beyond the tolerance fails, worse or better: settle is deterministic, so a\nchange means behaviour changed, and --update makes accepting it a reviewed commit.\n\nExample:\n  settle check scenarios/ci_quickstart.toml --baseline results/baselines/ci_quickstart.csv\n  settle check scenarios/ci_quickstart.toml --baseline results/baselines/ci_quickstart.csv --update"
    )]
    Check {
        /// The scenario file (TOML).
        scenario: PathBuf,
        /// The baseline: a runs.csv written by settle (results/baselines/<name>.csv).
        #[arg(long)]
        baseline: PathBuf,
        /// Relative tolerance in percent (numbers closer than this to the baseline pass).
        #[arg(long, value_name = "PCT", default_value_t = settle::workflows::check::DEFAULT_TOLERANCE_PCT)]
        tolerance: f64,
        /// Rewrite the baseline with this run's values (on purpose: commit the diff).
        #[arg(long)]
        update: bool,
        /// Pass when every change is an improvement of a settling metric.
        #[arg(long)]
        allow_improvements: bool,
        /// Simulation backend: modal, rapier, mujoco [default: the one the baseline was made
        /// with (its `backend` column); rapier for a new baseline].
        #[arg(long, value_parser = parse_backend)]
        backend: Option<Backend>,
        /// Worker threads [default: all cores].
        #[arg(long, value_parser = clap::value_parser!(u16).range(1..))]
        jobs: Option<u16>,
    },
    /// Combine the folders of a sharded sweep into the outputs of an unsharded one.
    #[command(
        after_help = "Example:\n  settle sweep scenarios/quickstart.toml --shard 1/2\n  settle sweep scenarios/quickstart.toml --shard 2/2\n  settle merge results/quickstart/shard-1-of-2 results/quickstart/shard-2-of-2\n  (writes results/quickstart/runs.csv, summary.md and plots/, as an unsharded sweep)"
    )]
    Merge {
        /// The shard folders (each written by `settle sweep --shard K/N`), in any order.
        #[arg(required = true)]
        dirs: Vec<PathBuf>,
        /// Output folder [default: results/<scenario name>/].
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Plan motion problems: JSON lines on stdin, one profile (or error) per line on stdout.
    #[command(
        after_help = "Example:\n  echo '{\"p0\":[0],\"pf\":[1],\"vmax\":[1],\"amax\":[2],\"jmax\":[10],\"sync\":\"time\"}' | settle plan\n\nInput keys (arrays, one value per axis): p0 v0 a0 pf vf af vmax amax jmax [vmin amin];\n\"sync\": time|phase|none, \"kind\": scurve|trapezoid, \"interface\": position|velocity.\nOutput: {\"duration\":..,\"axes\":[{\"p0\",\"v0\",\"a0\",\"segments\":[[duration,jerk],..]}]}\n(a constant-acceleration segment is [duration,0,accel]) or {\"error\":\"..\"}."
    )]
    Plan {
        /// Worker threads [default: all cores].
        #[arg(long, value_parser = clap::value_parser!(u16).range(1..))]
        jobs: Option<u16>,
    },
    /// Search the profile parameters (kind, jerk, PVT asymmetry, BOW1..4, input shaper)
    /// that minimise move-and-settle on the scenario's machine; export the winner.
    #[command(
        after_help = "Example:\n  settle tune scenarios/tune_printer.toml --check-on rapier\n  (writes results/tune_printer-tune/tune.md, candidates.csv, pareto.svg/png,\n  klipper.cfg and tmc5160.txt)"
    )]
    Tune {
        /// The scenario file (TOML) with [move], [limits] and an optional [tune] table.
        scenario: PathBuf,
        /// Output folder [default: results/<scenario name>-tune/].
        #[arg(long)]
        out: Option<PathBuf>,
        /// Backend of the search [default: modal, exact and fast; needs the linear driver].
        #[arg(long, default_value = "modal", value_parser = parse_backend)]
        backend: Backend,
        /// Re-run the default and the winner on this second backend and compare.
        #[arg(long, value_parser = parse_backend)]
        check_on: Option<Backend>,
        /// Worker threads [default: all cores].
        #[arg(long, value_parser = clap::value_parser!(u16).range(1..))]
        jobs: Option<u16>,
    },
    /// Run one point of a sweep in detail: print its metrics, write its full trace as CSV.
    #[command(
        after_help = "Example:\n  settle run scenarios/quickstart.toml --case 3\n  (prints the metrics of run 3 and writes results/quickstart/run-3.csv)"
    )]
    Run {
        /// The scenario file (TOML).
        scenario: PathBuf,
        /// The run index, as in the `run` column of runs.csv.
        #[arg(long)]
        case: usize,
        /// Trace file [default: results/<scenario name>/run-<case>.csv].
        #[arg(long)]
        out: Option<PathBuf>,
        #[command(flatten)]
        outputs: OutputFlags,
        /// Also draw the run's time series as run-<case>.svg and .png beside the trace.
        #[arg(long)]
        plot: bool,
        /// Simulation backend: modal, rapier, mujoco.
        #[arg(long, default_value = "rapier", value_parser = parse_backend)]
        backend: Backend,
    },
}

/// Recordings a sweep or a run can write.
#[derive(clap::Args, Debug, Clone, Copy)]
struct OutputFlags {
    /// Write an MCAP recording per run (zstd, JSON schemas; opens in Foxglove).
    #[arg(long)]
    mcap: bool,
    /// Write a rerun recording (.rrd) per run (needs the `rerun` cargo feature).
    #[arg(long)]
    rerun: bool,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match dispatch(cli) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            let input = e.downcast_ref::<Error>().is_some_and(Error::is_input_error);
            ExitCode::from(if input { 2 } else { 1 })
        }
    }
}

fn dispatch(cli: Cli) -> anyhow::Result<ExitCode> {
    match cli.command {
        Command::Sweep {
            scenario,
            out,
            jobs,
            backend,
            outputs,
            shard,
            resume,
        } => sweep(
            scenario,
            out,
            jobs.map(usize::from),
            backend,
            outputs,
            shard,
            resume,
        ),
        Command::Validate { backend, out } => {
            settle::workflows::validate::command(backend, out.as_deref())
        }
        Command::Check {
            scenario,
            baseline,
            tolerance,
            update,
            allow_improvements,
            backend,
            jobs,
        } => check(
            &scenario,
            &baseline,
            tolerance,
            update,
            allow_improvements,
            backend,
            jobs.map(usize::from),
        ),
        Command::Merge { dirs, out } => merge(&dirs, out),
        Command::Tune {
            scenario,
            out,
            backend,
            check_on,
            jobs,
        } => {
            let md = settle::workflows::tune::command(
                &scenario,
                out,
                backend,
                check_on,
                jobs.map(usize::from),
            )?;
            print!("{md}");
            Ok(ExitCode::SUCCESS)
        }
        Command::Plan { jobs } => plan_lines(jobs.map(usize::from)),
        Command::Run {
            scenario,
            case,
            out,
            outputs,
            plot,
            backend,
        } => run_one(scenario, case, out, outputs, plot, backend),
    }
}

fn create_dir(dir: &std::path::Path) -> Result<(), Error> {
    std::fs::create_dir_all(dir).map_err(|source| Error::Write {
        path: dir.to_path_buf(),
        source,
    })
}

fn usage_error(what: &str, message: impl Into<String>) -> Error {
    Error::Input {
        at: settle::error::Location {
            file: what.into(),
            line: None,
            column: None,
            key: None,
        },
        message: message.into(),
    }
}

/// Check recording flags before any work, so a missing feature costs no simulation.
fn recorder(
    flags: OutputFlags,
    dir: PathBuf,
    scenario: &std::path::Path,
    name: &str,
) -> anyhow::Result<Option<settle::output::sink::Recorder>> {
    if flags.rerun && !settle::output::sink::rerun::AVAILABLE {
        return Err(usage_error("--rerun", settle::output::sink::rerun::UNAVAILABLE).into());
    }
    if !(flags.mcap || flags.rerun) {
        return Ok(None);
    }
    Ok(Some(settle::output::sink::Recorder {
        dir,
        mcap: flags.mcap,
        rerun: flags.rerun,
        provenance: settle::output::sink::Provenance::load(scenario, name)?,
    }))
}

fn sweep(
    path: PathBuf,
    out: Option<PathBuf>,
    jobs: Option<usize>,
    backend: Backend,
    flags: OutputFlags,
    shard: Option<settle::workflows::shard::Shard>,
    resume: bool,
) -> anyhow::Result<ExitCode> {
    let started = Instant::now();
    let (sc, mut all_runs) = settle::load_runs(&path)?;
    settle::execute::run::set_backend(&path, &mut all_runs, backend)?;
    let base = PathBuf::from("results").join(&sc.name);
    let out = out.unwrap_or_else(|| match shard {
        Some(s) => base.join(s.folder()),
        None => base,
    });
    if let Some(s) = shard.filter(|s| s.n > all_runs.len()) {
        return Err(usage_error(
            "--shard",
            format!(
                "{s}: the scenario has {} runs, so at most {} shards",
                all_runs.len(),
                all_runs.len()
            ),
        )
        .into());
    }
    let rec = recorder(
        flags,
        out.join(settle::output::sweep_files::RECORDINGS),
        &path,
        &sc.name,
    )?;
    let runs = match shard {
        Some(s) => s.select(&all_runs),
        None => all_runs.clone(),
    };
    create_dir(&out)?;
    if let Some(r) = &rec {
        create_dir(&r.dir)?;
    }
    eprintln!(
        "{}: {} runs on {backend}{} -> {}",
        path.display(),
        runs.len(),
        shard.map_or(String::new(), |s| format!(
            " (shard {s} of {} runs)",
            all_runs.len()
        )),
        out.display()
    );
    // Every finished run's row goes to the journal at once, so an interruption (or a
    // crash) loses nothing: `--resume` runs only what is missing (see settle::workflows::journal).
    let header = report::runs_csv(&runs, &[]);
    let scenario_text = std::fs::read_to_string(&path).map_err(|source| Error::Read {
        path: path.clone(),
        source,
    })?;
    let key = settle::workflows::journal::key_line(
        &scenario_text,
        &sc.name,
        backend.name(),
        &shard.map_or(String::new(), |s| s.to_string()),
    );
    let ids: Vec<usize> = runs.iter().map(|r| r.id).collect();
    let (journal, done) = match settle::workflows::journal::existing(&out) {
        Some(_) if resume => {
            settle::workflows::journal::Journal::resume(&out, &key, &header, &ids)?
        }
        Some(p) => {
            return Err(usage_error(
                "--resume",
                format!(
                    "{} holds an interrupted sweep: continue it with --resume, or delete the file to start over",
                    p.display()
                ),
            )
            .into());
        }
        None => (
            settle::workflows::journal::Journal::start(&out, &key, &header)?,
            Default::default(),
        ),
    };
    if resume {
        eprintln!(
            "resuming: {} of {} runs already finished",
            done.len(),
            runs.len()
        );
    }
    let todo: Vec<settle::RunSpec> = runs
        .iter()
        .filter(|r| !done.contains_key(&r.id))
        .cloned()
        .collect();
    settle::execute::interrupt::install().map_err(|m| usage_error("signals", m))?;
    let run_one = |spec: &settle::RunSpec| -> Result<String, Error> {
        let m = match &rec {
            Some(r) => r.run(spec),
            None => settle::execute::run::execute(spec, None),
        }
        // A run that fails is a row with its reason; the sweep goes on (issue 8).
        .unwrap_or_else(|e| settle::Metrics::failed(&spec.bands_um, format!("{e}")));
        let row = report::runs_csv_row(&runs, spec, &m);
        journal.append(&row)?;
        Ok(row)
    };
    let results = settle::run_all_with(&todo, jobs, true, run_one)?;
    let mut rows = done;
    let mut interrupted = 0usize;
    for (spec, r) in todo.iter().zip(results) {
        match r {
            Ok(row) => {
                rows.insert(spec.id, row);
            }
            Err(Error::Interrupted { .. }) => interrupted += 1,
            Err(e) => return Err(e.into()),
        }
    }
    if interrupted > 0 || settle::execute::interrupt::requested() {
        eprintln!(
            "interrupted: {} of {} runs finished and kept in {}; continue with\n  settle sweep {} --out {} --resume{}",
            rows.len(),
            runs.len(),
            out.join(settle::workflows::journal::FILE).display(),
            path.display(),
            out.display(),
            shard.map_or(String::new(), |s| format!(" --shard {s}"))
        );
        return Ok(ExitCode::from(settle::execute::interrupt::EXIT_CODE));
    }
    let mut csv = header;
    for r in &runs {
        csv.push_str(&rows[&r.id]);
    }
    match shard {
        Some(s) => {
            report::write_atomic(&out.join("runs.csv"), csv.as_bytes())?;
            let scenario = std::fs::read_to_string(&path).map_err(|source| Error::Read {
                path: path.clone(),
                source,
            })?;
            settle::workflows::shard::write_manifest(
                &out,
                &settle::workflows::shard::Manifest {
                    format: settle::workflows::shard::FORMAT.to_string(),
                    settle_version: env!("CARGO_PKG_VERSION").to_string(),
                    scenario_name: sc.name.clone(),
                    scenario_file: path.display().to_string(),
                    shard: s.k,
                    shards: s.n,
                    total_runs: all_runs.len(),
                    runs: runs.iter().map(|r| r.id).collect(),
                    settings: [("backend".to_string(), backend.name().to_string())]
                        .into_iter()
                        .collect(),
                    scenario,
                },
            )?;
            eprintln!(
                "wrote shard {s}: {} and {} ({} runs in {:.2} s); combine all shards with `settle merge`",
                out.join("runs.csv").display(),
                out.join(settle::workflows::shard::MANIFEST).display(),
                runs.len(),
                started.elapsed().as_secs_f64()
            );
        }
        None => {
            settle::output::sweep_files::write_sweep(&out, &sc, &runs, &csv)?;
            eprintln!(
                "wrote {}, {} and {}/ ({} runs in {:.2} s){}",
                out.join("runs.csv").display(),
                out.join("summary.md").display(),
                out.join(settle::output::sweep_files::PLOTS).display(),
                runs.len(),
                started.elapsed().as_secs_f64(),
                rec.map_or(String::new(), |r| format!(
                    "; recordings in {}",
                    r.dir.display()
                ))
            );
        }
    }
    journal.finish()?;
    Ok(report_failures(&runs, &csv))
}

/// Print the failed runs (at most 20, then a count) from runs.csv's `status` and `reason`
/// columns, and return exit code 1 if there are any, success otherwise.
fn report_failures(runs: &[settle::RunSpec], csv: &str) -> ExitCode {
    let Ok(table) = settle::input::runs_table::RunsTable::parse(csv) else {
        return ExitCode::from(1);
    };
    let failed: Vec<usize> = (0..runs.len())
        .filter(|&i| table.cell(i, "status").is_some_and(|s| s != "ok"))
        .collect();
    if failed.is_empty() {
        return ExitCode::SUCCESS;
    }
    eprintln!(
        "{} of {} runs failed (status and reason in runs.csv):",
        failed.len(),
        runs.len()
    );
    const SHOWN: usize = 20;
    for &i in failed.iter().take(SHOWN) {
        let r = &runs[i];
        eprintln!(
            "  run {} ({}, {} mm): {}: {}",
            r.id,
            r.profile,
            r.distance_mm,
            table.cell(i, "status").unwrap_or_default(),
            table.cell(i, "reason").unwrap_or_default()
        );
    }
    if failed.len() > SHOWN {
        eprintln!("  ... and {} more", failed.len() - SHOWN);
    }
    ExitCode::from(1)
}

fn check(
    path: &std::path::Path,
    baseline: &std::path::Path,
    tolerance_pct: f64,
    update: bool,
    allow_improvements: bool,
    backend: Option<Backend>,
    jobs: Option<usize>,
) -> anyhow::Result<ExitCode> {
    if !(tolerance_pct.is_finite() && tolerance_pct >= 0.0) {
        return Err(usage_error(
            "--tolerance",
            format!("must be a finite percentage >= 0, got {tolerance_pct}"),
        )
        .into());
    }
    let (sc, mut runs) = settle::load_runs(path)?;
    let old = match std::fs::read_to_string(baseline) {
        Ok(text) => Some(text),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound && update => None,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(usage_error(
                &baseline.display().to_string(),
                format!(
                    "no baseline here; create it on purpose with `settle check {} --baseline {} --update`",
                    path.display(),
                    baseline.display()
                ),
            )
            .into());
        }
        Err(source) => {
            return Err(Error::Read {
                path: baseline.to_path_buf(),
                source,
            }
            .into());
        }
    };
    let old_table = old
        .as_deref()
        .map(settle::input::runs_table::RunsTable::parse)
        .transpose()
        .map_err(|e| usage_error(&baseline.display().to_string(), e))?;
    // The backend: as asked, else the baseline's own; a baseline made on another backend
    // than the one asked for is an error (its numbers are not comparable), unless updating.
    let made_with = old_table
        .as_ref()
        .map(settle::workflows::check::baseline_backend)
        .transpose()
        .map_err(|e| usage_error(&baseline.display().to_string(), e))?
        .flatten();
    let backend = match (backend, made_with.as_deref()) {
        (Some(b), Some(m)) if b.name() != m && !update => {
            return Err(usage_error(
                &baseline.display().to_string(),
                format!(
                    "this baseline was made on backend `{m}`, not `{b}`: pass --backend {m}, or rewrite it with --update"
                ),
            )
            .into());
        }
        (Some(b), _) => b,
        (None, Some(m)) => Backend::parse(m).ok_or_else(|| {
            usage_error(
                &baseline.display().to_string(),
                format!(
                    "unknown backend `{m}` in its backend column; allowed: {}",
                    Backend::ALLOWED
                ),
            )
        })?,
        (None, None) => Backend::default(),
    };
    settle::execute::run::set_backend(path, &mut runs, backend)?;
    let results = settle::run_all(&runs, jobs, true)?;
    let mut metrics = Vec::with_capacity(results.len());
    for r in results {
        metrics.push(r.context("a run failed")?);
    }
    let csv = report::runs_csv(&runs, &metrics);
    let now = settle::input::runs_table::RunsTable::parse(&csv)
        .map_err(|e| usage_error("runs.csv", e))?;
    let comparison = old_table
        .as_ref()
        .map(|b| settle::workflows::check::compare(b, &now, tolerance_pct));
    if update {
        if let Some(dir) = baseline.parent().filter(|d| !d.as_os_str().is_empty()) {
            create_dir(dir)?;
        }
        report::write_atomic(baseline, csv.as_bytes())?;
        match comparison {
            Some(Ok(c)) if !c.changes.is_empty() => println!(
                "updated {}: {} values changed beyond {tolerance_pct}%:\n{}",
                baseline.display(),
                c.changes.len(),
                settle::workflows::check::table(&c.changes, usize::MAX)
            ),
            Some(Ok(_)) => println!(
                "updated {} ({} runs; no value changed beyond {tolerance_pct}%)",
                baseline.display(),
                runs.len()
            ),
            Some(Err(e)) => println!("updated {} (it had another shape: {e})", baseline.display()),
            None => println!("created {} ({} runs)", baseline.display(), runs.len()),
        }
        return Ok(ExitCode::SUCCESS);
    }
    let c = match comparison {
        Some(Ok(c)) => c,
        Some(Err(e)) => {
            eprintln!(
                "settle check {}: FAILED against {}: {e}",
                sc.name,
                baseline.display()
            );
            return Ok(ExitCode::from(1));
        }
        None => unreachable!("a missing baseline without --update returned above"),
    };
    let failures = c.failures(allow_improvements);
    use settle::workflows::check::Verdict;
    let counts = format!(
        "{} worse, {} better, {} changed",
        c.count(Verdict::Worse),
        c.count(Verdict::Better),
        c.count(Verdict::Changed)
    );
    if !c.changes.is_empty() {
        println!("{}", settle::workflows::check::table(&c.changes, 500));
    }
    if failures > 0 {
        eprintln!(
            "settle check {}: FAILED: {} of {} values ({} runs) differ from {} by more than {tolerance_pct}% ({counts}).\n\
If the change is intended, rewrite the baseline and commit it:\n  settle check {} --baseline {} --update",
            sc.name,
            c.changes.len(),
            c.cells,
            c.runs,
            baseline.display(),
            path.display(),
            baseline.display()
        );
        return Ok(ExitCode::from(1));
    }
    println!(
        "settle check {}: ok: {} values ({} runs) match {} within {tolerance_pct}%{}",
        sc.name,
        c.cells,
        c.runs,
        baseline.display(),
        if c.changes.is_empty() {
            String::new()
        } else {
            format!(" except improvements ({counts}), allowed by --allow-improvements")
        }
    );
    Ok(ExitCode::SUCCESS)
}

fn merge(dirs: &[PathBuf], out: Option<PathBuf>) -> anyhow::Result<ExitCode> {
    let mut m = settle::workflows::shard::merge(dirs)?;
    // The backend the shards ran on (a setting every shard agrees on).
    if let Some(b) = m
        .manifest
        .settings
        .get("backend")
        .and_then(|b| Backend::parse(b))
    {
        let file = PathBuf::from(&m.manifest.scenario_file);
        settle::execute::run::set_backend(&file, &mut m.runs, b)?;
    }
    let out = out.unwrap_or_else(|| PathBuf::from("results").join(&m.scenario.name));
    create_dir(&out)?;
    settle::output::sweep_files::write_sweep(&out, &m.scenario, &m.runs, &m.csv)?;
    // Recordings: gathered into one folder, as an unsharded sweep leaves them.
    let mut copied = 0usize;
    for d in dirs {
        let src = d.join(settle::output::sweep_files::RECORDINGS);
        let Ok(entries) = std::fs::read_dir(&src) else {
            continue;
        };
        let dst = out.join(settle::output::sweep_files::RECORDINGS);
        create_dir(&dst)?;
        for e in entries {
            let e = e.map_err(|source| Error::Read {
                path: src.clone(),
                source,
            })?;
            let name = e.file_name();
            if name.to_string_lossy().starts_with('.') {
                continue;
            }
            let to = dst.join(&name);
            if std::fs::hard_link(e.path(), &to).is_err() {
                std::fs::copy(e.path(), &to).map_err(|source| Error::Write {
                    path: to.clone(),
                    source,
                })?;
            }
            copied += 1;
        }
    }
    eprintln!(
        "merged {} shards of `{}` ({} runs) into {}{}",
        dirs.len(),
        m.scenario.name,
        m.runs.len(),
        out.display(),
        if copied > 0 {
            format!(
                "; {copied} recordings gathered in {}",
                settle::output::sweep_files::RECORDINGS
            )
        } else {
            String::new()
        }
    );
    Ok(ExitCode::SUCCESS)
}

fn run_one(
    path: PathBuf,
    case: usize,
    out: Option<PathBuf>,
    flags: OutputFlags,
    plot: bool,
    backend: Backend,
) -> anyhow::Result<ExitCode> {
    let (sc, mut runs) = settle::load_runs(&path)?;
    settle::execute::run::set_backend(&path, &mut runs, backend)?;
    let Some(spec) = runs.get(case) else {
        return Err(Error::Input {
            at: settle::error::Location {
                file: path.clone(),
                line: None,
                column: None,
                key: None,
            },
            message: format!(
                "--case {case} does not exist: the scenario has runs 0..={}",
                runs.len().saturating_sub(1)
            ),
        }
        .into());
    };
    let out = out.unwrap_or_else(|| {
        PathBuf::from("results")
            .join(&sc.name)
            .join(format!("run-{case}.csv"))
    });
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|source| Error::Write {
            path: dir.to_path_buf(),
            source,
        })?;
    }
    let dir = out
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .map_or_else(|| PathBuf::from("."), PathBuf::from);
    let rec = recorder(flags, dir.clone(), &path, &sc.name)?;
    let (series, m) = settle::output::sink::record_run(spec)?;
    let mut csv = Vec::new();
    series.write_csv(&mut csv).context("formatting the trace")?;
    report::write_atomic(&out, &csv)?;
    let record = settle::output::sink::RunRecord {
        spec,
        series: &series,
        metrics: &m,
        row: settle::output::sink::row_of(spec, &m),
    };
    let mut written = vec![out.display().to_string()];
    if let Some(r) = &rec {
        if r.mcap {
            let p = out.with_extension("mcap");
            settle::output::sink::mcap::write_file(&p, &r.provenance, &record)?;
            written.push(p.display().to_string());
        }
        if r.rerun {
            let p = out.with_extension("rrd");
            settle::output::sink::rerun::write_file(&p, &r.provenance, &record)?;
            written.push(p.display().to_string());
        }
    }
    if plot {
        let stem = out.file_stem().map_or_else(
            || format!("run-{case}"),
            |s| s.to_string_lossy().into_owned(),
        );
        let swept: Vec<String> = spec
            .swept
            .iter()
            .map(|(k, v)| format!("{k} = {v}"))
            .collect();
        let title = format!("{} run {case}: {}", sc.name, swept.join(", "));
        let fig = settle::output::plot::trace::figure(&title, &record);
        settle::output::plot::write(&fig, &dir, &stem)?;
        written.push(dir.join(format!("{stem}.svg")).display().to_string());
        written.push(dir.join(format!("{stem}.png")).display().to_string());
    }
    println!(
        "run {case}: {} {} mm on axis {} of {} ({} driver, {backend})",
        spec.profile, spec.distance_mm, spec.axis, spec.machine_name, spec.driver
    );
    for (p, v) in &spec.swept {
        println!("  {p} = {v}");
    }
    println!("  move_time_s            {:.6}", m.move_time_s);
    println!("  residual_peak_um       {:.4}", m.residual_peak_um);
    println!("  residual_rms_um        {:.4}", m.residual_rms_um);
    for (i, b) in m.bands_um.iter().enumerate() {
        let show = |t: Option<f64>| t.map_or("not settled".to_string(), |t| format!("{t:.6}"));
        println!("  settle_time_s ({b} um)  {}", show(m.settle_time_s[i]));
        println!(
            "  move_and_settle_s ({b} um)  {}",
            show(m.move_and_settle_s(i))
        );
    }
    println!("  overshoot_um           {:.4}", m.overshoot_um);
    println!("  max_following_error_um {:.4}", m.max_following_error_um);
    if m.axes.len() > 1 {
        for a in &m.axes {
            println!(
                "  axis {}: residual_peak_um {:.4}, max_following_error_um {:.4}",
                a.name, a.residual_peak_um, a.max_following_error_um
            );
        }
    }
    for a in &m.axes {
        if let Some(deg) = a.max_load_angle_deg {
            println!(
                "  axis {}: max load angle {deg:.1} electrical degrees",
                a.name
            );
        }
    }
    if let settle::measure::metrics::Status::LostSteps { axis, steps } = &m.status {
        println!(
            "  FAILED: lost {steps} full steps (axis {axis}): the numbers above are not a settling result"
        );
    }
    println!("wrote {} ({} samples)", written.join(", "), series.len());
    Ok(ExitCode::SUCCESS)
}

/// Answer JSON lines from stdin in order, in parallel chunks.
fn plan_lines(jobs: Option<usize>) -> anyhow::Result<ExitCode> {
    use rayon::prelude::*;
    use std::io::{BufRead, Write};
    let mut builder = rayon::ThreadPoolBuilder::new();
    if let Some(n) = jobs {
        builder = builder.num_threads(n);
    }
    let pool = builder.build().context("starting worker threads")?;
    let stdin = std::io::stdin().lock();
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    let mut lines = stdin.lines();
    loop {
        let chunk: Vec<String> = lines
            .by_ref()
            .take(8192)
            .collect::<Result<_, _>>()
            .context("reading stdin")?;
        if chunk.is_empty() {
            break;
        }
        let answers: Vec<String> = pool.install(|| {
            chunk
                .par_iter()
                .map(|l| settle::workflows::plan::answer(l))
                .collect()
        });
        for a in answers {
            writeln!(out, "{a}").context("writing stdout")?;
        }
    }
    out.flush().context("writing stdout")?;
    Ok(ExitCode::SUCCESS)
}
