//! The rapier3d backend (f64): every body of every axis is a rapier rigid body, the
//! couplings and the stepper driver act on them as forces and torques.
//!
//! Bodies: each linear body (carriage, toolhead, frame, or a mode's mass) translates along
//! its axis's world direction (X, Y, Z) with every other degree of freedom locked; each
//! rotor rotates about Z with translations locked, with its inertia as the body's
//! principal inertia. No colliders, no gravity.
//!
//! Couplings as forces: rapier's joints relate the poses of two bodies, but a belt couples
//! a *rotation* (the pulley) to a *translation* (the carriage), and rapier's joint motors
//! are implicit springs that add numerical damping of about `w h / 2` per substep: to keep
//! that under 10 % of a `zeta = 0.05` mode at 250 Hz would take 160,000 substeps per
//! second. So each step the spring-damper forces of the [`Lumped`] couplings (with the
//! belt's stiffness at the current carriage position, `EA/s + EA/(L-s)`) and the driver
//! torque are computed from the bodies' state and applied, and rapier integrates
//! (symplectic Euler: velocities from forces, then positions from the new velocities).
//! That integrator adds no numerical damping to an undamped spring and shifts a mode's
//! frequency by about `-(w h)^2 / 24`; [`STEP_FRACTION`] sets `h` from the fastest mode at
//! the start, and the step shrinks with the square root of the belt's stiffening when the
//! carriage nears a pulley.
//! Couplings are evaluated with the commanded state at the start of each step; steps never
//! straddle a profile breakpoint (the harness splits them). The full stepper driver's
//! magnetic torque is the mean over the step's kick window `[t - h/2, t + h/2]` instead,
//! with the microstep edges resolved in time (`rapier_driver.rs`): sampling it at `t`
//! would move every edge by up to `h/2`, up to 7 % off in residual at the default step.

use rapier3d_f64::prelude::*;
use settle_planner::{Sample, State};

use crate::axis::{AxisModel, DriverMode};
use crate::lumped::{DofKind, Lumped, Node};
pub use crate::numerics::{STEP_FRACTION, start_equilibrium};
use crate::plant::{advance_sample, check_step};
use crate::rapier_driver::ReferenceCache;
use crate::stepper::StepperState;
use crate::{Observation, Plant, SimError};

/// How a position-dependent stiffness (a belt's spans) is treated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum BeltModel {
    /// Evaluated at the carriage's current position every step (the physics).
    #[default]
    Varying,
    /// Frozen at the start position (the linear model the modal reference solves; used to
    /// validate the integration against it).
    Frozen,
}

/// Options of the rapier backend.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RapierOptions {
    /// Largest integration step (s); `None` picks `STEP_FRACTION / w_max` from the model.
    pub max_step_s: Option<f64>,
    /// Belt stiffness treatment.
    pub belt: BeltModel,
}

/// The rapier backend (model: constant).
#[derive(Debug, Clone)]
pub struct RapierPlant {
    axes: Vec<AxisModel>,
    options: RapierOptions,
    /// Where the step is sized ([`RapierPlant::stepped_from`]), when not at each run's
    /// start: one position per axis (m).
    step_at_m: Option<Vec<f64>>,
}

/// One axis inside the rapier world.
#[derive(Debug, Clone)]
struct AxisBodies {
    handles: Vec<RigidBodyHandle>,
    dir: usize,
    /// Coordinates (m, rad; rotor angles unwrapped) and rates, read back after each step.
    q: Vec<f64>,
    qd: Vec<f64>,
    /// Where position-dependent stiffnesses are evaluated when frozen.
    q_frozen: Vec<f64>,
    /// Forces of the last step (N, N m); velocities advanced to the force instant.
    forces: Vec<f64>,
    qd_mid: Vec<f64>,
    base: Sample,
    stepper: Option<StepperState>,
    /// The equilibrium where the step is sized: the stiffness a belt's stiffening is
    /// measured against ([`RapierPlant::stepped_from`]; the start's by default).
    q_step: Vec<f64>,
    /// Full driver: the magnetic torque's impulse over the last step's second half
    /// (N m s) and that half's length (s; 0 before the first step): the first half of the
    /// next step's kick window (`crate::rapier_driver`).
    window: (f64, f64),
    reference: ReferenceCache,
    /// Whether the axis's bodies are in the world: an axis that starts at rest is left out
    /// (it sits exactly at its static equilibrium) until its command moves.
    awake: bool,
}

