//! Rest-to-rest planning time: settle's S-curve and trapezoid vs rsruckig on the same
//! random problems (drawn like the Ruckig paper).

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rsruckig::prelude::*;
use settle_planner::{Limits, ProfileKind};

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
    for kind in ProfileKind::ALL {
        g.bench_function(kind.name(), |b| {
            b.iter(|| {
                for &(d, v, a, j) in &probs {
                    let lim = Limits::new(v, a, Some(j)).expect("limits");
                    black_box(kind.rest_to_rest(0.0, black_box(d), &lim).expect("plan"));
                }
            })
        });
    }
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
}

criterion_group!(benches, bench);
criterion_main!(benches);
