//! Profile kinds by name, and one entry point that plans any of them.

use crate::{Limits, PlanError, Profile, scurve, trapezoid};

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

    /// Plan a rest-to-rest move of signed `distance` starting at `p0`.
    pub fn rest_to_rest(
        self,
        p0: f64,
        distance: f64,
        limits: &Limits,
    ) -> Result<Profile, PlanError> {
        match self {
            ProfileKind::Trapezoid => trapezoid::rest_to_rest(p0, distance, limits),
            ProfileKind::SCurve => scurve::rest_to_rest(p0, distance, limits),
        }
    }
}

impl std::fmt::Display for ProfileKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}
