//! [`MujocoPlant`]: the [`Plant`] trait over [`MujocoModel`].

use settle_planner::{Sample, State};

use super::{MujocoConfig, MujocoModel, MujocoSim};
use crate::lumped::Lumped;
use crate::{Observation, Plant, SimError};

/// The MuJoCo backend as a [`Plant`]: starts at rest at the commanded start, follows the
/// command through the lumped couplings; a driver force (if the model has an actuated
/// body) is set through [`MujocoPlant::model`] and [`MujocoModel::set_drive`].
#[derive(Debug)]
pub struct MujocoPlant {
    model: MujocoModel,
}

impl MujocoPlant {
    /// Compile `lumped` into MuJoCo with `config`.
    pub fn new(lumped: &Lumped, config: MujocoConfig) -> Result<Self, SimError> {
        Ok(Self {
            model: MujocoModel::new(lumped, config)?,
        })
    }

    /// The underlying model (MJCF, step size, driver input, state access).
    pub fn model(&self) -> &MujocoModel {
        &self.model
    }
}

impl Plant for MujocoPlant {
    type State = MujocoSim;

    fn initial_state(&self, start: &State) -> MujocoSim {
        self.model.state_at_rest(start)
    }

    fn step(&self, state: &mut MujocoSim, cmd: &Sample, dt_s: f64) -> Result<(), SimError> {
        self.model.advance(state, cmd, dt_s).map(|_| ())
    }

    fn observe(&self, state: &MujocoSim) -> Observation {
        Observation {
            commanded_m: state.command().p,
            toolhead_m: self.model.toolhead_m(state),
        }
    }
}
