//! The stepper driver model on rapier: lost steps appear when the load exceeds the
//! pull-out torque and not below it; the full driver reduces to the linear spring when its
//! nonlinearities are switched off.

use crate::common::{nema17, printer_x, run};
use settle_planner::{Limits, Profile, ProfileKind, Segment, State};
use settle_sim::lumped::{Body, Coupling, DofKind, Lumped, Node, Stiffness, Term};
use settle_sim::stepper::Stepper;
use settle_sim::{AxisModel, DriverMode, Observation, RapierOptions, RapierPlant};

/// A bare motor (17HS4401 at 0.8 A rms, no detent) turning a viscous load
/// (`c` N m s/rad to ground), its command expressed in metres of a 20-tooth GT2 pulley.
fn motor_with_drag(c: f64) -> AxisModel {
    let mut m = printer_x();
    m.motor = nema17();
    m.motor.detent_torque_n_m = 0.0;
    let mut stepper: Stepper = m.stepper();
    stepper.microsteps = 256;
    AxisModel {
        name: "x".into(),
        lumped: Lumped {
            bodies: vec![Body {
                name: "rotor".into(),
                kind: DofKind::Angular,
                inertia: m.motor.rotor_inertia_g_cm2 * 1e-7,
            }],
            couplings: vec![Coupling {
                name: "drag".into(),
                terms: vec![Term {
                    node: Node::Body(0),
                    gain: 1.0,
                }],
                stiffness: Stiffness::Constant(0.0),
                damping: c,
            }],
            output: vec![Term {
                node: Node::Body(0),
                gain: 1.0 / stepper.rad_per_m,
            }],
            actuated: Some(0),
        },
        mode: DriverMode::Full,
        stepper: Some(stepper),
        carriage: None,
    }
}

/// Accelerate gently to `v` (m/s), cruise for 0.3 s, stop.
fn cruise(v: f64) -> Profile {
    let a = 0.5;
    let t_acc = v / a;
    Profile::new(
        State::default(),
        vec![
            Segment::Accel {
                duration_s: t_acc,
                accel: a,
            },
            Segment::Accel {
                duration_s: 0.3,
                accel: 0.0,
            },
            Segment::Accel {
                duration_s: t_acc,
                accel: -a,
            },
            Segment::Accel {
                duration_s: 0.0,
                accel: 0.0,
            },
        ],
    )
    .expect("profile")
}

/// At a constant 2 rad/s (12.7 mm/s; back-EMF 0.3 V of 24 V) the pull-out torque is
/// `Km I` (no detent). A drag of 0.95 of it holds the rotor at asin(0.95) = 72 electrical
/// degrees behind its field; 1.05 of it has no equilibrium and the rotor slips poles. The
/// reported count matches the steps the rotor actually fell behind.
#[test]
fn lost_steps_appear_above_the_pull_out_torque_and_not_below() {
    let omega = 2.0;
    for (share, expect_loss) in [(0.8, false), (0.95, false), (1.05, true), (1.3, true)] {
        let probe = motor_with_drag(0.0);
        let s = probe.stepper.clone().expect("stepper");
        let c = share * s.peak_torque_n_m() / omega;
        let axis = motor_with_drag(c);
        let v = omega / s.rad_per_m;
        let p = cruise(v);
        let plant = RapierPlant::new(vec![axis], RapierOptions::default()).expect("plant");
        let trace = run(&plant, std::slice::from_ref(&p), 1e-4, 0.1);
        let last: &Observation = &trace.last().expect("samples").1[0];
        let lost = last.lost_steps;
        let max_deg = last.max_load_angle_rad.expect("motor").to_degrees();
        // Steps actually behind: the rotor's final angle against the command's.
        let behind =
            (p.end().p * s.rad_per_m - last.motor_angle_rad.expect("motor")) / s.full_step_rad();
        eprintln!(
            "load {share:.2} x pull-out: max load angle {max_deg:.1} deg, reported {lost} lost steps, rotor {behind:.2} full steps behind"
        );
        if expect_loss {
            assert!(lost >= 4, "{share}: expected lost steps, got {lost}");
            // Each pole slip is 4 full steps; the count must match the real lag within
            // one pole pitch (the final load angle itself is less than one).
            assert!(
                (behind - f64::from(lost)).abs() <= 4.0,
                "{share}: reported {lost}, rotor {behind} full steps behind"
            );
        } else {
            assert_eq!(lost, 0, "{share}: no steps may be lost");
            let expect = share.asin().to_degrees();
            assert!(
                (max_deg - expect).abs() < 2.0,
                "{share}: load angle {max_deg} vs asin = {expect}"
            );
            assert!(behind.abs() < 0.1, "{share}: rotor {behind} full steps off");
        }
    }
}

