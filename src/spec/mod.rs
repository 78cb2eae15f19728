//! What one run is: [`run_spec::RunSpec`] (one point of a sweep, resolved) with the values
//! it was swept to ([`value::Value`]), the backend it runs on ([`backend::Backend`]) and
//! the states of its studies ([`run_spec::StudyState`], filled in by `crate::studies`).

pub mod backend;
pub mod groups;
pub mod machine;
pub mod run_spec;
pub mod runs;
pub mod value;
