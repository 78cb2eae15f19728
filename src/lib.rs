//! settle: which motion profile makes my machine settle fastest, and by how much?
//!
//! The harness: scenario files are expanded into runs ([`expand`]), each run plans a profile
//! and drives a plant through it ([`execute`]), metrics are computed streaming ([`measure`]) and
//! written as tables ([`output`]).

pub mod error;
pub mod execute;
pub mod expand;
pub mod input;
pub mod kinds;
pub mod measure;
pub mod output;
pub mod workflows;

pub use error::Error;
pub use execute::pool::{run_all, run_all_with};
pub use expand::{RunSpec, load_runs};
pub use measure::metrics::Metrics;
