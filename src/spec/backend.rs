//! The simulation backends by name (the engines themselves are `settle_sim`'s plants; see
//! `crate::execute`).

/// A simulation backend.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Backend {
    /// The exact discretisation of the linear model (linear driver only).
    Modal,
    /// rapier3d (f64): rigid bodies with the couplings and the driver as forces. Needs
    /// nothing installed, so it is the default.
    #[default]
    Rapier,
    /// MuJoCo 3.17 through mujoco-rs (needs the MuJoCo library).
    Mujoco,
}

/// The message for `--backend mujoco` in a build without MuJoCo.
pub const NO_MUJOCO: &str =
    "not built with MuJoCo; run scripts/setup-mujoco.sh and build with --features mujoco";

impl Backend {
    /// Every backend, in a fixed order.
    pub const ALL: [Backend; 3] = [Backend::Modal, Backend::Rapier, Backend::Mujoco];
    /// Names accepted by [`Backend::parse`].
    pub const ALLOWED: &'static str = "modal, rapier, mujoco";

    /// The name as written on the command line and in tables.
    pub fn name(self) -> &'static str {
        match self {
            Backend::Modal => "modal",
            Backend::Rapier => "rapier",
            Backend::Mujoco => "mujoco",
        }
    }

    /// Parse a name.
    pub fn parse(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|b| b.name() == name)
    }

    /// Whether this build can run the backend.
    pub fn available(self) -> bool {
        cfg!(feature = "mujoco") || !matches!(self, Backend::Mujoco)
    }
}

impl std::fmt::Display for Backend {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}
