//! `settle merge DIR...`: the shard folders of a sharded sweep combined into the outputs of
//! an unsharded one (runs.csv, summary.md, plots), byte-identical to them, with the shards'
//! recordings gathered into one folder.

use std::path::{Path, PathBuf};

use settle_files::write::Inputs;

use crate::error::Error;
use crate::output::atomic::{create_dir, create_subdir};
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

/// The results of an earlier merge (or sweep), which `--force` overwrites.
const RESULTS: crate::output::folder::Results<'static> = crate::output::folder::Results {
    what: "a sweep",
    marks: &["runs.csv", "summary.md", crate::output::sweep_files::REPORT],
};

/// Merge `dirs` (any order) into `out` (default: `results/<name>/`); `force` overwrites
/// the results of an earlier sweep there.
pub fn merge(dirs: &[PathBuf], out: Option<PathBuf>, force: bool) -> Result<MergeOutcome, Error> {
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
    // Never into a shard folder (the next merge would fail), onto the scenario, or through
    // a link out of the folder.
    let mut inputs = Inputs::of(dirs);
    inputs.add(Path::new(&m.manifest.scenario_file));
    for d in dirs {
        inputs.add(&d.join("runs.csv"));
        inputs.add(&d.join(crate::workflows::shard::MANIFEST));
    }
    crate::output::folder::check(
        &out,
        &RESULTS,
        force,
        &inputs,
        crate::workflows::sweep::writes,
    )?;
    if std::fs::symlink_metadata(out.join(RECORDINGS)).is_ok() {
        create_subdir(&out.join(RECORDINGS))?;
    }
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
        create_subdir(&dst)?;
        for e in entries {
            let e = e.map_err(|e| Error::read(&src, e))?;
            let name = e.file_name();
            if name.to_string_lossy().starts_with('.') {
                continue;
            }
            // Recordings are regular files: a link, FIFO or device in a shard's folder is
            // not one (and a FIFO would block the copy).
            let from = e.path();
            if !std::fs::symlink_metadata(&from).is_ok_and(|m| m.is_file()) {
                return Err(Error::input(
                    &from,
                    "not a regular file: a shard's recordings are the files settle wrote there",
                ));
            }
            let to = dst.join(&name);
            settle_files::write::check_target(&to)?;
            let _ = std::fs::remove_file(&to);
            if std::fs::hard_link(&from, &to).is_err() {
                let (tmp, mut file) = crate::output::atomic::create_tmp(&to)?;
                let mut input =
                    crate::input::file::open(&from, crate::input::file::limit::RESULTS)?;
                std::io::copy(&mut input, &mut file).map_err(|e| Error::write(&to, e))?;
                drop(file);
                crate::output::atomic::commit(&tmp, &to)?;
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
