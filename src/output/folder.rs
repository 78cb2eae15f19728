//! The output folder of a command, claimed the same way by every command that writes one
//! (`sweep`, `merge`, `tune`, `gcode`, `identify`'s figures): an output folder that is one
//! of the command's inputs, or holds one where the command writes, is refused; one that
//! holds the results of an earlier run is refused without `--force` (they would be
//! overwritten, or mixed with the new ones); then the folder is made.

use std::path::{Path, PathBuf};

use settle_files::write::Inputs;

use crate::error::Error;

/// What a command leaves in its output folder: its name in messages (`a sweep`) and the
/// files that tell earlier results (any one of them present is earlier results).
#[derive(Debug, Clone, Copy)]
pub struct Results<'a> {
    /// The command's results in words: `a sweep`, `settle gcode`.
    pub what: &'a str,
    /// File names (relative to the folder) that mark earlier results.
    pub marks: &'a [&'a str],
}

impl Results<'_> {
    /// The marks present in `dir`.
    pub fn found(&self, dir: &Path) -> Vec<String> {
        self.marks
            .iter()
            .filter(|m| std::fs::symlink_metadata(dir.join(m)).is_ok())
            .map(|m| (*m).to_string())
            .collect()
    }

    /// An error when `dir` holds earlier results, naming them.
    pub fn refuse_earlier(&self, dir: &Path) -> Result<(), Error> {
        let found = self.found(dir);
        if found.is_empty() {
            return Ok(());
        }
        Err(Error::input(
            "--force",
            format!(
                "{} already holds the results of {} ({}): pass --force to overwrite it, --out DIR to write elsewhere",
                dir.display(),
                self.what,
                found.join(", ")
            ),
        ))
    }
}

/// Check the output folder `dir` of a command that writes `results` and the files
/// `writes` accepts (relative paths), with `inputs` read, before any work: refused when it
/// is not a folder, is an input or holds one where the command writes, holds something
/// other than a regular file where the command writes one (see `refuse_unwritable`), or
/// (without `force`) when it holds earlier results. Nothing is made: see [`claim`].
pub fn check(
    dir: &Path,
    results: &Results<'_>,
    force: bool,
    inputs: &Inputs,
    writes: impl Fn(&Path) -> bool,
) -> Result<(), Error> {
    if let Ok(meta) = std::fs::metadata(dir)
        && !meta.is_dir()
    {
        // What create_dir says of it, before any work.
        return crate::output::atomic::create_dir(dir);
    }
    inputs.refuse_folder(dir, &writes)?;
    if !force {
        results.refuse_earlier(dir)?;
    }
    refuse_unwritable(dir, &writes)
}

/// The entries of `dir` that the command writes, refused before any work as they would be
/// when written, `--force` or not: where a file goes, anything but a regular file (a link,
/// a folder, a device, a FIFO: [`settle_files::write::check_target`]); where the command
/// writes into a folder of its own (`plots/`: it writes `plots/NAME`), anything but a real
/// folder. (What lies inside such a folder is checked as each file is written: a sweep
/// then stops with its journal kept for `--resume`.) Names starting with a dot are
/// settle's temporary files (`.NAME.tmpPID`), which the writers replace whatever they are.
fn refuse_unwritable(dir: &Path, writes: &impl Fn(&Path) -> bool) -> Result<(), Error> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Ok(()); // a new folder
    };
    for entry in entries.flatten() {
        let rel = PathBuf::from(entry.file_name());
        if rel.to_string_lossy().starts_with('.') {
            continue;
        }
        let path = dir.join(&rel);
        if writes(&rel.join("NAME")) {
            // It exists: nothing is made, only its kind checked.
            crate::output::atomic::create_subdir(&path)?;
        } else if writes(&rel) {
            settle_files::write::check_target(&path)?;
        }
    }
    Ok(())
}

/// [`check`], then make the folder (with its parents).
pub fn claim(
    dir: &Path,
    results: &Results<'_>,
    force: bool,
    inputs: &Inputs,
    writes: impl Fn(&Path) -> bool,
) -> Result<(), Error> {
    check(dir, results, force, inputs, writes)?;
    crate::output::atomic::create_dir(dir)
}

/// Whether `rel` (a path inside an output folder) is one of `names` or lies in one of the
/// folders `folders` (`plots`, `recordings`), or has one of `prefixes` and `suffixes`
/// (`ringing-layer-`, `.svg`): the files a command writes, for [`claim`].
pub fn written(rel: &Path, names: &[&str], folders: &[&str], patterns: &[(&str, &str)]) -> bool {
    let text = rel.to_string_lossy();
    names.iter().any(|n| text == *n)
        || folders.iter().any(|f| rel.starts_with(f))
        || patterns
            .iter()
            .any(|(p, s)| text.starts_with(p) && text.ends_with(s) && !text.contains('/'))
}
