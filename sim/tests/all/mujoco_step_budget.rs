//! The full stepper driver's step on MuJoCo: RK4's `|lambda| h <= 0.2` on the MJCF model
//! (lumped springs and the driver's tendon), with the detent held at the predicted
//! mid-step like the rest of the driver torque, not counted as an RK4 spring. On the
//! `printer_xy` preset's Y axis that is one MuJoCo step per 10 kHz sample instead of two;
//! this shows what it costs: the post-move ringing (frequency by matrix pencil, residual
//! peak) against a 4x smaller step, within the `settle validate` thresholds.

use crate::common::run;
use crate::lean_support::run_lean;
use settle_planner::{Limits, ProfileKind};
use settle_sim::mujoco::{MujocoConfig, MujocoPlant};
use settle_sim::{DriverMode, Observation};

/// `settle validate`'s frequency threshold (%).
const FREQUENCY_PCT: f64 = 0.5;
/// `settle validate`'s residual threshold (%).
const RESIDUAL_PCT: f64 = 2.0;
const DT: f64 = 1e-4;

/// The toolhead error after the move (m), every sample.
fn post_move(trace: &[(f64, Vec<Observation>)], t_end: f64, target: f64) -> Vec<f64> {
    trace
        .iter()
        .filter(|(t, _)| *t >= t_end - 1e-12)
        .map(|(_, o)| o[0].toolhead_m - target)
        .collect()
}

/// The ringing after the move (a free decay about the microstep and detent rest offset:
/// frequency and damping by matrix pencil over the first 0.12 s) and the residual peak of
/// `a` against the reference `b`, printed and asserted within `settle validate`'s
/// frequency and residual thresholds.
fn compare(label: &str, a: &[f64], b: &[f64]) {
    let fit = |e: &[f64]| {
        let y: Vec<f64> = e.iter().take(1200).step_by(2).copied().collect();
        settle_identify::fit::pencil::fit(&y, 2.0 * DT, 8).expect("pencil fit")
    };
    let osc = |m: &[settle_identify::fit::pencil::MeasuredMode]| {
        *m.iter()
            .find(|m| m.frequency_hz > 5.0)
            .expect("an oscillatory mode")
    };
    let (ma, mb) = (osc(&fit(a)), osc(&fit(b)));
    let peak = |e: &[f64]| e.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let (ra, rb) = (peak(a), peak(b));
    let df = (ma.frequency_hz / mb.frequency_hz - 1.0) * 100.0;
    let dr = (ra / rb - 1.0) * 100.0;
    eprintln!(
        "{label}: ringing {:.3} / {:.3} Hz ({df:+.4} %), damping {:.4} / {:.4}, residual {:.3} / {:.3} um ({dr:+.2} %)",
        ma.frequency_hz,
        mb.frequency_hz,
        ma.damping_ratio,
        mb.damping_ratio,
        ra * 1e6,
        rb * 1e6
    );
    assert!(df.abs() <= FREQUENCY_PCT, "{label}: frequency {df} %");
    assert!(dr.abs() <= RESIDUAL_PCT, "{label}: residual {dr} %");
}

#[test]
fn full_driver_default_step_matches_a_4x_smaller_one_on_the_printer_y_axis() {
    let lim = Limits::new(0.3, 3.0, Some(100.0)).expect("limits");
    let axis = crate::common::printer_preset(true)
        .compile(DriverMode::Full)
        .expect("y");
    let plant = |max_lambda_h: f64| {
        MujocoPlant::new(
            vec![axis.clone()],
            MujocoConfig {
                max_lambda_h,
                ..MujocoConfig::default()
            },
        )
        .expect("plant")
    };
    let (coarse, fine) = (plant(0.2), plant(0.05));
    let linear = MujocoPlant::new(
        vec![
            crate::common::printer_preset(true)
                .compile(DriverMode::Linear)
                .expect("y"),
        ],
        MujocoConfig::default(),
    )
    .expect("linear");
    let h = coarse.model(0).nominal_step_s();
    eprintln!(
        "full driver step {:.2} us (linear driver {:.2} us), 4x smaller {:.2} us",
        h * 1e6,
        linear.model(0).nominal_step_s() * 1e6,
        fine.model(0).nominal_step_s() * 1e6
    );
    // The same step as the linear driver: the detent does not shorten it.
    assert_eq!(h, linear.model(0).nominal_step_s());
    for kind in [ProfileKind::Trapezoid, ProfileKind::SCurve] {
        let p = kind.rest_to_rest(0.0, 0.01, &lim).expect("plan");
        let (t_end, target) = (p.duration_s(), p.end().p);
        let a = post_move(
            &run(&coarse, std::slice::from_ref(&p), DT, 0.3),
            t_end,
            target,
        );
        let b = post_move(
            &run(&fine, std::slice::from_ref(&p), DT, 0.3),
            t_end,
            target,
        );
        compare(&format!("{kind}"), &a, &b);
    }
}

/// The lean path's long step on the same axis (`Plant::step_samples`: RK4 at
/// `|lambda| h <= 0.5`, 263.5 us = 2.6 samples per MuJoCo step, the samples in between
/// interpolated; the detent's own bound `w_e h <= 0.6` = 289 us does not bind) against the
/// same 4x smaller per-sample reference: ringing within 0.5 %, residual within 2 %.
#[test]
fn full_driver_long_step_matches_a_4x_smaller_one_on_the_printer_y_axis() {
    let lim = Limits::new(0.3, 3.0, Some(100.0)).expect("limits");
    let axis = crate::common::printer_preset(true)
        .compile(DriverMode::Full)
        .expect("y");
    let lean = MujocoPlant::new(vec![axis.clone()], MujocoConfig::default()).expect("plant");
    let fine = MujocoPlant::new(
        vec![axis],
        MujocoConfig {
            max_lambda_h: 0.05,
            ..MujocoConfig::default()
        },
    )
    .expect("plant");
    let h = lean.model(0).nominal_long_step_s().min(lean.long_cap_s(0));
    eprintln!(
        "long step {:.1} us ({:.2} samples), reference {:.2} us",
        h * 1e6,
        h / DT,
        fine.model(0).nominal_step_s() * 1e6
    );
    assert!(h > 2.0 * DT, "the long step spans more than two samples");
    for kind in [ProfileKind::Trapezoid, ProfileKind::SCurve] {
        let p = kind.rest_to_rest(0.0, 0.01, &lim).expect("plan");
        let (t_end, target) = (p.duration_s(), p.end().p);
        let one = std::slice::from_ref(&p);
        let a = post_move(&run_lean(&lean, one, DT, 0.3), t_end, target);
        let b = post_move(&run(&fine, one, DT, 0.3), t_end, target);
        compare(&format!("{kind} (lean)"), &a, &b);
    }
}
