//! Measuring runs: the metrics and their definitions ([`metrics`]), computed streaming
//! ([`accumulator`]; contour error along a path: [`path_metrics`]), and the full
//! [`series::Series`] a run records when asked, with its channels ([`channels`]); the bin
//! of a log-spaced histogram ([`log_bins`]). No knowledge of backends or studies.

pub mod accumulator;
pub mod channels;
pub mod log_bins;
pub mod metrics;
pub mod path_metrics;
pub mod series;