/// The rapier plant's mutable state: the physics world and each axis's bookkeeping.
pub struct RapierState {
    world: PhysicsWorld,
    axes: Vec<AxisBodies>,
    h_max: f64,
    /// Simulation time (s).
    pub t_s: f64,
}

impl std::fmt::Debug for RapierState {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RapierState")
            .field("t_s", &self.t_s)
            .field("h_max", &self.h_max)
            .field("bodies", &self.world.bodies.len())
            .finish_non_exhaustive()
    }
}

fn unit(dir: usize) -> Vector {
    match dir {
        1 => Vector::Y,
        2 => Vector::Z,
        _ => Vector::X,
    }
}

fn locked_all_but(dir: usize) -> LockedAxes {
    let free = match dir {
        1 => LockedAxes::TRANSLATION_LOCKED_Y,
        2 => LockedAxes::TRANSLATION_LOCKED_Z,
        _ => LockedAxes::TRANSLATION_LOCKED_X,
    };
    (LockedAxes::TRANSLATION_LOCKED | LockedAxes::ROTATION_LOCKED) - free
}

/// The fastest rate (1/s) of an axis at its start: the largest `|lambda|` of its damped
/// linearised dynamics, i.e. the highest natural frequency, or `c / m` of an overdamped
/// coupling if that is larger (an explicit integrator needs `|lambda| h < 2` to be stable
/// and much less to be accurate). In the full driver mode the driver's magnetic spring
/// (with the detent's extra stiffness) and damping are counted.
pub fn fastest_rate(axis: &AxisModel, start_m: f64) -> Result<f64, SimError> {
    let mut lumped: Lumped = axis.lumped.clone();
    let q0 = start_equilibrium(axis, start_m)?.0;
    if let (DriverMode::Full, Some(s)) = (axis.mode, &axis.stepper) {
        lumped.couplings.push(crate::lumped::Coupling {
            name: "driver".into(),
            terms: vec![crate::lumped::Term {
                node: Node::Body(s.rotor),
                gain: 1.0,
            }],
            stiffness: crate::lumped::Stiffness::Constant(s.k_theta() + s.detent_stiffness()),
            damping: s.damping_n_m_s_per_rad,
        });
    }
    let lin = lumped.linearised(&q0);
    let n = lumped.dof();
    let mut a = nalgebra::DMatrix::<f64>::zeros(2 * n, 2 * n);
    for i in 0..n {
        a[(i, n + i)] = 1.0;
        for j in 0..n {
            a[(n + i, j)] = -lin.k[(i, j)] / lin.m[(i, i)];
            a[(n + i, n + j)] = -lin.c[(i, j)] / lin.m[(i, i)];
        }
    }
    let lambda = crate::numerics::eigenvalues(&a).ok_or_else(|| SimError::Unsupported {
        backend: "rapier",
        reason: format!(
            "axis `{}`: the eigenvalues of its linearised model do not converge (parts that differ by hundreds of orders of magnitude: check their units)",
            axis.name
        ),
    })?;
    Ok(lambda.iter().map(|l| l.norm()).fold(0.0, f64::max))
}

/// Insert an axis's bodies into the world at coordinates `q` (m, rad), at rest.
fn insert_bodies(
    world: &mut PhysicsWorld,
    ax: &AxisModel,
    dir: usize,
    q: &[f64],
) -> Vec<RigidBodyHandle> {
    let mut handles = Vec::with_capacity(ax.lumped.dof());
    for (body, &q) in ax.lumped.bodies.iter().zip(q) {
        let builder = RigidBodyBuilder::dynamic()
            .can_sleep(false)
            .gyroscopic_forces_enabled(false)
            .allow_fast_rotation(true);
        let builder = match body.kind {
            DofKind::Linear => builder
                .translation(unit(dir) * q)
                .locked_axes(locked_all_but(dir))
                .additional_mass_properties(MassProperties::new(
                    Vector::ZERO,
                    body.inertia,
                    Vector::splat(1.0),
                )),
            DofKind::Angular => builder
                .rotation(Vector::Z * q)
                .locked_axes(
                    LockedAxes::TRANSLATION_LOCKED
                        | LockedAxes::ROTATION_LOCKED_X
                        | LockedAxes::ROTATION_LOCKED_Y,
                )
                .additional_mass_properties(MassProperties::new(
                    Vector::ZERO,
                    1.0,
                    Vector::splat(body.inertia),
                )),
        };
        handles.push(world.insert_body(builder));
    }
    handles
}

