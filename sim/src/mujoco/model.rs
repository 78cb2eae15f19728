//! The MuJoCo model of a [`Lumped`] axis and its stepper: build, set the command, apply
//! the driver force, step, read the state. Independent of the [`crate::Plant`] trait (the
//! adapter in `plant.rs` is a thin layer over it).

use mujoco_rs::prelude::{MjData, MjModel, MjtWarning};
use nalgebra::{DMatrix, DVector};
use settle_planner::{Sample, State};

use super::mjcf::{self, Integrator, Layout};
use crate::SimError;
use crate::lumped::Lumped;

/// How a [`MujocoModel`] integrates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MujocoConfig {
    /// Largest `|lambda| h` allowed, with `lambda` the fastest eigenvalue of the linearised
    /// model (rad/s) and `h` the MuJoCo time step (s). 0.2 keeps RK4's frequency error near
    /// `0.2^4/120 = 1.3e-5` and its numerical damping ratio near `0.2^5/144 = 2.2e-6` on
    /// the stiffest mode (the tests measure both): far below the 0.5% frequency and the
    /// physical damping (zeta >= 0.02) budgets, at about 30 steps per period of that mode.
    pub max_lambda_h: f64,
    /// Upper bound on the time step (s) whatever the model: 1 ms.
    pub max_step_s: f64,
    /// MuJoCo's integrator (RK4 unless comparing integrators).
    pub integrator: Integrator,
    /// Largest `|lambda| h` for the longer steps of the lean path
    /// ([`crate::Plant::step_samples`]: several samples per MuJoCo step, the samples in
    /// between interpolated). Never below `max_lambda_h`. See [`LONG_LAMBDA_H`].
    pub long_lambda_h: f64,
    /// The full driver's bound on the torque held over a long step (the detent and the
    /// sine law's departure from its tangent, which MuJoCo does not integrate itself):
    /// `w_e h <= long_explicit_w_h` on the lean path. See [`LONG_EXPLICIT_W_H`].
    pub long_explicit_w_h: f64,
}

/// Default [`MujocoConfig::long_lambda_h`].
pub const LONG_LAMBDA_H: f64 = 0.5;
/// Default [`MujocoConfig::long_explicit_w_h`].
pub const LONG_EXPLICIT_W_H: f64 = 0.6;

impl Default for MujocoConfig {
    fn default() -> Self {
        Self {
            max_lambda_h: 0.2,
            max_step_s: 1e-3,
            integrator: Integrator::Rk4,
            long_lambda_h: LONG_LAMBDA_H,
            long_explicit_w_h: LONG_EXPLICIT_W_H,
        }
    }
}

/// A lumped axis compiled into MuJoCo (constant: the model; see [`MujocoSim`] for the state).
pub struct MujocoModel {
    lumped: Lumped,
    mjcf: String,
    layout: Layout,
    template: MjModel,
    config: MujocoConfig,
    /// Step size (s) at the reference stiffnesses (position-dependent ones at q = 0).
    step_s: f64,
    /// The lean path's longer step (s) at the reference stiffnesses
    /// ([`MujocoConfig::long_lambda_h`]).
    long_step_s: f64,
    /// Whether the stiffness matrix is singular (a free rigid-body mode, e.g. a rotor held
    /// only by the driver force).
    singular: bool,
    /// Fastest eigenvalue magnitude of the linearised model at q = 0 (rad/s).
    lambda_max: f64,
}

impl std::fmt::Debug for MujocoModel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MujocoModel")
            .field("lumped", &self.lumped)
            .field("config", &self.config)
            .field("step_s", &self.step_s)
            .field("long_step_s", &self.long_step_s)
            .field("lambda_max", &self.lambda_max)
            .finish_non_exhaustive()
    }
}

