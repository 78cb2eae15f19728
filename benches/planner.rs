//! Rest-to-rest planning time: settle's S-curve and trapezoid vs rsruckig on the same
//! random problems (drawn like the Ruckig paper).

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rsruckig::prelude::*;
use settle_planner::position::{Shape, to_state};
use settle_planner::sync::{Axis, Sync, plan};
use settle_planner::{Limits, ProfileKind, State, scurve, trapezoid};

fn problems() -> Vec<(f64, f64, f64, f64)> {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    (0..1000)
        .map(|_| {
            (
                rng.random_range(-8.0..8.0),
                rng.random_range(0.1..4.0),
                rng.random_range(0.1..4.0),
                rng.random_range(0.1..4.0),
            )
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let probs = problems();
    let mut g = c.benchmark_group("rest_to_rest_1000");
    g.bench_function("scurve_closed_form", |b| {
        b.iter(|| {
            for &(d, v, a, j) in &probs {
                let lim = Limits::new(v, a, Some(j)).expect("limits");
                black_box(scurve::rest_to_rest(0.0, black_box(d), &lim).expect("plan"));
            }
        })
    });
    g.bench_function("trapezoid_closed_form", |b| {
        b.iter(|| {
            for &(d, v, a, _) in &probs {
                let lim = Limits::new(v, a, None).expect("limits");
                black_box(trapezoid::rest_to_rest(0.0, black_box(d), &lim).expect("plan"));
            }
        })
    });
    g.bench_function("scurve_any_state", |b| {
        b.iter(|| {
            for &(d, v, a, j) in &probs {
                let lim = Limits::new(v, a, Some(j)).expect("limits");
                black_box(
                    ProfileKind::SCurve
                        .rest_to_rest(0.0, black_box(d), &lim)
                        .expect("plan"),
                );
            }
        })
    });
    g.bench_function("rsruckig", |b| {
        let mut otg = Ruckig::<1, ThrowErrorHandler>::new(None, 0.001);
        let mut input = InputParameter::new(None);
        let mut traj = Trajectory::new(None);
        b.iter(|| {
            for &(d, v, a, j) in &probs {
                input.target_position[0] = black_box(d);
                input.max_velocity[0] = v;
                input.max_acceleration[0] = a;
                input.max_jerk[0] = j;
                black_box(otg.calculate(&input, &mut traj).expect("solves"));
            }
        })
    });
    g.finish();

    // Any state to any target (Ruckig's random distribution, bounded draws).
    let mut rng = ChaCha8Rng::seed_from_u64(8);
    let states: Vec<(State, State, Limits)> = (0..1000)
        .map(|_| {
            let mut st = || State {
                p: rng.random_range(-8.0..8.0),
                v: rng.random_range(-1.0..1.0),
                a: rng.random_range(-1.0..1.0),
            };
            let (s, mut t) = (st(), st());
            t.a = 0.0;
            t.v *= 0.3;
            let lim = Limits::new(
                rng.random_range(1.5..4.0),
                rng.random_range(1.5..4.0),
                Some(rng.random_range(1.5..4.0)),
            )
            .expect("limits");
            (s, t, lim)
        })
        .collect();
    let mut g = c.benchmark_group("any_state_1000");
    g.bench_function("settle", |b| {
        b.iter(|| {
            for (s, t, lim) in &states {
                black_box(to_state(*s, *t, lim, Shape::JerkLimited).ok());
            }
        })
    });
    g.bench_function("rsruckig", |b| {
        let mut otg = Ruckig::<1, ThrowErrorHandler>::new(None, 0.001);
        let mut input = InputParameter::new(None);
        let mut traj = Trajectory::new(None);
        b.iter(|| {
            for (s, t, lim) in &states {
                input.current_position[0] = s.p;
                input.current_velocity[0] = s.v;
                input.current_acceleration[0] = s.a;
                input.target_position[0] = t.p;
                input.target_velocity[0] = t.v;
                input.target_acceleration[0] = t.a;
                input.max_velocity[0] = lim.vmax();
                input.max_acceleration[0] = lim.amax();
                input.max_jerk[0] = lim.jmax().unwrap_or(f64::INFINITY);
                black_box(otg.calculate(&input, &mut traj).ok());
            }
        })
    });
    g.bench_function("ruckig_official", |b| {
        let mut otg = ruckig::Ruckig::new_direct_and_offline(1);
        let mut input = ruckig::InputParameter::new(1);
        let mut traj = ruckig::Trajectory::new_direct(1);
        b.iter(|| {
            for (s, t, lim) in &states {
                input.current_position[0] = s.p;
                input.current_velocity[0] = s.v;
                input.current_acceleration[0] = s.a;
                input.target_position[0] = t.p;
                input.target_velocity[0] = t.v;
                input.target_acceleration[0] = t.a;
                input.max_velocity[0] = lim.vmax();
                input.max_acceleration[0] = lim.amax();
                input.max_jerk[0] = lim.jmax().unwrap_or(f64::INFINITY);
                black_box(otg.calculate(&mut input, &mut traj));
            }
        })
    });
    g.finish();

    // Three axes, time-synchronised: 300 problems.
    let axes: Vec<[Axis; 3]> = states
        .chunks_exact(3)
        .map(|c| {
            std::array::from_fn(|i| Axis {
                start: c[i].0,
                target: c[i].1,
                limits: c[i].2,
            })
        })
        .collect();
    let mut g = c.benchmark_group("three_dof_333");
    g.bench_function("settle", |b| {
        b.iter(|| {
            for a in &axes {
                black_box(plan(a, Shape::JerkLimited, Sync::Time).ok());
            }
        })
    });
    g.bench_function("rsruckig", |b| {
        let mut otg = Ruckig::<3, ThrowErrorHandler>::new(None, 0.001);
        let mut input = InputParameter::new(None);
        let mut traj = Trajectory::new(None);
        b.iter(|| {
            for a in &axes {
                for (i, x) in a.iter().enumerate() {
                    input.current_position[i] = x.start.p;
                    input.current_velocity[i] = x.start.v;
                    input.current_acceleration[i] = x.start.a;
                    input.target_position[i] = x.target.p;
                    input.target_velocity[i] = x.target.v;
                    input.target_acceleration[i] = x.target.a;
                    input.max_velocity[i] = x.limits.vmax();
                    input.max_acceleration[i] = x.limits.amax();
                    input.max_jerk[i] = x.limits.jmax().unwrap_or(f64::INFINITY);
                }
                black_box(otg.calculate(&input, &mut traj).ok());
            }
        })
    });
    g.bench_function("ruckig_official", |b| {
        let mut otg = ruckig::Ruckig::new_direct_and_offline(3);
        let mut input = ruckig::InputParameter::new(3);
        let mut traj = ruckig::Trajectory::new_direct(3);
        b.iter(|| {
            for a in &axes {
                for (i, x) in a.iter().enumerate() {
                    input.current_position[i] = x.start.p;
                    input.current_velocity[i] = x.start.v;
                    input.current_acceleration[i] = x.start.a;
                    input.target_position[i] = x.target.p;
                    input.target_velocity[i] = x.target.v;
                    input.target_acceleration[i] = x.target.a;
                    input.max_velocity[i] = x.limits.vmax();
                    input.max_acceleration[i] = x.limits.amax();
                    input.max_jerk[i] = x.limits.jmax().unwrap_or(f64::INFINITY);
                }
                black_box(otg.calculate(&mut input, &mut traj));
            }
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
