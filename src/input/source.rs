//! A TOML input file kept with what is needed to report errors against it: its path, its
//! text and the key-to-line index of the text. Everything read from a scenario or machine
//! file is deserialized here, so every error names the file, line, column and key.
//!
//! A document can be read in parts: [`Source::document`] reads it without the tables that
//! others claim (the run kinds' `[corner]`, `[scan]`, ...; see `crate::kinds`), strictly
//! (`deny_unknown_fields` still rejects every other unknown key or table, naming its line),
//! and [`Source::table`] reads one claimed table. Both keep the spans of the whole text, so
//! an error inside `[corner]` names its line in the file.

use std::path::{Path, PathBuf};

use serde::de::DeserializeOwned;
use toml::de::{DeTable, ValueDeserializer};

use crate::error::{Error, Location};
use crate::input::keys::KeyIndex;

/// An input file's text, path and key index.
#[derive(Debug, Clone)]
pub struct Source {
    /// The file.
    pub path: PathBuf,
    /// Key-to-line index of its text.
    pub keys: KeyIndex,
    text: String,
}

impl Source {
    /// `text`, read from `path` (named in errors).
    pub fn new(text: &str, path: &Path) -> Self {
        Self {
            path: path.to_path_buf(),
            keys: KeyIndex::new(text),
            text: text.to_string(),
        }
    }

    /// Read the file at `path`.
    pub fn load(path: &Path) -> Result<Self, Error> {
        let text = crate::input::file::read_text(path)?;
        Ok(Self::new(&text, path))
    }

    /// The file's text.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// An input error at `key` (a dotted path; its line, or its closest parent's) with
    /// `message`.
    pub fn error_at(&self, key: &str, message: impl Into<String>) -> Error {
        let (line, column) = self.keys.find(key).unzip();
        Error::Input {
            at: Location {
                line,
                column,
                ..Location::key(&self.path, key)
            },
            message: message.into(),
        }
    }

    /// A TOML error located by its span: the line and column, and the key set on that line
    /// (the message names an unknown key itself; a wrong type is named by the key line).
    fn located(&self, e: &toml::de::Error) -> Error {
        let (line, column) = e.span().map(|s| self.keys.line_col(s.start)).unzip();
        let key = line
            .and_then(|l| self.keys.key_at_line(l))
            .map(str::to_string);
        Error::Input {
            at: Location {
                line,
                column,
                key,
                ..Location::file(&self.path)
            },
            message: e.message().trim().to_string(),
        }
    }

    fn parse(&self) -> Result<toml::Spanned<DeTable<'_>>, Error> {
        DeTable::parse(&self.text).map_err(|e| self.located(&e))
    }

    /// The whole document as `T`, without the top-level tables named in `claimed` (read
    /// those with [`Source::table`]).
    pub fn document<T: DeserializeOwned>(&self, claimed: &[&str]) -> Result<T, Error> {
        let mut doc = self.parse()?;
        for name in claimed {
            doc.get_mut().remove(*name);
        }
        T::deserialize(toml::de::Deserializer::from(doc)).map_err(|e| self.located(&e))
    }

    /// Top-level table `name` as `T`, `None` when the document has none.
    pub fn table<T: DeserializeOwned>(&self, name: &str) -> Result<Option<T>, Error> {
        let mut doc = self.parse()?;
        match doc.get_mut().remove(name) {
            None => Ok(None),
            Some(v) => T::deserialize(ValueDeserializer::from(v))
                .map(Some)
                .map_err(|e| self.located(&e)),
        }
    }

    /// Whether the document has a top-level key or table `name`.
    pub fn has(&self, name: &str) -> bool {
        self.parse()
            .is_ok_and(|doc| doc.get_ref().contains_key(name))
    }
}
