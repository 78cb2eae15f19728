//! `settle run SCENARIO --case ID`: one point of a sweep in detail: its full trace as CSV,
//! optionally its recordings and a figure of its time series, and its metrics.
//!
//! A run that fails (lost steps, a simulation fault, a planner or backend error) is a
//! result as in `settle sweep`: its status and reason are printed instead of its metrics
//! (runs.csv leaves them empty too), its trace up to where it stopped is written, and the
//! report ends with [`Exit::RunsFailed`]. A run whose trace would be too long to keep is
//! not started: it is refused (exit 2, the key at fault and the numbers) before anything
//! is written, as a recorded sweep refuses it
//! ([`crate::expand::validate::validate_recorded`]).

use std::fmt::Write as _;
use std::path::PathBuf;

use crate::error::Error;
use crate::measure::metrics::Metrics;
use crate::measure::series::Series;
use crate::output::atomic::{create_dir, write_atomic};
use crate::output::sink::{RunRecord, record_run, row_of};
use crate::spec::backend::Backend;
use crate::spec::run_spec::RunSpec;
use crate::workflows::{Exit, Report};

/// Which run, and what to write.
#[derive(Debug, Clone, PartialEq)]
pub struct RunOptions {
    /// The scenario file.
    pub scenario: PathBuf,
    /// The run index, as in the `run` column of runs.csv.
    pub case: usize,
    /// Trace file (default: `results/<name>/run-<case>.csv`).
    pub out: Option<PathBuf>,
    /// Also write an MCAP recording beside the trace.
    pub mcap: bool,
    /// Also write a rerun recording beside the trace (needs the `rerun` feature).
    pub rerun: bool,
    /// Also draw the run's time series as `<trace>.svg` and `.png`.
    pub plot: bool,
    /// The backend.
    pub backend: Backend,
}

impl RunOptions {
    /// Run `case` of `scenario` on `backend`, writing the trace only.
    pub fn new(scenario: impl Into<PathBuf>, case: usize, backend: Backend) -> Self {
        Self {
            scenario: scenario.into(),
            case,
            out: None,
            mcap: false,
            rerun: false,
            plot: false,
            backend,
        }
    }
}

/// What the run did and where it is written.
#[derive(Debug, Clone)]
pub struct RunOutcome {
    /// The run.
    pub spec: RunSpec,
    /// Its metrics.
    pub metrics: Metrics,
    /// The files written (the trace first).
    pub written: Vec<PathBuf>,
    /// Samples in the trace.
    pub samples: usize,
}

/// Run one case.
pub fn run(opts: &RunOptions) -> Result<RunOutcome, Error> {
    let path = &opts.scenario;
    let case = opts.case;
    let (sc, src) = crate::expand::load(path)?;
    let mut runs = crate::expand::expand(&sc, &src)?;
    crate::execute::set_backend(path, &mut runs, opts.backend)?;
    let Some(spec) = runs.get(case) else {
        return Err(Error::input(
            path,
            format!(
                "--case {case} does not exist: the scenario has runs 0..={}",
                runs.len().saturating_sub(1)
            ),
        ));
    };
    // Its trace is kept whole: too long a one is refused before anything is written, as
    // a recorded sweep refuses it.
    crate::expand::validate::validate_recorded(spec, &src)?;
    let out = opts.out.clone().unwrap_or_else(|| {
        PathBuf::from("results")
            .join(&sc.name)
            .join(format!("run-{case}.csv"))
    });
    let dir = out
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .map_or_else(|| PathBuf::from("."), PathBuf::from);
    // Never onto the scenario or a file it reads, a link or a device: checked for every
    // file the run writes, before it runs.
    let inputs = crate::expand::machine::input_files(&sc, &src);
    let stem = out.file_stem().map_or_else(
        || format!("run-{case}"),
        |s| s.to_string_lossy().into_owned(),
    );
    let mut outputs = vec![out.clone()];
    if opts.mcap {
        outputs.push(out.with_extension("mcap"));
    }
    if opts.rerun {
        outputs.push(out.with_extension("rrd"));
    }
    if opts.plot {
        outputs.push(dir.join(format!("{stem}.svg")));
        outputs.push(dir.join(format!("{stem}.png")));
    }
    for o in &outputs {
        inputs.refuse(o)?;
        settle_files::write::check_target(o)?;
    }
    if out.parent().is_some_and(|d| !d.as_os_str().is_empty()) {
        create_dir(&dir)?;
    }
    let rec =
        crate::workflows::sweep::recorder(opts.mcap, opts.rerun, dir.clone(), path, &sc.name)?;
    let (series, m) = match record_run(spec) {
        Ok(done) => done,
        // As in a sweep: not a result of the run.
        Err(e @ (Error::Interrupted { .. } | Error::Write { .. })) => return Err(e),
        // As in a sweep: the run failed before it measured anything; a result.
        Err(e) => (
            Series::default(),
            Metrics::failed(&spec.bands_um, e.to_string()),
        ),
    };
    let mut written = Vec::new();
    if series.is_empty() {
        return Ok(RunOutcome {
            spec: spec.clone(),
            metrics: m,
            written,
            samples: 0,
        });
    }
    let mut csv = Vec::new();
    series
        .write_csv(&mut csv)
        .map_err(|e| Error::write(&out, e))?;
    write_atomic(&out, &csv)?;
    written.push(out.clone());
    let record = RunRecord {
        spec,
        series: &series,
        metrics: &m,
        row: row_of(spec, &m),
    };
    if let Some(r) = &rec {
        if r.mcap {
            let p = out.with_extension("mcap");
            crate::output::sink::mcap::write_file(&p, &r.provenance, &record)?;
            written.push(p);
        }
        if r.rerun {
            let p = out.with_extension("rrd");
            crate::output::sink::rerun::write_file(&p, &r.provenance, &record)?;
            written.push(p);
        }
    }
    if opts.plot {
        let title = format!("{} run {case}: {}", sc.name, spec.swept_text(", "));
        let mut fig = crate::output::plot::trace::figure(&title, &record);
        crate::output::plot::scan_trace::scan_view(&record, &mut fig.panels);
        crate::output::plot::write(&fig, &dir, &stem)?;
        written.push(dir.join(format!("{stem}.svg")));
        written.push(dir.join(format!("{stem}.png")));
    }
    Ok(RunOutcome {
        spec: spec.clone(),
        metrics: m,
        written,
        samples: series.len(),
    })
}

