//! Measuring runs: the metrics and their definitions ([`metrics`]), computed streaming
//! ([`accumulator`]; contour error along a path: [`path_metrics`]), and the full
//! [`series::Series`] a run records when asked. No knowledge of backends or studies.

pub mod accumulator;
pub mod metrics;
pub mod path_metrics;
pub mod series;
