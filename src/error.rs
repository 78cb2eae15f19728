//! The harness's error type (the foundation layer: every other module may use it).
//!
//! Where an input error is: a [`Location`]. Locations are built here ([`Location::file`],
//! [`Location::key`]) or, for a key of a TOML file, by
//! [`crate::input::source::Source::error_at`], which adds the line and column; no call
//! site assembles one by hand.

use std::path::PathBuf;

/// Where in an input file something is wrong.
#[derive(Debug, Clone, PartialEq)]
pub struct Location {
    /// The file (or a folder, or a command-line option such as `--jobs`).
    pub file: PathBuf,
    /// 1-based line, when known.
    pub line: Option<usize>,
    /// 1-based column, when known.
    pub column: Option<usize>,
    /// The dotted key path (e.g. `limits.vmax_mm_s`), when known.
    pub key: Option<String>,
}

impl Location {
    /// A whole file, folder or command-line option, no line known.
    pub fn file(file: impl Into<PathBuf>) -> Self {
        Self {
            file: file.into(),
            line: None,
            column: None,
            key: None,
        }
    }

    /// A key of `file` whose line is not known (e.g. `--backend` for a scenario).
    pub fn key(file: impl Into<PathBuf>, key: impl Into<String>) -> Self {
        Self {
            key: Some(key.into()),
            ..Self::file(file)
        }
    }
}

impl std::fmt::Display for Location {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.file.display())?;
        if let Some(line) = self.line {
            write!(f, ":{line}")?;
            if let Some(col) = self.column {
                write!(f, ":{col}")?;
            }
        }
        if let Some(key) = &self.key {
            write!(f, ": key `{key}`")?;
        }
        Ok(())
    }
}

/// The most characters of an input value an error message repeats.
pub const ECHO_CHARS: usize = 60;

/// `value` as an error message repeats it: at most [`ECHO_CHARS`] characters, then how
/// many more there are (a 10 MB value in a file is not printed back).
pub fn echo(value: &str) -> String {
    match value.char_indices().nth(ECHO_CHARS) {
        None => value.to_string(),
        Some((i, _)) => format!("{}... ({} characters)", &value[..i], value.chars().count()),
    }
}

/// The most digits a number in a message is printed with whole: a longer run of digits
/// (`1e300` printed by `{}` is 301 of them) is printed in scientific notation instead.
pub const NUMBER_DIGITS: usize = 24;

/// `text` with every number of more than [`NUMBER_DIGITS`] digits written in scientific
/// notation (`1e300`, `1.5e-300`): messages repeat the numbers they refuse, and Rust's
/// `{}` writes every digit of a huge or tiny one.
pub fn shorten_numbers(text: &str) -> String {
    let bytes = text.as_bytes();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    while i < bytes.len() {
        let start = i;
        while i < bytes.len() && (bytes[i].is_ascii_digit() || bytes[i] == b'.') {
            i += 1;
        }
        // A number does not end in a dot: that one ends the sentence.
        if i > start + 1 && bytes[i - 1] == b'.' {
            i -= 1;
        }
        if i == start {
            // Not a number: copy the character whole.
            let c = text[i..].chars().next().unwrap_or(' ');
            out.push(c);
            i += c.len_utf8();
            continue;
        }
        let run = &text[start..i];
        let digits = run.bytes().filter(u8::is_ascii_digit).count();
        match run.parse::<f64>() {
            Ok(v) if digits > NUMBER_DIGITS && run.matches('.').count() <= 1 => {
                out.push_str(&format!("{v:e}"));
            }
            _ => out.push_str(run),
        }
    }
    out
}

/// The longest `` `quoted` `` part of a message [`echo_quoted`] leaves whole: far above a
/// command or a path settle suggests, far below input that is not worth printing back.
pub const QUOTED_CHARS: usize = 1000;

