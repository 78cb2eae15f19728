//! MuJoCo backend on a multi-body printer axis (NEMA17 rotor -- GT2 belt -- carriage --
//! mount -- toolhead): against the exact linear solution (matrix exponential of
//! `Lumped::linearised`), with position-dependent belt stiffness against an independent
//! fine RK4 written here, with a driver torque on a free rotor, bit-identical repeats, and
//! the errors a caller can hit.

use crate::mujoco_support::{
    Exact, Interval, MujocoOne, OneAxis, belt_spans, printer_axis, rk4_interval, schedule,
};
use settle_planner::{Limits, Profile, Sample, State, scurve, trapezoid};
use settle_sim::Mode;
use settle_sim::SimError;
use settle_sim::lumped::{Lumped, Stiffness};
use settle_sim::mujoco::{MujocoConfig, MujocoModel, MujocoPlant};

const DT: f64 = 1e-3;
const R_PULLEY: f64 = 20.0 * 0.002 / std::f64::consts::TAU;

fn moves(d: f64) -> Vec<(&'static str, Profile)> {
    let trap = Limits::new(0.3, 5.0, None).expect("limits");
    let sc = Limits::new(0.3, 5.0, Some(300.0)).expect("limits");
    vec![
        (
            "trapezoid",
            trapezoid::rest_to_rest(0.0, d, &trap).expect("plan"),
        ),
        ("s-curve", scurve::rest_to_rest(0.0, d, &sc).expect("plan")),
    ]
}

/// MuJoCo through the Plant trait: coordinates after every interval.
fn mujoco_trace(l: &Lumped, profile: &Profile, intervals: &[Interval]) -> Vec<Vec<f64>> {
    let plant = MujocoOne::new(l, MujocoConfig::default());
    trace_on(&plant, profile, intervals)
}

fn trace_on(plant: &MujocoOne, profile: &Profile, intervals: &[Interval]) -> Vec<Vec<f64>> {
    let mut st = plant.initial_state(&profile.start());
    intervals
        .iter()
        .map(|iv| {
            plant.step(&mut st, &iv.cmd, iv.h);
            st.q().to_vec()
        })
        .collect()
}

/// Largest |a - b| of one coordinate over two traces.
fn max_diff(a: &[Vec<f64>], b: &[Vec<f64>], i: usize) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x[i] - y[i]).abs())
        .fold(0.0f64, f64::max)
}

/// Largest toolhead deflection |q_toolhead - x_cmd| over a trace.
fn peak_deflection(trace: &[Vec<f64>], profile: &Profile, intervals: &[Interval]) -> f64 {
    trace
        .iter()
        .zip(intervals)
        .map(|(q, iv)| (q[2] - profile.state_at(iv.t0 + iv.h).p).abs())
        .fold(0.0f64, f64::max)
}

