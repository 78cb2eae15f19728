//! [`MujocoPlant`] as a [`Plant`]: the start state, one sample at a time, positions and
//! observations. A whole run of samples between two breakpoints of the command goes to
//! the lean path (`lean.rs`) instead.
//!
//! Per sample, each axis steps in equal pieces no longer than its model's step: the full
//! driver through [`full_step`], the spring driver holding the microstep of each piece's
//! start, the linear driver through [`super::MujocoModel::advance`]. An idle axis (at rest where
//! it started, its command held there) is not stepped.

use settle_planner::{Sample, State};

use super::plant::{AxisState, MujocoPlant, MujocoPlantState, full_step};
use crate::numerics::start_equilibrium;
use crate::stepper::StepperState;
use crate::{DriverMode, Observation, Plant, SimError, advance_sample, check_step};

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
