//! The full stepper driver on MuJoCo, against the same driver on rapier: the printer axes
//! (both) follow S-curve and trapezoid moves within the engines threshold (3 %) of rapier,
//! and lost steps appear above the pull-out torque and not below it (mirrors
//! `stepper.rs`, which proves the driver model itself on rapier).

use crate::common::{nema17, printer_x, printer_y, run};
use crate::lean_support::run_lean;
use settle_planner::{Limits, Profile, ProfileKind, Segment, State};
use settle_sim::lumped::{Body, Coupling, DofKind, Lumped, Node, Stiffness, Term};
use settle_sim::mujoco::{MujocoConfig, MujocoPlant};
use settle_sim::stepper::Stepper;
use settle_sim::{AxisModel, DriverMode, Observation, Plant, RapierOptions, RapierPlant};

/// The engines threshold of `settle validate` (%).
const ENGINES_PCT: f64 = 3.0;

/// A bare motor (no detent, 256 microsteps) turning a viscous load of `c` N m s/rad.
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
    let seg = |duration_s, accel| Segment::Accel { duration_s, accel };
    Profile::new(
        State::default(),
        vec![seg(t_acc, a), seg(0.3, 0.0), seg(t_acc, -a), seg(0.0, 0.0)],
    )
    .expect("profile")
}

fn mujoco(axes: Vec<AxisModel>) -> MujocoPlant {
    MujocoPlant::new(axes, MujocoConfig::default()).expect("mujoco plant")
}

fn rapier(axes: Vec<AxisModel>) -> RapierPlant {
    RapierPlant::new(axes, RapierOptions::default()).expect("rapier plant")
}

/// At a constant 2 rad/s the pull-out torque is `Km I`: a drag of 0.80 / 0.95 of it holds
/// the rotor at asin(share) behind its field with nothing lost; 1.05 / 1.30 of it slips
/// poles, and the reported count matches the steps the rotor really fell behind. Rapier
/// reports the same counts.
#[test]
fn lost_steps_appear_on_mujoco_above_the_pull_out_torque_and_not_below() {
    let omega = 2.0;
    for (share, expect_loss) in [(0.8, false), (0.95, false), (1.05, true), (1.3, true)] {
        let s = motor_with_drag(0.0).stepper.expect("stepper");
        let c = share * s.peak_torque_n_m() / omega;
        let p = cruise(omega / s.rad_per_m);
        let last = |trace: Vec<(f64, Vec<Observation>)>| trace.last().expect("samples").1[0];
        let mj = last(run(
            &mujoco(vec![motor_with_drag(c)]),
            std::slice::from_ref(&p),
            1e-4,
            0.1,
        ));
        let ra = last(run(
            &rapier(vec![motor_with_drag(c)]),
            std::slice::from_ref(&p),
            1e-4,
            0.1,
        ));
        let lost = mj.lost_steps;
        let max_deg = mj.max_load_angle_rad.expect("motor").to_degrees();
        let behind =
            (p.end().p * s.rad_per_m - mj.motor_angle_rad.expect("motor")) / s.full_step_rad();
        eprintln!(
            "load {share:.2} x pull-out on MuJoCo: max load angle {max_deg:.1} deg, {lost} lost steps, rotor {behind:.2} full steps behind (rapier: {} lost, {:.1} deg)",
            ra.lost_steps,
            ra.max_load_angle_rad.expect("motor").to_degrees()
        );
        assert!(mj.currents_a.is_some(), "the full driver reports currents");
        if expect_loss {
            assert!(lost >= 4, "{share}: expected lost steps, got {lost}");
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
            assert_eq!(ra.lost_steps, 0);
        }
    }
}

/// Peak |toolhead - target| after the move (m) and the first time after which it stays
/// within `band_m` (s after the move end), of axis `i`.
fn residual_and_settle(
    trace: &[(f64, Vec<Observation>)],
    p: &Profile,
    i: usize,
    band_m: f64,
) -> (f64, f64) {
    let t_end = p.duration_s();
    let target = p.end().p;
    let post: Vec<(f64, f64)> = trace
        .iter()
        .filter(|(t, _)| *t >= t_end - 1e-12)
        .map(|(t, o)| (*t - t_end, (o[i].toolhead_m - target).abs()))
        .collect();
    let peak = post.iter().map(|x| x.1).fold(0.0, f64::max);
    let settle = post
        .iter()
        .rev()
        .find(|(_, e)| *e > band_m)
        .map_or(0.0, |(t, _)| *t);
    (peak, settle)
}

