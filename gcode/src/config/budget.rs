//! What one configuration may read: its files (the main one, Klipper's includes,
//! RepRapFirmware's macros) through settle-files' reader (regular files of at most
//! [`settle_files::limit::FIRMWARE_CONFIG`] each), at most [`MAX_FILES`] reads and
//! [`MAX_BYTES`] in all. Real configurations read a few dozen files of a few KB;
//! `[include l0/*.cfg]` in a tree where every file includes the next level would read
//! millions, and a macro run a million times as many.

use std::path::Path;

use crate::error::{GcodeError, Location};

/// The most file reads one configuration makes (includes and macros, counting repeats).
pub const MAX_FILES: usize = 1000;

/// The most bytes one configuration reads in all its files.
pub const MAX_BYTES: u64 = 64 * 1024 * 1024;

/// A configuration file's text (settle-files' reader: a regular file of at most
/// [`settle_files::limit::FIRMWARE_CONFIG`], UTF-8, a byte-order mark dropped), or an
/// error naming it (and the line of invalid UTF-8).
fn read_text(path: &Path) -> Result<String, settle_files::FileError> {
    settle_files::read::read_text(path, settle_files::limit::FIRMWARE_CONFIG)
}

/// The reads left to a configuration.
#[derive(Debug)]
pub(crate) struct Budget {
    files: usize,
    bytes: u64,
}

impl Budget {
    /// A new configuration's budget (the main file not yet read).
    pub(crate) fn new() -> Self {
        Self { files: 0, bytes: 0 }
    }

    /// Refuse `more` further reads asked for at `at` by `what` (an include's pattern that
    /// matched that many files) when they would pass [`MAX_FILES`].
    pub(crate) fn reserve(&self, more: usize, at: &Location, what: &str) -> Result<(), GcodeError> {
        if self.files.saturating_add(more) <= MAX_FILES {
            return Ok(());
        }
        Err(GcodeError::ConfigSyntax {
            at: at.clone(),
            what: format!(
                "{what}: {more} more files after {} read; a configuration reads at most {MAX_FILES} files (includes and macros, each time it is read)",
                self.files
            ),
        })
    }

    /// The main file's text.
    pub(crate) fn main(&mut self, path: &Path) -> Result<String, GcodeError> {
        let text = read_text(path)?;
        self.count(text.len(), None, "")?;
        Ok(text)
    }

    /// The text of `path`, read for the line `at` (an include or a macro call, written
    /// `what`): its errors name that line.
    pub(crate) fn read(
        &mut self,
        path: &Path,
        at: &Location,
        what: &str,
    ) -> Result<String, GcodeError> {
        self.reserve(1, at, what)?;
        let text = read_text(path).map_err(|source| GcodeError::Include {
            at: at.clone(),
            what: what.to_string(),
            source: Box::new(source),
        })?;
        self.count(text.len(), Some(at), what)?;
        Ok(text)
    }

    fn count(&mut self, len: usize, at: Option<&Location>, what: &str) -> Result<(), GcodeError> {
        self.files += 1;
        self.bytes = self.bytes.saturating_add(len as u64);
        if self.bytes <= MAX_BYTES {
            return Ok(());
        }
        let why = format!(
            "the files read reach {} bytes; a configuration reads at most {MAX_BYTES} bytes (64 MiB) in all its files",
            self.bytes
        );
        Err(match at {
            Some(at) => GcodeError::ConfigSyntax {
                at: at.clone(),
                what: format!("{what}: {why}"),
            },
            None => GcodeError::JobSetting {
                key: "config",
                reason: why,
            },
        })
    }
}
