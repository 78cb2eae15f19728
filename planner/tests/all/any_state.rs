//! The any-state planner (position and velocity interfaces) against rsruckig, drawn like
//! the Ruckig paper: p ~ N(0, 4), v and a ~ N(0, 0.8), limits ~ Gamma(2, 2) + 0.05.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Gamma, Normal};
use rsruckig::prelude::*;
use settle_planner::position::{Shape, to_state};
use settle_planner::{Limits, State};

use crate::common::check_limits;

fn cases(var: &str, default: usize) -> usize {
    std::env::var(var)
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

struct Problem {
    start: State,
    target: State,
    lim: Limits,
}

fn draw(rng: &mut ChaCha8Rng, zero_af: bool) -> Problem {
    let p = Normal::new(0.0, 4.0).expect("normal");
    let va = Normal::new(0.0, 0.8).expect("normal");
    let g = Gamma::new(2.0, 2.0).expect("gamma");
    let lim = Limits::new(
        g.sample(rng) + 0.05,
        g.sample(rng) + 0.05,
        Some(g.sample(rng) + 0.05),
    )
    .expect("limits");
    let start = State {
        p: p.sample(rng),
        v: va.sample(rng),
        a: va.sample(rng),
    };
    let target = State {
        p: p.sample(rng),
        v: va.sample(rng),
        a: if zero_af { 0.0 } else { va.sample(rng) },
    };
    Problem { start, target, lim }
}

fn ruckig(pr: &Problem) -> Option<f64> {
    let mut otg = Ruckig::<1, ThrowErrorHandler>::new(None, 0.001);
    let mut input = InputParameter::new(None);
    input.current_position[0] = pr.start.p;
    input.current_velocity[0] = pr.start.v;
    input.current_acceleration[0] = pr.start.a;
    input.target_position[0] = pr.target.p;
    input.target_velocity[0] = pr.target.v;
    input.target_acceleration[0] = pr.target.a;
    input.max_velocity[0] = pr.lim.vmax();
    input.max_acceleration[0] = pr.lim.amax();
    input.max_jerk[0] = pr.lim.jmax().expect("jerk");
    let mut traj = Trajectory::new(None);
    otg.calculate(&input, &mut traj).ok()?;
    Some(traj.get_duration())
}

/// Outcome counts of a comparison run.
#[derive(Debug, Default)]
struct Counts {
    compared: usize,
    equal: usize,
    braked_shorter: usize,
    rejected_both: usize,
}

/// Plan `n` random problems; assert every profile reaches its target, respects the limits
/// and equals rsruckig's duration within 1e-9 relative, except after a brake, where it may
/// be shorter (never longer): Ruckig stops braking where the velocity is back inside the
/// limits, settle tries stopping earlier along the same brake law and keeps the fastest.
fn compare(n: usize, zero_af: bool, seed: u64) -> Counts {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut c = Counts::default();
    for _ in 0..n {
        let pr = draw(&mut rng, zero_af);
        let ours = to_state(pr.start, pr.target, &pr.lim, Shape::JerkLimited);
        let theirs = ruckig(&pr);
        let ctx = format!("start {:?} target {:?} {:?}", pr.start, pr.target, pr.lim);
        let (prof, t) = match (ours, theirs) {
            (Ok(p), Some(t)) => (p, t),
            (Err(_), None) => {
                c.rejected_both += 1;
                continue;
            }
            (ours, theirs) => {
                panic!("only one planner solved it: ours {ours:?} rsruckig {theirs:?}: {ctx}")
            }
        };
        let end = prof.end();
        assert!(
            (end.p - pr.target.p).abs() < 1e-8
                && (end.v - pr.target.v).abs() < 1e-8
                && (end.a - pr.target.a).abs() < 1e-10,
            "target missed: {end:?}: {ctx}"
        );
        if let Err(e) = check_limits(&prof, &pr.lim) {
            panic!("{e}: {ctx}\n{:?}", prof.segments());
        }
        c.compared += 1;
        let jm = pr.lim.jmax().expect("jerk");
        let vz = pr.start.v + pr.start.a * pr.start.a.abs() / (2.0 * jm);
        let braked = pr.start.a > pr.lim.amax()
            || pr.start.a < pr.lim.amin()
            || vz > pr.lim.vmax()
            || vz < pr.lim.vmin()
            || pr.start.v > pr.lim.vmax()
            || pr.start.v < pr.lim.vmin();
        let rel = (prof.duration_s() - t) / t;
        if rel.abs() <= 1e-9 {
            c.equal += 1;
        } else if braked && rel < 0.0 {
            c.braked_shorter += 1;
        } else {
            panic!(
                "duration {} vs rsruckig {t} (braked: {braked}): {ctx}\n{:?}",
                prof.duration_s(),
                prof.segments()
            );
        }
    }
    c
}

#[test]
fn equals_rsruckig_on_random_states_with_zero_target_acceleration() {
    let c = compare(cases("SETTLE_PLANNER_STATE_CASES", 500_000), true, 11);
    eprintln!("af = 0: {c:?}");
    assert!(c.compared > 0);
}

#[test]
fn equals_rsruckig_on_random_states_and_targets() {
    let c = compare(cases("SETTLE_PLANNER_STATE_CASES", 500_000), false, 12);
    eprintln!("any af: {c:?}");
    assert!(c.compared > 0);
}

/// Regression: a start above vmax where rsruckig brakes until the velocity is back inside
/// the limits; stopping the brake earlier is feasible and 2.7 s faster.
#[test]
fn braking_less_than_ruckig_is_feasible_and_faster() {
    let pr = Problem {
        start: State {
            p: -2.5799646673742784,
            v: 1.0708738021808355,
            a: -0.7458362648081073,
        },
        target: State {
            p: 4.975830638534197,
            v: 0.4194584380774127,
            a: 0.0,
        },
        lim: Limits::new(
            0.5416254984708054,
            2.295797324132117,
            Some(0.9983185657541818),
        )
        .expect("limits"),
    };
    let prof = to_state(pr.start, pr.target, &pr.lim, Shape::JerkLimited).expect("plans");
    let theirs = ruckig(&pr).expect("rsruckig solves");
    check_limits(&prof, &pr.lim).expect("feasible");
    let end = prof.end();
    assert!((end.p - pr.target.p).abs() < 1e-8 && (end.v - pr.target.v).abs() < 1e-8);
    assert!(
        prof.duration_s() < theirs - 1.0,
        "ours {} rsruckig {theirs}",
        prof.duration_s()
    );
}
