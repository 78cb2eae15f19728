//! A machine in either form, the one type that carries a machine from its input (a machine
//! file, a scenario's `[machine]`, a preset, `--machine`) to the plant: its parts
//! (settle-sim's [`Machine`]) or its modes per axis ([`crate::input::modes`]).
//! [`MachineForm::axes`] is where either becomes the axes a backend simulates.

use settle_sim::machine::Machine;
use settle_sim::{AxisModel, DriverMode, Mode, SimError};

use crate::input::modes::{AxisModes, ModeSpec};

/// A machine as a file or scenario describes it.
#[derive(Debug, Clone, PartialEq)]
pub enum MachineForm {
    /// Its parts (motor, driver, transmission, masses), compiled by settle-sim.
    Physical(Machine),
    /// Its modes per axis, ordered by axis name.
    Modes(Vec<AxisModes>),
}

impl MachineForm {
    /// The names of its axes, in order.
    pub fn axis_names(&self) -> Vec<String> {
        match self {
            MachineForm::Physical(m) => m.axes.iter().map(|a| a.name.clone()).collect(),
            MachineForm::Modes(axes) => axes.iter().map(|a| a.axis.clone()).collect(),
        }
    }

    /// Whether it has an axis called `name`.
    pub fn has_axis(&self, name: &str) -> bool {
        match self {
            MachineForm::Physical(m) => m.axis(name).is_some(),
            MachineForm::Modes(axes) => axes.iter().any(|a| a.axis == name),
        }
    }

    /// The physical machine, `None` for the modes form.
    pub fn physical(&self) -> Option<&Machine> {
        match self {
            MachineForm::Physical(m) => Some(m),
            MachineForm::Modes(_) => None,
        }
    }

    /// The modes per axis (empty for a physical machine).
    pub fn modes(&self) -> &[AxisModes] {
        match self {
            MachineForm::Physical(_) => &[],
            MachineForm::Modes(axes) => axes,
        }
    }

    /// The modes of `axis` as written (empty when it has none or the machine is
    /// physical).
    pub fn modes_of(&self, axis: &str) -> &[ModeSpec] {
        crate::input::modes::modes_of(self.modes(), axis).unwrap_or_default()
    }

    /// The modes of `axis` as settle-sim's modes.
    pub fn sim_modes(&self, axis: &str) -> Result<Vec<Mode>, SimError> {
        self.modes_of(axis)
            .iter()
            .map(|m| Mode::new(m.frequency_hz, m.damping_ratio, m.weight))
            .collect()
    }

    /// The axes the backends simulate: the physical machine compiled for `driver`, or one
    /// axis per axis of the modes form (which has no driver: `driver` does not change it).
    pub fn axes(&self, driver: DriverMode) -> Result<Vec<AxisModel>, SimError> {
        match self {
            MachineForm::Physical(m) => m.compile(driver),
            MachineForm::Modes(axes) => axes
                .iter()
                .map(|a| AxisModel::from_modes(&a.axis, &self.sim_modes(&a.axis)?))
                .collect(),
        }
    }
}
