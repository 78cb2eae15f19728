//! What can go wrong reading an input or writing an output. Every error names the path
//! as the caller gave it; none repeats the file's content.

use std::path::PathBuf;

use crate::limit::Limit;

/// An input that cannot be read, or an output that may not or cannot be written.
#[derive(Debug, thiserror::Error)]
pub enum FileError {
    /// The operating system could not open or read the file (missing, no permission).
    #[error("{}: cannot read: {source}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// The path is not a regular file (after following links).
    #[error("{}: {what}{}, not a regular file: settle reads regular files only", path.display(), link_text(link_to))]
    NotRegular {
        /// The file as named.
        path: PathBuf,
        /// What it is: `a folder`, `a FIFO (named pipe)`, `a character device`, ...
        what: &'static str,
        /// Where the link that was named leads, when it is a link.
        link_to: Option<PathBuf>,
    },
    /// The file is larger than its kind's limit.
    #[error("{}: {found}; the limit for {} is {}", path.display(), limit.what, limit.human())]
    TooLarge {
        /// The file.
        path: PathBuf,
        /// What was found (`20000000 bytes`, `more than ... bytes as read`).
        found: String,
        /// The limit.
        limit: Limit,
    },
    /// The file is not UTF-8 text.
    #[error("{}:{line}:{column}: not UTF-8 text ({}); expected {expected}", path.display(), packed_text(packed))]
    NotText {
        /// The file.
        path: PathBuf,
        /// 1-based line of the first byte that is not UTF-8.
        line: usize,
        /// Its 1-based byte column.
        column: usize,
        /// What the file should hold (`a G-code file` ...: the limit's kind).
        expected: &'static str,
        /// What it is, when its first bytes say: an archive or a compressed stream.
        packed: Option<crate::packed::Packed>,
    },
    /// An output could not be written (a full disk, no permission).
    #[error("cannot write {}: {source}", path.display())]
    Write {
        /// The file or folder.
        path: PathBuf,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// Writing here would destroy something the rule protects: a link, a device, a folder,
    /// one of the command's inputs.
    #[error("cannot write {}: {why}", path.display())]
    Refused {
        /// The output path.
        path: PathBuf,
        /// Why, and what to do instead.
        why: String,
    },
}

fn link_text(link_to: &Option<PathBuf>) -> String {
    link_to
        .as_ref()
        .map(|t| format!(" (a link to {})", t.display()))
        .unwrap_or_default()
}

impl FileError {
    /// True for what the user can fix by naming another file (exit code 2): a file that is
    /// missing, not a regular file, too large, not text, or an output the rule refuses;
    /// false for a failure while writing (exit code 1: a full disk).
    pub fn is_input_error(&self) -> bool {
        !matches!(self, FileError::Write { .. })
    }

    /// A file that is larger than `limit`: `found` says by how much.
    pub fn too_large(path: impl Into<PathBuf>, found: impl Into<String>, limit: Limit) -> Self {
        FileError::TooLarge {
            path: path.into(),
            found: found.into(),
            limit,
        }
    }
}

/// Why a file is not text, in [`FileError::NotText`]'s words.
fn packed_text(packed: &Option<crate::packed::Packed>) -> String {
    match packed {
        Some(p) => format!("{}: {}", p.name(), p.instead()),
        None => "binary data?".to_string(),
    }
}
