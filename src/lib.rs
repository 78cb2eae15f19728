//! settle: which motion profile makes my machine settle fastest, and by how much?
//!
//! The harness library behind the `settle` binary. Its modules are layers; data flows down
//! the list and a module imports only from its own layer and the layers above it here
//! (`tests/all/layers.rs` checks it, and that the module graph has no cycles):
//!
//! 1. [`error`]: the error type and where an input error is.
//! 2. [`input`]: scenario files (their core), machine files, runs tables, as plain data.
//! 3. [`spec`]: one run, resolved ([`spec::run_spec::RunSpec`]), with the states of its
//!    run kinds.
//! 4. [`measure`]: metrics computed streaming, path metrics, the series a run records.
//! 5. [`kinds`]: the run kinds (point move, corner path, scan step, input shaping), one
//!    module each, behind one trait ([`kinds::Kind`]).
//! 6. [`expand`]: a scenario's sweep axes -> validated runs, through the registered kinds.
//! 7. [`execute`]: a run's plan and simulation on its backend, the worker pool.
//! 8. [`output`]: runs.csv, summary.md, figures, recordings.
//! 9. [`workflows`]: the commands as library functions with typed results (sweep with its
//!    journal, resume and shards; run; check; merge; validate; tune; plan).
//!
//! The binary (`src/main.rs`) parses arguments, calls a workflow, prints and maps errors to
//! exit codes.

pub mod error;
pub mod execute;
pub mod expand;
pub mod input;
pub mod kinds;
pub mod measure;
pub mod output;
pub mod spec;
pub mod workflows;

pub use error::Error;
pub use expand::load_runs;
pub use measure::metrics::Metrics;
pub use spec::run_spec::RunSpec;