/// `message` with every `` `quoted` `` part longer than [`QUOTED_CHARS`] shortened by
/// [`echo`]: the messages of the TOML parser and of the checks quote the input they reject
/// (an unknown name, a key), and a 10 MB name is not printed back.
pub fn echo_quoted(message: &str) -> String {
    let parts: Vec<&str> = message.split('`').collect();
    if parts.len() < 3 || parts.iter().all(|p| p.chars().count() <= QUOTED_CHARS) {
        return message.to_string();
    }
    let last = parts.len() - 1;
    parts
        .iter()
        .enumerate()
        .map(|(i, p)| {
            // Odd parts lie between two backticks (a last one without its closing backtick
            // is plain text).
            if i % 2 == 1 && i < last && p.chars().count() > QUOTED_CHARS {
                echo(p)
            } else {
                (*p).to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("`")
}

/// `text` (a key path) whole up to [`QUOTED_CHARS`] characters, else shortened by [`echo`].
pub fn echo_long(text: &str) -> String {
    if text.chars().count() > QUOTED_CHARS {
        echo(text)
    } else {
        text.to_string()
    }
}

/// Everything the harness reports. Bad input (exit code 2) is told apart from failures
/// while running or writing (exit code 1) by [`Error::is_input_error`].
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A scenario file (or another input file, or a command-line value) is unreadable,
    /// malformed or invalid.
    #[error("{at}: {message}")]
    Input {
        /// Where.
        at: Location,
        /// What is wrong and what is allowed.
        message: String,
    },
    /// A file could not be read.
    #[error("cannot read {}: {source}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// An output could not be written.
    #[error("cannot write {}: {source}", path.display())]
    Write {
        /// The file or folder.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// A run failed in simulation.
    #[error("run {run}: {source}")]
    Sim {
        /// Run index.
        run: usize,
        /// What the plant reported.
        source: settle_sim::SimError,
    },
    /// A planner error while running (should have been caught by validation).
    #[error("run {run}: {source}")]
    Plan {
        /// Run index.
        run: usize,
        /// What the planner reported.
        source: settle_planner::PlanError,
    },
    /// An accelerometer file cannot be read or holds no usable data (settle-identify's
    /// error names the file and, where one is to blame, the line).
    #[error(transparent)]
    Identify(#[from] settle_identify::IdentifyError),
    /// An input that is not a regular file, too large or not text, or an output the
    /// output rule refuses (a link, a device, one of the command's inputs).
    #[error(transparent)]
    File(settle_files::FileError),
    /// The run was not started: the sweep was interrupted (Ctrl-C or SIGTERM).
    #[error("run {run}: not run, the sweep was interrupted")]
    Interrupted {
        /// Run index.
        run: usize,
    },
}

impl Error {
    /// Bad input in `file` (a file, folder or command-line option) at no particular line.
    pub fn input(file: impl Into<PathBuf>, message: impl Into<String>) -> Self {
        Error::Input {
            at: Location::file(file),
            message: echo_quoted(&message.into()),
        }
    }

    /// Bad input at `key` of `file`, line unknown (e.g. `--backend` against a scenario).
    pub fn input_key(
        file: impl Into<PathBuf>,
        key: impl Into<String>,
        message: impl Into<String>,
    ) -> Self {
        Error::Input {
            at: Location::key(file, echo_long(&key.into())),
            message: echo_quoted(&message.into()),
        }
    }

    /// `path` could not be read.
    pub fn read(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Read {
            path: path.into(),
            source,
        }
    }

    /// `path` could not be written.
    pub fn write(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Write {
            path: path.into(),
            source,
        }
    }

    /// True for bad input (exit code 2: a malformed or invalid file, a bad option, a file
    /// that cannot be read), false for failures while running or writing (exit code 1: a
    /// run that broke down, a full disk).
    pub fn is_input_error(&self) -> bool {
        matches!(
            self,
            Error::Input { .. } | Error::Read { .. } | Error::Identify(_)
        ) || matches!(self, Error::File(e) if e.is_input_error())
    }
}

impl Error {
    /// This error as a failure to write an output (exit code 1), when it is the output
    /// rule refusing a path found in the way while a command writes (a folder where a
    /// recording goes): not the user's input at fault but the output folder's state.
    pub fn as_write_failure(self) -> Self {
        match self {
            Error::File(settle_files::FileError::Refused { path, why }) => Error::Write {
                path,
                source: std::io::Error::other(why),
            },
            e => e,
        }
    }
}

impl From<settle_files::FileError> for Error {
    /// A file that cannot be read or written is [`Error::Read`] or [`Error::Write`] as
    /// everywhere in the harness; the rest is [`Error::File`].
    fn from(e: settle_files::FileError) -> Self {
        use settle_files::FileError;
        match e {
            FileError::Read { path, source } => Error::Read { path, source },
            FileError::Write { path, source } => Error::Write { path, source },
            other => Error::File(other),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_numbers_are_shortened_and_others_kept() {
        let huge = format!("{}", 1e300);
        assert_eq!(huge.len(), 301);
        assert_eq!(
            shorten_numbers(&format!("got {huge} Hz, at most 1000000 Hz")),
            "got 1e300 Hz, at most 1000000 Hz"
        );
        let tiny = format!("{}", -1.5e-300);
        assert_eq!(shorten_numbers(&format!("x = {tiny}.")), "x = -1.5e-300.");
        let kept = "line 12: 0.1 2.5e-7 v1.2.3 12345678901234567890 µm";
        assert_eq!(shorten_numbers(kept), kept);
    }
}
