//! The `Plant` trait every backend implements.

use settle_planner::{Sample, State};

use crate::SimError;

/// What a plant reports at an instant (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Observation {
    /// The commanded position the plant is following (m).
    pub commanded_m: f64,
    /// The toolhead position (m).
    pub toolhead_m: f64,
}

/// A plant: a constant model (`self`) and a separate mutable state.
pub trait Plant {
    /// The mutable state.
    type State;

    /// A fresh state, at rest at the commanded start state.
    fn initial_state(&self, start: &State) -> Self::State;

    /// Advance `dt_s` seconds. `cmd` is the commanded sample at the step start; its jerk is
    /// constant over the step (callers split steps at profile breakpoints).
    fn step(&self, state: &mut Self::State, cmd: &Sample, dt_s: f64) -> Result<(), SimError>;

    /// What the plant shows now.
    fn observe(&self, state: &Self::State) -> Observation;
}
