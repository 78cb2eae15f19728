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
    /// A machine parameter is missing or out of range. `field` is the key path inside the
    /// axis, as written in a machine file (e.g. `mount.stiffness_n_per_m`).
    #[error("axis `{axis}`: {field} = {value} is invalid: allowed {allowed}")]
    InvalidMachine {
        /// The axis (`x`, `y`, ...), or `machine` for machine-wide problems.
        axis: String,
        /// The field, as a dotted key path inside the axis.
        field: String,
        /// The offending value.
        value: f64,
        /// What is allowed.
        allowed: String,
    },
    /// A backend cannot simulate this model (e.g. the linear modal backend and the
    /// nonlinear stepper driver).
    #[error("the {backend} backend cannot simulate this model: {reason}")]
    Unsupported {
        /// The backend.
        backend: &'static str,
        /// Why, and what to do instead.
        reason: String,
    },
    /// The command has a different number of axes than the plant.
    #[error("the command has {got} axes, the plant {expected}")]
    AxisCount {
        /// Axes of the plant.
        expected: usize,
        /// Axes commanded.
        got: usize,
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
