//! Planning time: settle vs rsruckig vs the official Ruckig (C++, `ruckig` crate) on the
//! same random problems, in the same run.
//!
//! - `rest_to_rest_1000`: settle's closed-form S-curve and trapezoid, the any-state planner
//!   on rest-to-rest moves, and rsruckig.
//! - `any_state_1000`: 1,000 one-axis problems from any state to any target (Ruckig's
//!   random distribution, bounded draws).
//! - `three_dof_333`: the same states as 333 three-axis problems, time-synchronised.
//!
//! On a machine shared with other work the groups' times drift with the load between one
//! function's measurement and the next. After the criterion groups, `interleaved` times
//! settle and rsruckig in alternating batches of the same problems (load drift then hits
//! both alike) and prints the ratio of the totals. Run it alone with
//! `cargo bench -p settle-planner --bench planner -- interleaved`.

use std::hint::black_box;
use std::time::Instant;

use criterion::{Criterion, criterion_group};
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

/// 1,000 any-state problems: (start, target, limits).
fn states() -> Vec<(State, State, Limits)> {
    let mut rng = ChaCha8Rng::seed_from_u64(8);
    (0..1000)
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
        .collect()
}

/// The same states, three to a problem.
fn three_axes(states: &[(State, State, Limits)]) -> Vec<[Axis; 3]> {
    states
        .chunks_exact(3)
        .map(|c| {
            std::array::from_fn(|i| Axis {
                start: c[i].0,
                target: c[i].1,
                limits: c[i].2,
            })
        })
        .collect()
}

fn settle_1dof(states: &[(State, State, Limits)]) {
    for (s, t, lim) in states {
        black_box(to_state(*s, *t, lim, Shape::JerkLimited).ok());
    }
}

fn settle_3dof(axes: &[[Axis; 3]]) {
    for a in axes {
        black_box(plan(a, Shape::JerkLimited, Sync::Time).ok());
    }
}

/// rsruckig with its reusable input and output.
struct Rs<const N: usize> {
    otg: Ruckig<N, ThrowErrorHandler>,
    input: InputParameter<N>,
    traj: Trajectory<N>,
}

impl<const N: usize> Rs<N> {
    fn new() -> Self {
        Self {
            otg: Ruckig::<N, ThrowErrorHandler>::new(None, 0.001),
            input: InputParameter::new(None),
            traj: Trajectory::new(None),
        }
    }

    fn solve(&mut self, axes: &[(State, State, Limits)]) {
        for (i, (s, t, lim)) in axes.iter().enumerate() {
            self.input.current_position[i] = s.p;
            self.input.current_velocity[i] = s.v;
            self.input.current_acceleration[i] = s.a;
            self.input.target_position[i] = t.p;
            self.input.target_velocity[i] = t.v;
            self.input.target_acceleration[i] = t.a;
            self.input.max_velocity[i] = lim.vmax();
            self.input.max_acceleration[i] = lim.amax();
            self.input.max_jerk[i] = lim.jmax().unwrap_or(f64::INFINITY);
        }
        black_box(self.otg.calculate(&self.input, &mut self.traj).ok());
    }
}

/// The official Ruckig with its reusable input and output.
struct Official {
    otg: ruckig::Ruckig,
    input: ruckig::InputParameter,
    traj: ruckig::Trajectory,
}

impl Official {
    fn new(dofs: usize) -> Self {
        Self {
            otg: ruckig::Ruckig::new_direct_and_offline(dofs),
            input: ruckig::InputParameter::new(dofs),
            traj: ruckig::Trajectory::new_direct(dofs),
        }
    }

    fn solve(&mut self, axes: &[(State, State, Limits)]) {
        for (i, (s, t, lim)) in axes.iter().enumerate() {
            self.input.current_position[i] = s.p;
            self.input.current_velocity[i] = s.v;
            self.input.current_acceleration[i] = s.a;
            self.input.target_position[i] = t.p;
            self.input.target_velocity[i] = t.v;
            self.input.target_acceleration[i] = t.a;
            self.input.max_velocity[i] = lim.vmax();
            self.input.max_acceleration[i] = lim.amax();
            self.input.max_jerk[i] = lim.jmax().unwrap_or(f64::INFINITY);
        }
        black_box(self.otg.calculate(&mut self.input, &mut self.traj));
    }
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
        let mut rs = Rs::<1>::new();
        b.iter(|| {
            for &(d, v, a, j) in &probs {
                let lim = Limits::new(v, a, Some(j)).expect("limits");
                let target = State {
                    p: black_box(d),
                    v: 0.0,
                    a: 0.0,
                };
                rs.solve(&[(State::default(), target, lim)]);
            }
        })
    });
    g.finish();

    let states = states();
    let mut g = c.benchmark_group("any_state_1000");
    g.bench_function("settle", |b| b.iter(|| settle_1dof(&states)));
    g.bench_function("rsruckig", |b| {
        let mut rs = Rs::<1>::new();
        b.iter(|| {
            for x in &states {
                rs.solve(std::slice::from_ref(x));
            }
        })
    });
    g.bench_function("ruckig_official", |b| {
        let mut official = Official::new(1);
        b.iter(|| {
            for x in &states {
                official.solve(std::slice::from_ref(x));
            }
        })
    });
    g.finish();

    let axes = three_axes(&states);
    let mut g = c.benchmark_group("three_dof_333");
    g.bench_function("settle", |b| b.iter(|| settle_3dof(&axes)));
    g.bench_function("rsruckig", |b| {
        let mut rs = Rs::<3>::new();
        b.iter(|| {
            for x in states.chunks_exact(3) {
                rs.solve(x);
            }
        })
    });
    g.bench_function("ruckig_official", |b| {
        let mut official = Official::new(3);
        b.iter(|| {
            for x in states.chunks_exact(3) {
                official.solve(x);
            }
        })
    });
    g.finish();
}

