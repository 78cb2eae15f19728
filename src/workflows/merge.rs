//! `settle merge DIR...`: the shard folders of a sharded sweep combined into the outputs of
//! an unsharded one (runs.csv, summary.md, plots), byte-identical to them, with the shards'
//! recordings gathered into one folder.

use std::path::PathBuf;

use crate::error::Error;
use crate::output::atomic::create_dir;
use crate::output::report::ScenarioFile;
use crate::output::sweep_files::{RECORDINGS, write_sweep};
use crate::spec::backend::Backend;
use crate::workflows::sweep::{FailedRun, failures, list_failures};
use crate::workflows::{Exit, Report};

/// What a merge did.
#[derive(Debug, Clone, PartialEq)]
pub struct MergeOutcome {
    /// Shard folders merged.
    pub shards: usize,
    /// The scenario's name.
    pub name: String,
    /// Runs in the merged sweep.
    pub runs: usize,
    /// The output folder.
    pub out: PathBuf,
    /// Recordings gathered.
    pub recordings: usize,
    /// The failed runs the shards hold (results, as in an unsharded sweep).
    pub failed: Vec<FailedRun>,
}

/// Merge `dirs` (any order) into `out` (default: `results/<name>/`).
pub fn merge(dirs: &[PathBuf], out: Option<PathBuf>) -> Result<MergeOutcome, Error> {
    let mut m = crate::workflows::shard::merge(dirs)?;
    // The backend the shards ran on (a setting every shard agrees on).
    if let Some(b) = m
        .manifest
        .settings
        .get("backend")
        .and_then(|b| Backend::parse(b))
    {
        let file = PathBuf::from(&m.manifest.scenario_file);
        crate::execute::set_backend(&file, &mut m.runs, b)?;
    }
    let out = out.unwrap_or_else(|| PathBuf::from("results").join(&m.scenario.name));
    create_dir(&out)?;
    let file = ScenarioFile {
        path: std::path::Path::new(&m.manifest.scenario_file),
        text: &m.manifest.scenario,
    };
    write_sweep(&out, &m.scenario, file, &m.runs, &m.csv)?;
    // Recordings: gathered into one folder, as an unsharded sweep leaves them.
    let mut copied = 0usize;
    for d in dirs {
        let src = d.join(RECORDINGS);
        let Ok(entries) = std::fs::read_dir(&src) else {
            continue;
        };
        let dst = out.join(RECORDINGS);
        create_dir(&dst)?;
        for e in entries {
            let e = e.map_err(|e| Error::read(&src, e))?;
            let name = e.file_name();
            if name.to_string_lossy().starts_with('.') {
                continue;
            }
            let to = dst.join(&name);
            if std::fs::hard_link(e.path(), &to).is_err() {
                std::fs::copy(e.path(), &to).map_err(|e| Error::write(&to, e))?;
            }
            copied += 1;
        }
    }
    Ok(MergeOutcome {
        shards: dirs.len(),
        failed: failures(&m.runs, &m.csv),
        name: m.scenario.name,
        runs: m.runs.len(),
        out,
        recordings: copied,
    })
}

impl MergeOutcome {
    /// What `settle merge` prints: where, and the failed runs as `settle sweep` lists them
    /// (results: exit 0 unless `--fail-on-failed-runs`).
    pub fn report(&self) -> Report {
        let mut r = Report::new(if self.failed.is_empty() {
            Exit::Ok
        } else {
            Exit::RunsFailed
        });
        r.err(format!(
            "merged {} shards of `{}` ({} runs) into {}{}",
            self.shards,
            self.name,
            self.runs,
            self.out.display(),
            if self.recordings > 0 {
                format!("; {} recordings gathered in {RECORDINGS}", self.recordings)
            } else {
                String::new()
            }
        ));
        list_failures(&mut r, &self.failed, self.runs);
        r
    }
}
