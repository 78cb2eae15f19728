//! Trinamic motion-controller registers of planned ramps.
//!
//! - [`ramp`]: the TMC4361A's seven-phase S-shaped ramp with four independent bows (jerks)
//!   in physical units;
//! - [`registers`]: its TMC4361A register values for a clock and the machine's microsteps
//!   per unit (export, import, register file);
//! - [`tmc5160`]: the TMC5160's sixPoint ramp registers (A1/AMAX/D1/DMAX/V1/VMAX/VSTART/
//!   VSTOP). The TMC5160 (like the TMC5130/5240) has no jerk registers: a jerk-limited
//!   ramp goes to the TMC4361A, a trapezoid to either.

mod field;
pub mod ramp;
pub mod registers;
pub mod tmc5160;

pub use field::{RegisterWrite, register_file_text};
pub use ramp::{RampPhase, SRamp, SRampParams};
pub use registers::{RegisterSet, TmcUnits};
