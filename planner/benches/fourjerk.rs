//! Planning time of the four-jerk planner (any state, four independent jerks) and the
//! TMC4361A S-ramp, on fixed seeded random problems:
//!
//! - `fourjerk_any_state_1000`: 1,000 problems from any start (p, v, a) to a target at rest,
//!   jerks drawn independently (ratios up to 40), DMAX independent of AMAX.
//! - `fourjerk_rest_to_rest_1000`: the same limits, rest to rest (the chip's case).
//! - `tmc_ramp_1000`: 1,000 chip ramps (VSTART/VSTOP, AMAX/DMAX, four BOWs).
//!
//! `cargo bench -p settle-planner --bench fourjerk`

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use settle_planner::State;
use settle_planner::fourjerk::{self, FourJerkLimits};
use settle_planner::tmc::ramp::{self, SRampParams};

struct Problem {
    start: State,
    target: f64,
    limits: FourJerkLimits,
}

fn problems() -> Vec<Problem> {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    (0..1000)
        .map(|_| {
            let (vmax, amax, dmax) = (
                rng.random_range(0.1..4.0),
                rng.random_range(0.1..4.0),
                rng.random_range(0.1..4.0),
            );
            let jerk = [0; 4].map(|_| rng.random_range(0.1..4.0));
            Problem {
                start: State {
                    p: rng.random_range(-8.0..8.0),
                    v: rng.random_range(-vmax..vmax),
                    a: rng.random_range(-dmax..amax),
                },
                target: rng.random_range(-8.0..8.0),
                limits: FourJerkLimits::new(vmax, amax, dmax, jerk).expect("limits"),
            }
        })
        .collect()
}

fn ramps() -> Vec<(f64, SRampParams)> {
    let mut rng = ChaCha8Rng::seed_from_u64(12);
    (0..1000)
        .map(|_| {
            let vmax = rng.random_range(0.1..4.0);
            let prm = SRampParams {
                vstart: rng.random_range(0.0..0.2) * vmax,
                vmax,
                vstop: rng.random_range(0.0..0.2) * vmax,
                amax: rng.random_range(0.1..4.0),
                dmax: rng.random_range(0.1..4.0),
                bow: [0; 4].map(|_| rng.random_range(0.1..4.0)),
            };
            (rng.random_range(5.0..20.0), prm)
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let ps = problems();
    c.bench_function("fourjerk_any_state_1000", |b| {
        b.iter(|| {
            for p in &ps {
                let target = State {
                    p: p.target,
                    v: 0.0,
                    a: 0.0,
                };
                let _ = black_box(fourjerk::plan(black_box(p.start), target, &p.limits));
            }
        })
    });
    c.bench_function("fourjerk_rest_to_rest_1000", |b| {
        b.iter(|| {
            for p in &ps {
                let d = p.target - p.start.p;
                let _ = black_box(fourjerk::rest_to_rest(black_box(p.start.p), d, &p.limits));
            }
        })
    });
    let rs = ramps();
    c.bench_function("tmc_ramp_1000", |b| {
        b.iter(|| {
            for (d, prm) in &rs {
                let _ = black_box(ramp::plan(0.0, black_box(*d), prm));
            }
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
