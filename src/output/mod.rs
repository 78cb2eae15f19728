//! Outputs.

pub mod plot;
pub mod report;
pub mod sink;
pub mod sweep_files;
