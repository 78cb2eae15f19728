//! The point-to-point move of `[move]`: a rest-to-rest profile of the run's kind on one
//! machine axis, every other axis holding at 0. It claims no table: it is the study of every
//! run that no other motion study claims, and the common metrics (move and settle, residual
//! vibration) are its figures.

use settle_planner::PlanError;

use crate::studies::{Motion, PlanContext, Planned, Role, Study, jerk_unused, on_axis};
use crate::spec::run_spec::RunSpec;

/// The point-to-point move.
#[derive(Debug, Clone, Copy)]
pub struct PointMove;

impl Study for PointMove {
    fn name(&self) -> &'static str {
        "point-to-point move"
    }

    fn table(&self) -> Option<&'static str> {
        None
    }

    fn role(&self) -> Role {
        Role::Move
    }

    fn plan(&self, run: &RunSpec, ctx: &PlanContext) -> Result<Planned, PlanError> {
        let limits = run.limits_si()?;
        let profile = run.profile.rest_to_rest_with(
            run.start_mm * 1e-3,
            run.distance_mm * 1e-3,
            &limits,
            &run.profile_params,
        )?;
        let profile = match &ctx.shaper {
            Some(s) => s.apply(&profile)?,
            None => profile,
        };
        Ok(Planned {
            motion: Motion::Whole(on_axis(ctx.axes, &run.axis, &profile)?),
            probe: None,
            linearise_at_m: None,
            step_at_m: None,
        })
    }

    fn unused(&self, run: &RunSpec, key: &str) -> Option<&'static str> {
        jerk_unused(run, key)
    }
}