impl RapierPlant {
    /// A plant for these axes (any driver mode).
    pub fn new(axes: Vec<AxisModel>, options: RapierOptions) -> Result<Self, SimError> {
        if axes.is_empty() {
            return Err(SimError::NoModes);
        }
        for a in &axes {
            a.validate()?;
        }
        if let Some(h) = options.max_step_s
            && !(h.is_finite() && h > 0.0)
        {
            return Err(SimError::InvalidStep { dt_s: h });
        }
        Ok(Self {
            axes,
            options,
            step_at_m: None,
        })
    }

    /// The same plant with its integration step sized at these axis positions (m, one
    /// per axis, in the order of the axes) instead of each run's start: the largest step
    /// ([`RapierPlant::max_step_s`]) from the model there, and the shrinking when a belt
    /// stiffens measured against its stiffness there. Runs of one job that start at
    /// different places (a G-code layer range and the whole file) then step alike where
    /// their states agree.
    pub fn stepped_from(mut self, positions_m: Vec<f64>) -> Result<Self, SimError> {
        crate::plant::check_positions(
            self.axes.len(),
            &positions_m,
            "the step's reference position",
        )?;
        self.step_at_m = Some(positions_m);
        Ok(self)
    }

    /// The axes.
    pub fn axis_models(&self) -> &[AxisModel] {
        &self.axes
    }

    /// The largest integration step (s) this plant uses for runs starting at `start`.
    pub fn max_step_s(&self, start: &[State]) -> Result<f64, SimError> {
        if let Some(h) = self.options.max_step_s {
            return Ok(h);
        }
        let mut w = 0.0f64;
        for (a, s) in self.axes.iter().zip(start) {
            w = w.max(fastest_rate(a, s.p)?);
        }
        Ok(if w > 0.0 { STEP_FRACTION / w } else { 1e-3 })
    }

    fn read_back(&self, state: &mut RapierState) {
        for (ax, ab) in self.axes.iter().zip(&mut state.axes) {
            for (i, (body, h)) in ax.lumped.bodies.iter().zip(&ab.handles).enumerate() {
                let rb = &state.world.bodies[*h];
                match body.kind {
                    DofKind::Linear => {
                        ab.q[i] = rb.translation()[ab.dir];
                        ab.qd[i] = rb.linvel()[ab.dir];
                    }
                    DofKind::Angular => {
                        let r = rb.rotation();
                        let wrapped = 2.0 * r.z.atan2(r.w);
                        let d = (wrapped - ab.q[i] + std::f64::consts::PI)
                            .rem_euclid(std::f64::consts::TAU)
                            - std::f64::consts::PI;
                        ab.q[i] += d;
                        ab.qd[i] = rb.angvel().z;
                    }
                }
            }
        }
    }
}

impl Plant for RapierPlant {
    type State = RapierState;

    fn axes(&self) -> usize {
        self.axes.len()
    }

