//! Metrics, computed streaming from a run's samples, and the series a run records.

pub mod metrics;
pub mod path_metrics;
pub mod series;