/// settle's time over rsruckig's on the any-state problems, 1-DoF and 3-DoF, timed in
/// alternating batches (40 of each, 20 repetitions of the problem set per batch).
fn interleaved() {
    let states = states();
    let axes = three_axes(&states);
    let (mut rs1, mut rs3) = (Rs::<1>::new(), Rs::<3>::new());
    let time = |f: &mut dyn FnMut()| {
        let t0 = Instant::now();
        for _ in 0..20 {
            f();
        }
        t0.elapsed().as_secs_f64()
    };
    let (mut s1, mut r1, mut s3, mut r3) = (0.0, 0.0, 0.0, 0.0);
    for _ in 0..40 {
        s1 += time(&mut || settle_1dof(&states));
        r1 += time(&mut || {
            for x in &states {
                rs1.solve(std::slice::from_ref(x));
            }
        });
        s3 += time(&mut || settle_3dof(&axes));
        r3 += time(&mut || {
            for x in states.chunks_exact(3) {
                rs3.solve(x);
            }
        });
    }
    let per = |t: f64, n: usize| t / (40.0 * 20.0 * n as f64) * 1e6;
    println!(
        "interleaved any_state_1000: settle {:.3} us, rsruckig {:.3} us per problem: ratio {:.3}",
        per(s1, states.len()),
        per(r1, states.len()),
        s1 / r1
    );
    println!(
        "interleaved three_dof_333:  settle {:.3} us, rsruckig {:.3} us per problem: ratio {:.3}",
        per(s3, axes.len()),
        per(r3, axes.len()),
        s3 / r3
    );
}

/// The benches compare equal work: settle's durations on the problem sets equal
/// rsruckig's within 1e-9 relative (shorter only after a brake, where settle may stop
/// braking earlier), checked before timing. Prints the counts.
fn check_durations() {
    let states = states();
    let mut rs1 = Rs::<1>::new();
    let (mut equal, mut shorter) = (0, 0);
    for x in &states {
        let ours = to_state(x.0, x.1, &x.2, Shape::JerkLimited)
            .expect("settle plans")
            .duration_s();
        rs1.solve(std::slice::from_ref(x));
        let theirs = rs1.traj.get_duration();
        let rel = (ours - theirs) / theirs;
        assert!(rel <= 1e-9, "settle {ours} s vs rsruckig {theirs} s: {x:?}");
        if rel >= -1e-9 {
            equal += 1;
        } else {
            shorter += 1;
        }
    }
    let mut rs3 = Rs::<3>::new();
    let (mut equal3, mut shorter3) = (0, 0);
    for (a, x) in three_axes(&states).iter().zip(states.chunks_exact(3)) {
        let ours = plan(a, Shape::JerkLimited, Sync::Time)
            .expect("settle plans")
            .iter()
            .map(|p| p.duration_s())
            .fold(0.0, f64::max);
        rs3.solve(x);
        let theirs = rs3.traj.get_duration();
        let rel = (ours - theirs) / theirs;
        assert!(rel <= 1e-9, "settle {ours} s vs rsruckig {theirs} s: {x:?}");
        if rel >= -1e-9 {
            equal3 += 1;
        } else {
            shorter3 += 1;
        }
    }
    println!(
        "durations vs rsruckig: 1-DoF {equal} equal, {shorter} shorter after a brake; \
         3-DoF {equal3} equal, {shorter3} shorter after a brake; none longer"
    );
}

criterion_group!(benches, bench);

fn main() {
    check_durations();
    benches();
    // The interleaved comparison runs with no filter or a filter naming it.
    let filters: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with('-'))
        .collect();
    if filters.is_empty() || filters.iter().any(|f| "interleaved".contains(f.as_str())) {
        interleaved();
    }
    Criterion::default().configure_from_args().final_summary();
}