    fn initial_state(&self, start: &[State]) -> Result<RapierState, SimError> {
        if start.len() != self.axes.len() {
            return Err(SimError::AxisCount {
                expected: self.axes.len(),
                got: start.len(),
            });
        }
        // Where the step is sized: the start, or the positions given.
        let step_at: Vec<State> = match &self.step_at_m {
            Some(at) => at.iter().map(|&p| State { p, v: 0.0, a: 0.0 }).collect(),
            None => start.to_vec(),
        };
        let h_max = self.max_step_s(&step_at)?;
        let mut world = PhysicsWorld::new();
        world.gravity = Vector::ZERO;
        world.integration_parameters.dt = h_max;
        world.integration_parameters.num_solver_iterations = 1;
        // No colliders and no constraints: continuous collision detection and the solver's
        // stabilisation pass have nothing to act on, but each costs a pass over the bodies
        // every step (CCD's motion checks were ~16 % of a step). Switching them off leaves
        // every result bit for bit the same.
        world.integration_parameters.max_ccd_substeps = 0;
        world
            .integration_parameters
            .num_internal_stabilization_iterations = 0;
        let mut axes = Vec::with_capacity(self.axes.len());
        for (k, (ax, s)) in self.axes.iter().zip(start).enumerate() {
            let dir = k % 3;
            let (q0, stepper) = start_equilibrium(ax, s.p)?;
            // An axis at rest with its command at rest stays exactly where it is: its bodies
            // join the world when its command first moves (see `step`).
            let awake = s.v != 0.0 || s.a != 0.0;
            let handles = if awake {
                insert_bodies(&mut world, ax, dir, &q0)
            } else {
                Vec::new()
            };
            let n = ax.lumped.dof();
            let q_step = match &self.step_at_m {
                Some(at) => start_equilibrium(ax, at[k])?.0,
                None => q0.clone(),
            };
            axes.push(AxisBodies {
                q_step,
                handles,
                dir,
                q: q0.clone(),
                qd: vec![0.0; n],
                q_frozen: q0,
                forces: vec![0.0; n],
                qd_mid: vec![0.0; n],
                base: Sample {
                    p: s.p,
                    v: s.v,
                    a: s.a,
                    j: 0.0,
                },
                stepper,
                window: (0.0, 0.0),
                reference: ReferenceCache::default(),
                awake,
            });
        }
        let mut st = RapierState {
            world,
            axes,
            h_max,
            t_s: 0.0,
        };
        // A moving start: every body moves with the command (springs relaxed), q' = g v
        // with g the change of the equilibrium per metre of command.
        for ((ax, ab), s) in self.axes.iter().zip(&mut st.axes).zip(start) {
            if s.v == 0.0 {
                continue;
            }
            let dx = 1e-3;
            let q1 = start_equilibrium(ax, s.p + dx)?.0;
            for (i, (body, h)) in ax.lumped.bodies.iter().zip(&ab.handles).enumerate() {
                let v = (q1[i] - ab.q[i]) / dx * s.v;
                let rb = &mut st.world.bodies[*h];
                match body.kind {
                    DofKind::Linear => rb.set_linvel(unit(ab.dir) * v, false),
                    DofKind::Angular => rb.set_angvel(Vector::Z * v, false),
                }
            }
        }
        self.read_back(&mut st);
        Ok(st)
    }

