//! The lean path on MuJoCo ([`crate::Plant::step_samples`]): RK4 steps spanning several
//! samples, the samples in between interpolated.
//!
//! Between two breakpoints of the command the harness hands over a whole run of samples.
//! Each axis then takes MuJoCo steps of up to [`MujocoModel::long_step_at`]
//! (`|lambda| h <= MujocoConfig::long_lambda_h`, shrunk where the belt is stiffer) and, for
//! the full driver, `w_e h <= MujocoConfig::long_explicit_w_h` for the driver torque held
//! over the step; the steps are equal pieces of what is left of the call's span, so they
//! need not line up with the samples, and the last one ends on the last sample. A sample
//! inside a step gets the coordinates by cubic Hermite interpolation from the coordinates
//! and rates at the step's ends (error `<= (w h)^4 / 384` of a mode's amplitude at `w`);
//! the toolhead follows from them and the exact command. `sim/tests/all/mujoco_lean.rs`
//! measures both errors against per-sample stepping and a converged reference.
//!
//! A sample that fails the plant's checks (a non-finite value, a blow-up) ends the call
//! there: every axis whose step reaches past that sample goes back to the step's start
//! and takes one step to the sample, so the caller observes the state at that sample.

use settle_planner::{Sample, State};

use super::plant::{AxisState, MujocoPlant, MujocoPlantState, full_step};
use super::{MujocoModel, MujocoSim};
use crate::stepper::StepperState;
use crate::{AxisModel, DriverMode, SimError, advance_sample};

/// One axis's current step `[t0, t1]` (s after the call's start), with the coordinates and
/// rates at both ends (the end is the MuJoCo state now) and what is needed to go back to
/// `t0`.
struct Span {
    t0: f64,
    t1: f64,
    q0: Vec<f64>,
    qd0: Vec<f64>,
    q1: Vec<f64>,
    qd1: Vec<f64>,
    /// Scratch: the interpolated coordinates.
    qi: Vec<f64>,
    /// Scratch: the full driver's current and command angles inside a step.
    inner: Vec<[f64; 3]>,
    stepper0: Option<StepperState>,
    command0: State,
    time0_s: f64,
    steps0: u64,
    /// At rest for the whole call (an idle axis whose command stays put): not stepped.
    rest: bool,
    /// The toolhead of a resting axis (m).
    rest_toolhead_m: f64,
}

impl Span {
    fn new(ax: &AxisModel, st: &mut AxisState, c: &Sample) -> Self {
        let rest = st.idle && c.p == st.base.p && c.v == 0.0 && c.a == 0.0 && c.j == 0.0;
        if !rest {
            st.idle = false;
        }
        let (q, qd) = (st.sim.q().to_vec(), st.sim.qd().to_vec());
        Self {
            t0: 0.0,
            t1: 0.0,
            q0: q.clone(),
            qd0: qd.clone(),
            qi: q.clone(),
            inner: Vec::new(),
            rest_toolhead_m: ax.lumped.toolhead_m(&q, ax.command_node_m(st.base.p)),
            q1: q,
            qd1: qd,
            stepper0: st.stepper.clone(),
            command0: st.sim.command(),
            time0_s: st.sim.time_s(),
            steps0: st.sim.steps(),
            rest,
        }
    }

    /// Take the next step of the axis towards `span_s`: an equal piece of what is left, no
    /// longer than the axis's long step.
    #[allow(clippy::too_many_arguments)]
    fn advance(
        &mut self,
        ax: &AxisModel,
        model: &MujocoModel,
        cap_s: f64,
        st: &mut AxisState,
        c: &Sample,
        span_s: f64,
    ) -> Result<(), SimError> {
        let left = span_s - self.t1;
        let h_max = model.long_step_at(&st.sim).min(cap_s);
        let m = ((left / h_max) * (1.0 - 1e-12)).ceil().max(1.0);
        let t0 = self.t1;
        let t1 = if m <= 1.0 { span_s } else { t0 + left / m };
        std::mem::swap(&mut self.q0, &mut self.q1);
        std::mem::swap(&mut self.qd0, &mut self.qd1);
        self.stepper0.clone_from(&st.stepper);
        self.command0 = st.sim.command();
        self.time0_s = st.sim.time_s();
        self.steps0 = st.sim.steps();
        step_axis(ax, model, st, c, t0, t1 - t0, &mut self.inner)?;
        self.q1.copy_from_slice(st.sim.q());
        self.qd1.copy_from_slice(st.sim.qd());
        self.t0 = t0;
        self.t1 = t1;
        Ok(())
    }

    /// The coordinates at `t` (s after the call's start, inside the step) into `qi`.
    fn interpolate(&mut self, t: f64) {
        if t >= self.t1 {
            self.qi.copy_from_slice(&self.q1);
            return;
        }
        let h = self.t1 - self.t0;
        let s = (t - self.t0) / h;
        let r = 1.0 - s;
        // Cubic Hermite basis, the rate terms scaled by the step.
        let h00 = (1.0 + 2.0 * s) * r * r;
        let h10 = s * r * r * h;
        let h01 = s * s * (3.0 - 2.0 * s);
        let h11 = -s * s * r * h;
        for j in 0..self.qi.len() {
            self.qi[j] =
                h00 * self.q0[j] + h10 * self.qd0[j] + h01 * self.q1[j] + h11 * self.qd1[j];
        }
    }

