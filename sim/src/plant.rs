//! The `Plant` trait every backend implements.
//!
//! A plant simulates one or more independent axes ([`crate::AxisModel`]s), each following
//! its own commanded profile. The model (`self`) is constant; the mutable state is a
//! separate value, so one model serves many runs in parallel.

use settle_planner::{Sample, State};

use crate::SimError;

/// What a plant reports about one axis at an instant. Lengths in m, angles in rad.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Observation {
    /// The commanded position the axis is following (m), before microstep quantisation.
    pub commanded_m: f64,
    /// The toolhead position (m).
    pub toolhead_m: f64,
    /// The carriage position (m), when the axis has a carriage body.
    pub carriage_m: Option<f64>,
    /// The motor rotor angle (rad), when the axis has a motor.
    pub motor_angle_rad: Option<f64>,
    /// Phase currents A and B (A), when the full driver model runs.
    pub currents_a: Option<[f64; 2]>,
    /// Load angle (electrical rad) between the driver's field and the rotor, when the axis
    /// has a motor.
    pub load_angle_rad: Option<f64>,
    /// Full steps lost so far (0 = in step; see [`crate::stepper::StepperState::lost_steps`]).
    pub lost_steps: u32,
    /// Largest |load angle| so far (electrical rad), when the axis has a motor.
    pub max_load_angle_rad: Option<f64>,
}

/// A breakpoint of one axis's command inside a step of
/// [`Plant::step_samples_across`]: at `before_end_s` before the step's end the command's
/// velocity, acceleration and jerk jump by `dv`, `da`, `dj` from the continuation of the
/// piece before (a new piece of its profile starts; positions are continuous).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct InnerBreak {
    /// The step (its index in the call).
    pub step: usize,
    /// How long before the step's end (s), in `(0, dt_s)`.
    pub before_end_s: f64,
    /// Jump of the velocity (m/s).
    pub dv: f64,
    /// Jump of the acceleration (m/s^2).
    pub da: f64,
    /// Jump of the jerk (m/s^3).
    pub dj: f64,
}

/// A plant: a constant model (`self`) and a separate mutable state.
pub trait Plant {
    /// The mutable state.
    type State;

    /// Number of axes.
    fn axes(&self) -> usize;

    /// A fresh state, at rest at the static equilibrium of each axis's commanded start
    /// state (`start` has one entry per axis).
    fn initial_state(&self, start: &[State]) -> Result<Self::State, SimError>;

    /// Advance `dt_s` seconds. `cmd` has one commanded sample per axis at the step start;
    /// each axis's jerk is constant over the step (callers split steps at profile
    /// breakpoints).
    fn step(&self, state: &mut Self::State, cmd: &[Sample], dt_s: f64) -> Result<(), SimError>;

    /// What the plant shows now, one entry per axis written into `out`.
    fn observe(&self, state: &Self::State, out: &mut [Observation]);

    /// The commanded and toolhead positions per axis (m), written into `commanded_m` and
    /// `toolhead_m` (the values equal [`Observation::commanded_m`] and
    /// [`Observation::toolhead_m`] bit for bit): what streaming metrics need each sample,
    /// without building [`Observation`]s. Returns `true` only when every position and
    /// angle [`Plant::observe`] would report is finite; `false` (the default, which may
    /// write nothing) tells the caller to use [`Plant::observe`] instead.
    fn positions(
        &self,
        _state: &Self::State,
        _commanded_m: &mut [f64],
        _toolhead_m: &mut [f64],
    ) -> bool {
        false
    }

