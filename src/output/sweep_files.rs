//! The files a sweep leaves in its output folder, written the same way by `settle sweep`
//! and `settle merge`:
//!
//! ```text
//! DIR/runs.csv            one row per run: parameters, then metrics
//! DIR/summary.md          winner per band, every swept setting ranked per swept point;
//!                         links the figures
//! DIR/report.html         the same with the figures embedded, every run (sortable,
//!                         filterable), failed runs, provenance: one self-contained file
//! DIR/plots/vs_<P>.svg    settle time and residual against each swept numeric parameter P
//! DIR/plots/vs_<P>.png    the same as PNG
//! DIR/plots/ranking.svg   every candidate's move-and-settle time per band, ranked (bars)
//! DIR/plots/gcode_jobs.svg  G-code sweeps: print time against contour error, Pareto front
//! DIR/recordings/run-<id>.mcap / .rrd   with --mcap / --rerun
//! ```
//!
//! `summary.md`, `report.html` and the plots are functions of `runs.csv` and the scenario
//! alone, which is what makes a merged sweep byte-identical to an unsharded one.

use std::path::{Path, PathBuf};

use crate::error::Error;
use crate::input::runs_columns::RunsColumns;
use crate::input::scenario::Scenario;
use crate::output::atomic::{write_atomic, write_atomic_with};
use crate::output::html::Sink;
use crate::output::report::{RUNS_TITLE, ScenarioFile, sweep_report};
use crate::output::summary::summary_to;
use crate::spec::runs::RunList;

/// Folder of the sweep figures inside the output folder.
pub const PLOTS: &str = "plots";

/// Folder of the per-run recordings inside the output folder.
pub const RECORDINGS: &str = "recordings";

/// Write `runs.csv` (the text `csv`, as written by [`crate::output::runs_csv`]), the
/// figures, `summary.md` and `report.html` into `out`; `file` is the scenario the runs come
/// from (its path as the commands in the summary name it, and its text).
pub fn write_sweep(
    out: &Path,
    sc: &Scenario,
    file: ScenarioFile<'_>,
    runs: &dyn RunList,
    csv: &str,
) -> Result<(), Error> {
    let table =
        RunsColumns::parse(csv).map_err(|message| Error::input(out.join("runs.csv"), message))?;
    write_atomic(&out.join("runs.csv"), csv.as_bytes())?;
    let plots = out.join(PLOTS);
    let mut figures = crate::output::plot::sweep::write_all(&plots, &sc.name, runs, &table)?;
    if crate::output::summary::ranks_candidates(runs, &table) {
        let ranking = crate::output::ranking::rank(sc, runs, &table);
        figures.extend(crate::output::plot::bars::write(
            &plots, &sc.name, &ranking,
        )?);
    }
    if let Some(j) = crate::output::jobs::jobs(sc, runs, &table) {
        figures.extend(crate::output::plot::jobs::write(&plots, &sc.name, &j)?);
    }
    let summary = out.join("summary.md");
    write_atomic_with(&summary, |w| {
        let mut sink = Sink::new(w);
        summary_to(&mut sink, sc, file.path, runs, &table, &figures);
        sink.finish(&summary)
    })?;
    // The figures are read from their files, and the table of every run from `csv`, as
    // the page is written: report.html is never held whole.
    let svgs: Vec<(String, PathBuf)> = figures
        .iter()
        .map(|f| (f.title.clone(), out.join(&f.svg)))
        .collect();
    let (report, ranking_rows) = sweep_report(sc, file, runs, &table, &svgs);
    let path = out.join(REPORT);
    write_atomic_with(&path, |w| {
        crate::output::html::render_to(&report, Some((RUNS_TITLE, csv)), &ranking_rows, w, &path)
    })
}

/// The report's file name inside the output folder.
pub const REPORT: &str = "report.html";