/// Without detent and with 256 microsteps the full driver behaves like the linear spring
/// `k_theta = Km I Nr` at small load angles: residual vibration within 2 %.
#[test]
fn full_driver_reduces_to_the_linear_spring() {
    let lim = Limits::new(0.3, 3.0, Some(100.0)).expect("limits");
    let mut m = printer_x();
    m.motor.detent_torque_n_m = 0.0;
    m.driver.microsteps = 256;
    for kind in [ProfileKind::Trapezoid, ProfileKind::SCurve] {
        let p = kind.rest_to_rest(0.0, 0.01, &lim).expect("plan");
        let peak = |mode: DriverMode| {
            let plant = RapierPlant::new(
                vec![m.compile(mode).expect("compile")],
                RapierOptions::default(),
            )
            .expect("plant");
            let trace = run(&plant, std::slice::from_ref(&p), 1e-4, 0.3);
            trace
                .iter()
                .filter(|(t, _)| *t >= p.duration_s())
                .map(|(_, o)| (o[0].toolhead_m - p.end().p).abs())
                .fold(0.0, f64::max)
        };
        let (lin, full) = (peak(DriverMode::Linear), peak(DriverMode::Full));
        eprintln!(
            "{kind}: linear {:.3} um, full {:.3} um",
            lin * 1e6,
            full * 1e6
        );
        assert!((full - lin).abs() <= 0.02 * lin, "{kind}: {full} vs {lin}");
    }
}

/// Past the torque-speed curve (the back-EMF eats the supply) a fast move loses steps;
/// the same move slower does not.
#[test]
fn too_fast_for_the_supply_loses_steps() {
    let m = crate::common::stage_x();
    let axis = m.compile(DriverMode::Full).expect("compile");
    let lost = |vmax: f64| {
        let lim = Limits::new(vmax, 2.0, Some(200.0)).expect("limits");
        let p = ProfileKind::SCurve
            .rest_to_rest(0.0, 0.02, &lim)
            .expect("plan");
        let plant = RapierPlant::new(vec![axis.clone()], RapierOptions::default()).expect("plant");
        run(&plant, std::slice::from_ref(&p), 1e-4, 0.05)
            .last()
            .expect("samples")
            .1[0]
            .lost_steps
    };
    // 5 mm lead: 0.3 m/s is 377 rad/s, back-EMF 63 V against a 24 V supply.
    assert!(lost(0.3) > 0);
    assert_eq!(lost(0.04), 0);
}

/// The spring driver (linear spring to the microstep-quantised command) converges to the
/// linear driver as the microsteps get finer: at 256 microsteps (0.78 um on a 20-tooth
/// GT2 pulley) the residual is within 2 % (plus one microstep) of the continuous command's.
#[test]
fn spring_driver_converges_to_the_linear_one_with_fine_microsteps() {
    let lim = Limits::new(0.3, 3.0, Some(100.0)).expect("limits");
    let mut m = printer_x();
    m.driver.microsteps = 256;
    let step = m.stepper().microstep_m();
    for kind in [ProfileKind::Trapezoid, ProfileKind::SCurve] {
        let p = kind.rest_to_rest(0.0, 0.01, &lim).expect("plan");
        let peak = |mode: DriverMode| {
            let plant = RapierPlant::new(
                vec![m.compile(mode).expect("compile")],
                RapierOptions::default(),
            )
            .expect("plant");
            run(&plant, std::slice::from_ref(&p), 1e-4, 0.3)
                .iter()
                .filter(|(t, _)| *t >= p.duration_s())
                .map(|(_, o)| (o[0].toolhead_m - p.end().p).abs())
                .fold(0.0, f64::max)
        };
        let (lin, spring) = (peak(DriverMode::Linear), peak(DriverMode::Spring));
        eprintln!(
            "{kind}: linear {:.3} um, spring (256 microsteps) {:.3} um",
            lin * 1e6,
            spring * 1e6
        );
        assert!(
            (spring - lin).abs() <= 0.02 * lin + step,
            "{kind}: {spring} vs {lin}"
        );
    }
}
