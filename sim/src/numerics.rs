//! Numerics shared by the simulation backends (none of them imports another): the step
//! bound for explicitly integrated forces, and the configuration an axis starts from.

use crate::SimError;
use crate::axis::{AxisModel, DriverMode};
use crate::stepper::StepperState;

/// Step size against the fastest mode of an explicitly integrated force:
/// `h <= STEP_FRACTION / w_max` (rapier: every coupling force, `w_max` from
/// [`crate::rapier::fastest_rate`]; MuJoCo: the driver torque it holds over a step).
/// Symplectic Euler shifts a mode of angular frequency `w` by `-(w h)^2 / 24`: at most
/// 0.375 % for the highest mode (a rotor or mount mode nobody settles on), so every mode
/// stays within the 0.5 % frequency threshold, and `0.375 % (w / w_max)^2` for the others,
/// e.g. 0.006 % for a 43 Hz belt mode under a 345 Hz mount mode. The damping terms use
/// velocities advanced to the force instant (second order), so the damping error is of
/// the same order. `settle validate` and the tests measure both. (At 10 kHz sampling the
/// printer preset needs no substeps: its `h_max` is 0.14 ms.)
pub const STEP_FRACTION: f64 = 0.3;

/// The start configuration of an axis for a command at rest at `start_m`: body
/// coordinates and the driver state (full mode: the rotor where magnetic torque balances
/// the detent; otherwise the linear spring's equilibrium).
pub fn start_equilibrium(
    axis: &AxisModel,
    start_m: f64,
) -> Result<(Vec<f64>, Option<StepperState>), SimError> {
    match (axis.mode, &axis.stepper) {
        (DriverMode::Full, Some(s)) => {
            let (st, theta) = s.at_rest(start_m);
            let q = axis.lumped.equilibrium(start_m, Some((s.rotor, theta)))?;
            Ok((q, Some(st)))
        }
        (_, stepper) => {
            let x = axis.command_node_m(start_m);
            let q = axis.lumped.equilibrium(x, None)?;
            let st = stepper.as_ref().map(|s| {
                let mut st = s.at_rest(start_m).0;
                s.track_spring(&mut st, q[s.rotor], x);
                st.max_load_angle_rad = st.load_angle_rad.abs();
                st
            });
            Ok((q, st))
        }
    }
}

/// Most QR iterations [`eigenvalues`] allows per row of the matrix: a well-posed axis
/// converges in a few per eigenvalue.
const SCHUR_ITERATIONS_PER_ROW: usize = 1000;

/// The eigenvalues of `a` (nalgebra's real Schur form, as `complex_eigenvalues` computes
/// them), or `None` when its QR iteration does not converge: nalgebra's
/// `complex_eigenvalues` iterates without a bound and never returns on a model whose
/// parts differ by hundreds of orders of magnitude (a mount stiffness of 1e308 N/m).
pub fn eigenvalues(a: &nalgebra::DMatrix<f64>) -> Option<Vec<nalgebra::Complex<f64>>> {
    let n = a.nrows();
    let max_niter = SCHUR_ITERATIONS_PER_ROW * n.max(1);
    nalgebra::linalg::Schur::try_new(a.clone(), f64::EPSILON, max_niter)
        .map(|s| s.complex_eigenvalues().iter().copied().collect())
}
