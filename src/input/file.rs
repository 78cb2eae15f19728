//! Reading an input file: every file settle reads (scenarios, machine files, baselines,
//! shard folders' files, journals, and G-code and accelerometer files in their crates) goes
//! through settle-files' reader ([`settle_files::read`]): links resolved, regular files
//! only (not a device, a FIFO or a folder: `/dev/zero` never ends, a FIFO blocks), at most
//! the limit of the file's kind ([`settle_files::limit`]).

use std::path::Path;

pub use settle_files::limit::{self, Limit};

use crate::error::Error;

/// The bytes of the regular file at `path`, a file of the kind `limit` describes.
pub fn read_bytes(path: &Path, limit: Limit) -> Result<Vec<u8>, Error> {
    Ok(settle_files::read::read_bytes(path, limit)?)
}

/// The text of the regular file at `path` (UTF-8; a leading byte-order mark is dropped), a
/// file of the kind `limit` describes.
pub fn read_text(path: &Path, limit: Limit) -> Result<String, Error> {
    Ok(settle_files::read::read_text(path, limit)?)
}

/// The regular file at `path`, open for streaming, a file of the kind `limit` describes;
/// read errors of the stream go through [`stream_error`].
pub fn open(path: &Path, limit: Limit) -> Result<settle_files::read::Input, Error> {
    Ok(settle_files::read::open(path, limit)?)
}

/// The error of a failed read from a stream [`open`] opened (past its limit, or the
/// operating system's).
pub fn stream_error(path: &Path, e: std::io::Error) -> Error {
    settle_files::read::unwrap_io(path, e).into()
}

/// `e`, a command's refusal of the file at `path` (read as a file of the kind `limit`
/// describes), or, when the file is another kind of file settle knows
/// ([`settle_files::looks`]: a G-code job, a printer.cfg, an STL model), that kind at its
/// line 1, named with the command that reads it: `a G-code job (...), not {expected}:
/// replay it with ...`. Kinds in `own` (what the command reads) and errors that are not
/// bad input keep `e`; a file that cannot be read keeps its error.
pub fn name_foreign(
    path: &Path,
    e: Error,
    limit: Limit,
    expected: &str,
    own: &[settle_files::looks::Looks],
) -> Error {
    if !e.is_input_error() {
        return e;
    }
    match settle_files::looks::file(path, limit) {
        // Archives, compressed and UTF-16 files are named by the readers already.
        Some(settle_files::looks::Looks::Packed(_)) => e,
        Some(l) if !own.contains(&l) => Error::Input {
            at: crate::error::Location {
                line: Some(1),
                ..crate::error::Location::file(path)
            },
            message: format!("{}, not {expected}: {}", l.what(), l.then()),
        },
        _ => e,
    }
}

/// FNV-1a, 64 bit, over `parts` (each followed by a 0xff byte, which no UTF-8 text holds):
/// a stable digest (std's hasher may change between releases) for the identity of inputs
/// and the checksums of journal rows.
pub fn digest(parts: &[&[u8]]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for p in parts {
        for b in p.iter().copied().chain(std::iter::once(0xff)) {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
    }
    h
}
