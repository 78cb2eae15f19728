//! MuJoCo backend speed: simulated seconds per wall second for a printer-like axis (NEMA17
//! rotor on a stiff-spring driver, GT2 belt with position-dependent span stiffness,
//! carriage, toolhead mount), stepped through the `Plant` trait at the harness's 10 kHz
//! sample rate and MuJoCo's RK4 at the validated step (|lambda h| <= 0.2), and for one
//! 40 Hz mode. Throughput is reported in simulated milliseconds ("elements") per second:
//! divide by 1000 for the real-time factor.
//!
//! Needs `--features mujoco` (scripts/setup-mujoco.sh once):
//! `cargo bench --features mujoco --bench mujoco`.

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use settle_planner::{Limits, Profile, scurve};
use settle_sim::Mode;
use settle_sim::lumped::{Body, Coupling, DofKind, Lumped, Node, Stiffness, Term};
use settle_sim::mujoco::{MujocoConfig, MujocoModel};

/// The harness's sample period (s).
const DT: f64 = 1e-4;

/// The printer axis of sim/tests/mujoco_support (rotor 6.8e-6 kg m^2, 12 N m/rad driver
/// spring, r = 6.37 mm, belt EA 20 kN over 0.5 m, carriage 0.2 kg, toolhead 0.5 kg on
/// 100 kN/m): modes 48, 158 and 282 Hz at mid-travel.
fn printer_axis() -> Lumped {
    let r = 20.0 * 0.002 / std::f64::consts::TAU;
    let t = |node, gain| Term { node, gain };
    let body = |name: &str, kind, inertia| Body {
        name: name.into(),
        kind,
        inertia,
    };
    Lumped {
        bodies: vec![
            body("rotor", DofKind::Angular, 6.8e-6),
            body("carriage", DofKind::Linear, 0.2),
            body("toolhead", DofKind::Linear, 0.5),
        ],
        couplings: vec![
            Coupling {
                name: "driver".into(),
                terms: vec![t(Node::Body(0), 1.0), t(Node::Command, -1.0 / r)],
                stiffness: Stiffness::Constant(12.0),
                damping: 9e-4,
            },
            Coupling {
                name: "belt".into(),
                terms: vec![t(Node::Body(1), 1.0), t(Node::Body(0), -r)],
                stiffness: Stiffness::BeltSpans {
                    ea_n: 20_000.0,
                    length_m: 0.5,
                    s0_m: 0.25,
                    carriage: 1,
                },
                damping: 7.2,
            },
            Coupling {
                name: "mount".into(),
                terms: vec![t(Node::Body(2), 1.0), t(Node::Body(1), -1.0)],
                stiffness: Stiffness::Constant(1.0e5),
                damping: 22.4,
            },
        ],
        output: vec![t(Node::Body(2), 1.0)],
        actuated: Some(0),
    }
}

/// One run: the move, then a hold until `t_stop`, sampled every DT (steps split at the
/// profile's breakpoints as the harness does). Returns the final toolhead position.
fn run(plant: &MujocoModel, profile: &Profile, t_stop: f64) -> f64 {
    let mut st = plant.state_at_rest(&profile.start());
    for (t0, s0, seg) in profile.iter() {
        let t1 = t0 + seg.duration_s();
        let mut t = t0;
        while t < t1 {
            let next = (((t / DT) + 1e-9).floor() + 1.0) * DT;
            let next = next.min(t1);
            plant
                .advance(&mut st, &seg.sample(&s0, t - t0), next - t)
                .expect("step");
            t = next;
        }
    }
    let end = profile.end();
    let hold = settle_planner::Sample {
        p: end.p,
        ..Default::default()
    };
    let mut t = profile.duration_s();
    while t < t_stop - 1e-12 {
        let h = DT.min(t_stop - t);
        plant.advance(&mut st, &hold, h).expect("step");
        t += h;
    }
    plant.toolhead_m(&st)
}

fn bench(c: &mut Criterion) {
    let lim = Limits::new(0.3, 5.0, Some(300.0)).expect("limits");
    let profile = scurve::rest_to_rest(0.0, 0.1, &lim).expect("plan");
    let t_stop = profile.duration_s() + 0.2;
    let mut g = c.benchmark_group("mujoco");
    g.throughput(Throughput::Elements((t_stop * 1e3).round() as u64));

    let axis = MujocoModel::new(&printer_axis(), MujocoConfig::default()).expect("plant");
    eprintln!(
        "printer axis: {:.3} s simulated per run, MuJoCo RK4 step {:.3e} s at mid-travel",
        t_stop,
        axis.nominal_step_s()
    );
    g.bench_function("printer_axis_scurve_100mm", |b| {
        b.iter(|| black_box(run(&axis, black_box(&profile), t_stop)))
    });

    let mode = Mode::new(40.0, 0.05, 1.0).expect("mode");
    let single = MujocoModel::new(
        &Lumped::from_modes(&[mode]).expect("lumped"),
        MujocoConfig::default(),
    )
    .expect("plant");
    g.bench_function("one_mode_40hz_scurve_100mm", |b| {
        b.iter(|| black_box(run(&single, black_box(&profile), t_stop)))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
