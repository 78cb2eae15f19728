//! [`MujocoPlant`]: the [`Plant`] trait over one [`MujocoModel`] per axis.
//!
//! The `full` driver on MuJoCo: the MJCF gets the driver's linear part as a tendon from
//! the rotor to the command (stiffness `k_theta = Km I Nr`, the driver damping `c`), so
//! MuJoCo's RK4 integrates the stiff magnetic spring and the slip damping exactly within a
//! step, and the step size is chosen with that spring in the model. The stepper model's
//! remaining torque (currents, sinusoidal law, detent, microsteps: the full torque of
//! [`crate::stepper::Stepper::torque`] minus the tendon's) enters through the MJCF `motor`
//! actuator on the rotor, held over each MuJoCo step at its mean along the predicted rotor
//! path (`theta0 + omega t`) minus the tendon's spring at the predicted midpoint (for a
//! torque linear in the angle that is the midpoint value, and a position force held at
//! the predicted midpoint adds no numerical damping to a spring: the step's transition
//! matrix has determinant 1). One pass of the current loop per step gives both that mean
//! and the currents at the step's end ([`crate::stepper::Stepper::advance_predicted`]);
//! after the step the load angle is tracked from the currents and the rotor's new angle,
//! as on rapier, so lost steps are detected the same way.

use settle_planner::{Sample, State};

use super::{MujocoConfig, MujocoModel, MujocoSim};
use crate::lumped::{Coupling, Node, Stiffness, Term};
use crate::numerics::STEP_FRACTION;
use crate::stepper::{Stepper, StepperState};
use crate::{AxisModel, DriverMode, SimError, advance_sample};

/// The MuJoCo backend as a [`crate::Plant`]: one MuJoCo model per axis, each starting at rest at
/// its commanded start and following the command through the lumped couplings.
///
/// Driver modes: `linear` (a spring to the continuous command), `spring` (a spring to the
/// microstep-quantised command, stepped as a piecewise-constant command) and `full` (the
/// current-loop stepper driver, see the module documentation).
#[derive(Debug)]
pub struct MujocoPlant {
    pub(super) axes: Vec<(AxisModel, MujocoModel)>,
    /// Per axis, the lean path's cap on a long step (s) from the torque held over it (the
    /// full driver's [`MujocoConfig::long_explicit_w_h`]; infinite otherwise).
    pub(super) long_cap_s: Vec<f64>,
}

/// The state of every axis.
#[derive(Debug)]
pub struct MujocoPlantState {
    pub(super) axes: Vec<AxisState>,
}

#[derive(Debug)]
pub(super) struct AxisState {
    pub(super) sim: MujocoSim,
    pub(super) stepper: Option<StepperState>,
    /// The commanded sample (continuous, before quantisation) at the current time.
    pub(super) base: State,
    /// Still at rest where it started, with the command held there all along: stepping
    /// would only keep it there (at its static equilibrium), so steps are skipped until
    /// the command moves (an idle axis of a multi-axis machine costs nothing).
    pub(super) idle: bool,
}

impl MujocoPlant {
    /// Compile each axis into MuJoCo with `config`.
    pub fn new(axes: Vec<AxisModel>, config: MujocoConfig) -> Result<Self, SimError> {
        if axes.is_empty() {
            return Err(SimError::NoModes);
        }
        let mut out = Vec::with_capacity(axes.len());
        let mut long_cap_s = Vec::with_capacity(axes.len());
        for a in axes {
            a.validate()?;
            let (m, cap) = match (a.mode, &a.stepper) {
                (DriverMode::Full, Some(sp)) => (
                    full_driver_model(&a, sp, config)?,
                    config.long_explicit_w_h / explicit_rate(&a, sp),
                ),
                _ => (MujocoModel::new(&a.lumped, config)?, f64::INFINITY),
            };
            out.push((a, m));
            long_cap_s.push(cap);
        }
        Ok(Self {
            axes: out,
            long_cap_s,
        })
    }

    /// The MuJoCo model of axis `i` (MJCF, step size, state access).
    pub fn model(&self, i: usize) -> &MujocoModel {
        &self.axes[i].1
    }

    /// The lean path's cap on a long step of axis `i` (s) from the driver torque held over
    /// it (the full driver's [`MujocoConfig::long_explicit_w_h`]; infinite otherwise). The
    /// long step is the smaller of this and [`MujocoModel::long_step_at`].
    pub fn long_cap_s(&self, i: usize) -> f64 {
        self.long_cap_s[i]
    }
}