/// The mutable state of a MuJoCo run: MuJoCo's `mjData` (which owns a copy of the compiled
/// model), the commanded state and the driver force.
#[derive(Debug)]
pub struct MujocoSim {
    data: MjData<Box<MjModel>>,
    dof: usize,
    drive: Option<usize>,
    command: State,
    time_s: f64,
    steps: u64,
}

fn mujoco_err(what: impl Into<String>) -> SimError {
    SimError::Mujoco { what: what.into() }
}

impl MujocoModel {
    /// Compile `lumped` into MuJoCo. Fails on an invalid model or if MuJoCo rejects the
    /// generated MJCF.
    pub fn new(lumped: &Lumped, config: MujocoConfig) -> Result<Self, SimError> {
        lumped.validate()?;
        if !(config.max_lambda_h.is_finite() && config.max_lambda_h > 0.0) {
            return Err(SimError::InvalidModel {
                what: format!(
                    "max_lambda_h must be finite and > 0, got {}",
                    config.max_lambda_h
                ),
            });
        }
        for (what, v) in [
            ("long_lambda_h", config.long_lambda_h),
            ("long_explicit_w_h", config.long_explicit_w_h),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(SimError::InvalidModel {
                    what: format!("{what} must be finite and > 0, got {v}"),
                });
            }
        }
        if !(config.max_step_s.is_finite() && config.max_step_s > 0.0) {
            return Err(SimError::InvalidStep {
                dt_s: config.max_step_s,
            });
        }
        let n = lumped.dof();
        let lin = lumped.linearised(&vec![0.0; n]);
        let m_inv_sqrt =
            DVector::from_iterator(n, lumped.bodies.iter().map(|b| b.inertia.sqrt().recip()));
        // Mass-normalised stiffness: its eigenvalues are the undamped w^2.
        let kn = DMatrix::from_fn(n, n, |i, j| lin.k[(i, j)] * m_inv_sqrt[i] * m_inv_sqrt[j]);
        let w2 = kn.symmetric_eigenvalues();
        let w2_max = w2.max().max(0.0);
        let singular = w2.min() <= 1e-12 * w2_max;
        // First-order form x' = A x, x = [q, q']: its spectral radius bounds |lambda|.
        let mut a = DMatrix::zeros(2 * n, 2 * n);
        for i in 0..n {
            a[(i, n + i)] = 1.0;
            for j in 0..n {
                let mi = lumped.bodies[i].inertia;
                a[(n + i, j)] = -lin.k[(i, j)] / mi;
                a[(n + i, n + j)] = -lin.c[(i, j)] / mi;
            }
        }
        let lambda_max = crate::numerics::eigenvalues(&a)
            .ok_or_else(|| SimError::InvalidModel {
                what: "the eigenvalues of the linearised model do not converge (parts that differ by hundreds of orders of magnitude: check their units)".into(),
            })?
            .iter()
            .map(|l| l.norm())
            .fold(0.0f64, f64::max);
        let step_s = if lambda_max > 0.0 {
            (config.max_lambda_h / lambda_max).min(config.max_step_s)
        } else {
            config.max_step_s
        };
        let long_step_s = if lambda_max > 0.0 {
            let lambda_bound = config.long_lambda_h.max(config.max_lambda_h) / lambda_max;
            let weighted = if singular {
                None
            } else {
                weighted_rate(lumped, &kn, &m_inv_sqrt)
            };
            // Without the weights (a free rigid-body mode): the per-sample bound.
            let share_bound = weighted.map_or(config.max_lambda_h / lambda_max, |w| {
                config.max_lambda_h / w
            });
            lambda_bound
                .min(share_bound.max(config.max_lambda_h / lambda_max))
                .min(config.max_step_s)
        } else {
            config.max_step_s
        };
        let (mjcf, layout) = mjcf::generate(lumped, step_s, config.integrator);
        let template = MjModel::from_xml_string(&mjcf)
            .map_err(|e| mujoco_err(format!("MuJoCo rejected the generated MJCF: {e}")))?;
        Ok(Self {
            lumped: lumped.clone(),
            mjcf,
            layout,
            template,
            config,
            step_s,
            long_step_s,
            singular,
            lambda_max,
        })
    }

    /// The generated MJCF (for inspection, or to load into MuJoCo's own viewer).
    pub fn mjcf(&self) -> &str {
        &self.mjcf
    }

    /// The lumped model this was built from.
    pub fn lumped(&self) -> &Lumped {
        &self.lumped
    }

    /// The configuration.
    pub fn config(&self) -> &MujocoConfig {
        &self.config
    }

    /// The time step (s) used at the reference stiffness (position-dependent stiffnesses at
    /// coordinate 0); stiffer positions use proportionally smaller steps (see
    /// [`MujocoModel::step_at`]).
    pub fn nominal_step_s(&self) -> f64 {
        self.step_s
    }

    /// Fastest eigenvalue magnitude |lambda| (rad/s) of the linearised model at q = 0.
    pub fn lambda_max(&self) -> f64 {
        self.lambda_max
    }

    /// The time step (s) for the state `sim`: the nominal step shrunk by
    /// `sqrt(k_now / k_ref)` for the stiffest position-dependent coupling relative to its
    /// reference (a stiffness scaled by `alpha >= 1` raises no eigenvalue `w^2` by more than
    /// `alpha`, so `|lambda| h` stays within the budget).
    pub fn step_at(&self, sim: &MujocoSim) -> f64 {
        self.step_s / self.stiffening(sim).sqrt()
    }

    /// The lean path's longer step (s) at the reference stiffnesses
    /// ([`MujocoConfig::long_lambda_h`]).
    pub fn nominal_long_step_s(&self) -> f64 {
        self.long_step_s
    }

    /// The lean path's longer step (s) for the state `sim`, shrunk like
    /// [`MujocoModel::step_at`].
    pub fn long_step_at(&self, sim: &MujocoSim) -> f64 {
        self.long_step_s / self.stiffening(sim).sqrt()
    }

    /// The largest ratio `k_now / k_ref` over the position-dependent couplings (>= 1).
    fn stiffening(&self, sim: &MujocoSim) -> f64 {
        let q = sim.q();
        self.layout
            .variable
            .iter()
            .map(|(_, s, k0)| s.at(s.depends_on().map_or(0.0, |i| q[i])) / k0)
            .fold(1.0f64, f64::max)
    }

    /// Coordinates (m, rad) at rest with the command held at `x_cmd` (m): the static
    /// equilibrium `K q = bk x_cmd` when the stiffness matrix is regular; otherwise (a free
    /// rigid-body mode, e.g. a rotor positioned by a driver force) the coordinates that
    /// leave every coupling unstretched with the toolhead at `x_cmd`, in the least-squares
    /// sense.
    pub fn rest_coordinates(&self, x_cmd: f64) -> Vec<f64> {
        let n = self.lumped.dof();
        let mut q = vec![0.0; n];
        // Position-dependent stiffness: a few fixed-point passes (exact in one pass when
        // every coupling can be unstretched, which is the case for a chain).
        for _ in 0..3 {
            q = self.rest_with_stiffness_at(&q, x_cmd);
        }
        q
    }

    fn rest_with_stiffness_at(&self, q_k: &[f64], x: f64) -> Vec<f64> {
        let n = self.lumped.dof();
        let lin = self.lumped.linearised(q_k);
        if !self.singular
            && let Some(chol) = lin.k.clone().cholesky()
        {
            return chol.solve(&(&lin.bk * x)).iter().copied().collect();
        }
        // Rows: sqrt(k) * extension = 0 for every coupling, and toolhead = x.
        let rows = self.lumped.couplings.len() + 1;
        let mut a = DMatrix::zeros(rows, n);
        let mut b = DVector::zeros(rows);
        let node_coeffs =
            |terms: &[crate::lumped::Term], a: &mut DMatrix<f64>, r: usize, s: f64| {
                let mut cmd = 0.0;
                for t in terms {
                    match t.node {
                        crate::lumped::Node::Body(i) => a[(r, i)] += s * t.gain,
                        crate::lumped::Node::Command => cmd += s * t.gain,
                        crate::lumped::Node::Ground => {}
                    }
                }
                cmd
            };
        let k_scale = lin.k.diagonal().max().max(1e-300);
        for (r, c) in self.lumped.couplings.iter().enumerate() {
            let k = c
                .stiffness
                .at(c.stiffness.depends_on().map_or(0.0, |i| q_k[i]));
            let s = (k / k_scale).sqrt().max(1e-6);
            b[r] = -node_coeffs(&c.terms, &mut a, r, s) * x;
        }
        let r = rows - 1;
        b[r] = x - node_coeffs(&self.lumped.output, &mut a, r, 1.0) * x;
        let svd = a.svd(true, true);
        match svd.solve(&b, 1e-12) {
            Ok(q) => q.iter().copied().collect(),
            Err(_) => vec![0.0; n],
        }
    }

    /// A state at coordinates `q` (m, rad) and rates `qd` (m/s, rad/s) with the command at
    /// `command`, time 0 and no driver force.
    pub fn state(&self, q: &[f64], qd: &[f64], command: &State) -> Result<MujocoSim, SimError> {
        let n = self.lumped.dof();
        if q.len() != n || qd.len() != n {
            return Err(SimError::InvalidModel {
                what: format!(
                    "a state needs {n} coordinates and {n} rates, got {} and {}",
                    q.len(),
                    qd.len()
                ),
            });
        }
        let mut sim = MujocoSim {
            data: MjData::new(Box::new(self.template.clone())),
            dof: n,
            drive: self.layout.drive,
            command: *command,
            time_s: 0.0,
            steps: 0,
        };
        sim.data.qpos_mut()[..n].copy_from_slice(q);
        sim.data.qvel_mut()[..n].copy_from_slice(qd);
        Ok(sim)
    }

    /// A state at rest at the commanded start: coordinates at [`MujocoModel::rest_coordinates`]
    /// for `start.p`, moving rigidly with `start.v` (the start acceleration is taken as
    /// reached from rest, as in the modal plant).
    pub fn state_at_rest(&self, start: &State) -> MujocoSim {
        let q = self.rest_coordinates(start.p);
        // The rest shape is linear in the command for a chain: its rate is shape * v.
        let shape = self.rest_coordinates(1.0);
        let shape0 = self.rest_coordinates(0.0);
        let qd: Vec<f64> = shape
            .iter()
            .zip(&shape0)
            .map(|(s1, s0)| (s1 - s0) * start.v)
            .collect();
        self.state(&q, &qd, start)
            .expect("rest coordinates have the model's dimension")
    }

    /// One MuJoCo step of exactly `h_s` seconds. `cmd` is the commanded sample at the step
    /// start; its jerk is constant over the step. The driver force set with
    /// [`MujocoModel::set_drive`] is held over the step.
    pub fn step(&self, sim: &mut MujocoSim, cmd: &Sample, h_s: f64) -> Result<(), SimError> {
        if !(h_s.is_finite() && h_s > 0.0) {
            return Err(SimError::InvalidStep { dt_s: h_s });
        }
        let n = self.lumped.dof();
        if sim.data.model_opt().timestep != h_s {
            sim.data.model_opt_mut().timestep = h_s;
        }
        if let Some((joint, actuator)) = self.layout.command {
            sim.data.qpos_mut()[joint] = cmd.p;
            sim.data.qvel_mut()[joint] = cmd.v;
            sim.data.act_mut()[0] = cmd.a;
            sim.data.ctrl_mut()[actuator] = cmd.j;
        }
        // Position-dependent stiffness at the predicted mid-step coordinates (second order
        // in h), as the control of its correction actuator.
        for (actuator, law, k_ref) in &self.layout.variable {
            let (q, qd) = (sim.data.qpos(), sim.data.qvel());
            let mid = law.depends_on().map_or(0.0, |i| q[i] + 0.5 * h_s * qd[i]);
            let dk = law.at(mid) - k_ref;
            sim.data.ctrl_mut()[*actuator] = -dk;
        }
        sim.data.step();
        sim.time_s += h_s;
        sim.steps += 1;
        sim.command = advance(cmd, h_s);
        let warn = sim.data.warning();
        let bad = [
            MjtWarning::mjWARN_BADQPOS,
            MjtWarning::mjWARN_BADQVEL,
            MjtWarning::mjWARN_BADQACC,
        ]
        .iter()
        .any(|w| warn[*w as usize].number > 0);
        let finite = sim.data.qpos()[..n]
            .iter()
            .chain(&sim.data.qvel()[..n])
            .all(|v| v.is_finite());
        if bad || !finite {
            return Err(SimError::NonFinite { t_s: sim.time_s });
        }
        Ok(())
    }

    /// Advance `dt_s` seconds in equal steps no longer than [`MujocoModel::step_at`];
    /// `cmd` is the commanded sample at the start (constant jerk throughout). Returns the
    /// number of MuJoCo steps taken.
    pub fn advance(&self, sim: &mut MujocoSim, cmd: &Sample, dt_s: f64) -> Result<usize, SimError> {
        if !(dt_s.is_finite() && dt_s >= 0.0) {
            return Err(SimError::InvalidStep { dt_s });
        }
        if dt_s == 0.0 {
            return Ok(0);
        }
        let h_max = self.step_at(sim);
        // The relative slack keeps a dt that is a whole multiple of h_max from taking one
        // extra step through rounding.
        let steps = ((dt_s / h_max) * (1.0 - 1e-12)).ceil().max(1.0) as usize;
        let h = dt_s / steps as f64;
        for k in 0..steps {
            let s = if k == 0 {
                *cmd
            } else {
                let st = advance(cmd, h * k as f64);
                Sample {
                    p: st.p,
                    v: st.v,
                    a: st.a,
                    j: cmd.j,
                }
            };
            self.step(sim, &s, h)?;
        }
        // The end command exactly (not accumulated through the substeps).
        sim.command = advance(cmd, dt_s);
        Ok(steps)
    }

    /// The toolhead position (m) of the state.
    pub fn toolhead_m(&self, sim: &MujocoSim) -> f64 {
        self.lumped.toolhead_m(sim.q(), sim.command.p)
    }

    /// The number of lumped coordinates.
    pub fn dof(&self) -> usize {
        self.lumped.dof()
    }

    /// Whether the model has a driver input ([`Lumped::actuated`]).
    pub fn has_drive(&self) -> bool {
        self.layout.drive.is_some()
    }

    /// Set the generalised force (N m for an angular body, N for a linear one) the driver
    /// applies to the actuated body from now on (held over the following steps).
    pub fn set_drive(&self, sim: &mut MujocoSim, force: f64) -> Result<(), SimError> {
        match self.layout.drive {
            Some(a) if force.is_finite() => {
                sim.data.ctrl_mut()[a] = force;
                Ok(())
            }
            Some(_) => Err(SimError::NonFinite { t_s: sim.time_s }),
            None => Err(SimError::InvalidModel {
                what: "the lumped model has no actuated body to apply a driver force to".into(),
            }),
        }
    }
}

