//! A TOML input file kept with what is needed to report errors against it: its path, its
//! text and the key-to-line index of the text. Everything read from a scenario or machine
//! file is deserialized here, so every error names the file, line, column and key.
//!
//! A document can be read in parts: [`Source::document`] reads it without the tables that
//! others claim (the studies' `[corner]`, `[scan]`, ...; see `crate::studies`), strictly
//! (`deny_unknown_fields` still rejects every other unknown key or table, naming its line),
//! and [`Source::table`] reads one claimed table. Both keep the spans of the whole text, so
//! an error inside `[corner]` names its line in the file.

use std::path::{Path, PathBuf};

use serde::de::DeserializeOwned;
use toml::de::{DeTable, ValueDeserializer};

use crate::error::{Error, Location, echo_long, echo_quoted};
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
        let text = crate::input::file::read_text(path, crate::input::file::limit::SETTINGS)?;
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
                ..Location::key(&self.path, echo_long(key))
            },
            message: echo_quoted(&message.into()),
        }
    }

    /// A TOML error located by its span: the line and column, and the key set on that line
    /// (the message names an unknown key itself; a wrong type is named by the key line).
    /// A missing key is named as such: the table the span covers, and the key in it. An
    /// error without a span (nesting beyond the parser's recursion limit) is put on the
    /// most deeply nested line.
    fn located(&self, e: &toml::de::Error) -> Error {
        let message = e.message().trim();
        let (line, column) = match e.span() {
            Some(s) => Some(self.keys.line_col(s.start)),
            None => deepest_line(&self.text).map(|l| (l, 1)),
        }
        .unzip();
        let missing = message
            .strip_prefix("missing field `")
            .and_then(|m| m.strip_suffix('`'));
        let key = match (missing, e.span()) {
            (Some(field), Some(s)) => {
                // The span is the table missing the field: the document (from 0), an
                // inline table (from its brace, on its key's line) or a `[table]`.
                let table = if s.start == 0 {
                    String::new()
                } else if self.text.as_bytes().get(s.start) == Some(&b'{') {
                    line.and_then(|l| self.keys.key_at_line(l))
                        .unwrap_or_default()
                        .to_string()
                } else {
                    self.keys.table_at(s.start, &self.text)
                };
                Some(if table.is_empty() {
                    field.to_string()
                } else {
                    format!("{table}.{field}")
                })
            }
            (Some(field), None) => Some(field.to_string()),
            (None, _) => line
                .and_then(|l| self.keys.key_at_line(l))
                .map(str::to_string),
        };
        Error::Input {
            at: Location {
                line,
                column,
                key: key.map(|k| echo_long(&k)),
                ..Location::file(&self.path)
            },
            message: echo_quoted(message),
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

/// The line (1-based) nested most deeply: the most brackets and braces open at once plus
/// the parts of a dotted key (outside strings, roughly: enough to point at the line that
/// breaks a recursion limit). `None` for an empty text.
fn deepest_line(text: &str) -> Option<usize> {
    let mut depth: i64 = 0;
    let mut best: Option<(i64, usize)> = None;
    for (n, raw) in text.lines().enumerate() {
        let mut peak = depth;
        let mut quote: Option<char> = None;
        let mut dots = 0;
        let mut in_key = true;
        for c in raw.chars() {
            match (quote, c) {
                (Some(q), c) if c == q => quote = None,
                (Some(_), _) => {}
                (None, '"' | '\'') => quote = Some(c),
                (None, '#') => break,
                (None, '=') => in_key = false,
                (None, '.') if in_key => dots += 1,
                (None, '[' | '{') => {
                    depth += 1;
                    peak = peak.max(depth);
                }
                (None, ']' | '}') => depth -= 1,
                _ => {}
            }
        }
        let score = peak + dots;
        if best.is_none_or(|(b, _)| score > b) {
            best = Some((score, n + 1));
        }
    }
    best.map(|(_, line)| line)
}
