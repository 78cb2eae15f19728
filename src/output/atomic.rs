//! Writing an output file: through settle-files' output rule ([`settle_files::write`]):
//! only where nothing is or a regular file is (never onto a link, a folder, a device), a
//! temporary file then a rename, so a reader (or a crash) never sees half a file; folders
//! made inside an output folder are real folders, never links out of it.

use std::path::Path;

pub use settle_files::write::{commit, create_tmp, prepare_tmp, tmp_path};

use crate::error::Error;

/// Write `contents` to `path` atomically (temporary file + rename).
pub fn write_atomic(path: &Path, contents: &[u8]) -> Result<(), Error> {
    Ok(settle_files::write::write_atomic(path, contents)?)
}

/// Write `path` atomically as `write` makes it (temporary file + rename), through a
/// buffer: a large output (a report of 100,000 runs) is never held whole. Nothing is left
/// behind when `write` fails.
pub fn write_atomic_with(
    path: &Path,
    write: impl FnOnce(&mut std::io::BufWriter<std::fs::File>) -> Result<(), Error>,
) -> Result<(), Error> {
    settle_files::write::write_atomic_with(path, write)
}

/// Create the output folder `dir` the user named (or its default) and its parents; an
/// existing one must be a folder (a link to one is fine: the user named it).
pub fn create_dir(dir: &Path) -> Result<(), Error> {
    Ok(settle_files::write::create_folder(dir)?)
}

/// Create the folder `dir` inside an output folder (`plots/`, `recordings/`); an existing
/// one must be a real folder, not a link out of the output folder.
pub fn create_subdir(dir: &Path) -> Result<(), Error> {
    Ok(settle_files::write::create_subfolder(dir)?)
}

/// Write the PNG image `png` as `draw` draws it into the file it is given (a temporary
/// file beside `png`, ending in `.png`: the encoder picks the format from the extension),
/// then rename it; nothing is left behind when `draw` fails.
pub fn write_png(png: &Path, draw: impl FnOnce(&Path) -> Result<(), String>) -> Result<(), Error> {
    let stem = png
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tmp = png.with_file_name(format!(".{stem}.tmp{}.png", std::process::id()));
    prepare_tmp(png, &tmp)?;
    let drawn = draw(&tmp)
        .map_err(|e| {
            Error::write(
                png,
                os_error_in(&e).unwrap_or_else(|| std::io::Error::other(e)),
            )
        })
        .and_then(|()| Ok(commit(&tmp, png)?));
    if drawn.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    drawn
}

/// The operating system's error a drawing library's message quotes (the image encoder
/// turns the file's I/O error into text, ending in `(os error N)` as the standard library
/// writes it), so that a full disk says "No space left on device" rather than how the
/// drawing backend wrapped it.
fn os_error_in(message: &str) -> Option<std::io::Error> {
    let (_, after) = message.rsplit_once("(os error ")?;
    let code = after.split(')').next()?.parse().ok()?;
    Some(std::io::Error::from_raw_os_error(code))
}

/// The operating system's error behind a writer's error (an MCAP or compression stream
/// wraps it), so that a full disk says "No space left on device" rather than what the
/// stream was doing; `e` itself when no I/O error is behind it.
pub fn io_cause(e: &(dyn std::error::Error + 'static)) -> std::io::Error {
    let mut at: Option<&(dyn std::error::Error + 'static)> = Some(e);
    while let Some(cur) = at {
        if let Some(io) = cur.downcast_ref::<std::io::Error>() {
            if let Some(code) = io.raw_os_error() {
                return std::io::Error::from_raw_os_error(code);
            }
            if let Some(inner) = io.get_ref()
                && inner.is::<std::io::Error>()
            {
                // An io::Error wrapping another: look inside.
                at = Some(inner);
                continue;
            }
            return std::io::Error::new(io.kind(), io.to_string());
        }
        at = cur.source();
    }
    std::io::Error::other(e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_full_disk_is_named_through_wrapping_errors() {
        #[derive(Debug)]
        struct Stream(std::io::Error);
        impl std::fmt::Display for Stream {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                write!(f, "compression stream failed")
            }
        }
        impl std::error::Error for Stream {
            fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
                Some(&self.0)
            }
        }
        // ENOSPC inside an io::Error::other inside a stream error.
        let full = std::io::Error::other(std::io::Error::from_raw_os_error(28));
        let e = io_cause(&Stream(full));
        assert_eq!(e.kind(), std::io::ErrorKind::StorageFull, "{e}");
        assert!(e.to_string().contains("No space left on device"), "{e}");
        let e = io_cause(&Stream(std::io::Error::other("plain")));
        assert_eq!(e.to_string(), "plain");
    }

    #[test]
    fn a_full_disk_is_named_through_a_drawing_backends_text() {
        // What plotters reports when the PNG encoder's write fails on a full disk.
        let text = r#"Drawing backend error: ImageError(IoError(Custom { kind: Other, error: "No space left on device (os error 28)" }))"#;
        let e = os_error_in(text).expect("an OS error");
        assert_eq!(e.kind(), std::io::ErrorKind::StorageFull, "{e}");
        assert!(os_error_in("backend error: no such font").is_none());
    }
}
