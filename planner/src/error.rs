//! The planner's one error type.

/// Everything that can go wrong when building or planning a profile.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlanError {
    /// A limit is zero, negative, NaN or infinite (for `vmin`/`amin`: zero, positive, ...).
    #[error(
        "limit `{name}` must be finite and nonzero, on the right side of zero (vmax, amax, jmax > 0; vmin, amin < 0), got {value}"
    )]
    InvalidLimit {
        /// Which limit (`vmax`, `amax`, `jmax`).
        name: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A jerk-limited planner was asked to plan without a jerk limit.
    #[error("profile kind `{kind}` needs a jerk limit (jmax)")]
    MissingJerkLimit {
        /// The profile kind that needs it.
        kind: &'static str,
    },
    /// A move parameter (distance, start position) is NaN or infinite.
    #[error("`{name}` must be finite, got {value}")]
    NonFinite {
        /// Which parameter.
        name: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A segment has a negative or non-finite duration, or a non-finite jerk/acceleration.
    #[error("segment {index}: {reason}")]
    InvalidSegment {
        /// Index of the segment in the profile.
        index: usize,
        /// What is wrong with it.
        reason: &'static str,
    },
    /// No profile reaches the target (should not happen for valid inputs; reported rather
    /// than returning a wrong profile).
    #[error("no valid profile found: {reason}")]
    NoSolution {
        /// What failed.
        reason: &'static str,
    },
    /// The target state cannot be held within the limits.
    #[error("infeasible target: {reason}")]
    InfeasibleTarget {
        /// Why.
        reason: &'static str,
    },
    /// An error on one axis of a multi-axis problem.
    #[error("axis {axis}: {source}")]
    OnAxis {
        /// 0-based axis index.
        axis: usize,
        /// What went wrong there.
        source: Box<PlanError>,
    },
    /// Input that does not describe a problem (e.g. a trajectory without axes).
    #[error("invalid input: {reason}")]
    InvalidInput {
        /// What is wrong.
        reason: &'static str,
    },
    /// A path that cannot be planned (see [`crate::path::PathFault`] for what is wrong).
    #[error("invalid path: {fault}")]
    InvalidPath {
        /// What is wrong, and at which point.
        fault: crate::path::PathFault,
    },
    /// An unknown profile kind name.
    #[error("unknown profile kind `{name}`; allowed: {allowed}")]
    UnknownKind {
        /// The name given.
        name: String,
        /// The allowed names, comma separated.
        allowed: &'static str,
    },
    /// An unknown input shaper name.
    #[error("unknown shaper `{name}`; allowed: {allowed}")]
    UnknownShaper {
        /// The name given.
        name: String,
        /// The allowed names.
        allowed: &'static str,
    },
    /// A shaper name that parses but whose parameters, frequency or damping ratio its
    /// firmware refuses.
    #[error("shaper `{name}`: {reason}")]
    InvalidShaper {
        /// The shaper as written (or as `Display` writes it).
        name: String,
        /// What is wrong and what is allowed.
        reason: String,
    },
    /// A value a motion-controller chip cannot hold in its register.
    #[error("{chip} register {register}: {reason} (value {value})")]
    Register {
        /// The chip (`TMC4361A`, `TMC5160`).
        chip: &'static str,
        /// The register (`AMAX`, `BOW1`, ...).
        register: &'static str,
        /// The physical value asked for, in the caller's units.
        value: f64,
        /// Why it does not fit, with the register's range.
        reason: String,
    },
}
