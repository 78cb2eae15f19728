//! The four-jerk planner: every profile reaches its target within the strict limits check,
//! the symmetric case equals settle's jerk-limited planner (`position::to_state`), and
//! rest-to-rest moves equal the TMC ramp (an independent construction). Optimality against
//! an independent search is in `fourjerk_oracle.rs`.
//!
//! Case count: `SETTLE_PLANNER_CASES` (default 100,000; this suite uses a fiftieth).

use crate::fourjerk_check::{check_profile, draw};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use settle_planner::fourjerk::{self, FourJerkLimits};
use settle_planner::position::{Shape, to_state};
use settle_planner::tmc::SRampParams;
use settle_planner::{PlanError, State};

fn cases() -> usize {
    std::env::var("SETTLE_PLANNER_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(100_000usize)
        .div_ceil(50)
}

fn assert_reaches(p: &settle_planner::Profile, target: &State, l: &FourJerkLimits, ctx: &str) {
    let e = p.end();
    let scale = p
        .iter()
        .map(|(_, s, _)| s.p.abs())
        .fold(target.p.abs(), f64::max);
    assert!(
        (e.p - target.p).abs() <= 1e-9 * scale,
        "p {} vs {}: {ctx}",
        e.p,
        target.p
    );
    assert!(
        (e.v - target.v).abs() <= 1e-9 * l.vmax,
        "v {} vs {}: {ctx}",
        e.v,
        target.v
    );
    assert!(e.a.abs() <= 1e-9 * l.amax.max(l.dmax), "a {}: {ctx}", e.a);
}

#[test]
fn every_profile_reaches_its_target_within_the_limits() {
    let mut rng = ChaCha8Rng::seed_from_u64(30);
    for _ in 0..cases() {
        let (start, target, l) = draw(&mut rng);
        let ctx = format!("{start:?} -> {target:?} {l:?}");
        let p = fourjerk::plan(start, target, &l).unwrap_or_else(|e| panic!("{e}: {ctx}"));
        assert_reaches(&p, &target, &l, &ctx);
        if let Err(e) = check_profile(&p, &l) {
            panic!("{e}: {ctx}");
        }
    }
}

/// With four equal jerks and DMAX = AMAX the planner solves settle's jerk-limited problem.
/// Where the start needs no braking the two must agree to 1e-9. Where it brakes, settle's
/// planner tries nine stopping times of its brake law and this one refines the best: it
/// may be faster, never slower; and some of settle's braked profiles break the velocity
/// limit once it holds (its own checker only looks at segment ends, where the velocity
/// can pass through the band unseen), which the strict check reports and counts here.
#[test]
fn symmetric_case_equals_the_jerk_limited_planner() {
    let mut rng = ChaCha8Rng::seed_from_u64(31);
    let (mut equal, mut faster, mut theirs_invalid, mut n) = (0usize, 0usize, 0usize, 0usize);
    let mut max_gain = 0.0f64;
    for _ in 0..cases() {
        let mut ax = crate::common::draw_axis(&mut rng);
        ax.target.a = 0.0;
        if ax.target.v.abs() > ax.limits.vmax() {
            continue;
        }
        let l = FourJerkLimits::symmetric(&ax.limits).expect("limits");
        let ctx = format!("{:?} -> {:?} {:?}", ax.start, ax.target, ax.limits);
        let theirs = to_state(ax.start, ax.target, &ax.limits, Shape::JerkLimited)
            .unwrap_or_else(|e| panic!("to_state {e}: {ctx}"));
        let mine = fourjerk::plan(ax.start, ax.target, &l).unwrap_or_else(|e| panic!("{e}: {ctx}"));
        n += 1;
        if let Err(e) = check_profile(&mine, &l) {
            panic!("{e}: {ctx}");
        }
        let rel = (mine.duration_s() - theirs.duration_s()) / theirs.duration_s();
        if check_profile(&theirs, &l).is_err() {
            assert!(
                crate::common::braked(&ax),
                "unbraked start, invalid to_state profile: {ctx}"
            );
            theirs_invalid += 1;
            continue;
        }
        if rel.abs() <= 1e-9 {
            equal += 1;
        } else {
            assert!(
                crate::common::braked(&ax),
                "rel {rel:e} without braking: {ctx}"
            );
            assert!(rel < 0.0, "slower by {rel:e} than to_state: {ctx}");
            faster += 1;
            max_gain = max_gain.max(-rel);
        }
    }
    println!(
        "symmetric: {n} problems, {equal} equal to 1e-9, {faster} braked ones faster (up to {:.2e}), {theirs_invalid} to_state profiles fail the strict check",
        max_gain
    );
    assert!(equal >= n * 95 / 100, "{equal} of {n}");
}

/// Rest to rest, the time-optimal profile is the chip's ramp with VSTART = VSTOP = 0: the
/// highest peak velocity that fits (found by bisection in `tmc::ramp`, by the three-arc
/// and cruise families here).
#[test]
fn rest_to_rest_equals_the_tmc_ramp_both_directions() {
    let mut rng = ChaCha8Rng::seed_from_u64(32);
    let lu =
        |rng: &mut ChaCha8Rng, lo: f64, hi: f64| rng.random_range(f64::ln(lo)..f64::ln(hi)).exp();
    for _ in 0..cases() {
        let l = FourJerkLimits::new(
            lu(&mut rng, 1e-2, 1e2),
            lu(&mut rng, 1e-2, 1e2),
            lu(&mut rng, 1e-2, 1e2),
            [0; 4].map(|_| lu(&mut rng, 1e-2, 1e3)),
        )
        .expect("limits");
        let d = lu(&mut rng, 1e-4, 1e3) * if rng.random_bool(0.5) { 1.0 } else { -1.0 };
        let p = fourjerk::rest_to_rest(0.5, d, &l).expect("fourjerk");
        let ramp = settle_planner::tmc::ramp::plan(
            0.5,
            d,
            &SRampParams {
                vstart: 0.0,
                vmax: l.vmax,
                vstop: 0.0,
                amax: l.amax,
                dmax: l.dmax,
                bow: l.jerk,
            },
        )
        .expect("ramp");
        let rel = (p.duration_s() - ramp.duration_s()).abs() / ramp.duration_s();
        assert!(
            rel <= 1e-9,
            "d={d} {l:?}: {} vs {}",
            p.duration_s(),
            ramp.duration_s()
        );
        // Oriented along the move: the first phase speeds up with j1 in the move's
        // direction.
        let (_, s, seg) = p.iter().next().expect("segment");
        assert_eq!(seg.accel_and_jerk(&s).1, d.signum() * l.jerk[0]);
        assert!((p.end().p - (0.5 + d)).abs() <= 1e-9 * (1.0 + d.abs()));
    }
}

#[test]
fn bad_input_is_an_error() {
    let l = FourJerkLimits::new(1.0, 1.0, 1.0, [1.0; 4]).expect("limits");
    let s = State::default();
    let t = |p, v, a| State { p, v, a };
    assert!(matches!(
        fourjerk::plan(s, t(1.0, 0.0, 0.5), &l),
        Err(PlanError::InvalidInput { .. })
    ));
    assert!(matches!(
        fourjerk::plan(s, t(1.0, 2.0, 0.0), &l),
        Err(PlanError::InfeasibleTarget { .. })
    ));
    assert!(matches!(
        FourJerkLimits::new(1.0, 1.0, 1.0, [1.0, 0.0, 1.0, 1.0]),
        Err(PlanError::InvalidLimit { name: "j2", .. })
    ));
    assert!(matches!(
        fourjerk::plan(t(f64::NAN, 0.0, 0.0), t(1.0, 0.0, 0.0), &l),
        Err(PlanError::NonFinite { .. })
    ));
}
