//! Outputs: runs.csv ([`runs_csv`]), summary.md ([`summary`]), report.html ([`html`]), the
//! figures ([`plot`]), the per-run recordings ([`sink`]: MCAP, rerun), all written whole
//! ([`atomic`]); and the files of a sweep's output folder together ([`sweep_files`]).

pub mod atomic;
pub mod html;
pub mod plot;
pub mod runs_csv;
pub mod sink;
pub mod summary;
pub mod sweep_files;
