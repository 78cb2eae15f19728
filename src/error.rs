//! The harness's error type.

use std::path::PathBuf;

/// Where in an input file something is wrong.
#[derive(Debug, Clone, PartialEq)]
pub struct Location {
    /// The file.
    pub file: PathBuf,
    /// 1-based line, when known.
    pub line: Option<usize>,
    /// 1-based column, when known.
    pub column: Option<usize>,
    /// The dotted key path (e.g. `limits.vmax_mm_s`), when known.
    pub key: Option<String>,
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

/// Everything the harness reports. Input errors (exit code 2) are separated from failures
/// while running (exit code 1) by [`Error::is_input_error`].
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A scenario file (or another input file) is unreadable, malformed or invalid.
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
    /// The run was not started: the sweep was interrupted (Ctrl-C or SIGTERM).
    #[error("run {run}: not run, the sweep was interrupted")]
    Interrupted {
        /// Run index.
        run: usize,
    },
}

impl Error {
    /// True for bad input (exit code 2), false for failures while running (exit code 1).
    pub fn is_input_error(&self) -> bool {
        matches!(
            self,
            Error::Input { .. } | Error::Read { .. } | Error::Write { .. }
        )
    }
}
