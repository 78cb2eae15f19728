//! How settle touches the file system, in one place for the `settle` command and the
//! crates that read users' files (`settle-gcode`: G-code, printer.cfg and its includes,
//! config.g; `settle-identify`: accelerometer recordings).
//!
//! - Inputs ([`read`]): every file is opened through [`read::open`], which resolves links,
//!   accepts regular files only (a FIFO would block, `/dev/zero` never ends, a folder is
//!   not a file), refuses a file above its kind's [`Limit`] before reading it and stops at
//!   the limit while reading (a file that grows). [`read::read_capped`] bounds what a
//!   decompressor may produce. [`lines::BoundedLines`] splits a stream into lines of
//!   bounded length without holding an over-long line. [`packed::Packed`] names an input
//!   that is an archive or a compressed stream by its first bytes; [`looks::Looks`] names
//!   the kind of a file a command was handed by mistake (a G-code job, a printer.cfg, an
//!   STL model) with the command that reads it.
//! - Outputs ([`mod@write`]): a file is written only where nothing is or where a regular file
//!   is (never onto a link, a folder, a device or a FIFO), through a temporary file and a
//!   rename; a folder settle makes inside its output folder is never a link out of it; and
//!   [`write::Inputs`] refuses an output that is one of the command's inputs, compared by
//!   identity (the same file through any link or path).
//! - [`limit`]: the size limit of every kind of input file, listed in the book's page on
//!   failures and limits (docs/guide/failures.md).
//!
//! The planner crate does no I/O and does not use this crate.

pub mod error;
pub mod identity;
pub mod limit;
pub mod lines;
pub mod looks;
pub mod packed;
pub mod read;
pub mod write;

pub use error::FileError;

/// A FIFO (named pipe) made at `path` with the system's `mkfifo`, for the readers' and
/// writers' tests that refuse one without waiting on it.
#[cfg(all(test, unix))]
pub(crate) fn make_fifo(path: &std::path::Path) {
    let made = std::process::Command::new("mkfifo")
        .arg(path)
        .status()
        .expect("mkfifo runs");
    assert!(made.success());
}
pub use identity::FileId;
pub use limit::Limit;
