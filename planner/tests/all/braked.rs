//! Braked starts (the start violates, or must violate, the velocity or acceleration
//! limits): every profile reaches its target and, once braked, keeps the limits, checked
//! inside segments too (`common::check_limits`). Durations are compared with rsruckig: equal,
//! or shorter where settle stops braking earlier along the same brake law.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use settle_planner::position::{Shape, to_state};
use settle_planner::{Limits, State};

use crate::common::{braked, check_limits, draw_axis, ruckig_1dof};

fn cases(var: &str, default: usize) -> usize {
    std::env::var(var)
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

/// Regression: the brake's latest stop lay past the point where the velocity after
/// ramping the acceleration to zero (vz) reaches the opposite limit; stopping there made
/// the velocity swing to -3.9 against vmin = -0.574.
#[test]
fn brake_stops_before_vz_passes_the_opposite_limit() {
    let start = State {
        p: -1.69,
        v: 1.631,
        a: 2.477,
    };
    let target = State {
        p: -4.86,
        v: -0.508,
        a: 0.0,
    };
    let lim = Limits::new(0.574, 5.82, Some(0.454)).expect("limits");
    let prof = to_state(start, target, &lim, Shape::JerkLimited).expect("plans");
    check_limits(&prof, &lim).unwrap_or_else(|e| panic!("{e}\n{:?}", prof.segments()));
    let vlow = prof
        .iter()
        .flat_map(|(_, s, seg)| {
            (0..=64).map(move |k| seg.sample(&s, seg.duration_s() * k as f64 / 64.0).v)
        })
        .fold(f64::INFINITY, f64::min);
    assert!(vlow >= -0.574 * (1.0 + 1e-9), "lowest velocity {vlow}");
    let end = prof.end();
    assert!((end.p - target.p).abs() < 1e-8 && (end.v - target.v).abs() < 1e-8);
    assert!(end.a.abs() < 1e-10);
    let theirs = ruckig_1dof(&start, &target, &lim, false).expect("rsruckig solves");
    assert!(
        prof.duration_s() <= theirs * (1.0 + 1e-9),
        "ours {} rsruckig {theirs}",
        prof.duration_s()
    );
}

/// Seeded random braked starts (drawn like the Ruckig paper, kept only when braked).
#[test]
fn random_braked_starts_keep_the_limits() {
    let n = cases("SETTLE_PLANNER_BRAKED_CASES", 100_000);
    let mut rng = ChaCha8Rng::seed_from_u64(31);
    let (mut done, mut equal, mut shorter) = (0, 0, 0);
    while done < n {
        let ax = draw_axis(&mut rng);
        if !braked(&ax) {
            continue;
        }
        done += 1;
        let ctx = format!(
            "start {:?} target {:?} {:?}",
            ax.start, ax.target, ax.limits
        );
        let ours = to_state(ax.start, ax.target, &ax.limits, Shape::JerkLimited);
        let theirs = ruckig_1dof(&ax.start, &ax.target, &ax.limits, false);
        let (prof, t) = match (ours, theirs) {
            (Ok(p), Some(t)) => (p, t),
            (Err(_), None) => continue,
            (o, t) => panic!("only one planner solved it: ours {o:?} rsruckig {t:?}: {ctx}"),
        };
        let end = prof.end();
        assert!(
            (end.p - ax.target.p).abs() < 1e-8
                && (end.v - ax.target.v).abs() < 1e-8
                && (end.a - ax.target.a).abs() < 1e-10,
            "target missed: {end:?}: {ctx}"
        );
        if let Err(e) = check_limits(&prof, &ax.limits) {
            panic!("{e}: {ctx}\n{:?}", prof.segments());
        }
        let rel = (prof.duration_s() - t) / t;
        assert!(rel <= 1e-9, "longer than rsruckig by {rel}: {ctx}");
        if rel >= -1e-9 {
            equal += 1;
        } else {
            shorter += 1;
        }
    }
    eprintln!("braked starts: {done}, equal {equal}, shorter {shorter}");
    assert!(equal > 0);
}
