//! Marlin's planner (Marlin/src/module/planner.cpp) with its block buffer.
//!
//! Read from planner.cpp of Marlin 2.0.9.x and stepper.cpp of a 2.1.x version; later 2.1
//! releases reworked the rounding in `calculate_trapezoid_for_block`, which this model
//! does not follow.
//!
//! Marlin plans in stepper steps. A move becomes a *block* (`_populate_block`): positions
//! are rounded to whole steps, a block of fewer than `MIN_STEPS_PER_SEGMENT` steps on
//! every axis is dropped (its steps join the next block), the feed rate is raised to the
//! minimum feed rate and lowered to each axis's `M203` limit, the nominal step rate is
//! `ceil(steps / time)`, the acceleration is `M204` print, travel or retract acceleration
//! in steps/s^2 (`ceil`), lowered for each axis to its `M201` limit (`floor`). The corner
//! speed comes from junction deviation (`M205 J`, with the small-segment arc limit of
//! `JD_HANDLE_SMALL_SEGMENTS`) or classic jerk (`M205 X Y Z E`, the "safe speed" logic).
//! Look-ahead runs `reverse_pass` and `forward_pass` over the non-busy blocks each time a
//! block is added, with Marlin's `block_buffer_planned` bookkeeping; the last block ends at
//! `MINIMUM_PLANNER_SPEED`. When the stepper takes a block its trapezoid is fixed
//! (`calculate_trapezoid_for_block`): entry and exit rates `ceil`ed and raised to
//! `MINIMAL_STEP_RATE`, acceleration steps `ceil`ed, deceleration steps `floor`ed.
//! [`crate::firmware::PlannedMove`] then follows the stepper (stepper.cpp): the rate ramps
//! in time (linearly, or along the quintic Bezier with `S_CURVE_ACCELERATION`) and phases
//! end at the planned step counts, holding the ramp's target rate if it is reached early
//! and leaving a deceleration cut short above the exit rate.
//!
//! The queue holds `BLOCK_BUFFER_SIZE - 1` blocks. Printing from a file it is full: the
//! stepper takes block `k` (fixing its trapezoid and the next block's entry speed) before
//! block `k + 14` is added. After an empty queue the first block starts once
//! [`MarlinConfig::first_block_after`] blocks are queued (stepper.cpp delivers it when 3
//! are, `BLOCK_DELAY_FOR_1ST_MOVE`).
//!
//! Approximations: f64 instead of the firmware's f32; the stepper's timer-tick rounding
//! and one-step offsets at phase boundaries are not modelled (each phase is exact in
//! continuous time between the planned step counts: an error of about one step period per
//! phase). Classic jerk can, in Marlin, let a junction exceed the previous block's nominal
//! speed (the "safe speed" branch); here the junction is capped at it, as junction
//! deviation does. Not modelled: `LIN_ADVANCE` limits, `XY_FREQUENCY_LIMIT`, volumetric
//! limits, `FT_MOTION`.

mod block;
mod config;
mod planner;
mod prusa;
mod trapezoid;

pub use config::{JdSmallSegments, MarlinConfig, MarlinJerk, MarlinStepper};
pub use planner::MarlinPlanner;
pub use prusa::{PLANNER_STEPS_MULTIPLIER, PrusaModel};