#[test]
fn printer_axis_matches_the_matrix_exponential() {
    let l = printer_axis(Stiffness::Constant(160e3), true);
    let model = MujocoModel::new(&l, MujocoConfig::default()).expect("model");
    // The linearised model's undamped modes, for the record.
    let lin = l.linearised(&[0.0; 3]);
    let kn = nalgebra::DMatrix::from_fn(3, 3, |i, j| {
        lin.k[(i, j)] / (lin.m[(i, i)] * lin.m[(j, j)]).sqrt()
    });
    let mut f: Vec<f64> = kn
        .symmetric_eigenvalues()
        .iter()
        .map(|w2| w2.sqrt() / std::f64::consts::TAU)
        .collect();
    f.sort_by(f64::total_cmp);
    eprintln!(
        "printer axis modes {f:.1?} Hz; |lambda|max {:.0} rad/s; MuJoCo step {:.3e} s",
        model.lambda_max(),
        model.nominal_step_s()
    );
    assert!(f[0] > 30.0 && f[0] < 50.0, "lowest mode {} Hz", f[0]);
    for d in [0.005, 0.1] {
        for (kind, profile) in moves(d) {
            let t_stop = profile.duration_s() + 0.25;
            let ivs = schedule(&profile, DT, t_stop);
            let mj = mujoco_trace(&l, &profile, &ivs);
            let mut exact = Exact::new(&lin, None);
            let (mut q, mut qd) = (vec![0.0; 3], vec![0.0; 3]);
            let reference: Vec<Vec<f64>> = ivs
                .iter()
                .map(|iv| {
                    exact.step(&mut q, &mut qd, &iv.cmd, 0.0, iv.h);
                    q.clone()
                })
                .collect();
            let peak = peak_deflection(&reference, &profile, &ivs);
            let rel_toolhead = max_diff(&mj, &reference, 2) / peak;
            let rel_carriage = max_diff(&mj, &reference, 1) / peak;
            // The rotor angle times r is its belt-side position (m).
            let rel_rotor = max_diff(&mj, &reference, 0) * R_PULLEY / peak;
            eprintln!(
                "{kind:>9} {d} m: peak deflection {peak:.3e} m; max error / peak: toolhead \
                 {rel_toolhead:.1e}, carriage {rel_carriage:.1e}, rotor {rel_rotor:.1e}"
            );
            for rel in [rel_toolhead, rel_carriage, rel_rotor] {
                assert!(rel < 0.03, "engines differ by {rel} of the peak deflection");
                assert!(rel < 2e-3, "error {rel} beyond the RK4 budget");
            }
        }
    }
}

#[test]
fn belt_spans_match_an_independent_fine_rk4() {
    let l = printer_axis(belt_spans(), true);
    // 0.2 m towards the idler: the short span goes from 0.25 m to 0.05 m and the belt
    // stiffens from 160 kN/m to 444 kN/m.
    for (kind, profile) in moves(0.2) {
        let t_stop = profile.duration_s() + 0.2;
        let ivs = schedule(&profile, DT, t_stop);
        let mj = mujoco_trace(&l, &profile, &ivs);
        let (mut q, mut qd) = (vec![0.0; 3], vec![0.0; 3]);
        let reference: Vec<Vec<f64>> = ivs
            .iter()
            .map(|iv| {
                rk4_interval(&l, &mut q, &mut qd, &iv.cmd, 0.0, iv.h, 64);
                q.clone()
            })
            .collect();
        let peak = peak_deflection(&reference, &profile, &ivs);
        let rel = max_diff(&mj, &reference, 2) / peak;
        let k_end = belt_spans().at(q[1]);
        eprintln!(
            "{kind:>9} 0.2 m with belt spans (k {:.0} -> {k_end:.0} N/m): peak deflection \
             {peak:.3e} m, toolhead error / peak {rel:.1e}",
            belt_spans().at(0.0)
        );
        assert!(k_end > 4e5);
        // The variation matters: a belt frozen at its start stiffness is visibly off.
        let frozen = mujoco_trace(
            &printer_axis(Stiffness::Constant(160e3), true),
            &profile,
            &ivs,
        );
        let rel_frozen = max_diff(&frozen, &reference, 2) / peak;
        eprintln!("          (frozen at the start stiffness: {rel_frozen:.1e})");
        assert!(rel_frozen > 1e3 * rel, "frozen {rel_frozen} vs {rel}");
        assert!(rel < 0.03, "engines differ by {rel}");
        assert!(rel < 2e-3, "error {rel} beyond the budget");
    }
}

#[test]
fn the_step_shrinks_where_the_belt_stiffens() {
    let l = printer_axis(belt_spans(), true);
    let model = MujocoModel::new(&l, MujocoConfig::default()).expect("model");
    let middle = model.state_at_rest(&State::default());
    let near_idler = model.state_at_rest(&State {
        p: 0.2,
        ..State::default()
    });
    let ratio = model.step_at(&middle) / model.step_at(&near_idler);
    // sqrt(444 kN/m / 160 kN/m) = 1.67.
    assert!((ratio - (belt_spans().at(0.2) / belt_spans().at(0.0)).sqrt()).abs() < 1e-9);
    assert_eq!(model.step_at(&middle), model.nominal_step_s());
    // At rest the belt is unstretched: rotor at x/r, carriage and toolhead at x.
    let q = near_idler.q();
    assert!((q[0] - 0.2 / R_PULLEY).abs() < 1e-9 && (q[1] - 0.2).abs() < 1e-12);
    assert!((q[2] - 0.2).abs() < 1e-12);
}

