//! A Marlin block's trapezoid (`calculate_trapezoid_for_block`, planner.cpp) and how the
//! stepper runs it (`Stepper::block_phase_isr`, stepper.cpp).
//!
//! The planner fixes step rates and step counts; the stepper changes the rate in time:
//! while accelerating `rate = min(initial + A t, nominal)` (or the Bezier from `initial`
//! to `cruise_rate` over `(cruise_rate - initial) / A`, then `cruise_rate`), until
//! `accelerate_until` steps; then `nominal_rate` until `decelerate_after`; then
//! `max(peak - A t, final)` (or the Bezier from `cruise_rate` to `final`) until the block's
//! last step. Each phase here is that law in continuous time, ended at its step count.

use super::block::Block;
use super::config::{MarlinConfig, MarlinStepper};
use crate::firmware::{Phase, PlannedMove, RampShape};

/// The trapezoid of `b` for entry and exit speeds `entry_speed`, `exit_speed` (m/s), as
/// the stepper runs it.
pub(super) fn plan_block(
    b: &Block,
    entry_speed: f64,
    exit_speed: f64,
    cfg: &MarlinConfig,
) -> PlannedMove {
    if cfg.stepper == MarlinStepper::PreciseStepping {
        return precise(b, entry_speed, exit_speed);
    }
    let n = b.step_event_count;
    let rn = b.nominal_rate.max(1.0);
    let nomr = 1.0 / b.nominal_speed_sqr.sqrt();
    let r0 = (rn * entry_speed * nomr)
        .ceil()
        .max(cfg.minimal_step_rate_hz);
    let rf = (rn * exit_speed * nomr)
        .ceil()
        .max(cfg.minimal_step_rate_hz);
    let a = b.accel_steps;
    // Steps to change rate at `accel` (estimate_acceleration_distance); a negative count
    // saturates to 0 when the firmware converts it to an unsigned integer on ARM.
    let est = |from: f64, to: f64, accel: f64| (to * to - from * from) / (2.0 * accel);
    let mut accel_steps = est(r0, rn, a).ceil().max(0.0);
    let decel_steps = est(rn, rf, -a).floor().max(0.0);
    let mut plateau = n - accel_steps - decel_steps;
    let mut cruise_rate = rn;
    if plateau < 0.0 {
        // No cruise: meet the final rate at the last step (intersection_distance).
        let meet = (2.0 * a * n - r0 * r0 + rf * rf) / (4.0 * a);
        accel_steps = meet.ceil().max(0.0).min(n);
        plateau = 0.0;
        cruise_rate = (r0 * r0 + 2.0 * a * accel_steps).sqrt();
    }
    let decel_n = n - accel_steps - plateau;

    let (acc, dec) = if cfg.s_curve {
        let acc = ramp(accel_steps, r0, cruise_rate, true, a, RampShape::Bezier);
        let dec = ramp(decel_n, cruise_rate, rf, false, a, RampShape::Bezier);
        (acc, dec)
    } else {
        let acc = ramp(accel_steps, r0.min(rn), rn, true, a, RampShape::Linear);
        let dec = ramp(decel_n, acc.end_rate, rf, false, a, RampShape::Linear);
        (acc, dec)
    };
    let cruise = Phase::constant(plateau / rn, rn);

    // Rates (steps/s) to path speed (m/s).
    let mps = b.millimeters / n;
    let scale = |p: Phase| Phase {
        v0_m_s: p.v0_m_s * mps,
        dv_m_s: p.dv_m_s * mps,
        ..p
    };
    let phases = [acc.ramp, acc.hold, cruise, dec.ramp, dec.hold].map(scale);
    let mut p = PlannedMove::new(b.seq, b.start_m, b.axes_r, b.millimeters, &phases);
    p.start_speed_m_s = phases[0].v0_m_s;
    p.cruise_speed_m_s = if plateau > 0.0 {
        rn * mps
    } else {
        acc.end_rate * mps
    };
    p.end_speed_m_s = dec.end_rate * mps;
    p.accel_m_s2 = a * mps;
    p.decel_m_s2 = a * mps;
    p.accel_t_s = acc.ramp.duration_s + acc.hold.duration_s;
    p.cruise_t_s = cruise.duration_s;
    p.decel_t_s = dec.ramp.duration_s + dec.hold.duration_s;
    p.s_curve = cfg.s_curve;
    p
}

/// Distances below this are none (`EPSILON_DISTANCE`, 1e-6 mm, precise_stepping.hpp), m.
const EPSILON_DISTANCE_M: f64 = 1e-9;

