//! Whether this build has the MuJoCo backend, and how to get it (compiled with and
//! without the `mujoco` feature, so a caller can give a clear error either way).

use crate::SimError;

/// True when settle-sim was built with the `mujoco` feature (the `mujoco` module exists).
pub const BUILT: bool = cfg!(feature = "mujoco");

/// What to do when the MuJoCo backend is asked for but not built in.
pub const HOWTO: &str = "the MuJoCo backend is not built into this settle: run \
    scripts/setup-mujoco.sh (fetches libmujoco 3.17.0 from the `mujoco` PyPI wheel into \
    .deps/mujoco/), then build with `cargo build --release --features mujoco`";

/// `Ok` when the MuJoCo backend is built in, otherwise an error that says how to get it.
pub fn require() -> Result<(), SimError> {
    if BUILT {
        Ok(())
    } else {
        Err(SimError::Mujoco { what: HOWTO.into() })
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn require_matches_the_feature() {
        let r = super::require();
        assert_eq!(r.is_ok(), super::BUILT);
        if let Err(e) = r {
            assert!(e.to_string().contains("scripts/setup-mujoco.sh"), "{e}");
        }
    }
}
