//! Trinamic TMC4361A-style S-shaped ramps (seed 000): the seven-phase ramp with four
//! independent bows (jerks) in physical units ([`ramp`]), and its chip register values
//! for a given clock frequency ([`registers`]).

pub mod ramp;
pub mod registers;

pub use ramp::{RampPhase, SRamp, SRampParams};
pub use registers::{RegisterSet, TmcUnits};
