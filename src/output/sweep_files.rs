//! The files a sweep leaves in its output folder, written the same way by `settle sweep`
//! and `settle merge`:
//!
//! ```text
//! DIR/runs.csv            one row per run: parameters, then metrics
//! DIR/summary.md          profile kinds side by side per swept point; links the figures
//! DIR/plots/vs_<P>.svg    settle time and residual against each swept numeric parameter P
//! DIR/plots/vs_<P>.png    the same as PNG
//! DIR/recordings/run-<id>.mcap / .rrd   with --mcap / --rerun
//! ```
//!
//! `summary.md` and the plots are functions of `runs.csv` and the scenario alone, which is
//! what makes a merged sweep byte-identical to an unsharded one.

use std::path::Path;

use crate::error::Error;
use crate::input::runs_table::RunsTable;
use crate::input::scenario::Scenario;
use crate::output::atomic::write_atomic;
use crate::output::summary::summary_md;
use crate::spec::run_spec::RunSpec;

/// Folder of the sweep figures inside the output folder.
pub const PLOTS: &str = "plots";

/// Folder of the per-run recordings inside the output folder.
pub const RECORDINGS: &str = "recordings";

/// Write `runs.csv` (the text `csv`, as written by [`crate::output::runs_csv`]), the
/// figures and `summary.md` into `out`.
pub fn write_sweep(out: &Path, sc: &Scenario, runs: &[RunSpec], csv: &str) -> Result<(), Error> {
    let table =
        RunsTable::parse(csv).map_err(|message| Error::input(out.join("runs.csv"), message))?;
    write_atomic(&out.join("runs.csv"), csv.as_bytes())?;
    let figures = crate::output::plot::sweep::write_all(&out.join(PLOTS), &sc.name, runs, &table)?;
    write_atomic(
        &out.join("summary.md"),
        summary_md(sc, runs, &table, &figures).as_bytes(),
    )
}
