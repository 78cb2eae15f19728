//! The simulation driver's batches across breakpoints ([`Driver::across_breakpoints`]: the
//! modal plant takes a whole step holding breakpoints, each breakpoint one more term of
//! the exact solution) against steps split at every breakpoint (the exact transition of
//! each piece): the same samples, the toolhead the same to rounding, on random piecewise
//! commands (jerk changes, acceleration steps, segments of zero length, breakpoints on
//! sample instants) over machines given by their modes (one to four, 15-300 Hz, zeta
//! 0.01-0.3) and printer_xy's physical axes, at 1-10 kHz; and where the step is too long
//! for the series (a stiff mode at a low rate) the plant declines and the driver splits
//! the steps: bit for bit the split run.
//!
//! The tolerance: both are the exact solution of the same linear model, rounded
//! differently. The toolhead is a sum of body positions around a command of up to a few
//! cm, whose unit in the last place is a few 1e-18 m; 1e-16 m is some thirty of them
//! (the 24 cases differ by 2e-17 m at most).

use std::ops::ControlFlow;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use settle::execute::driver::{Driver, Samples, Sink};
use settle_planner::{Profile, Segment, State, Trajectory};
use settle_sim::{AxisModel, DriverMode, ModalPlant, Mode};

/// Every sample's index and toolhead positions.
#[derive(Default)]
struct Record {
    samples: Vec<(u64, Vec<f64>)>,
}

impl Sink for Record {
    fn samples(&mut self, b: &Samples<'_>) -> ControlFlow<usize> {
        for i in 0..b.count {
            self.samples
                .push((b.k0 + i as u64, b.positions(i).1.to_vec()));
        }
        ControlFlow::Continue(())
    }
}

/// A random piecewise command of about `duration_s`: jerk segments, acceleration steps
/// (some of zero length), segments on the sample grid `dt` now and then.
fn random_profile(rng: &mut ChaCha8Rng, duration_s: f64, dt: f64) -> Profile {
    let mut segments = Vec::new();
    let mut t = 0.0;
    while t < duration_s {
        let d = match rng.random_range(0..6) {
            0 => 0.0,
            1 => dt * rng.random_range(1..4) as f64,
            _ => rng.random_range(0.0..4.0 * dt),
        };
        segments.push(if rng.random_bool(0.3) {
            Segment::Accel {
                duration_s: d,
                accel: rng.random_range(-5.0..5.0),
            }
        } else {
            Segment::Jerk {
                duration_s: d,
                jerk: rng.random_range(-3000.0..3000.0),
            }
        });
        t += d;
    }
    Profile::new(
        State {
            p: rng.random_range(-0.02..0.02),
            v: rng.random_range(-0.05..0.05),
            a: 0.0,
        },
        segments,
    )
    .expect("profile")
}

fn modes_axis(rng: &mut ChaCha8Rng, name: &str) -> AxisModel {
    let n = rng.random_range(1..=4);
    let modes: Vec<Mode> = (0..n)
        .map(|_| {
            Mode::new(
                rng.random_range(15.0..300.0),
                rng.random_range(0.01..0.3),
                rng.random_range(0.1..1.0),
            )
            .expect("mode")
        })
        .collect();
    AxisModel::from_modes(name, &modes).expect("axis")
}

/// Follow `traj` from rest on a fresh modal plant, across breakpoints or split at them.
fn run(axes: &[AxisModel], traj: &Trajectory, dt: f64, t0: f64, across: bool) -> Record {
    let plant = ModalPlant::new(axes.to_vec(), dt).expect("plant");
    let names: Vec<String> = axes.iter().map(|a| a.name.clone()).collect();
    let starts: Vec<State> = traj.axes().iter().map(Profile::start).collect();
    let mut d = Driver::new(&plant, &names, &starts, 1.0 / dt, t0, false).expect("driver");
    if across {
        d = d.across_breakpoints();
    }
    let mut rec = Record::default();
    d.follow(traj, t0, true, &mut rec).expect("runs");
    rec
}

#[test]
fn batches_across_breakpoints_agree_with_split_steps() {
    let mut rng = ChaCha8Rng::seed_from_u64(0xb4ea);
    let printer = settle::workflows::gcode::resolve_machine("printer_xy")
        .expect("preset")
        .compile(DriverMode::Linear)
        .expect("axes");
    for case in 0..24 {
        let dt = 1.0 / [1000.0, 2000.0, 5000.0, 10000.0][case % 4];
        let axes: Vec<AxisModel> = if case % 3 == 2 {
            printer.clone()
        } else {
            vec![modes_axis(&mut rng, "x"), modes_axis(&mut rng, "y")]
        };
        let traj = Trajectory::new(
            (0..axes.len())
                .map(|_| random_profile(&mut rng, 0.15, dt))
                .collect(),
        )
        .expect("trajectory");
        // The trajectory starts between two samples of the clock.
        let t0 = rng.random_range(0.0..dt);
        let split = run(&axes, &traj, dt, t0, false);
        let across = run(&axes, &traj, dt, t0, true);
        assert_eq!(split.samples.len(), across.samples.len(), "case {case}");
        for ((ka, a), (kb, b)) in split.samples.iter().zip(&across.samples) {
            assert_eq!(ka, kb, "case {case}");
            for (x, y) in a.iter().zip(b) {
                assert!(
                    (x - y).abs() <= 1e-16,
                    "case {case}, sample {ka}: split {x} vs across {y} ({:e} m)",
                    x - y
                );
            }
        }
    }
}

/// A 2 kHz mode at 200 Hz sampling: a step is too long for the series (`|A| dt` about
/// 60), the plant declines and the driver splits: the same run bit for bit.
#[test]
fn a_step_too_long_for_the_series_is_split_as_before() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let axes = vec![
        AxisModel::from_modes("x", &[Mode::new(2000.0, 0.05, 1.0).expect("mode")]).expect("axis"),
    ];
    let dt = 1.0 / 200.0;
    let traj = Trajectory::new(vec![random_profile(&mut rng, 0.3, dt)]).expect("trajectory");
    let split = run(&axes, &traj, dt, 0.0, false);
    let across = run(&axes, &traj, dt, 0.0, true);
    let bits = |r: &Record| -> Vec<(u64, Vec<u64>)> {
        r.samples
            .iter()
            .map(|(k, v)| (*k, v.iter().map(|x| x.to_bits()).collect()))
            .collect()
    };
    assert_eq!(bits(&split), bits(&across));
}
