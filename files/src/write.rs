//! The one rule for outputs: settle writes a file only where nothing is or where a regular
//! file is, never onto a link, a folder, a device or a FIFO (as root, replacing
//! `/dev/null` with a regular file breaks the machine); the folders it makes inside its
//! output folder are real folders, never links out of it; and no output is one of the
//! command's inputs ([`Inputs`]).
//!
//! Files are written whole: a temporary file beside the target (created new, never opened
//! through whatever was at its name), then a rename, so a reader or a crash never sees
//! half a file and nothing is left behind on failure.

use std::fs::File;
use std::io::{BufWriter, Write as _};
use std::path::{Path, PathBuf};

use crate::error::FileError;
use crate::identity::FileId;
use crate::read::{link_target, what_is};

fn write_err(path: &Path) -> impl FnOnce(std::io::Error) -> FileError + '_ {
    move |source| FileError::Write {
        path: path.to_path_buf(),
        source,
    }
}

/// Refuse writing a file at `path` unless nothing is there or a regular file is (a link
/// is refused even when it leads to a regular file: writing through it would change a
/// file elsewhere, replacing it would break the link someone made).
pub fn check_target(path: &Path) -> Result<(), FileError> {
    let Ok(meta) = std::fs::symlink_metadata(path) else {
        return Ok(());
    };
    if meta.is_file() {
        return Ok(());
    }
    let why = match link_target(path) {
        Some(to) => format!(
            "it is a link (to {}); settle writes regular files or new paths only, never through a link: remove the link or write elsewhere",
            to.display()
        ),
        None => format!(
            "it is {}; settle writes regular files or new paths only: write elsewhere",
            what_is(&meta)
        ),
    };
    Err(FileError::Refused {
        path: path.to_path_buf(),
        why,
    })
}

/// Make the output folder `dir` the user named (and its parents) if it is missing. An
/// existing `dir` must be a folder; it may be a link to one (the user named it).
pub fn create_folder(dir: &Path) -> Result<(), FileError> {
    if let Ok(meta) = std::fs::metadata(dir) {
        if meta.is_dir() {
            return Ok(());
        }
        return Err(FileError::Refused {
            path: dir.to_path_buf(),
            why: format!(
                "it is {}, not a folder: name a folder (or a new path) for the output",
                what_is(&meta)
            ),
        });
    }
    std::fs::create_dir_all(dir).map_err(write_err(dir))
}

/// Make the folder `dir` settle writes into inside its output folder (`plots/`,
/// `recordings/`) if it is missing. An existing one must be a real folder, not a link:
/// files written into a link would land outside the output folder.
pub fn create_subfolder(dir: &Path) -> Result<(), FileError> {
    match std::fs::symlink_metadata(dir) {
        Ok(meta) if meta.is_dir() => Ok(()),
        Ok(meta) => Err(FileError::Refused {
            path: dir.to_path_buf(),
            why: match link_target(dir) {
                Some(to) => format!(
                    "it is a link (to {}); settle writes only inside its output folder, never through a link out of it: remove the link",
                    to.display()
                ),
                None => format!(
                    "it is {}, where settle makes a folder of its output: remove it or write elsewhere",
                    what_is(&meta)
                ),
            },
        }),
        Err(_) => std::fs::create_dir_all(dir).map_err(write_err(dir)),
    }
}

/// A temporary name beside `path` (same folder, so the rename is atomic), `.NAME.tmpPID`.
pub fn tmp_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!(".{name}.tmp{}", std::process::id()))
}

/// Make `tmp` ready for a writer that opens its file by name (an image encoder) to write
/// what becomes `path`: [`check_target`] of `path`, and whatever was at `tmp` removed, not
/// followed. Finish with [`commit`].
pub fn prepare_tmp(path: &Path, tmp: &Path) -> Result<(), FileError> {
    check_target(path)?;
    let _ = std::fs::remove_file(tmp);
    Ok(())
}