/// Prusa-Firmware-Buddy's precise stepping (`append_move_segments_to_queue`,
/// lib/Marlin/Marlin/src/feature/precise_stepping/precise_stepping.cpp): the block's
/// `initial_speed`, `nominal_speed`, `final_speed` and `acceleration` as they are, up
/// to the nominal speed, on at it, down to the exit; a block too short to reach it
/// turns where the two ramps meet. Distances under `EPSILON_DISTANCE` are none.
fn precise(b: &Block, start_v: f64, end_v: f64) -> PlannedMove {
    let (l, a) = (b.millimeters, b.acceleration);
    let mut cruise_v = b.nominal_speed_sqr.sqrt();
    let to_cruise = |from: f64, cruise: f64| {
        let d = (cruise * cruise - from * from) / (2.0 * a);
        if d < EPSILON_DISTANCE_M { 0.0 } else { d }
    };
    let mut accel_d = to_cruise(start_v, cruise_v);
    let mut decel_d = to_cruise(end_v, cruise_v);
    let mut cruise_d = l - accel_d - decel_d;
    if cruise_d < EPSILON_DISTANCE_M {
        let meet = (2.0 * l * a + end_v * end_v - start_v * start_v) / (4.0 * a);
        accel_d = if meet <= EPSILON_DISTANCE_M {
            0.0
        } else if meet > l - EPSILON_DISTANCE_M {
            l
        } else {
            meet
        };
        decel_d = (l - accel_d).max(0.0);
        cruise_d = 0.0;
        cruise_v = (2.0 * accel_d * a + start_v * start_v).sqrt();
    }
    let acc = if accel_d != 0.0 {
        Phase::linear((cruise_v - start_v) / a, start_v, a)
    } else {
        Phase::constant(0.0, start_v)
    };
    let cruise = if cruise_d != 0.0 {
        Phase::constant(cruise_d / cruise_v, cruise_v)
    } else {
        Phase::constant(0.0, cruise_v)
    };
    let dec = if decel_d != 0.0 {
        Phase::linear((cruise_v - end_v) / a, cruise_v, -a)
    } else {
        Phase::constant(0.0, cruise_v)
    };
    let phases = [acc, cruise, dec];
    let mut p = PlannedMove::new(b.seq, b.start_m, b.axes_r, l, &phases);
    p.start_speed_m_s = start_v;
    p.cruise_speed_m_s = cruise_v;
    p.end_speed_m_s = if decel_d != 0.0 { end_v } else { cruise_v };
    p.accel_m_s2 = a;
    p.decel_m_s2 = a;
    p.accel_t_s = acc.duration_s;
    p.cruise_t_s = cruise.duration_s;
    p.decel_t_s = dec.duration_s;
    p.s_curve = false;
    p
}

/// A rate ramp ended at a step count: the (possibly cut-short) ramp, the hold at the
/// target rate after it, and the rate at the end. Rates in steps/s, "distances" in steps.
#[derive(Debug, Clone, Copy)]
struct Ramp {
    ramp: Phase,
    hold: Phase,
    end_rate: f64,
}

/// Run `steps` steps starting at rate `from`, ramping at `accel` (steps/s^2) towards `to`
/// (`up`: accelerating) with `shape`, then holding `to`. A target on the wrong side of
/// `from` is taken at once, as the stepper's clamps do.
fn ramp(steps: f64, from: f64, to: f64, up: bool, accel: f64, shape: RampShape) -> Ramp {
    let none = Phase::constant(0.0, from);
    if !(steps > 0.0) {
        return Ramp {
            ramp: none,
            hold: none,
            end_rate: from,
        };
    }
    if (up && to <= from) || (!up && to >= from) {
        return Ramp {
            ramp: Phase::constant(0.0, to),
            hold: Phase::constant(steps / to, to),
            end_rate: to,
        };
    }
    let dv = to - from;
    let t_full = dv.abs() / accel;
    let full = Phase {
        duration_s: t_full,
        v0_m_s: from,
        dv_m_s: dv,
        ramp_s: t_full,
        shape,
    };
    let d_full = 0.5 * (from + to) * t_full;
    if steps >= d_full {
        return Ramp {
            ramp: full,
            hold: Phase::constant((steps - d_full) / to, to),
            end_rate: to,
        };
    }
    let tau = match shape {
        RampShape::Linear => {
            let disc = if up {
                from * from + 2.0 * accel * steps
            } else {
                (from * from - 2.0 * accel * steps).max(0.0)
            };
            2.0 * steps / (from + disc.sqrt())
        }
        RampShape::Bezier => time_to_cover(&full, steps),
    };
    let cut = Phase {
        duration_s: tau,
        ..full
    };
    Ramp {
        ramp: cut,
        hold: Phase::constant(0.0, to),
        end_rate: cut.end_speed_m_s(),
    }
}

/// The time at which `phase` (speed > 0 throughout) has covered `distance`: Newton's
/// method safeguarded by bisection on `[0, ramp_s]`.
fn time_to_cover(phase: &Phase, distance: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, phase.ramp_s);
    let mut t = distance / (phase.v0_m_s + 0.5 * phase.dv_m_s).max(f64::MIN_POSITIVE);
    for _ in 0..100 {
        if !(t > lo && t < hi) {
            t = 0.5 * (lo + hi);
        }
        let st = phase.state_at(t);
        let err = st.s_m - distance;
        if err > 0.0 {
            hi = t;
        } else {
            lo = t;
        }
        if err.abs() <= 1e-12 * distance || hi - lo <= 1e-15 * phase.ramp_s {
            break;
        }
        t -= err / st.v_m_s;
    }
    t.clamp(0.0, phase.ramp_s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cut_bezier_ramp_covers_the_asked_steps() {
        let r = ramp(100.0, 8000.0, 120.0, false, 240_000.0, RampShape::Bezier);
        assert!((r.ramp.distance_m() - 100.0).abs() < 1e-9);
        assert!(r.end_rate > 120.0 && r.end_rate < 8000.0);
        let l = ramp(100.0, 8000.0, 120.0, false, 240_000.0, RampShape::Linear);
        assert!((l.ramp.distance_m() - 100.0).abs() < 1e-9);
    }
}
