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
use crate::rapier::start_equilibrium;
use crate::stepper::{Stepper, StepperState};
use crate::{AxisModel, DriverMode, Observation, Plant, SimError, advance_sample, check_step};

/// The MuJoCo backend as a [`Plant`]: one MuJoCo model per axis, each starting at rest at
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
/// `4 Nr Td`), so the step is also held to `w_e h <= STEP_FRACTION` (rapier's bound:
/// 0.375 % at most on that share). For the printer preset that second bound is 145 us,
/// above the RK4 step; the detent no longer shortens the step as an RK4 spring (that
/// took a second MuJoCo step per 10 kHz sample on the printer's Y axis for a frequency
/// change below 0.01 %, see `sim/tests/mujoco_stepper.rs`).
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
    crate::rapier::STEP_FRACTION / explicit_rate(a, sp)
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

impl Plant for MujocoPlant {
    type State = MujocoPlantState;

    fn axes(&self) -> usize {
        self.axes.len()
    }

    fn initial_state(&self, start: &[State]) -> Result<MujocoPlantState, SimError> {
        if start.len() != self.axes.len() {
            return Err(SimError::AxisCount {
                expected: self.axes.len(),
                got: start.len(),
            });
        }
        let mut axes = Vec::with_capacity(start.len());
        for ((ax, model), s) in self.axes.iter().zip(start) {
            if ax.mode == DriverMode::Full {
                // At rest where the magnetic torque balances the detent and the couplings
                // (rapier starts from the same configuration), moving rigidly with `s.v`.
                let (q, stepper) = start_equilibrium(ax, s.p)?;
                let qd = if s.v == 0.0 {
                    vec![0.0; q.len()]
                } else {
                    let dx = 1e-3;
                    let q1 = start_equilibrium(ax, s.p + dx)?.0;
                    q.iter().zip(&q1).map(|(a, b)| (b - a) / dx * s.v).collect()
                };
                axes.push(AxisState {
                    sim: model.state(&q, &qd, s)?,
                    stepper,
                    base: *s,
                    idle: s.v == 0.0 && s.a == 0.0,
                });
                continue;
            }
            let x = ax.command_node_m(s.p);
            let node = State { p: x, ..*s };
            let sim = model.state_at_rest(&node);
            let stepper = ax.stepper.as_ref().map(|sp| {
                let mut st = sp.at_rest(s.p).0;
                sp.track_spring(&mut st, sim.q()[sp.rotor], x);
                st.max_load_angle_rad = st.load_angle_rad.abs();
                st
            });
            axes.push(AxisState {
                sim,
                stepper,
                base: *s,
                idle: s.v == 0.0 && s.a == 0.0,
            });
        }
        Ok(MujocoPlantState { axes })
    }

    fn step(
        &self,
        state: &mut MujocoPlantState,
        cmd: &[Sample],
        dt_s: f64,
    ) -> Result<(), SimError> {
        check_step(self.axes.len(), cmd, dt_s)?;
        if dt_s == 0.0 {
            return Ok(());
        }
        for ((ax, model), (st, c)) in self.axes.iter().zip(state.axes.iter_mut().zip(cmd)) {
            if st.idle {
                if c.p == st.base.p && c.v == 0.0 && c.a == 0.0 && c.j == 0.0 {
                    continue;
                }
                st.idle = false;
            }
            match (ax.mode, &ax.stepper) {
                (DriverMode::Full, Some(sp)) => {
                    let ss = st.stepper.as_mut().ok_or_else(|| SimError::InvalidModel {
                        what: format!("axis `{}`: the full driver has no state", ax.name),
                    })?;
                    let h_max = model.step_at(&st.sim);
                    let n = ((dt_s / h_max) * (1.0 - 1e-12)).ceil().max(1.0) as usize;
                    let h = dt_s / n as f64;
                    for k in 0..n {
                        full_step(sp, model, &mut st.sim, ss, c, h * k as f64, h, None)?;
                    }
                }
                (DriverMode::Spring, Some(sp)) => {
                    // The quantised command is piecewise constant: step in equal pieces no
                    // longer than the model's step, holding the microstep of each piece's
                    // start.
                    let h_max = model.step_at(&st.sim);
                    let n = ((dt_s / h_max) * (1.0 - 1e-12)).ceil().max(1.0) as usize;
                    let h = dt_s / n as f64;
                    for k in 0..n {
                        let x = sp.quantise_m(advance_sample(c, h * k as f64).p);
                        let hold = Sample {
                            p: x,
                            ..Sample::default()
                        };
                        model.step(&mut st.sim, &hold, h)?;
                        if let Some(ss) = st.stepper.as_mut() {
                            let x1 = sp.quantise_m(advance_sample(c, h * (k + 1) as f64).p);
                            sp.track_spring(ss, st.sim.q()[sp.rotor], x1);
                        }
                    }
                }
                _ => {
                    model.advance(&mut st.sim, c, dt_s)?;
                    if let (Some(sp), Some(ss)) = (&ax.stepper, st.stepper.as_mut()) {
                        let x1 = advance_sample(c, dt_s).p;
                        sp.track_spring(ss, st.sim.q()[sp.rotor], x1);
                    }
                }
            }
            let e = advance_sample(c, dt_s);
            st.base = State {
                p: e.p,
                v: e.v,
                a: e.a,
            };
        }
        Ok(())
    }

    fn positions(
        &self,
        state: &MujocoPlantState,
        commanded_m: &mut [f64],
        toolhead_m: &mut [f64],
    ) -> bool {
        let mut finite = true;
        for (i, ((ax, _), st)) in self.axes.iter().zip(&state.axes).enumerate() {
            let q = st.sim.q();
            commanded_m[i] = st.base.p;
            toolhead_m[i] = ax.lumped.toolhead_m(q, ax.command_node_m(st.base.p));
            finite &= st.base.p.is_finite()
                && toolhead_m[i].is_finite()
                && q.iter().all(|v| v.is_finite());
        }
        finite
    }

    fn step_samples(
        &self,
        state: &mut MujocoPlantState,
        cmds: &[Sample],
        dt_s: f64,
        blowup_m: f64,
        commanded_m: &mut [f64],
        toolhead_m: &mut [f64],
    ) -> Result<Option<usize>, (usize, SimError)> {
        super::lean::step_samples(self, state, cmds, dt_s, blowup_m, commanded_m, toolhead_m)
    }

    fn observe(&self, state: &MujocoPlantState, out: &mut [Observation]) {
        for ((ax, _), (st, o)) in self.axes.iter().zip(state.axes.iter().zip(out.iter_mut())) {
            let x_node = ax.command_node_m(st.base.p);
            let q = st.sim.q();
            *o = Observation {
                commanded_m: st.base.p,
                toolhead_m: ax.lumped.toolhead_m(q, x_node),
                carriage_m: ax.carriage.map(|i| q[i]),
                motor_angle_rad: ax.stepper.as_ref().map(|s| q[s.rotor]),
                currents_a: st
                    .stepper
                    .as_ref()
                    .filter(|_| ax.mode == DriverMode::Full)
                    .map(|s| [s.i_a, s.i_b]),
                load_angle_rad: st.stepper.as_ref().map(|s| s.load_angle_rad),
                lost_steps: st.stepper.as_ref().map_or(0, StepperState::lost_steps),
                max_load_angle_rad: st.stepper.as_ref().map(|s| s.max_load_angle_rad),
            };
        }
    }
}