/// The MuJoCo model of a `full`-driver axis: its lumped model plus the driver's linear
/// spring-damper as a coupling from the rotor to the command (the rotor stays the actuated
/// body).
///
/// The step: RK4 integrates the MJCF model (the lumped springs and the driver's tendon),
/// so `max_lambda_h` applies to that model's fastest eigenvalue, as for the linear driver.
/// The rest of the driver torque (the detent, the sine law's departure from its tangent)
/// is not in MuJoCo's model: it is held over each step at the predicted mid-step angle,
/// which integrates it like rapier's explicit force, with a frequency error of about
/// `(w_e h)^2 / 24` on the share of stiffness it carries (`w_e^2 = k_e / J`, `J` the rotor
/// inertia). Its stiffness `k_e` is at most `2 k_theta + 4 Nr Td` (the sine's slope
/// departs from the tangent's by at most `2 k_theta`, the detent's slope is at most
/// `4 Nr Td`), so the step is also held to `w_e h <= STEP_FRACTION` (the explicit-force
/// bound of [`crate::numerics::STEP_FRACTION`]: 0.375 % at most on that share). For the
/// printer preset that second bound is 145 us, above the RK4 step. (Integrating the detent
/// as an RK4 spring instead would take a second MuJoCo step per 10 kHz sample on the
/// printer's Y axis for a frequency change below 0.01 %, see `sim/tests/all/mujoco_stepper.rs`.)
fn full_driver_model(
    a: &AxisModel,
    sp: &Stepper,
    config: MujocoConfig,
) -> Result<MujocoModel, SimError> {
    let mut lumped = a.lumped.clone();
    lumped.couplings.push(Coupling {
        name: "driver".into(),
        terms: vec![
            Term {
                node: Node::Body(sp.rotor),
                gain: 1.0,
            },
            Term {
                node: Node::Command,
                gain: -sp.rad_per_m,
            },
        ],
        stiffness: Stiffness::Constant(sp.k_theta()),
        damping: sp.damping_n_m_s_per_rad,
    });
    let model = MujocoModel::new(&lumped, config)?;
    let h_explicit = explicit_step_s(a, sp);
    if model.nominal_step_s() <= h_explicit {
        return Ok(model);
    }
    let config = MujocoConfig {
        max_step_s: config.max_step_s.min(h_explicit),
        ..config
    };
    MujocoModel::new(&lumped, config)
}

/// The longest step (s) for the driver torque MuJoCo does not integrate itself (see
/// [`full_driver_model`]): `STEP_FRACTION / w_e`.
fn explicit_step_s(a: &AxisModel, sp: &Stepper) -> f64 {
    STEP_FRACTION / explicit_rate(a, sp)
}

/// `w_e = sqrt((2 k_theta + 4 Nr Td) / J)` (rad/s): the rate of the driver torque held
/// over a step (see [`full_driver_model`]).
fn explicit_rate(a: &AxisModel, sp: &Stepper) -> f64 {
    let j = a.lumped.bodies[sp.rotor].inertia;
    let k_e = 2.0 * sp.k_theta() + sp.detent_stiffness();
    (k_e / j).sqrt()
}

/// The cubic Hermite interpolant at `t` in `[0, h]` of a coordinate at `x0`, rate `v0` at
/// 0 and `x1`, `v1` at `h`.
#[inline]
pub(super) fn hermite(x0: f64, v0: f64, x1: f64, v1: f64, h: f64, t: f64) -> f64 {
    let s = t / h;
    let r = 1.0 - s;
    (1.0 + 2.0 * s) * r * r * x0 + s * r * r * h * v0 + s * s * (3.0 - 2.0 * s) * x1
        - s * s * r * h * v1
}

/// One MuJoCo step of the full driver over `[tau, tau + h]` after the command sample `c`
/// (constant jerk): the current loop advanced along the predicted rotor path, the rest of
/// the driver torque held at its mean (see the module documentation), then the load angle
/// tracked at the step's end. With `inner` (the lean path's long steps), also its
/// largest value inside the step, at the electrical sub-step boundaries with the rotor
/// angle interpolated (cubic Hermite) between the step's ends.
#[allow(clippy::too_many_arguments)]
#[inline]
pub(super) fn full_step(
    sp: &Stepper,
    model: &MujocoModel,
    sim: &mut MujocoSim,
    ss: &mut StepperState,
    c: &Sample,
    tau: f64,
    h: f64,
    inner: Option<&mut Vec<[f64; 3]>>,
) -> Result<(), SimError> {
    let r = sp.rotor;
    let c0 = advance_sample(c, tau);
    let (th0, w0) = (sim.q()[r], sim.qd()[r]);
    // The stepper torque beyond the tendon's linear spring: its mean over the step from
    // the one-pass advance that carries the currents over it, minus the tendon's spring at
    // the predicted midpoint (the damping terms are equal in both and cancel).
    let x_m = advance_sample(c, tau + 0.5 * h).p;
    let mid = match inner {
        Some(buf) => {
            let mid = sp.advance_predicted_inner_angles(ss, th0, w0, &c0, h, buf);
            let rest = mid.torque_n_m + sp.k_theta() * (mid.theta_rad - sp.rad_per_m * x_m);
            model.set_drive(sim, rest)?;
            model.step(sim, &c0, h)?;
            let (th1, w1) = (sim.q()[r], sim.qd()[r]);
            sp.track_peak(ss, buf, |t| hermite(th0, w0, th1, w1, h, t));
            sp.track_currents(ss, th1, advance_sample(c, tau + h).p);
            return Ok(());
        }
        None => sp.advance_predicted(ss, th0, w0, &c0, h),
    };
    let rest = mid.torque_n_m + sp.k_theta() * (mid.theta_rad - sp.rad_per_m * x_m);
    model.set_drive(sim, rest)?;
    model.step(sim, &c0, h)?;
    sp.track_currents(ss, sim.q()[r], advance_sample(c, tau + h).p);
    Ok(())
}
