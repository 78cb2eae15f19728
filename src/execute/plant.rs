//! The backends: the one constructor from a backend and a machine's axes to a plant, with
//! the [`SimOptions`] every backend honours. The plant types differ, so what runs on the
//! plant is a [`Simulation`], generic over them.

use settle_sim::{AxisModel, BeltModel, ModalPlant, Plant, RapierOptions, RapierPlant, SimError};

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
    /// per axis (m, in the order of the axes); `None`: each axis's start. The study
    /// chooses it ([`crate::studies::Planned::linearise_at_m`]), `settle gcode` takes the
    /// print's centre; the nonlinear backends follow the stiffness along the travel and
    /// ignore it.
    pub linearise_at_m: Option<Vec<f64>>,
    /// Where rapier sizes its integration step: one position per axis (m, in the order
    /// of the axes); `None`: each run's start. A G-code job gives its start (the origin)
    /// for the whole file and any layer range alike, so that both step alike.
    pub step_at_m: Option<Vec<f64>>,
}

/// What runs on a plant (usually a [`crate::execute::driver::Driver`] and its sink).
pub trait Simulation {
    /// What it gives.
    type Output;

    /// Run on `plant`.
    fn run<P: Plant>(self, plant: &P) -> Self::Output;
}

/// Build the plant of `backend` for `axes`, sampled at `sample_rate_hz` (the modal
/// backend's nominal step), and run `sim` on it. `start_m` is each axis's start position
/// (m), where MuJoCo freezes a belt's stiffness for [`BeltModel::Frozen`].
pub fn with_plant<S: Simulation>(
    backend: Backend,
    axes: Vec<AxisModel>,
    options: &SimOptions,
    sample_rate_hz: f64,
    start_m: &[f64],
    sim: S,
) -> Result<S::Output, SimError> {
    match backend {
        Backend::Modal => {
            let mut plant = ModalPlant::new(axes, 1.0 / sample_rate_hz)?;
            if let Some(at) = &options.linearise_at_m {
                plant = plant.linearised_at(at.clone())?;
            }
            Ok(sim.run(&plant))
        }
        Backend::Rapier => {
            let mut plant = RapierPlant::new(
                axes,
                RapierOptions {
                    max_step_s: options.max_step_s,
                    belt: options.belt,
                },
            )?;
            if let Some(at) = &options.step_at_m {
                plant = plant.stepped_from(at.clone())?;
            }
            Ok(sim.run(&plant))
        }
        #[cfg(feature = "mujoco")]
        Backend::Mujoco => {
            let axes = match options.belt {
                BeltModel::Frozen => freeze_belts(axes, start_m)?,
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
            Ok(sim.run(&plant))
        }
        #[cfg(not(feature = "mujoco"))]
        Backend::Mujoco => {
            let _ = start_m;
            Err(SimError::Unsupported {
                backend: "mujoco",
                reason: NO_MUJOCO.into(),
            })
        }
    }
}

/// Every position-dependent stiffness fixed at its value at the start equilibrium (the
/// frozen belt of the linear model) for backends that otherwise vary it.
#[cfg(feature = "mujoco")]
fn freeze_belts(mut axes: Vec<AxisModel>, start_m: &[f64]) -> Result<Vec<AxisModel>, SimError> {
    for (ax, &p) in axes.iter_mut().zip(start_m) {
        let q0 = settle_sim::rapier::start_equilibrium(ax, p)?.0;
        for c in &mut ax.lumped.couplings {
            if let Some(i) = c.stiffness.depends_on() {
                c.stiffness = settle_sim::lumped::Stiffness::Constant(c.stiffness.at(q0[i]));
            }
        }
    }
    Ok(axes)
}