/// The toolhead-weighted mode rate `(sum_i s_i w_i^4)^(1/4)` (rad/s) of a model with a
/// regular stiffness matrix: `w_i` the undamped mode frequencies, `s_i` each mode's share
/// of the toolhead's deflection under a steady commanded acceleration (`|c_i| / sum |c_j|`,
/// `c_i = (g M^-1/2 phi_i)(phi_i M^1/2 r) / w_i^2`, `g` the toolhead's gains on the bodies,
/// `r = K^-1 bk` the rigid shape per unit command, `phi_i` the mass-normalised modes).
///
/// RK4 shifts mode `i`'s frequency by `(w_i h)^4 / 120`; weighted by the share, the
/// toolhead's error is `h^4 sum_i s_i w_i^4 / 120`, so `h = max_lambda_h / rate` keeps it at
/// the per-sample path's bound on its fastest mode (`max_lambda_h^4 / 120`). One mode: the
/// per-sample step. `None` when the toolhead does not deflect (no weights).
fn weighted_rate(lumped: &Lumped, kn: &DMatrix<f64>, m_inv_sqrt: &DVector<f64>) -> Option<f64> {
    let n = lumped.dof();
    let lin = lumped.linearised(&vec![0.0; n]);
    let r = lin.k.clone().cholesky()?.solve(&lin.bk);
    let mut g: DVector<f64> = DVector::zeros(n);
    for t in &lumped.output {
        if let crate::lumped::Node::Body(i) = t.node {
            g[i] += t.gain;
        }
    }
    let eig = kn.clone().symmetric_eigen();
    let (mut sum_c, mut sum_cw4) = (0.0, 0.0);
    for (i, &w2) in eig.eigenvalues.iter().enumerate() {
        if w2 <= 0.0 {
            continue;
        }
        let phi = eig.eigenvectors.column(i);
        let out: f64 = (0..n).map(|j| g[j] * m_inv_sqrt[j] * phi[j]).sum();
        let inp: f64 = (0..n).map(|j| phi[j] * r[j] / m_inv_sqrt[j]).sum();
        let c = (out * inp / w2).abs();
        sum_c += c;
        sum_cw4 += c * w2 * w2;
    }
    (sum_c > 0.0 && sum_cw4.is_finite()).then(|| (sum_cw4 / sum_c).powf(0.25))
}

