//! One machine axis compiled for simulation: a [`Lumped`] model plus how the command
//! enters it. Every backend builds from this.

use crate::lumped::Lumped;
use crate::stepper::Stepper;
use crate::{Mode, SimError};

/// How the commanded position drives the model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum DriverMode {
    /// The full stepper driver: microstep quantisation, current loop with back-EMF and
    /// supply clamp, sinusoidal torque with detent, lost-step detection. The lumped model
    /// has no driver spring; its `actuated` body (the rotor) gets the driver torque.
    Full,
    /// The driver as a linear spring `k_theta = Km I Nr` from the rotor to the
    /// *microstep-quantised* command (step/dir resolution, no current dynamics).
    Spring,
    /// The driver as a linear spring to the continuous command: the linear model the
    /// modal reference solves exactly and every backend is validated against.
    Linear,
}

impl DriverMode {
    /// Every mode, in a fixed order.
    pub const ALL: [DriverMode; 3] = [DriverMode::Full, DriverMode::Spring, DriverMode::Linear];
    /// Names accepted by [`DriverMode::parse`], for error messages.
    pub const ALLOWED: &'static str = "full, spring, linear";

    /// The name as written in scenario files.
    pub fn name(self) -> &'static str {
        match self {
            DriverMode::Full => "full",
            DriverMode::Spring => "spring",
            DriverMode::Linear => "linear",
        }
    }

    /// Parse a name.
    pub fn parse(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|m| m.name() == name)
    }
}

impl std::fmt::Display for DriverMode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// One axis, ready to simulate.
#[derive(Debug, Clone, PartialEq)]
pub struct AxisModel {
    /// Axis name (`x`, `y`, ...).
    pub name: String,
    /// Bodies and couplings. In [`DriverMode::Linear`] and [`DriverMode::Spring`] the
    /// driver is a coupling to [`crate::lumped::Node::Command`]; in [`DriverMode::Full`]
    /// the rotor is `lumped.actuated` and nothing couples to the command.
    pub lumped: Lumped,
    /// How the command enters.
    pub mode: DriverMode,
    /// The motor and driver, when the axis has one (machines described by their modes do
    /// not). Used for the torque in [`DriverMode::Full`], the quantisation in
    /// [`DriverMode::Spring`] and the load angle (lost steps) in every mode.
    pub stepper: Option<Stepper>,
    /// The carriage body, when there is one (for recording its position).
    pub carriage: Option<usize>,
}

impl AxisModel {
    /// An axis described by its modes (the modal form, [`Lumped::from_modes`]).
    pub fn from_modes(name: &str, modes: &[Mode]) -> Result<Self, SimError> {
        Ok(Self {
            name: name.to_string(),
            lumped: Lumped::from_modes(modes)?,
            mode: DriverMode::Linear,
            stepper: None,
            carriage: None,
        })
    }

    /// The command position (m) the lumped model's `Command` node sees for a commanded
    /// position `x_m`: quantised to microsteps in [`DriverMode::Spring`], as is otherwise.
    #[inline]
    pub fn command_node_m(&self, x_m: f64) -> f64 {
        match (&self.stepper, self.mode) {
            (Some(s), DriverMode::Spring) => s.quantise_m(x_m),
            _ => x_m,
        }
    }

    /// Check the model's consistency.
    pub fn validate(&self) -> Result<(), SimError> {
        self.lumped.validate()?;
        let bad = |what: &str| {
            Err(SimError::InvalidModel {
                what: format!("axis `{}`: {what}", self.name),
            })
        };
        match (&self.stepper, self.mode) {
            (None, DriverMode::Full) => return bad("the full driver mode needs a stepper"),
            (Some(s), DriverMode::Full) if self.lumped.actuated != Some(s.rotor) => {
                return bad("in the full driver mode the rotor must be the actuated body");
            }
            (Some(s), _) => {
                s.validate(&self.name)?;
                if s.rotor >= self.lumped.dof() {
                    return bad("the stepper's rotor body does not exist");
                }
            }
            _ => {}
        }
        if self.carriage.is_some_and(|c| c >= self.lumped.dof()) {
            return bad("the carriage body does not exist");
        }
        Ok(())
    }
}
