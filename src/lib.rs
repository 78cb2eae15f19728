//! settle: which motion profile makes my machine settle fastest, and by how much?
//!
//! The harness library behind the `settle` binary. Its modules are layers; data flows down
//! the list and a module imports only from its own layer and the layers above it here
//! (`tests/all/layers.rs` checks it; `tests/all/module_graph.rs` that no crate's module
//! graph has a cycle):
//!
//! 1. [`error`]: the error type and where an input error is.
//! 2. [`input`]: scenario files (their core), machine files, runs tables, as plain data.
//! 3. [`spec`]: one run, resolved ([`spec::run_spec::RunSpec`]), with the states of its
//!    studies.
//! 4. [`measure`]: metrics computed streaming, path metrics, the series a run records.
//! 5. [`studies`]: what one run does with the machine (point move, corner path, scan
//!    step, input shaping, G-code job), one module each, behind one trait
//!    ([`studies::Study`]).
//! 6. [`expand`]: a scenario's sweep axes -> validated runs, through the registered studies.
//! 7. [`execute`]: the simulation driver every command runs its plants on, the plant of
//!    a backend, a run's plan and simulation, the worker pool.
//! 8. [`output`]: runs.csv, summary.md, figures, recordings.
//! 9. [`workflows`]: the commands as library functions with typed results (sweep with its
//!    journal, resume and shards; run; check; merge; validate; tune; plan; machine;
//!    identify; import; gcode).
//!
//! The binary (`src/main.rs`) parses arguments, calls a workflow, prints and maps errors to
//! exit codes.

pub mod error;
pub mod execute;
pub mod expand;
pub mod input;
pub mod measure;
pub mod output;
pub mod spec;
pub mod studies;
pub mod workflows;

pub use error::Error;
pub use expand::load_runs;
pub use measure::metrics::Metrics;
pub use spec::run_spec::RunSpec;
