//! The `settle` command.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::Context;
use clap::{Parser, Subcommand};

use settle::run::Backend;
use settle::{Error, report};

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
    /// Run every point of a scenario's sweep and write runs.csv and summary.md.
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
    /// Plan motion problems: JSON lines on stdin, one profile (or error) per line on stdout.
    #[command(
        after_help = "Example:\n  echo '{\"p0\":[0],\"pf\":[1],\"vmax\":[1],\"amax\":[2],\"jmax\":[10],\"sync\":\"time\"}' | settle plan\n\nInput keys (arrays, one value per axis): p0 v0 a0 pf vf af vmax amax jmax [vmin amin];\n\"sync\": time|phase|none, \"kind\": scurve|trapezoid, \"interface\": position|velocity.\nOutput: {\"duration\":..,\"axes\":[{\"p0\",\"v0\",\"a0\",\"segments\":[[duration,jerk],..]}]}\n(a constant-acceleration segment is [duration,0,accel]) or {\"error\":\"..\"}."
    )]
    Plan {
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
        /// Simulation backend: modal, rapier, mujoco.
        #[arg(long, default_value = "rapier", value_parser = parse_backend)]
        backend: Backend,
    },
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
        } => sweep(scenario, out, jobs.map(usize::from), backend),
        Command::Validate { backend, out } => settle::validate::command(backend, out.as_deref()),
        Command::Plan { jobs } => plan_lines(jobs.map(usize::from)),
        Command::Run {
            scenario,
            case,
            out,
            backend,
        } => run_one(scenario, case, out, backend),
    }
}

fn sweep(
    path: PathBuf,
    out: Option<PathBuf>,
    jobs: Option<usize>,
    backend: Backend,
) -> anyhow::Result<ExitCode> {
    let started = Instant::now();
    let (sc, mut runs) = settle::load_runs(&path)?;
    settle::run::set_backend(&path, &mut runs, backend)?;
    let out = out.unwrap_or_else(|| PathBuf::from("results").join(&sc.name));
    std::fs::create_dir_all(&out).map_err(|source| Error::Write {
        path: out.clone(),
        source,
    })?;
    eprintln!(
        "{}: {} runs on {backend} -> {}",
        path.display(),
        runs.len(),
        out.display()
    );
    let results = settle::run_all(&runs, jobs, true)?;
    let mut metrics = Vec::with_capacity(results.len());
    for r in results {
        metrics.push(r.context("a run failed; nothing was written")?);
    }
    report::write_atomic(
        &out.join("runs.csv"),
        report::runs_csv(&runs, &metrics).as_bytes(),
    )?;
    report::write_atomic(
        &out.join("summary.md"),
        report::summary_md(&sc, &runs, &metrics).as_bytes(),
    )?;
    eprintln!(
        "wrote {} and {} ({} runs in {:.2} s)",
        out.join("runs.csv").display(),
        out.join("summary.md").display(),
        runs.len(),
        started.elapsed().as_secs_f64()
    );
    Ok(ExitCode::SUCCESS)
}

fn run_one(
    path: PathBuf,
    case: usize,
    out: Option<PathBuf>,
    backend: Backend,
) -> anyhow::Result<ExitCode> {
    let (sc, mut runs) = settle::load_runs(&path)?;
    settle::run::set_backend(&path, &mut runs, backend)?;
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
    let mut series = settle::series::Series::default();
    let m = settle::run::execute(spec, Some(&mut series))?;
    let mut csv = Vec::new();
    series.write_csv(&mut csv).context("formatting the trace")?;
    report::write_atomic(&out, &csv)?;
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
    if let settle::metrics::Status::LostSteps { axis, steps } = &m.status {
        println!(
            "  FAILED: lost {steps} full steps (axis {axis}): the numbers above are not a settling result"
        );
    }
    println!("trace: {} ({} samples)", out.display(), series.len());
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
                .map(|l| settle::plan_lines::answer(l))
                .collect()
        });
        for a in answers {
            writeln!(out, "{a}").context("writing stdout")?;
        }
    }
    out.flush().context("writing stdout")?;
    Ok(ExitCode::SUCCESS)
}