/// The printer's X and Y axes (Y with its beam and frame mode), the full driver with
/// detent and 16 microsteps, the varying belt: MuJoCo's residual and settle time (10 um)
/// within 3 % of rapier's on 10 mm S-curve and trapezoid moves, both axes moving at once.
///
/// Rapier applies the driver torque explicitly at each step start, which at its default
/// step is 2 % off on the trapezoid's residual here (128.7 um; 126.1 um converged, 10 ms
/// later settling); MuJoCo (tendon + mid-step torque) is 0.3 % off at its default. So
/// rapier runs with a 4x finer step (converged within 0.2 %) as the reference.
#[test]
fn full_driver_on_mujoco_matches_rapier_on_the_printer() {
    let lim = Limits::new(0.3, 3.0, Some(100.0)).expect("limits");
    let axes = vec![
        printer_x().compile(DriverMode::Full).expect("x"),
        printer_y().compile(DriverMode::Full).expect("y"),
    ];
    let h = rapier(axes.clone())
        .max_step_s(&[State::default(), State::default()])
        .expect("step");
    let ra = RapierPlant::new(
        axes.clone(),
        RapierOptions {
            max_step_s: Some(h / 4.0),
            ..RapierOptions::default()
        },
    )
    .expect("rapier plant");
    let mj = mujoco(axes);
    assert_eq!(mj.axes(), 2);
    for kind in [ProfileKind::SCurve, ProfileKind::Trapezoid] {
        let p = kind.rest_to_rest(0.0, 0.01, &lim).expect("plan");
        let profiles = [p.clone(), p.clone()];
        let t_mj = run(&mj, &profiles, 1e-4, 0.3);
        let t_ra = run(&ra, &profiles, 1e-4, 0.3);
        for (i, name) in ["x", "y"].iter().enumerate() {
            let (r_mj, s_mj) = residual_and_settle(&t_mj, &p, i, 10e-6);
            let (r_ra, s_ra) = residual_and_settle(&t_ra, &p, i, 10e-6);
            let last = (
                &t_mj.last().expect("mj").1[i],
                &t_ra.last().expect("ra").1[i],
            );
            eprintln!(
                "{kind} {name}: residual MuJoCo {:.3} um, rapier {:.3} um ({:+.2} %); settle {:.1} / {:.1} ms; max load angle {:.1} / {:.1} deg",
                r_mj * 1e6,
                r_ra * 1e6,
                (r_mj - r_ra) / r_ra * 100.0,
                s_mj * 1e3,
                s_ra * 1e3,
                last.0.max_load_angle_rad.expect("motor").to_degrees(),
                last.1.max_load_angle_rad.expect("motor").to_degrees(),
            );
            assert!(
                (r_mj - r_ra).abs() <= ENGINES_PCT / 100.0 * r_ra,
                "{kind} {name}: residual {r_mj} vs {r_ra}"
            );
            assert!(
                (s_mj - s_ra).abs() <= (ENGINES_PCT / 100.0 * s_ra).max(1.001e-4),
                "{kind} {name}: settle {s_mj} vs {s_ra}"
            );
            assert_eq!((last.0.lost_steps, last.1.lost_steps), (0, 0));
        }
    }
}

/// Two runs of the full driver on MuJoCo are bit-identical.
#[test]
fn full_driver_on_mujoco_is_deterministic() {
    let lim = Limits::new(0.3, 3.0, Some(100.0)).expect("limits");
    let p = ProfileKind::SCurve
        .rest_to_rest(0.0, 0.01, &lim)
        .expect("plan");
    let plant = mujoco(vec![printer_y().compile(DriverMode::Full).expect("y")]);
    let a = run(&plant, std::slice::from_ref(&p), 1e-4, 0.05);
    let b = run(&plant, std::slice::from_ref(&p), 1e-4, 0.05);
    assert_eq!(a, b);
}

