//! GRBL's planner (gnea/grbl 1.1h grbl/planner.c, and the block profile of
//! grbl/stepper.c `st_prep_buffer`); grblHAL's planner.c computes the same blocks (its
//! optional jerk-limited acceleration, `ENABLE_JERK_ACCELERATION`, is off by default).
//!
//! A move becomes a block (`plan_buffer_line`): its end point is rounded to whole steps
//! (`$100`-`$102`), a block of no step is dropped, its acceleration and rapid rate are the
//! largest along its direction inside the per-axis box of `$120`-`$122` and `$110`-`$112`
//! (`limit_value_by_axis_maximum`), its nominal speed is the programmed feed capped by the
//! rapid rate (a rapid, `G0`, runs at the rapid rate) and at least `MINIMUM_FEED_RATE`
//! (1 mm/min). The corner speed comes from junction deviation (`$11`): with `cos theta =
//! -u_prev . u`, `sin(theta/2) = sqrt((1 - cos theta)/2)` and the acceleration limited
//! along `u - u_prev`, `v_j^2 = a_j * $11 * sin(theta/2) / (1 - sin(theta/2))`; a block
//! added to an empty buffer starts from rest, a reversal (`cos theta > 0.999999`) has
//! `MINIMUM_JUNCTION_SPEED` (0), a straight continuation no limit. The entry is also
//! capped by both blocks' nominal speeds (`plan_compute_profile_parameters`).
//! `planner_recalculate` runs the reverse pass (the newest block ends at rest) and the
//! forward pass from `block_buffer_planned`, as the firmware does.
//!
//! The buffer holds `BLOCK_BUFFER_SIZE - 1` blocks (15 on an Arduino Uno). Streaming
//! from a sender faster than the machine moves, it is full: `mc_line` starts the cycle
//! when a block finds it full, and when the segment generator has finished a block the
//! next line enters at once, so block `k` runs with blocks `k` to `k + 14` planned. Each
//! block is a trapezoid at its own acceleration from its entry speed to the next block's
//! (`st_prep_buffer`: acceleration-only, deceleration-only, trapezoid or triangle).
//! A synchronising command (`G4`, `M3`/`M4`/`M5`, a spindle speed change with the laser
//! mode off, coolant, program end) waits for the buffer to empty (`dwell`).
//!
//! Approximations: f64 instead of the firmware's f32; the segment generator's 10 ms
//! segments (`ACCELERATION_TICKS_PER_SECOND`) and step timing are taken as the exact
//! trapezoid; Cartesian machines only (GRBL's `COREXY` build limits motor speeds).
//! Feed, rapid and spindle overrides stay at 100 %.

mod config;
mod planner;

pub use config::GrblConfig;
pub use planner::GrblPlanner;