    /// Several samples in one call: what the harness's lean path (no recording) does
    /// between two breakpoints of the command, without a call per sample.
    ///
    /// `cmds` holds `n = cmds.len() / axes` samples, sample-major (`cmds[i * axes + a]` is
    /// axis `a`'s command at the start of step `i`); the steps are consecutive, each
    /// `dt_s` long, and all lie inside one piece of every axis's command (constant jerk
    /// throughout), so `cmds[i * axes + a]` is `cmds[a]` advanced by `i dt_s` up to
    /// rounding. After step `i` the plant writes what [`Plant::positions`] would write
    /// into `commanded_m[i * axes ..]` and `toolhead_m[i * axes ..]` (same layout). A plant
    /// may take longer internal steps than `dt_s` and interpolate the samples between
    /// them, as long as it stays within its validated accuracy.
    ///
    /// It stops after the first sample it cannot vouch for (a value [`Plant::observe`]
    /// would report is not finite, or `|toolhead - commanded| > blowup_m` on an axis),
    /// leaving the state at that sample: the caller then observes it in full. Returns
    /// `Ok(Some(k))` with the `k >= 1` samples done and written and the state at sample
    /// `k` (when `k < n` the last one is not vouched for; a plant that stops at the last
    /// sample of the call also returns `n`, so callers evaluate the last sample of every
    /// call in full), `Err((k, e))` when step `k` failed
    /// after `k` good samples (the state is then undefined), and `Ok(None)` (the default)
    /// when the plant does not implement this: the caller steps sample by sample.
    #[allow(clippy::too_many_arguments, clippy::type_complexity)]
    fn step_samples(
        &self,
        _state: &mut Self::State,
        _cmds: &[Sample],
        _dt_s: f64,
        _blowup_m: f64,
        _commanded_m: &mut [f64],
        _toolhead_m: &mut [f64],
    ) -> Result<Option<usize>, (usize, SimError)> {
        Ok(None)
    }

    /// [`Plant::step_samples`] across breakpoints: a step may hold breakpoints of an
    /// axis's command, `breaks[a]` those of axis `a` in step order ([`InnerBreak`]), the
    /// command at the start of step `i` being `cmds[i * axes + a]` as there. A plant that
    /// solves its model exactly whatever the command's jerk does (the modal plant: the
    /// response to a jump is one more term of the exact solution) takes a whole step
    /// where others split it at each breakpoint; its results then agree with the split
    /// steps' to rounding, not bit for bit. `Ok(None)` (the default): not implemented,
    /// the caller splits the steps.
    #[allow(clippy::too_many_arguments, clippy::type_complexity)]
    fn step_samples_across(
        &self,
        _state: &mut Self::State,
        _cmds: &[Sample],
        _breaks: &[&[InnerBreak]],
        _dt_s: f64,
        _blowup_m: f64,
        _commanded_m: &mut [f64],
        _toolhead_m: &mut [f64],
    ) -> Result<Option<usize>, (usize, SimError)> {
        Ok(None)
    }
}

/// Check a command's axis count and step size (shared by the backends).
pub fn check_step(axes: usize, cmd: &[Sample], dt_s: f64) -> Result<(), SimError> {
    if cmd.len() != axes {
        return Err(SimError::AxisCount {
            expected: axes,
            got: cmd.len(),
        });
    }
    if !(dt_s.is_finite() && dt_s >= 0.0) {
        return Err(SimError::InvalidStep { dt_s });
    }
    Ok(())
}

/// Check positions given one per axis (m): their count, and that each is finite (`what`
/// names the position in the error, e.g. "the linearisation point"). Shared by the
/// backends that take a reference position for the whole job.
pub fn check_positions(axes: usize, positions_m: &[f64], what: &str) -> Result<(), SimError> {
    if positions_m.len() != axes {
        return Err(SimError::AxisCount {
            expected: axes,
            got: positions_m.len(),
        });
    }
    if let Some(p) = positions_m.iter().find(|p| !p.is_finite()) {
        return Err(SimError::InvalidModel {
            what: format!("{what} {p} m is not finite"),
        });
    }
    Ok(())
}

/// The command polynomial of a sample `tau` s later (constant jerk).
#[inline]
pub fn advance_sample(s: &Sample, tau: f64) -> Sample {
    Sample {
        p: s.p + tau * (s.v + tau * (s.a / 2.0 + tau * s.j / 6.0)),
        v: s.v + tau * (s.a + tau * s.j / 2.0),
        a: s.a + tau * s.j,
        j: s.j,
    }
}