/// The same loads through the lean path (`Plant::step_samples`; the drag's `c / J` holds
/// the RK4 step to 22-36 us here, so the steps are shorter than the samples and not
/// aligned with them; the load angle is tracked at every step's end): the same lost-step
/// counts as the per-sample path, no loss below pull-out, and the largest load angle within
/// 2 degrees of asin(share) there.
#[test]
fn lost_steps_on_the_lean_path_match_the_per_sample_path() {
    let omega = 2.0;
    for (share, expect_loss) in [(0.8, false), (0.95, false), (1.05, true), (1.3, true)] {
        let s = motor_with_drag(0.0).stepper.expect("stepper");
        let c = share * s.peak_torque_n_m() / omega;
        let p = cruise(omega / s.rad_per_m);
        let plant = mujoco(vec![motor_with_drag(c)]);
        let lean = run_lean(&plant, std::slice::from_ref(&p), 1e-4, 0.1)
            .last()
            .expect("samples")
            .1[0];
        let per_sample = run(&plant, std::slice::from_ref(&p), 1e-4, 0.1)
            .last()
            .expect("samples")
            .1[0];
        let deg = |o: &Observation| o.max_load_angle_rad.expect("motor").to_degrees();
        let behind = |o: &Observation| {
            (p.end().p * s.rad_per_m - o.motor_angle_rad.expect("motor")) / s.full_step_rad()
        };
        eprintln!(
            "load {share:.2} x pull-out: lean {} lost, max load angle {:.2} deg, rotor {:.2} full steps behind; per-sample {} lost, {:.2} deg, {:.2} behind (long step {:.1} us)",
            lean.lost_steps,
            deg(&lean),
            behind(&lean),
            per_sample.lost_steps,
            deg(&per_sample),
            behind(&per_sample),
            plant
                .model(0)
                .nominal_long_step_s()
                .min(plant.long_cap_s(0))
                * 1e6
        );
        if expect_loss {
            assert!(lean.lost_steps >= 4, "{share}: expected lost steps");
            assert!((behind(&lean) - f64::from(lean.lost_steps)).abs() <= 4.0);
        } else {
            assert_eq!(lean.lost_steps, 0, "{share}: no steps may be lost");
            assert!((deg(&lean) - share.asin().to_degrees()).abs() < 2.0);
            assert!(behind(&lean).abs() < 0.1);
        }
        assert_eq!(lean.lost_steps, per_sample.lost_steps, "{share}");
    }
}

/// The printer's Y axis (fixture) with long lean steps (several samples per MuJoCo step):
/// a 20 mm trapezoid at 0.3 m/s and 3 m/s^2 keeps every step, at 1 m/s and 10 m/s^2 the
/// motor runs out of torque (back-EMF against the 24 V supply) and both paths report the
/// same lost steps; below pull-out the largest load angle is within 3 % of a reference
/// that samples it every 26 us (the per-sample path at a 4x smaller step). The lean path
/// takes it at the 25 us electrical sub-steps inside each long step (along the predicted
/// rotor path), as the load angle ripples with every microstep.
#[test]
fn lost_steps_on_the_printer_with_long_lean_steps() {
    let plant = mujoco(vec![printer_y().compile(DriverMode::Full).expect("y")]);
    let fine = MujocoPlant::new(
        vec![printer_y().compile(DriverMode::Full).expect("y")],
        MujocoConfig {
            max_lambda_h: 0.05,
            ..MujocoConfig::default()
        },
    )
    .expect("plant");
    let h = plant
        .model(0)
        .nominal_long_step_s()
        .min(plant.long_cap_s(0));
    for (speed, accel, expect_loss) in [(0.3, 3.0, false), (1.0, 10.0, true)] {
        let lim = Limits::new(speed, accel, None).expect("limits");
        let p = ProfileKind::Trapezoid
            .rest_to_rest(0.0, 0.02, &lim)
            .expect("plan");
        let one = std::slice::from_ref(&p);
        let lean = run_lean(&plant, one, 1e-4, 0.1).last().expect("lean").1[0];
        let per_sample = run(&plant, one, 1e-4, 0.1).last().expect("run").1[0];
        let reference = run(&fine, one, 1e-4, 0.1).last().expect("run").1[0];
        let deg = |o: &Observation| o.max_load_angle_rad.expect("motor").to_degrees();
        eprintln!(
            "{speed} m/s, {accel} m/s^2 (long step {:.1} us): lean {} lost, max load angle {:.2} deg; per-sample {} lost, {:.2} deg; reference {} lost, {:.2} deg",
            h * 1e6,
            lean.lost_steps,
            deg(&lean),
            per_sample.lost_steps,
            deg(&per_sample),
            reference.lost_steps,
            deg(&reference)
        );
        assert!(h > 2e-4, "long steps");
        if expect_loss {
            assert!(lean.lost_steps > 0);
            assert_eq!(lean.lost_steps, per_sample.lost_steps);
        } else {
            assert_eq!((lean.lost_steps, per_sample.lost_steps), (0, 0));
            assert!((deg(&lean) / deg(&reference) - 1.0).abs() < 0.03);
        }
    }
}