impl RunOutcome {
    /// What `settle run` prints: the run, its swept values and metrics, the files.
    pub fn report(&self) -> Report {
        let (spec, m) = (&self.spec, &self.metrics);
        let mut s = String::new();
        let _ = writeln!(
            s,
            "run {}: {} {} mm on axis {} of {} ({} driver, {})",
            spec.id,
            spec.profile,
            spec.distance_mm,
            spec.axis,
            spec.machine_name,
            spec.driver,
            spec.backend
        );
        for (p, v) in &spec.swept {
            let _ = writeln!(s, "  {p} = {v}");
        }
        if !m.is_ok() {
            return self.failed_report(s);
        }
        let _ = writeln!(s, "  move_time_s            {:.6}", m.move_time_s);
        let _ = writeln!(s, "  residual_peak_um       {:.4}", m.residual_peak_um);
        let _ = writeln!(s, "  residual_rms_um        {:.4}", m.residual_rms_um);
        let show = |t: Option<f64>| t.map_or("not settled".to_string(), |t| format!("{t:.6}"));
        for (i, b) in m.bands_um.iter().enumerate() {
            let _ = writeln!(s, "  settle_time_s ({b} um)  {}", show(m.settle_time_s[i]));
            let _ = writeln!(
                s,
                "  move_and_settle_s ({b} um)  {}",
                show(m.move_and_settle_s(i))
            );
        }
        let _ = writeln!(s, "  overshoot_um           {:.4}", m.overshoot_um);
        let _ = writeln!(
            s,
            "  max_following_error_um {:.4}",
            m.max_following_error_um
        );
        if m.axes.len() > 1 {
            for a in &m.axes {
                let _ = writeln!(
                    s,
                    "  axis {}: residual_peak_um {:.4}, max_following_error_um {:.4}",
                    a.name, a.residual_peak_um, a.max_following_error_um
                );
            }
        }
        self.load_angles(&mut s);
        if let Some((_, e)) = m.extra.iter().find(|(n, _)| n == "scan_reentry_error_um") {
            let _ = writeln!(
                s,
                "  scan: |error| of the step axis when the next line starts (re-entry) {e:.4} um (worst turnaround)"
            );
        }
        let extra = |n: &str| m.extra.iter().find(|(k, _)| k == n).map(|(_, v)| *v);
        if let (Some(w), Some(step)) = (extra("scan_window_s"), extra("scan_step_s")) {
            for b in &m.bands_um {
                if let Some(t) = extra(&format!("scan_step_settle_time_s_{b}um")) {
                    let _ = writeln!(
                        s,
                        "  scan: inside {b} um for good {} after the step's end, re-entry {:.1} ms after it: {}",
                        if t.is_finite() {
                            format!("{:.1} ms", t * 1e3)
                        } else {
                            "never (not before the next exit)".to_string()
                        },
                        (w - step) * 1e3,
                        if t <= w - step {
                            "settled before re-entry"
                        } else {
                            "NOT settled before re-entry"
                        }
                    );
                }
            }
        }
        for (name, v) in &m.extra {
            let _ = writeln!(s, "  {name:<22} {v}");
        }
        self.written_line(&mut s);
        Report {
            stdout: s,
            stderr: String::new(),
            exit: Exit::Ok,
        }
    }

    /// A failed run: its status and reason instead of metrics (none of them is a settling
    /// result), the load angles that show how far a motor slipped, the trace up to the
    /// failure.
    fn failed_report(&self, mut s: String) -> Report {
        let status = &self.metrics.status;
        let _ = writeln!(
            s,
            "  FAILED ({}): {}: no settling result (runs.csv leaves its metrics empty too)",
            status.name(),
            status.reason()
        );
        self.load_angles(&mut s);
        if self.written.is_empty() {
            let _ = writeln!(s, "no trace: the run failed before its first sample");
        } else {
            self.written_line(&mut s);
        }
        Report {
            stdout: s,
            stderr: String::new(),
            exit: Exit::RunsFailed,
        }
    }

    /// The largest load angle per axis with a stepper.
    fn load_angles(&self, s: &mut String) {
        for a in &self.metrics.axes {
            if let Some(deg) = a.max_load_angle_deg {
                let _ = writeln!(
                    s,
                    "  axis {}: max load angle {deg:.1} electrical degrees",
                    a.name
                );
            }
        }
    }

    /// `wrote FILES (N samples)`.
    fn written_line(&self, s: &mut String) {
        let written: Vec<String> = self
            .written
            .iter()
            .map(|p| p.display().to_string())
            .collect();
        let _ = writeln!(s, "wrote {} ({} samples)", written.join(", "), self.samples);
    }
}
