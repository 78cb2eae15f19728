//! Outputs: runs.csv ([`runs_csv`]), the ranking ([`ranking`]) and the G-code jobs'
//! table ([`jobs`]) that summary.md
//! ([`summary`]) and report.html ([`report`], rendered by [`html`]) show, the figures
//! ([`plot`]), the per-run recordings ([`sink`]: MCAP, rerun), all written whole
//! ([`atomic`]); and the files of a sweep's output folder together ([`sweep_files`]).

pub mod atomic;
pub mod folder;
pub mod html;
pub mod jobs;
pub mod plot;
pub mod ranking;
pub mod report;
pub mod runs_csv;
pub mod sha256;
pub mod sink;
pub mod summary;
pub mod sweep_files;
