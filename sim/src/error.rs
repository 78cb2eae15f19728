//! The sim crate's one error type.

/// What can go wrong building or stepping a plant.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SimError {
    /// A mode parameter is out of range.
    #[error("mode {field} = {value} is invalid: allowed {allowed}")]
    InvalidMode {
        /// Which field (`frequency_hz`, `damping_ratio`, `weight`).
        field: &'static str,
        /// The offending value.
        value: f64,
        /// What is allowed.
        allowed: &'static str,
    },
    /// A lumped model with a missing body, a bad index or an out-of-range parameter.
    #[error("invalid lumped model: {what}")]
    InvalidModel {
        /// What is wrong.
        what: String,
    },
    /// A plant needs at least one mode.
    #[error("a modal plant needs at least one mode")]
    NoModes,
    /// A step size that is negative or not finite.
    #[error("step size {dt_s} s is invalid: must be finite and >= 0")]
    InvalidStep {
        /// The step size (s).
        dt_s: f64,
    },
    /// The state became NaN or infinite.
    #[error("non-finite state at t = {t_s} s (NaN or infinity in the simulation)")]
    NonFinite {
        /// Simulation time of the step that produced it (s).
        t_s: f64,
    },
    /// The MuJoCo library rejected the generated model or failed while stepping.
    #[error("MuJoCo: {what}")]
    Mujoco {
        /// What MuJoCo reported.
        what: String,
    },
}
