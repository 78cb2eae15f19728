//! The modal reference plant: exact discretisation of base-excited modes.
//!
//! Each mode's deflection e (toolhead relative to command) obeys
//! `e'' + 2 zeta w e' + w^2 e = -a(t)`, with `a` the commanded acceleration. Over a step in
//! which the commanded jerk `j` is constant, the augmented state `[e, e', a, j]` evolves
//! linearly, so the step is exactly the matrix exponential of the augmented system. The
//! state is scaled to `[w^2 e, w e', a, j / w]` (all in acceleration units), which makes the
//! system matrix `w * [[0,1,0,0],[-1,-2 zeta,-1,0],[0,0,0,1],[0,0,0,0]]` well balanced for
//! the exponential.

use nalgebra::Matrix4;
use settle_planner::{Sample, State};

use crate::{Mode, Observation, Plant, SimError};

/// The rows of one mode's transition that produce the new (scaled) deflection and rate.
type Rows = [[f64; 4]; 2];

/// The modal reference plant (model: constant).
#[derive(Debug, Clone)]
pub struct ModalPlant {
    modes: Vec<Mode>,
    nominal_dt_s: f64,
    nominal: Vec<Rows>,
}

/// The modal plant's mutable state.
#[derive(Debug, Clone, PartialEq)]
pub struct ModalState {
    /// Simulation time (s).
    pub t_s: f64,
    /// Commanded base state at `t_s`.
    pub base: State,
    /// Per mode: deflection e (m) and its rate e' (m/s).
    pub modes: Vec<(f64, f64)>,
}

fn transition(mode: &Mode, dt_s: f64) -> Rows {
    let w = mode.omega();
    let z = mode.damping_ratio();
    #[rustfmt::skip]
    let a = Matrix4::new(
        0.0, 1.0, 0.0, 0.0,
        -1.0, -2.0 * z, -1.0, 0.0,
        0.0, 0.0, 0.0, 1.0,
        0.0, 0.0, 0.0, 0.0,
    ) * (w * dt_s);
    let phi = a.exp();
    [
        [phi[(0, 0)], phi[(0, 1)], phi[(0, 2)], phi[(0, 3)]],
        [phi[(1, 0)], phi[(1, 1)], phi[(1, 2)], phi[(1, 3)]],
    ]
}

impl ModalPlant {
    /// A plant with these modes. `nominal_dt_s` is the step size used most (the sample
    /// period): its transition is computed once; other step sizes (partial steps at
    /// profile breakpoints) are computed when needed.
    pub fn new(modes: Vec<Mode>, nominal_dt_s: f64) -> Result<Self, SimError> {
        if modes.is_empty() {
            return Err(SimError::NoModes);
        }
        if !(nominal_dt_s.is_finite() && nominal_dt_s >= 0.0) {
            return Err(SimError::InvalidStep { dt_s: nominal_dt_s });
        }
        let nominal = modes.iter().map(|m| transition(m, nominal_dt_s)).collect();
        Ok(Self {
            modes,
            nominal_dt_s,
            nominal,
        })
    }

    /// The modes.
    pub fn modes(&self) -> &[Mode] {
        &self.modes
    }

    /// Envelope of the free vibration of mode `i` from its current state:
    /// `sqrt(e^2 + ((e' + zeta w e)/wd)^2)` (m). After the move this is the residual
    /// amplitude at the current instant.
    pub fn free_amplitude(&self, state: &ModalState, i: usize) -> f64 {
        let m = &self.modes[i];
        let (e, ed) = state.modes[i];
        let x = (ed + m.damping_ratio() * m.omega() * e) / m.omega_d();
        e.hypot(x)
    }
}

#[inline]
fn apply(rows: &Rows, w: f64, e: &mut (f64, f64), a: f64, j: f64) {
    let y = [w * w * e.0, w * e.1, a, j / w];
    let y1 = rows[0][0] * y[0] + rows[0][1] * y[1] + rows[0][2] * y[2] + rows[0][3] * y[3];
    let y2 = rows[1][0] * y[0] + rows[1][1] * y[1] + rows[1][2] * y[2] + rows[1][3] * y[3];
    *e = (y1 / (w * w), y2 / w);
}

impl Plant for ModalPlant {
    type State = ModalState;

    fn initial_state(&self, start: &State) -> ModalState {
        ModalState {
            t_s: 0.0,
            base: *start,
            modes: vec![(0.0, 0.0); self.modes.len()],
        }
    }

    fn step(&self, state: &mut ModalState, cmd: &Sample, dt_s: f64) -> Result<(), SimError> {
        if !(dt_s.is_finite() && dt_s >= 0.0) {
            return Err(SimError::InvalidStep { dt_s });
        }
        let nominal = dt_s == self.nominal_dt_s;
        for (i, (mode, e)) in self.modes.iter().zip(&mut state.modes).enumerate() {
            let w = mode.omega();
            if nominal {
                apply(&self.nominal[i], w, e, cmd.a, cmd.j);
            } else {
                apply(&transition(mode, dt_s), w, e, cmd.a, cmd.j);
            }
        }
        let h = dt_s;
        state.base = State {
            p: cmd.p + h * (cmd.v + h * (cmd.a / 2.0 + h * cmd.j / 6.0)),
            v: cmd.v + h * (cmd.a + h * cmd.j / 2.0),
            a: cmd.a + h * cmd.j,
        };
        state.t_s += dt_s;
        let finite = state.base.p.is_finite()
            && state
                .modes
                .iter()
                .all(|(e, ed)| e.is_finite() && ed.is_finite());
        if finite {
            Ok(())
        } else {
            Err(SimError::NonFinite { t_s: state.t_s })
        }
    }

    fn observe(&self, state: &ModalState) -> Observation {
        let deflection: f64 = self
            .modes
            .iter()
            .zip(&state.modes)
            .map(|(m, (e, _))| m.weight() * e)
            .sum();
        Observation {
            commanded_m: state.base.p,
            toolhead_m: state.base.p + deflection,
        }
    }
}
