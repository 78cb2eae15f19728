//! The commands as library functions with typed results: [`sweep`] (with its [`journal`],
//! `--resume` and [`shard`]s, K and N given or read from a [`scheduler`]'s environment),
//! [`run`] (one case in detail), [`check`] (the regression
//! gate), [`merge`] (sharded sweeps), [`validate`] (backends against the closed form),
//! [`tune`] (the profile search), [`import`] (firmware configurations in), [`plan`] (JSON
//! lines), [`machine`] (a machine's modes per axis) and [`identify`] (modes from
//! accelerometer data). Each returns an outcome whose [`Report`] is what the binary prints
//! and the exit status it maps to a code.

pub mod check;
pub mod gcode;
pub mod identify;
pub mod import;
pub mod journal;
pub mod lock;
pub mod machine;
pub mod merge;
pub mod plan;
pub mod run;
pub mod scheduler;
pub mod shard;
pub mod sweep;
#[cfg(test)]
mod toy_pipeline;
pub mod tune;
pub mod validate;

/// How a command ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Exit {
    /// Everything ran and passed (exit code 0).
    Ok,
    /// The command finished and wrote every output, and some runs failed physically (lost
    /// steps, a simulation fault): results, recorded with their reasons, not a failure of
    /// the command (exit code 0, or 1 with `--fail-on-failed-runs`).
    RunsFailed,
    /// A check found a regression or a validation failed (exit code 1).
    Failed,
    /// A sweep was interrupted; its finished runs are kept for `--resume` (exit code 130,
    /// [`crate::execute::interrupt::EXIT_CODE`]).
    Interrupted,
}

/// What a command prints: its result on stdout, notes on stderr, and how it ended.
#[derive(Debug, Clone, PartialEq)]
pub struct Report {
    /// For stdout.
    pub stdout: String,
    /// For stderr.
    pub stderr: String,
    /// How it ended.
    pub exit: Exit,
}

impl Report {
    /// A report that ended `exit`.
    pub fn new(exit: Exit) -> Self {
        Self {
            stdout: String::new(),
            stderr: String::new(),
            exit,
        }
    }

    /// Add a line to stdout.
    pub fn out(&mut self, line: impl AsRef<str>) {
        self.stdout.push_str(line.as_ref());
        self.stdout.push('\n');
    }

    /// Add a line to stderr.
    pub fn err(&mut self, line: impl AsRef<str>) {
        self.stderr.push_str(line.as_ref());
        self.stderr.push('\n');
    }
}
