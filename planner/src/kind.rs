//! Profile kinds by name, and one entry point that plans any of them.

use crate::position::{Shape, to_state};
use crate::{Limits, PlanError, Profile, State};

/// The profile kinds settle can plan.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ProfileKind {
    /// Time-optimal velocity trapezoid (jerk unlimited; triangular when vmax is not reached).
    Trapezoid,
    /// Time-optimal 7-phase jerk-limited S-curve.
    SCurve,
}

impl ProfileKind {
    /// Every kind, in a fixed order.
    pub const ALL: [ProfileKind; 2] = [ProfileKind::Trapezoid, ProfileKind::SCurve];
    /// The names accepted by [`ProfileKind::parse`], for error messages.
    pub const ALLOWED: &'static str = "trapezoid, scurve";

    /// The kind's name as written in scenario files and tables.
    pub fn name(self) -> &'static str {
        match self {
            ProfileKind::Trapezoid => "trapezoid",
            ProfileKind::SCurve => "scurve",
        }
    }

    /// Parse a kind from its name.
    pub fn parse(name: &str) -> Result<Self, PlanError> {
        ProfileKind::ALL
            .into_iter()
            .find(|k| k.name() == name)
            .ok_or_else(|| PlanError::UnknownKind {
                name: name.to_string(),
                allowed: ProfileKind::ALLOWED,
            })
    }

    /// Plan a rest-to-rest move of signed `distance` starting at `p0`, with the any-state
    /// planner of [`crate::position`]. (The closed-form planners in [`crate::scurve`] and
    /// [`crate::trapezoid`] are kept as independent references for the tests.)
    pub fn rest_to_rest(
        self,
        p0: f64,
        distance: f64,
        limits: &Limits,
    ) -> Result<Profile, PlanError> {
        let shape = match self {
            ProfileKind::Trapezoid => Shape::Trapezoid,
            ProfileKind::SCurve => {
                limits
                    .jmax()
                    .ok_or(PlanError::MissingJerkLimit { kind: "scurve" })?;
                Shape::JerkLimited
            }
        };
        for (name, value) in [("p0", p0), ("distance", distance)] {
            if !value.is_finite() {
                return Err(PlanError::NonFinite { name, value });
            }
        }
        let start = State {
            p: p0,
            v: 0.0,
            a: 0.0,
        };
        if distance == 0.0 {
            return Ok(Profile::empty(start));
        }
        let target = State {
            p: p0 + distance,
            v: 0.0,
            a: 0.0,
        };
        to_state(start, target, limits, shape)
    }
}

impl std::fmt::Display for ProfileKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}
