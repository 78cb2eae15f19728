//! Input files as plain data: scenario files (their core; the studies read their own
//! tables), machine files, the `[tune]` table and runs tables (runs.csv: baselines and
//! shard folders are inputs too). [`source::Source`] is where every input error gets its
//! file, line and key.

pub mod file;
pub mod keys;
pub mod machine_file;
pub mod machine_form;
pub mod modes;
pub mod runs_columns;
pub mod runs_table;
pub mod scenario;
pub mod source;
pub mod tune_spec;