#[test]
fn driver_torque_on_a_free_rotor_matches_the_exact_solution() {
    // No driver spring: the rotor is positioned only by the torque the driver computes.
    let l = printer_axis(Stiffness::Constant(160e3), false);
    let model = MujocoModel::new(&l, MujocoConfig::default()).expect("model");
    // Rest with a rigid-body mode: unstretched couplings, toolhead at the command.
    let rest = model.rest_coordinates(0.05);
    assert!((rest[0] - 0.05 / R_PULLEY).abs() < 1e-9, "{rest:?}");
    assert!((rest[1] - 0.05).abs() < 1e-12 && (rest[2] - 0.05).abs() < 1e-12);

    let mut sim = model
        .state(&[0.0; 3], &[0.0; 3], &State::default())
        .expect("state");
    let mut exact = Exact::new(&l.linearised(&[0.0; 3]), Some(0));
    let (mut q, mut qd) = (vec![0.0; 3], vec![0.0; 3]);
    let hold = Sample::default();
    let mut worst = 0.0f64;
    let mut peak = 0.0f64;
    // 20 ms of +0.05 N m, 20 ms of -0.05 N m, then 100 ms free.
    for k in 0..140 {
        let torque = if k < 20 {
            0.05
        } else if k < 40 {
            -0.05
        } else {
            0.0
        };
        model.set_drive(&mut sim, torque).expect("driver input");
        assert_eq!(sim.drive(), torque);
        model.advance(&mut sim, &hold, DT).expect("step");
        exact.step(&mut q, &mut qd, &hold, torque, DT);
        for (i, (got, want)) in sim.q().iter().zip(&q).enumerate() {
            let scale = if i == 0 { R_PULLEY } else { 1.0 };
            worst = worst.max((got - want).abs() * scale);
        }
        peak = peak.max(q[2].abs());
    }
    eprintln!("free rotor, +-0.05 N m: toolhead travel {peak:.3e} m, max error {worst:.2e} m");
    assert!(peak > 1e-3);
    assert!(worst < 1e-6 * peak, "max error {worst} m");
}

#[test]
fn repeated_runs_are_bit_identical() {
    let l = printer_axis(belt_spans(), true);
    let (_, profile) = moves(0.1).remove(1);
    let ivs = schedule(&profile, DT, profile.duration_s() + 0.1);
    let a = mujoco_trace(&l, &profile, &ivs);
    let b = mujoco_trace(&l, &profile, &ivs);
    assert!(
        a.iter()
            .flatten()
            .zip(b.iter().flatten())
            .all(|(x, y)| x.to_bits() == y.to_bits())
    );
}

#[test]
fn errors_are_reported_not_hidden() {
    // A driver force on a model without a driver input.
    let modes = Lumped::from_modes(&[Mode::new(40.0, 0.05, 1.0).expect("mode")]).expect("lumped");
    let model = MujocoModel::new(&modes, MujocoConfig::default()).expect("model");
    let mut sim = model.state_at_rest(&State::default());
    assert!(matches!(
        model.set_drive(&mut sim, 1.0),
        Err(SimError::InvalidModel { .. })
    ));
    assert!(matches!(
        model.advance(&mut sim, &Sample::default(), f64::NAN),
        Err(SimError::InvalidStep { .. })
    ));
    assert!(model.state(&[0.0, 0.0], &[0.0], &State::default()).is_err());
    // An invalid lumped model.
    let mut bad = modes.clone();
    bad.bodies[0].inertia = -1.0;
    assert!(matches!(
        MujocoModel::new(&bad, MujocoConfig::default()),
        Err(SimError::InvalidModel { .. })
    ));
    // A step far beyond RK4's stability limit (|lambda h| = 13 on a 2 kHz mode) diverges:
    // the run stops with an error instead of MuJoCo silently resetting the state.
    let stiff = Lumped::from_modes(&[Mode::new(2000.0, 0.0, 1.0).expect("mode")]).expect("lumped");
    let config = MujocoConfig {
        max_lambda_h: 100.0,
        ..MujocoConfig::default()
    };
    let model = MujocoModel::new(&stiff, config).expect("model");
    assert_eq!(model.nominal_step_s(), 1e-3);
    let mut sim = model
        .state(&[1e-3], &[0.0], &State::default())
        .expect("state");
    let err = (0..10_000)
        .find_map(|_| model.advance(&mut sim, &Sample::default(), DT).err())
        .expect("an unstable run must fail");
    assert!(matches!(err, SimError::NonFinite { .. }), "{err}");
}

