//! The backends: one trajectory simulated on the plant of a [`Backend`] with the
//! [`SimOptions`] every backend honours.

use settle_planner::Trajectory;
use settle_sim::{AxisModel, BeltModel, ModalPlant, RapierOptions, RapierPlant, SimError};

use crate::execute::Observe;
use crate::execute::simulate::{AxisMeta, channels, simulate};
use crate::measure::metrics::Metrics;
use crate::measure::series::Series;
use crate::spec::backend::Backend;
#[cfg(not(feature = "mujoco"))]
use crate::spec::backend::NO_MUJOCO;

/// Options every backend honours.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SimOptions {
    /// Position-dependent belt stiffness: varying (the physics) or frozen at the start
    /// (the linear model; the modal backend always freezes it).
    pub belt: BeltModel,
    /// Largest integration step of time-stepping backends (s); `None`: their own choice
    /// (rapier: `STEP_FRACTION / w_max`).
    pub max_step_s: Option<f64>,
    /// Where the modal backend linearises a position-dependent stiffness: one position
    /// per axis (m, in the order of the axes); `None`: each axis's start. The run kind
    /// chooses it ([`crate::kinds::Planned::linearise_at_m`]); the nonlinear backends
    /// follow the stiffness along the travel and ignore it.
    pub linearise_at_m: Option<Vec<f64>>,
}

/// Simulate `traj` (one profile per axis, in the order of `axes`) on `backend` and measure
/// it against the trajectory's end point.
pub fn run_trajectory(
    axes: Vec<AxisModel>,
    backend: Backend,
    options: &SimOptions,
    traj: &Trajectory,
    observe: &Observe,
    record: Option<&mut Series>,
) -> Result<Metrics, SimError> {
    if traj.dof() != axes.len() {
        return Err(SimError::AxisCount {
            expected: axes.len(),
            got: traj.dof(),
        });
    }
    let names: Vec<String> = axes.iter().map(|a| a.name.clone()).collect();
    let record = record.map(|rec| {
        let mut ch = channels(&axes);
        if traj.path().is_some() {
            // Distance from the toolhead to the commanded path.
            ch.push(("contour_error".into(), "m".into()));
        }
        *rec = Series::with_channels(ch);
        rec
    });
    let meta: Vec<AxisMeta> = axes.iter().map(AxisMeta::of).collect();
    match backend {
        Backend::Modal => {
            let mut plant = ModalPlant::new(axes, 1.0 / observe.sample_rate_hz)?;
            if let Some(at) = &options.linearise_at_m {
                plant = plant.linearised_at(at.clone())?;
            }
            simulate(&plant, &names, &meta, traj, observe, record)
        }
        Backend::Rapier => {
            let plant = RapierPlant::new(
                axes,
                RapierOptions {
                    max_step_s: options.max_step_s,
                    belt: options.belt,
                },
            )?;
            simulate(&plant, &names, &meta, traj, observe, record)
        }
        #[cfg(feature = "mujoco")]
        Backend::Mujoco => {
            let axes = match options.belt {
                BeltModel::Frozen => freeze_belts(axes, traj)?,
                BeltModel::Varying => axes,
            };
            let config = match options.max_step_s {
                // A forced step: no model-based bound below it.
                Some(h) => settle_sim::mujoco::MujocoConfig {
                    max_step_s: h,
                    max_lambda_h: f64::MAX,
                    ..settle_sim::mujoco::MujocoConfig::default()
                },
                None => settle_sim::mujoco::MujocoConfig::default(),
            };
            let plant = settle_sim::mujoco::MujocoPlant::new(axes, config)?;
            simulate(&plant, &names, &meta, traj, observe, record)
        }
        #[cfg(not(feature = "mujoco"))]
        Backend::Mujoco => Err(SimError::Unsupported {
            backend: "mujoco",
            reason: NO_MUJOCO.into(),
        }),
    }
}

/// Every position-dependent stiffness fixed at its value at the start equilibrium (the
/// frozen belt of the linear model) for backends that otherwise vary it.
#[cfg(feature = "mujoco")]
fn freeze_belts(
    mut axes: Vec<settle_sim::AxisModel>,
    traj: &Trajectory,
) -> Result<Vec<settle_sim::AxisModel>, SimError> {
    for (ax, prof) in axes.iter_mut().zip(traj.axes()) {
        let q0 = settle_sim::rapier::start_equilibrium(ax, prof.start().p)?.0;
        for c in &mut ax.lumped.couplings {
            if let Some(i) = c.stiffness.depends_on() {
                c.stiffness = settle_sim::lumped::Stiffness::Constant(c.stiffness.at(q0[i]));
            }
        }
    }
    Ok(axes)
}