    fn step(&self, state: &mut RapierState, cmd: &[Sample], dt_s: f64) -> Result<(), SimError> {
        check_step(self.axes.len(), cmd, dt_s)?;
        if dt_s == 0.0 {
            return Ok(());
        }
        // A belt stiffer than where the step was sized (the start unless
        // [`RapierPlant::stepped_from`] says; the carriage nearer a pulley) raises the
        // fastest rate by at most the square root of the stiffness ratio (one spring
        // scaled by f >= 1 gives K <= f K0): shrink the step to keep STEP_FRACTION.
        let mut stiffer = 1.0f64;
        if self.options.belt == BeltModel::Varying {
            for (ax, ab) in self.axes.iter().zip(&state.axes) {
                for c in &ax.lumped.couplings {
                    if c.stiffness.depends_on().is_some() {
                        let now = Lumped::stiffness_of(c, &ab.q);
                        let start = Lumped::stiffness_of(c, &ab.q_step);
                        stiffer = stiffer.max(now / start);
                    }
                }
            }
        }
        // Idle axes whose command starts to move join the world (at rest, where they are).
        let mut any_awake = false;
        for ((ax, ab), c) in self.axes.iter().zip(&mut state.axes).zip(cmd) {
            if !ab.awake && (c.p != ab.base.p || c.v != 0.0 || c.a != 0.0 || c.j != 0.0) {
                ab.handles = insert_bodies(&mut state.world, ax, ab.dir, &ab.q);
                ab.awake = true;
            }
            any_awake |= ab.awake;
        }
        if !any_awake {
            for (ab, c) in state.axes.iter_mut().zip(cmd) {
                ab.base = advance_sample(c, dt_s);
            }
            state.t_s += dt_s;
            return Ok(());
        }
        let h_max = state.h_max / stiffer.sqrt();
        let n = (dt_s / h_max * (1.0 - 1e-12)).ceil().max(1.0);
        let h = dt_s / n;
        state.world.integration_parameters.dt = h;
        let varying = self.options.belt == BeltModel::Varying;
        for k in 0..n as usize {
            let tau = k as f64 * h;
            for ((ax, ab), c) in self.axes.iter().zip(&mut state.axes).zip(cmd) {
                if !ab.awake {
                    continue;
                }
                // Symplectic Euler is leapfrog with the velocities at half steps: the
                // bodies' velocities are those of t - h/2. The damping forces need them at
                // t: advance them by h/2 with the last step's accelerations (second order).
                let cn = advance_sample(c, tau);
                let x = ax.command_node_m(cn.p);
                for (i, body) in ax.lumped.bodies.iter().enumerate() {
                    ab.qd_mid[i] = ab.qd[i] + 0.5 * h * ab.forces[i] / body.inertia;
                }
                let stiff_q = if varying { &ab.q } else { &ab.q_frozen };
                ax.lumped
                    .generalised_forces(&ab.q, &ab.qd_mid, x, cn.v, stiff_q, &mut ab.forces);
                if let (DriverMode::Full, Some(sp), Some(ss)) =
                    (ax.mode, &ax.stepper, ab.stepper.as_mut())
                {
                    // The driver torque: the magnetic part as its mean over the kick window
                    // [t - h/2, t + h/2] along the rotor's leapfrog path (the half before t
                    // from the last step, the half after it predicted now), detent and slip
                    // damping at t (crate::rapier_driver).
                    let r = sp.rotor;
                    let (theta, omega) = (ab.q[r], ab.qd[r]);
                    if ab.window.1 == 0.0 {
                        // At rest before the first step.
                        ab.window = (sp.magnetic_torque(ss, theta) * 0.5 * h, 0.5 * h);
                    }
                    let ahead = sp.advance_span(
                        ss,
                        &mut ab.reference,
                        &cn,
                        0.0,
                        0.5 * h,
                        theta,
                        0.0,
                        omega,
                    );
                    let magnetic = (ab.window.0 + ahead) / (ab.window.1 + 0.5 * h);
                    ab.forces[r] += magnetic + sp.passive_torque(theta, ab.qd_mid[r], cn.v);
                }
                for ((body, hd), f) in ax.lumped.bodies.iter().zip(&ab.handles).zip(&ab.forces) {
                    let rb = &mut state.world.bodies[*hd];
                    rb.reset_forces(false);
                    rb.reset_torques(false);
                    match body.kind {
                        DofKind::Linear => rb.add_force(unit(ab.dir) * *f, false),
                        DofKind::Angular => rb.add_torque(Vector::Z * *f, false),
                    }
                }
            }
            state.world.step();
            self.read_back(state);
            for ((ax, ab), c) in self.axes.iter().zip(&mut state.axes).zip(cmd) {
                let (true, Some(sp), Some(ss)) = (ab.awake, &ax.stepper, ab.stepper.as_mut())
                else {
                    continue;
                };
                let r = sp.rotor;
                let x1 = advance_sample(c, tau + h).p;
                match ax.mode {
                    DriverMode::Full => {
                        // The step's second half along the path rapier took (the line
                        // through the end angle with the step's speed), then the load
                        // angle at the step's end.
                        let cn = advance_sample(c, tau);
                        let (theta, omega) = (ab.q[r], ab.qd[r]);
                        let behind = sp.advance_span(
                            ss,
                            &mut ab.reference,
                            &cn,
                            0.5 * h,
                            h,
                            theta,
                            h,
                            omega,
                        );
                        ab.window = (behind, 0.5 * h);
                        sp.track_currents(ss, theta, x1);
                    }
                    _ => sp.track_spring(ss, ab.q[r], ax.command_node_m(x1)),
                }
            }
        }
        for (ab, c) in state.axes.iter_mut().zip(cmd) {
            ab.base = advance_sample(c, dt_s);
            if !ab.q.iter().chain(&ab.qd).all(|x| x.is_finite()) {
                return Err(SimError::NonFinite {
                    t_s: state.t_s + dt_s,
                });
            }
        }
        state.t_s += dt_s;
        Ok(())
    }

    fn observe(&self, state: &RapierState, out: &mut [Observation]) {
        for ((ax, ab), o) in self.axes.iter().zip(&state.axes).zip(out.iter_mut()) {
            let x = ab.base.p;
            let toolhead = ax
                .lumped
                .output
                .iter()
                .map(|t| {
                    t.gain
                        * match t.node {
                            Node::Ground => 0.0,
                            Node::Command => x,
                            Node::Body(i) => ab.q[i],
                        }
                })
                .sum();
            let full = ax.mode == DriverMode::Full;
            *o = Observation {
                commanded_m: x,
                toolhead_m: toolhead,
                carriage_m: ax.carriage.map(|i| ab.q[i]),
                motor_angle_rad: ax.stepper.as_ref().map(|s| ab.q[s.rotor]),
                currents_a: ab.stepper.as_ref().filter(|_| full).map(|s| [s.i_a, s.i_b]),
                load_angle_rad: ab.stepper.as_ref().map(|s| s.load_angle_rad),
                lost_steps: ab.stepper.as_ref().map_or(0, StepperState::lost_steps),
                max_load_angle_rad: ab.stepper.as_ref().map(|s| s.max_load_angle_rad),
            };
        }
    }
}