#[test]
fn the_mjcf_maps_every_part_of_the_lumped_model() {
    let l = printer_axis(belt_spans(), true);
    let model = MujocoModel::new(&l, MujocoConfig::default()).expect("model");
    let x = model.mjcf();
    // Rotor as a hinge with its inertia as armature (all but a 1/1024 token on the body).
    assert!(x.contains("name=\"q0_rotor\" type=\"hinge\""), "{x}");
    assert!(x.contains(&format!("armature=\"{:e}\"", 6.8e-6 - 6.8e-6 / 1024.0)));
    assert!(x.contains("name=\"q1_carriage\" type=\"slide\""));
    // Couplings as fixed tendons with the gains as coefficients; the command as a joint.
    assert!(x.contains(&format!(
        "<joint joint=\"command\" coef=\"{:e}\"/>",
        -1.0 / R_PULLEY
    )));
    assert!(x.contains(&format!(
        "<joint joint=\"q0_rotor\" coef=\"{:e}\"/>",
        -R_PULLEY
    )));
    assert!(x.contains("<motor name=\"drive\" joint=\"q0_rotor\""));
    // The belt: its mid-travel stiffness on the tendon, the rest through an actuator.
    assert!(x.contains("stiffness=\"1.6e5\""), "{x}");
    assert!(x.contains("tendon=\"c1_belt\" gaintype=\"affine\" gainprm=\"0 1 0\""));
    assert!(x.contains("integrator=\"RK4\""));
    assert_eq!(x.matches("<fixed ").count(), 3);
    // The lumped inertia reaches MuJoCo: a torque on the rotor alone accelerates it at T/J.
    let free = Lumped {
        couplings: vec![],
        ..printer_axis(Stiffness::Constant(1.0), false)
    };
    let model = MujocoModel::new(&free, MujocoConfig::default()).expect("model");
    let mut sim = model
        .state(&[0.0; 3], &[0.0; 3], &State::default())
        .expect("state");
    model.set_drive(&mut sim, 0.01).expect("drive");
    model
        .step(&mut sim, &Sample::default(), 1e-3)
        .expect("step");
    let expect = 0.01 / 6.8e-6 * 1e-3;
    assert!(
        (sim.qd()[0] - expect).abs() < 1e-12 * expect,
        "{}",
        sim.qd()[0]
    );
}

#[test]
fn plants_can_run_on_worker_threads() {
    fn send_sync<T: Send + Sync>() {}
    fn send<T: Send>() {}
    send_sync::<MujocoPlant>();
    send_sync::<MujocoModel>();
    send::<settle_sim::mujoco::MujocoSim>();
    // Two threads running one shared plant at once give the numbers of a lone run.
    let plant = MujocoOne::new(&printer_axis(belt_spans(), true), MujocoConfig::default());
    let (_, profile) = moves(0.05).remove(1);
    let ivs = schedule(&profile, DT, profile.duration_s() + 0.05);
    let alone = trace_on(&plant, &profile, &ivs);
    let (a, b) = std::thread::scope(|s| {
        let a = s.spawn(|| trace_on(&plant, &profile, &ivs));
        let b = s.spawn(|| trace_on(&plant, &profile, &ivs));
        (a.join().expect("thread"), b.join().expect("thread"))
    });
    assert_eq!(alone, a);
    assert_eq!(alone, b);
}
