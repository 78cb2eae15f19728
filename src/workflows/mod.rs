//! Workflows.

pub mod check;
pub mod journal;
pub mod plan;
pub mod shard;
pub mod tune;
pub mod validate;
