//! Profile kinds by name, and one entry point that plans any of them.

use crate::fourjerk::FourJerkLimits;
use crate::position::{Shape, to_state};
use crate::{Limits, PlanError, Profile, State};

/// The profile kinds settle can plan.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ProfileKind {
    /// Time-optimal velocity trapezoid (jerk unlimited; triangular when vmax is not reached).
    Trapezoid,
    /// Time-optimal 7-phase jerk-limited S-curve.
    SCurve,
    /// Time-optimal profile under four jerks (Trinamic BOW1..BOW4): raise and lower the
    /// acceleration at `j1`, `j2`, raise and lower the deceleration at `j3`, `j4`, with
    /// DMAX for braking (see [`crate::fourjerk`]). Parameters: [`ProfileParams`]
    /// `fourjerk_jerk_scale` (multiples of `jmax`) and `fourjerk_dmax_scale` (multiple of
    /// `amax`); with the defaults it is the S-curve.
    FourJerk,
    /// Symmetric PVT step: five linear-acceleration segments (plus a
    /// constant-velocity one when vmax is reached), knots at the S-curve's phase ends, the
    /// fastest within vmax, amax, jmax (see [`crate::pvt::step::symmetric`]). No
    /// parameters.
    PvtSym,
    /// Asymmetric PVT step: peak acceleration and jerk in the first half, time scaled to
    /// the fastest within vmax, amax, jmax (see [`crate::pvt::step::asymmetric`]).
    /// Parameter: [`ProfileParams`] `pvt_asym_ki` (`Ki`, 1/3 < Ki < 1).
    PvtAsym,
}

/// Parameters of the kinds that take any (ignored by the others). The defaults make every
/// kind plannable from [`Limits`] alone.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProfileParams {
    /// `pvt_asym`: `Ki` (twice the fraction of the step covered when the acceleration
    /// peaks, see [`crate::pvt::step::AsymShape`]), in (1/3, 1). Default 0.5: peak
    /// acceleration at one third of the move, 0.375 d/t1^2 against a final deceleration
    /// of a third of that.
    pub pvt_asym_ki: f64,
    /// `fourjerk`: the jerks `[j1, j2, j3, j4]` as multiples of `jmax` (raise acceleration,
    /// lower it, raise deceleration, lower it: BOW1..BOW4). Default `[1, 1, 1, 1]`.
    pub fourjerk_jerk_scale: [f64; 4],
    /// `fourjerk`: DMAX as a multiple of `amax`. Default 1.
    pub fourjerk_dmax_scale: f64,
}

impl Default for ProfileParams {
    fn default() -> Self {
        Self {
            pvt_asym_ki: 0.5,
            fourjerk_jerk_scale: [1.0; 4],
            fourjerk_dmax_scale: 1.0,
        }
    }
}

impl ProfileKind {
    /// Every kind, in a fixed order.
    pub const ALL: [ProfileKind; 5] = [
        ProfileKind::Trapezoid,
        ProfileKind::SCurve,
        ProfileKind::FourJerk,
        ProfileKind::PvtSym,
        ProfileKind::PvtAsym,
    ];
    /// The names accepted by [`ProfileKind::parse`], for error messages.
    pub const ALLOWED: &'static str = "trapezoid, scurve, fourjerk, pvt_sym, pvt_asym";

    /// The kind's name as written in scenario files and tables.
    pub fn name(self) -> &'static str {
        match self {
            ProfileKind::Trapezoid => "trapezoid",
            ProfileKind::SCurve => "scurve",
            ProfileKind::FourJerk => "fourjerk",
            ProfileKind::PvtSym => "pvt_sym",
            ProfileKind::PvtAsym => "pvt_asym",
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

    /// Plan a rest-to-rest move of signed `distance` starting at `p0` with the default
    /// [`ProfileParams`]. Trapezoids and S-curves use the any-state planner of
    /// [`crate::position`] (the closed-form planners in [`crate::scurve`] and
    /// [`crate::trapezoid`] are kept as independent references for the tests).
    pub fn rest_to_rest(
        self,
        p0: f64,
        distance: f64,
        limits: &Limits,
    ) -> Result<Profile, PlanError> {
        self.rest_to_rest_with(p0, distance, limits, &ProfileParams::default())
    }

    /// [`Self::rest_to_rest`] with explicit parameters. The kinds after `scurve` use
    /// `vmax`, `amax` and `jmax` of `limits` (symmetric) and need the jerk limit.
    pub fn rest_to_rest_with(
        self,
        p0: f64,
        distance: f64,
        limits: &Limits,
        params: &ProfileParams,
    ) -> Result<Profile, PlanError> {
        let shape = match self {
            ProfileKind::Trapezoid => Shape::Trapezoid,
            ProfileKind::SCurve => {
                limits
                    .jmax()
                    .ok_or(PlanError::MissingJerkLimit { kind: "scurve" })?;
                Shape::JerkLimited
            }
            ProfileKind::FourJerk | ProfileKind::PvtSym | ProfileKind::PvtAsym => {
                return self.plan_extended(p0, distance, limits, params);
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

    /// The four-jerk and PVT-step kinds.
    fn plan_extended(
        self,
        p0: f64,
        distance: f64,
        limits: &Limits,
        params: &ProfileParams,
    ) -> Result<Profile, PlanError> {
        let jmax = limits
            .jmax()
            .ok_or(PlanError::MissingJerkLimit { kind: self.name() })?;
        for (name, value) in [("p0", p0), ("distance", distance)] {
            if !value.is_finite() {
                return Err(PlanError::NonFinite { name, value });
            }
        }
        if distance == 0.0 {
            return Ok(Profile::empty(State {
                p: p0,
                v: 0.0,
                a: 0.0,
            }));
        }
        match self {
            ProfileKind::FourJerk => {
                let l = FourJerkLimits::new(
                    limits.vmax(),
                    limits.amax(),
                    limits.amax() * params.fourjerk_dmax_scale,
                    params.fourjerk_jerk_scale.map(|s| s * jmax),
                )?;
                crate::fourjerk::rest_to_rest(p0, distance, &l)
            }
            ProfileKind::PvtSym => Ok(crate::pvt::step::symmetric(p0, distance, limits)?.profile),
            ProfileKind::PvtAsym => {
                Ok(crate::pvt::step::asymmetric(p0, distance, params.pvt_asym_ki, limits)?.profile)
            }
            ProfileKind::Trapezoid | ProfileKind::SCurve => Err(PlanError::InvalidInput {
                reason: "not an extended kind",
            }),
        }
    }
}

impl std::fmt::Display for ProfileKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}