    /// Go back to the step's start and take one step to `t` instead (the state at a
    /// sample inside the step).
    fn settle_at(
        &mut self,
        ax: &AxisModel,
        model: &MujocoModel,
        st: &mut AxisState,
        c: &Sample,
        t: f64,
    ) -> Result<(), SimError> {
        if self.rest || t >= self.t1 {
            return Ok(());
        }
        rewind(
            &mut st.sim,
            &self.q0,
            &self.qd0,
            self.command0,
            self.time0_s,
            self.steps0,
        );
        st.stepper.clone_from(&self.stepper0);
        step_axis(ax, model, st, c, self.t0, t - self.t0, &mut self.inner)
    }
}

fn rewind(sim: &mut MujocoSim, q: &[f64], qd: &[f64], command: State, time_s: f64, steps: u64) {
    sim.rewind(q, qd, command, time_s, steps);
}

/// One MuJoCo step of `h` s starting `tau` s after the command sample `c` (`inner`: the
/// full driver's scratch for the load angle inside the step).
fn step_axis(
    ax: &AxisModel,
    model: &MujocoModel,
    st: &mut AxisState,
    c: &Sample,
    tau: f64,
    h: f64,
    inner: &mut Vec<[f64; 3]>,
) -> Result<(), SimError> {
    match (ax.mode, &ax.stepper) {
        (DriverMode::Full, Some(sp)) => {
            let ss = st.stepper.as_mut().ok_or_else(|| SimError::InvalidModel {
                what: format!("axis `{}`: the full driver has no state", ax.name),
            })?;
            full_step(sp, model, &mut st.sim, ss, c, tau, h, Some(inner))
        }
        _ => {
            model.step(&mut st.sim, &advance_sample(c, tau), h)?;
            if let (Some(sp), Some(ss)) = (&ax.stepper, st.stepper.as_mut()) {
                sp.track_spring(ss, st.sim.q()[sp.rotor], advance_sample(c, tau + h).p);
            }
            Ok(())
        }
    }
}

/// [`crate::Plant::step_samples`] for [`MujocoPlant`] (see the module documentation).
#[allow(clippy::type_complexity)]
pub(super) fn step_samples(
    plant: &MujocoPlant,
    state: &mut MujocoPlantState,
    cmds: &[Sample],
    dt_s: f64,
    blowup_m: f64,
    commanded_m: &mut [f64],
    toolhead_m: &mut [f64],
) -> Result<Option<usize>, (usize, SimError)> {
    let na = plant.axes.len();
    if na == 0 || cmds.is_empty() || !cmds.len().is_multiple_of(na) || state.axes.len() != na {
        return Ok(None);
    }
    // The microstep-quantised spring holds a piecewise-constant command: per sample.
    if plant
        .axes
        .iter()
        .any(|(ax, _)| ax.mode == DriverMode::Spring && ax.stepper.is_some())
    {
        return Ok(None);
    }
    if !(dt_s.is_finite() && dt_s > 0.0) {
        return Err((0, SimError::InvalidStep { dt_s }));
    }
    let n = cmds.len() / na;
    if commanded_m.len() < n * na || toolhead_m.len() < n * na {
        return Ok(None);
    }
    let span_s = n as f64 * dt_s;
    let mut spans: Vec<Span> = plant
        .axes
        .iter()
        .zip(state.axes.iter_mut())
        .zip(cmds)
        .map(|(((ax, _), st), c)| Span::new(ax, st, c))
        .collect();
    // A step end this close below a sample covers it (rounding of the step sums).
    let slack = 1e-9 * dt_s;
    for i in 0..n {
        let t = (i + 1) as f64 * dt_s;
        let mut bad = false;
        for a in 0..na {
            let (ax, model) = &plant.axes[a];
            let st = &mut state.axes[a];
            let sp = &mut spans[a];
            let k = i * na + a;
            let p = advance_sample(&cmds[k], dt_s).p;
            commanded_m[k] = p;
            let th = if sp.rest {
                sp.rest_toolhead_m
            } else {
                while sp.t1 < t - slack {
                    sp.advance(ax, model, plant.long_cap_s[a], st, &cmds[a], span_s)
                        .map_err(|e| (i, e))?;
                }
                sp.interpolate(t);
                ax.lumped.toolhead_m(&sp.qi, ax.command_node_m(p))
            };
            toolhead_m[k] = th;
            bad |= !(th.is_finite() && p.is_finite() && (th - p).abs() <= blowup_m);
        }
        if bad {
            for a in 0..na {
                let (ax, model) = &plant.axes[a];
                let st = &mut state.axes[a];
                spans[a]
                    .settle_at(ax, model, st, &cmds[a], t)
                    .map_err(|e| (i, e))?;
                st.base = end_state(&cmds[i * na + a], dt_s);
            }
            return Ok(Some(i + 1));
        }
    }
    for (a, st) in state.axes.iter_mut().enumerate() {
        st.base = end_state(&cmds[(n - 1) * na + a], dt_s);
    }
    Ok(Some(n))
}

fn end_state(c: &Sample, dt_s: f64) -> State {
    let e = advance_sample(c, dt_s);
    State {
        p: e.p,
        v: e.v,
        a: e.a,
    }
}
