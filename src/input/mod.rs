//! Input files as plain data: scenario files, machine files and runs tables.

pub mod keys;
pub mod machine_file;
pub mod runs_table;
pub mod scenario;