/// The command state `h` seconds after sample `s` (constant jerk).
fn advance(s: &Sample, h: f64) -> State {
    State {
        p: s.p + h * (s.v + h * (s.a / 2.0 + h * s.j / 6.0)),
        v: s.v + h * (s.a + h * s.j / 2.0),
        a: s.a + h * s.j,
    }
}

impl MujocoSim {
    /// The lumped coordinates q (m, rad).
    pub fn q(&self) -> &[f64] {
        &self.data.qpos()[..self.dof]
    }

    /// Their rates q' (m/s, rad/s).
    pub fn qd(&self) -> &[f64] {
        &self.data.qvel()[..self.dof]
    }

    /// The commanded state now.
    pub fn command(&self) -> State {
        self.command
    }

    /// Simulated time since the state was made (s).
    pub fn time_s(&self) -> f64 {
        self.time_s
    }

    /// MuJoCo steps taken so far.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// The driver force currently applied (N m or N; 0 without a driver).
    pub fn drive(&self) -> f64 {
        self.drive.map_or(0.0, |a| self.data.ctrl()[a])
    }

    /// Put the lumped coordinates and rates back to `q`, `qd` with the bookkeeping of an
    /// earlier moment (the lean path's return to a sample inside a step; everything else
    /// MuJoCo keeps is set again before each step).
    pub(super) fn rewind(
        &mut self,
        q: &[f64],
        qd: &[f64],
        command: State,
        time_s: f64,
        steps: u64,
    ) {
        self.data.qpos_mut()[..self.dof].copy_from_slice(q);
        self.data.qvel_mut()[..self.dof].copy_from_slice(qd);
        self.command = command;
        self.time_s = time_s;
        self.steps = steps;
    }

    /// The MuJoCo data (read only), e.g. for MuJoCo's own energy or force arrays.
    pub fn data(&self) -> &MjData<Box<MjModel>> {
        &self.data
    }
}
