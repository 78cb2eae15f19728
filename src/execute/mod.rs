//! Executing runs.

pub mod cursor;
pub mod interrupt;
pub mod pool;
pub mod run;
