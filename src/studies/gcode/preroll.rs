//! The pre-roll of a layer range: how long before the range's first move a simulation of
//! the range starts, so that it starts from the motion the layers before leave (used by
//! the `[gcode]` study and by `settle gcode --layers`).
//!
//! A range simulated from rest differs from the same layers in the whole job by a free
//! vibration of the machine's modes (the model is linear, so the difference of the two
//! runs obeys the free equations). Started [`preroll_s`] before the range, that difference
//! has decayed by [`PREROLL_DECAY`] when the range starts (the envelope
//! `exp(-sigma t)`, `sigma` the slowest decay rate), up to a constant of the modes'
//! eigenvectors.

use settle_planner::{Profile, State};
use settle_sim::AxisModel;
use settle_sim::closed_form::LinearResponse;

/// How much smaller the vibration present when a layer range's pre-roll starts must
/// become by the range's first move: 1e-6 (the envelope `exp(-sigma t)`, `sigma` the
/// slowest decay rate).
pub const PREROLL_DECAY: f64 = 1e-6;

/// The slowest decay rate (1/s) of the axes' free vibration: the least `-Re(p)` over the
/// poles `p` of every axis linearised at rest at the origin (a mode's `zeta w`; a real
/// pole's rate). Every disturbance of the linear model decays at least this fast, up to a
/// constant of its eigenvectors. The error is a message: an axis the closed form cannot
/// linearise, or a mode that never decays (undamped or unstable).
pub fn slowest_decay_per_s(linear_axes: &[AxisModel]) -> Result<f64, String> {
    let rest = Profile::empty(State::default());
    let mut slowest = f64::INFINITY;
    for a in linear_axes {
        let lr = LinearResponse::new(a, &rest).map_err(|e| e.to_string())?;
        for p in lr.poles() {
            slowest = slowest.min(-p.re);
        }
    }
    if !(slowest.is_finite() && slowest > 0.0) {
        return Err(
            "the machine has an undamped or unstable mode: its vibration never decays".into(),
        );
    }
    Ok(slowest)
}

/// The pre-roll of a layer range (s): the time the slowest mode needs to decay by
/// [`PREROLL_DECAY`], `ln(1 / PREROLL_DECAY) / sigma`.
pub fn preroll_s(slowest_decay_per_s: f64) -> f64 {
    (1.0 / PREROLL_DECAY).ln() / slowest_decay_per_s
}