/// A new temporary file for `path` ([`tmp_path`]), after [`check_target`] of `path`:
/// whatever was at the temporary name (a leftover of a killed run, or a link) is removed,
/// not followed. Finish with [`commit`].
pub fn create_tmp(path: &Path) -> Result<(PathBuf, File), FileError> {
    check_target(path)?;
    let tmp = tmp_path(path);
    let _ = std::fs::remove_file(&tmp);
    let file = File::options()
        .write(true)
        .create_new(true)
        .open(&tmp)
        .map_err(write_err(path))?;
    Ok((tmp, file))
}

/// A file written in place at `path` (a log that grows as the work goes, such as a
/// sweep's journal, which a rename cannot produce), emptied, after [`check_target`] of
/// `path`; the open itself follows no link and does not wait on a FIFO put at `path`
/// since the check, and what it opened must be a regular file.
pub fn create_in_place(path: &Path) -> Result<File, FileError> {
    check_target(path)?;
    open_in_place(path)
}

/// [`create_in_place`]'s open, without the check before it.
fn open_in_place(path: &Path) -> Result<File, FileError> {
    let mut options = File::options();
    options.write(true).create(true).truncate(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt as _;
        options.custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK);
    }
    // A refused open (a link: O_NOFOLLOW; a FIFO without a reader: O_NONBLOCK) is
    // named as the check names it.
    let file = options
        .open(path)
        .map_err(|source| match check_target(path) {
            Err(refused) => refused,
            Ok(()) => write_err(path)(source),
        })?;
    let meta = file.metadata().map_err(write_err(path))?;
    if !meta.is_file() {
        return Err(FileError::Refused {
            path: path.to_path_buf(),
            why: format!(
                "it is {}; settle writes regular files or new paths only: write elsewhere",
                what_is(&meta)
            ),
        });
    }
    Ok(file)
}

/// Move the finished temporary file `tmp` to `path` (checked again: nothing may have taken
/// its place meanwhile), removing `tmp` on failure.
pub fn commit(tmp: &Path, path: &Path) -> Result<(), FileError> {
    let done =
        check_target(path).and_then(|()| std::fs::rename(tmp, path).map_err(write_err(path)));
    if done.is_err() {
        let _ = std::fs::remove_file(tmp);
    }
    done
}

/// Write `contents` to `path` whole (temporary file + rename).
pub fn write_atomic(path: &Path, contents: &[u8]) -> Result<(), FileError> {
    write_atomic_with(path, |w| w.write_all(contents).map_err(write_err(path)))
}

/// Write `path` whole as `write` makes it, through a buffer (a large output is never held
/// whole). Nothing is left behind when `write` fails.
pub fn write_atomic_with<E: From<FileError>>(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> Result<(), E>,
) -> Result<(), E> {
    let (tmp, file) = create_tmp(path)?;
    let mut w = BufWriter::with_capacity(1 << 16, file);
    let done = write(&mut w).and_then(|()| {
        let file = w
            .into_inner()
            .map_err(|e| write_err(path)(e.into_error()))?;
        drop(file);
        commit(&tmp, path).map_err(E::from)
    });
    if done.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    done
}

/// The inputs of a command, by identity: an output that is one of them is refused before
/// any work (`settle identify rec.csv --out rec.csv` would replace the recording).
#[derive(Debug, Default, Clone)]
pub struct Inputs {
    files: Vec<(PathBuf, FileId)>,
}

impl Inputs {
    /// No inputs yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// `paths` as inputs.
    pub fn of<P: AsRef<Path>>(paths: impl IntoIterator<Item = P>) -> Self {
        let mut inputs = Self::new();
        for p in paths {
            inputs.add(p.as_ref());
        }
        inputs
    }

    /// Add the file or folder `path` (nothing when nothing is there: reading it fails).
    pub fn add(&mut self, path: &Path) {
        if let Some(id) = FileId::of(path) {
            self.files.push((path.to_path_buf(), id));
        }
    }

