//! [`MujocoPlant`]: the [`Plant`] trait over one [`MujocoModel`] per axis.

use settle_planner::{Sample, State};

use super::{MujocoConfig, MujocoModel, MujocoSim};
use crate::stepper::StepperState;
use crate::{AxisModel, DriverMode, Observation, Plant, SimError, advance_sample, check_step};

/// The MuJoCo backend as a [`Plant`]: one MuJoCo model per axis, each starting at rest at
/// its commanded start and following the command through the lumped couplings.
///
/// Driver modes: `linear` (a spring to the continuous command) and `spring` (a spring to
/// the microstep-quantised command, stepped as a piecewise-constant command) run here.
/// The `full` current-loop driver runs on rapier: [`MujocoPlant::new`] refuses it with an
/// error that says so.
#[derive(Debug)]
pub struct MujocoPlant {
    axes: Vec<(AxisModel, MujocoModel)>,
}

/// The state of every axis.
#[derive(Debug)]
pub struct MujocoPlantState {
    axes: Vec<AxisState>,
}

#[derive(Debug)]
struct AxisState {
    sim: MujocoSim,
    stepper: Option<StepperState>,
    /// The commanded sample (continuous, before quantisation) at the current time.
    base: State,
}

impl MujocoPlant {
    /// Compile each axis into MuJoCo with `config`.
    pub fn new(axes: Vec<AxisModel>, config: MujocoConfig) -> Result<Self, SimError> {
        if axes.is_empty() {
            return Err(SimError::NoModes);
        }
        let mut out = Vec::with_capacity(axes.len());
        for a in axes {
            a.validate()?;
            if a.mode == DriverMode::Full {
                return Err(SimError::InvalidModel {
                    what: format!(
                        "axis `{}`: the MuJoCo backend runs the `linear` and `spring` driver models; the `full` current-loop driver runs on rapier (--backend rapier)",
                        a.name
                    ),
                });
            }
            let m = MujocoModel::new(&a.lumped, config)?;
            out.push((a, m));
        }
        Ok(Self { axes: out })
    }

    /// The MuJoCo model of axis `i` (MJCF, step size, state access).
    pub fn model(&self, i: usize) -> &MujocoModel {
        &self.axes[i].1
    }
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
            match (ax.mode, &ax.stepper) {
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

    fn observe(&self, state: &MujocoPlantState, out: &mut [Observation]) {
        for ((ax, _), (st, o)) in self.axes.iter().zip(state.axes.iter().zip(out.iter_mut())) {
            let x_node = ax.command_node_m(st.base.p);
            let q = st.sim.q();
            *o = Observation {
                commanded_m: st.base.p,
                toolhead_m: ax.lumped.toolhead_m(q, x_node),
                carriage_m: ax.carriage.map(|i| q[i]),
                motor_angle_rad: ax.stepper.as_ref().map(|s| q[s.rotor]),
                currents_a: None,
                load_angle_rad: st.stepper.as_ref().map(|s| s.load_angle_rad),
                lost_steps: st.stepper.as_ref().map_or(0, StepperState::lost_steps),
                max_load_angle_rad: st.stepper.as_ref().map(|s| s.max_load_angle_rad),
            };
        }
    }
}
