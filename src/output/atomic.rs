//! Writing files whole: a temporary file in the same folder, then a rename, so a reader
//! (or a crash) never sees half a file.

use std::path::{Path, PathBuf};

use crate::error::Error;

/// A temporary name beside `path` (same folder, so a rename is atomic).
pub fn tmp_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!(".{name}.tmp{}", std::process::id()))
}

/// Write `contents` to `path` atomically (temporary file + rename).
pub fn write_atomic(path: &Path, contents: &[u8]) -> Result<(), Error> {
    let tmp = tmp_path(path);
    std::fs::write(&tmp, contents).map_err(|e| Error::write(path, e))?;
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        Error::write(path, e)
    })
}

/// Write `path` atomically as `write` makes it (temporary file + rename), through a
/// buffer: a large output (a report of 100,000 runs) is never held whole. Nothing is left
/// behind when `write` fails.
pub fn write_atomic_with(
    path: &Path,
    write: impl FnOnce(&mut std::io::BufWriter<std::fs::File>) -> Result<(), Error>,
) -> Result<(), Error> {
    let tmp = tmp_path(path);
    let file = std::fs::File::create(&tmp).map_err(|e| Error::write(path, e))?;
    let mut w = std::io::BufWriter::with_capacity(1 << 16, file);
    let done = write(&mut w).and_then(|()| {
        std::io::Write::flush(&mut w).map_err(|e| Error::write(path, e))?;
        drop(w);
        std::fs::rename(&tmp, path).map_err(|e| Error::write(path, e))
    });
    if done.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    done
}

/// Create `dir` and its parents.
pub fn create_dir(dir: &Path) -> Result<(), Error> {
    std::fs::create_dir_all(dir).map_err(|e| Error::write(dir, e))
}