    fn input_at(&self, path: &Path) -> Option<&Path> {
        let id = FileId::of(path)?;
        self.files
            .iter()
            .find(|(_, i)| *i == id)
            .map(|(p, _)| p.as_path())
    }

    /// Refuse the output file (or folder) `out` when it is one of the inputs.
    pub fn refuse(&self, out: &Path) -> Result<(), FileError> {
        match self.input_at(out) {
            None => Ok(()),
            Some(input) => Err(FileError::Refused {
                path: out.to_path_buf(),
                why: format!(
                    "{}; settle never writes onto its inputs: write elsewhere",
                    if input == out {
                        "it is one of this command's inputs".to_string()
                    } else {
                        format!(
                            "it is the same {} as the input {}",
                            if out.is_dir() { "folder" } else { "file" },
                            input.display()
                        )
                    },
                ),
            }),
        }
    }

    /// Refuse the output folder `dir` when it is an input, or when an input lies inside it
    /// where the command writes: `writes(relative path)` says whether it does.
    pub fn refuse_folder(
        &self,
        dir: &Path,
        writes: impl Fn(&Path) -> bool,
    ) -> Result<(), FileError> {
        self.refuse(dir)?;
        let Ok(root) = std::fs::canonicalize(dir) else {
            return Ok(()); // a new folder holds no input
        };
        for (input, _) in &self.files {
            let Ok(real) = std::fs::canonicalize(input) else {
                continue;
            };
            if let Ok(rel) = real.strip_prefix(&root)
                && writes(rel)
            {
                return Err(FileError::Refused {
                    path: dir.join(rel),
                    why: format!(
                        "it is the input {}, and this command writes this file of its output folder; settle never writes onto its inputs: write elsewhere",
                        input.display()
                    ),
                });
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The open of a file written in place holds the rule by itself, for what takes a
    /// path's place after [`check_target`] looked: a link is not followed (its target
    /// keeps its bytes), a FIFO is refused without waiting for a reader, a regular file
    /// is emptied.
    #[cfg(unix)]
    #[test]
    fn a_file_written_in_place_is_opened_without_following_or_waiting() {
        let dir = tempfile::tempdir().expect("temp dir");
        let target = dir.path().join("elsewhere.txt");
        std::fs::write(&target, b"keep").expect("target");
        let link = dir.path().join("journal.csv");
        std::os::unix::fs::symlink(&target, &link).expect("link");
        let e = open_in_place(&link).expect_err("a link").to_string();
        assert!(e.contains("it is a link"), "{e}");
        assert_eq!(std::fs::read(&target).expect("read"), b"keep");
        let fifo = dir.path().join("fifo");
        crate::make_fifo(&fifo);
        let e = open_in_place(&fifo).expect_err("a FIFO").to_string();
        assert!(e.contains("it is a FIFO"), "{e}");
        let file = dir.path().join("file.csv");
        std::fs::write(&file, b"old").expect("file");
        drop(create_in_place(&file).expect("a regular file"));
        assert_eq!(std::fs::read(&file).expect("read"), b"");
    }

    #[test]
    fn writes_new_paths_and_regular_files_whole() {
        let dir = tempfile::tempdir().expect("temp dir");
        let p = dir.path().join("out.txt");
        write_atomic(&p, b"one").expect("new path");
        write_atomic(&p, b"two").expect("regular file");
        assert_eq!(std::fs::read(&p).expect("read"), b"two");
        let names: Vec<_> = std::fs::read_dir(dir.path())
            .expect("list")
            .map(|e| e.expect("entry").file_name())
            .collect();
        assert_eq!(names, ["out.txt"], "no temporary file is left");
    }

    #[test]
    fn refuses_folders_and_leaves_nothing_on_failure() {
        let dir = tempfile::tempdir().expect("temp dir");
        let e = write_atomic(dir.path(), b"x")
            .expect_err("a folder")
            .to_string();
        assert!(
            e.contains("is a folder; settle writes regular files"),
            "{e}"
        );
        let p = dir.path().join("out.txt");
        let failed: Result<(), FileError> = write_atomic_with(&p, |_| {
            Err(FileError::Refused {
                path: p.clone(),
                why: "test".into(),
            })
        });
        assert!(failed.is_err());
        assert_eq!(std::fs::read_dir(dir.path()).expect("list").count(), 0);
    }

    #[cfg(unix)]
    #[test]
    fn never_writes_through_links_or_onto_devices() {
        let dir = tempfile::tempdir().expect("temp dir");
        let target = dir.path().join("precious.txt");
        std::fs::write(&target, "keep").expect("write");
        let link = dir.path().join("out.txt");
        std::os::unix::fs::symlink(&target, &link).expect("symlink");
        let e = write_atomic(&link, b"x").expect_err("a link").to_string();
        assert!(e.contains("is a link (to "), "{e}");
        assert_eq!(std::fs::read(&target).expect("read"), b"keep");
        let e = check_target(Path::new("/dev/null"))
            .expect_err("device")
            .to_string();
        assert!(e.contains("is a character device"), "{e}");
        // A subfolder that is a link out of the output folder.
        let elsewhere = tempfile::tempdir().expect("temp dir");
        let plots = dir.path().join("plots");
        std::os::unix::fs::symlink(elsewhere.path(), &plots).expect("symlink");
        let e = create_subfolder(&plots).expect_err("a link").to_string();
        assert!(e.contains("never through a link out of it"), "{e}");
        // The output folder itself may be a link the user made.
        create_folder(&plots).expect("a link to a folder the user named");
        let e = create_folder(&target).expect_err("a file").to_string();
        assert!(e.contains("not a folder"), "{e}");
    }

    #[cfg(unix)]
    #[test]
    fn a_stale_link_at_the_temporary_name_is_removed_not_followed() {
        let dir = tempfile::tempdir().expect("temp dir");
        let victim = dir.path().join("victim.txt");
        std::fs::write(&victim, "keep").expect("write");
        let p = dir.path().join("out.txt");
        std::os::unix::fs::symlink(&victim, tmp_path(&p)).expect("symlink");
        write_atomic(&p, b"new").expect("writes");
        assert_eq!(std::fs::read(&victim).expect("read"), b"keep");
        assert_eq!(std::fs::read(&p).expect("read"), b"new");
    }

    #[test]
    fn an_output_that_is_an_input_is_refused() {
        let dir = tempfile::tempdir().expect("temp dir");
        let rec = dir.path().join("rec.csv");
        std::fs::write(&rec, "data").expect("write");
        let inputs = Inputs::of([&rec]);
        let e = inputs.refuse(&rec).expect_err("the input").to_string();
        assert!(e.contains("it is one of this command's inputs"), "{e}");
        inputs
            .refuse(&dir.path().join("machine.toml"))
            .expect("another file");
        let shard = dir.path().join("s1");
        std::fs::create_dir(&shard).expect("mkdir");
        let inputs = Inputs::of([&shard]);
        assert!(inputs.refuse_folder(&shard, |_| true).is_err());
        // An input inside the output folder, where the command writes / does not write.
        let inputs = Inputs::of([&rec]);
        let e = inputs
            .refuse_folder(dir.path(), |rel| rel == Path::new("rec.csv"))
            .expect_err("written")
            .to_string();
        assert!(e.contains("is the input"), "{e}");
        inputs
            .refuse_folder(dir.path(), |rel| rel == Path::new("runs.csv"))
            .expect("not written");
        #[cfg(unix)]
        {
            let link = dir.path().join("link.csv");
            std::os::unix::fs::symlink(&rec, &link).expect("symlink");
            let e = inputs
                .refuse(&link)
                .expect_err("through a link")
                .to_string();
            assert!(e.contains("is the same file as the input "), "{e}");
        }
    }
}
