//! Run kinds.

pub mod corner;
pub mod scan;
pub mod shaping;
