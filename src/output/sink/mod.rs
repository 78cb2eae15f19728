//! Sinks for whole runs: recordings (MCAP, rerun) written from a run's full [`Series`].
//!
//! Recording needs the full series of a run in memory (one per worker thread at a time);
//! a sweep that records nothing keeps the streaming path ([`crate::execute::pool::run_all`]) and holds no
//! traces at all. The series is written generically: whatever channels the run records, in
//! the groups of [`groups`].

pub mod groups;
pub mod mcap;
pub mod rerun;

use std::path::{Path, PathBuf};

use crate::error::Error;
use crate::input::runs_table::RunsTable;
use crate::measure::metrics::Metrics;
use crate::measure::series::Series;
use crate::spec::run_spec::RunSpec;

/// Where a recording comes from (MCAP metadata, rerun recording properties).
#[derive(Debug, Clone)]
pub struct Provenance {
    /// settle's version (`CARGO_PKG_VERSION`).
    pub settle_version: &'static str,
    /// The scenario's `name`.
    pub scenario_name: String,
    /// The scenario file as given on the command line.
    pub scenario_file: String,
    /// The scenario file's full text.
    pub scenario_text: String,
}

impl Provenance {
    /// Read the scenario file's text for the record.
    pub fn load(path: &Path, scenario_name: &str) -> Result<Self, Error> {
        let scenario_text =
            crate::input::file::read_text(path, crate::input::file::limit::SETTINGS)?;
        Ok(Self {
            settle_version: env!("CARGO_PKG_VERSION"),
            scenario_name: scenario_name.to_string(),
            scenario_file: path.display().to_string(),
            scenario_text,
        })
    }
}

/// One run, recorded in full.
#[derive(Debug)]
pub struct RunRecord<'a> {
    /// The run.
    pub spec: &'a RunSpec,
    /// Everything it recorded.
    pub series: &'a Series,
    /// Its metrics.
    pub metrics: &'a Metrics,
    /// Its row of `runs.csv` (header and one row): parameters and metrics by column name.
    pub row: RunsTable,
}

/// Run `spec` recording its full series (the run chooses its channels). The one place a
/// run is executed with a recorder.
pub fn record_run(spec: &RunSpec) -> Result<(Series, Metrics), Error> {
    let mut series = Series::default();
    let m = crate::execute::execute(spec, Some(&mut series))?;
    Ok((series, m))
}

/// The `runs.csv` row of one run, as a table.
pub fn row_of(spec: &RunSpec, m: &Metrics) -> RunsTable {
    let csv = crate::output::runs_csv::runs_csv(&vec![spec.clone()], std::slice::from_ref(m));
    // runs_csv writes one header and one row of plain cells: this cannot fail.
    RunsTable::parse(&csv).unwrap_or_default()
}

/// Which recordings to write for each run, and where.
#[derive(Debug, Clone)]
pub struct Recorder {
    /// Folder for `run-<id>.mcap` / `run-<id>.rrd`.
    pub dir: PathBuf,
    /// Write MCAP.
    pub mcap: bool,
    /// Write rerun (.rrd); needs the `rerun` feature.
    pub rerun: bool,
    /// Scenario and version for the records.
    pub provenance: Provenance,
}

impl Recorder {
    /// True when there is something to record.
    pub fn active(&self) -> bool {
        self.mcap || self.rerun
    }

    /// The recording file of run `id` with extension `ext`.
    pub fn path(&self, id: usize, ext: &str) -> PathBuf {
        self.dir.join(format!("run-{id}.{ext}"))
    }

    /// Run `spec`, write its recordings, return its metrics. The series is dropped on return.
    pub fn run(&self, spec: &RunSpec) -> Result<Metrics, Error> {
        let (series, m) = record_run(spec)?;
        self.write(spec, &series, &m)?;
        Ok(m)
    }

    /// Write the recordings of an already executed run.
    pub fn write(&self, spec: &RunSpec, series: &Series, m: &Metrics) -> Result<(), Error> {
        let rec = RunRecord {
            spec,
            series,
            metrics: m,
            row: row_of(spec, m),
        };
        if self.mcap {
            mcap::write_file(&self.path(spec.id, "mcap"), &self.provenance, &rec)?;
        }
        if self.rerun {
            rerun::write_file(&self.path(spec.id, "rrd"), &self.provenance, &rec)?;
        }
        Ok(())
    }
}
