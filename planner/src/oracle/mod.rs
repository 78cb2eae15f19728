//! Test-only oracle: a bracketing implementation of the any-state planner (step 1) and
//! of step 2, independent of the closed-form cases. It is slow (it samples every one-
//! parameter family on a grid and bisects every sign change) but independent of the
//! closed forms, so the property tests in `tests` check that both agree on random
//! problems.

pub(crate) mod duration;
pub(crate) mod peak;
mod roots;
mod stretch;
pub(crate) mod sync;
mod tests;
mod three_arc;
