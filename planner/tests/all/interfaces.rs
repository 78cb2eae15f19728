//! The velocity interface, asymmetric limits, the trapezoid variant and edge families,
//! each against rsruckig; and known-value cases of the no-cruise profiles (DD, DT, TD, TT:
//! triangular or trapezoidal acceleration in each half) and of the a0 > amax and
//! velocity-overshoot brakes (closed forms, or rsruckig's durations with the phase
//! structure checked).
//!
//! Case count per family: `SETTLE_PLANNER_EDGE_CASES` (default 100,000).

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Gamma, Normal};
use settle_planner::position::{Shape, to_state, to_velocity};
use settle_planner::{Limits, Profile, Segment, State};

use crate::common::{check_limits, ruckig_1dof};

fn cases() -> usize {
    std::env::var("SETTLE_PLANNER_EDGE_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(100_000)
}

fn state(rng: &mut ChaCha8Rng, p: f64, va: f64) -> State {
    let n = |s: f64| Normal::new(0.0, s).expect("normal");
    State {
        p: n(p).sample(rng),
        v: n(va).sample(rng),
        a: n(va).sample(rng),
    }
}

fn gamma(rng: &mut ChaCha8Rng) -> f64 {
    Gamma::new(2.0, 2.0).expect("gamma").sample(rng) + 0.05
}

/// Was `start` braked (outside the limits, or bound to overshoot them)?
fn braked(s: &State, lim: &Limits) -> bool {
    let j = lim.jmax().unwrap_or(f64::INFINITY);
    let vz = s.v + s.a * s.a.abs() / (2.0 * j);
    s.a > lim.amax()
        || s.a < lim.amin()
        || s.v > lim.vmax()
        || s.v < lim.vmin()
        || vz > lim.vmax()
        || vz < lim.vmin()
}

/// Plan, check target and limits, compare with rsruckig: equal within 1e-9 relative, or
/// shorter after a brake. Returns true when compared.
fn agree(
    prof: Result<Profile, settle_planner::PlanError>,
    theirs: Option<f64>,
    start: &State,
    target: &State,
    lim: &Limits,
    pos_free: bool,
) -> bool {
    let ctx = format!("start {start:?} target {target:?} {lim:?}");
    let (prof, t) = match (prof, theirs) {
        (Ok(p), Some(t)) => (p, Some(t)),
        (Err(_), None) => return false,
        // rsruckig gives up on some extreme scales; ours must then still be exact and valid.
        (Ok(p), None) => (p, None),
        (Err(e), Some(t)) => panic!("we reject what rsruckig solves ({t} s): {e}: {ctx}"),
    };
    let e = prof.end();
    // Positions are compared relative to the largest position magnitude along the move
    // (f64 carries ~16 digits of it).
    let scale = prof
        .iter()
        .map(|(_, s, _)| s.p.abs())
        .fold(1.0f64.max(target.p.abs()).max(start.p.abs()), f64::max);
    assert!(
        pos_free || (e.p - target.p).abs() < 1e-8 * scale,
        "p missed {e:?}: {ctx}"
    );
    assert!(
        (e.v - target.v).abs() < 1e-8 * 1.0f64.max(lim.vmax()),
        "v missed {e:?}: {ctx}"
    );
    if lim.jmax().is_some() {
        assert!(
            (e.a - target.a).abs() < 1e-10 * 1.0f64.max(lim.amax()),
            "a missed {e:?}: {ctx}"
        );
    }
    if let Err(m) = check_limits(&prof, lim) {
        panic!("{m}: {ctx}\n{:?}", prof.segments());
    }
    let Some(t) = t else { return true };
    let rel = (prof.duration_s() - t) / t.max(1e-300);
    assert!(
        rel.abs() <= 1e-9
            || (rel < 0.0 && braked(start, lim))
            || (t == 0.0 && prof.duration_s() < 1e-12),
        "duration {} vs rsruckig {t}: {ctx}\n{:?}",
        prof.duration_s(),
        prof.segments()
    );
    true
}

#[test]
fn velocity_interface_equals_rsruckig() {
    let mut rng = ChaCha8Rng::seed_from_u64(21);
    let mut n = 0;
    for _ in 0..cases() {
        let lim =
            Limits::new(gamma(&mut rng), gamma(&mut rng), Some(gamma(&mut rng))).expect("limits");
        let (s, mut t) = (state(&mut rng, 4.0, 0.8), state(&mut rng, 4.0, 0.8));
        t.p = 0.0;
        let ours = to_velocity(s, t.v, t.a, &lim, Shape::JerkLimited);
        let theirs = ruckig_1dof(&s, &t, &lim, true);
        // The velocity interface has no velocity limits: check against acceleration and
        // jerk only.
        let free = Limits::new(f64::MAX, lim.amax(), lim.jmax()).expect("limits");
        n += usize::from(agree(ours, theirs, &s, &t, &free, true));
    }
    assert!(n > cases() / 2, "compared only {n}");
}

#[test]
fn asymmetric_limits_equal_rsruckig() {
    let mut rng = ChaCha8Rng::seed_from_u64(22);
    let mut n = 0;
    for _ in 0..cases() {
        let lim = Limits::asymmetric(
            gamma(&mut rng),
            Some(-gamma(&mut rng)),
            gamma(&mut rng),
            Some(-gamma(&mut rng)),
            Some(gamma(&mut rng)),
        )
        .expect("limits");
        let (s, t) = (state(&mut rng, 4.0, 0.8), state(&mut rng, 4.0, 0.8));
        let ours = to_state(s, t, &lim, Shape::JerkLimited);
        n += usize::from(agree(
            ours,
            ruckig_1dof(&s, &t, &lim, false),
            &s,
            &t,
            &lim,
            false,
        ));
    }
    assert!(n > cases() / 2, "compared only {n}");
}

#[test]
fn trapezoid_variant_equals_rsruckig_second_order() {
    let mut rng = ChaCha8Rng::seed_from_u64(23);
    let mut n = 0;
    for _ in 0..cases() {
        let lim = Limits::new(gamma(&mut rng), gamma(&mut rng), None).expect("limits");
        let (mut s, mut t) = (state(&mut rng, 4.0, 0.8), state(&mut rng, 4.0, 0.8));
        // Without a jerk limit the acceleration is free to jump: only zero end accelerations
        // are meaningful targets, and the start acceleration is irrelevant.
        s.a = 0.0;
        t.a = 0.0;
        let ours = to_state(s, t, &lim, Shape::Trapezoid);
        n += usize::from(agree(
            ours,
            ruckig_1dof(&s, &t, &lim, false),
            &s,
            &t,
            &lim,
            false,
        ));
    }
    assert!(n > cases() / 2, "compared only {n}");
}

#[test]
fn edge_families_equal_rsruckig() {
    let mut rng = ChaCha8Rng::seed_from_u64(24);
    let mut n = 0;
    let total = cases();
    for i in 0..total {
        // Limits from 1e-3 to 1e6, the problem scaled to match, cycling through families.
        let scale = 10f64.powf(rng.random_range(-3.0..6.0));
        let lim = Limits::new(
            scale * gamma(&mut rng),
            scale * gamma(&mut rng),
            Some(scale * gamma(&mut rng)),
        )
        .expect("limits");
        let mut s = state(&mut rng, 4.0 * scale, 0.8 * scale);
        let mut t = state(&mut rng, 4.0 * scale, 0.8 * scale);
        match i % 5 {
            0 => s.v = lim.vmax() * rng.random_range(1.0..3.0), // start above vmax
            1 => s.a = lim.amax() * rng.random_range(1.0..3.0), // start above amax
            2 => {
                t = State {
                    p: t.p,
                    v: 0.0,
                    a: 0.0,
                }
            } // zero target state
            // Very short rest-to-rest moves (with random start and end velocities a move
            // of 1e-6 would be ill-conditioned: its duration is then known only to the
            // rounding of the much larger excursion).
            3 => {
                s = State {
                    p: s.p,
                    v: 0.0,
                    a: 0.0,
                };
                t = State {
                    p: s.p + scale * 1e-6 * rng.random_range(-1.0..1.0),
                    v: 0.0,
                    a: 0.0,
                };
            }
            _ => t.p = s.p + scale * 1e3 * rng.random_range(-1.0..1.0), // very long moves
        }
        let ours = to_state(s, t, &lim, Shape::JerkLimited);
        // Durations are invariant when p, v, a and the limits all scale by one factor:
        // rsruckig, which loses accuracy far from unit scale, gets the problem normalised.
        // Likewise under a shift of position (start.p - start.p is exact in f64).
        let unit = |x: &State| State {
            p: (x.p - s.p) / scale,
            v: x.v / scale,
            a: x.a / scale,
        };
        let lim_unit = Limits::new(
            lim.vmax() / scale,
            lim.amax() / scale,
            lim.jmax().map(|j| j / scale),
        )
        .expect("limits");
        let theirs = ruckig_1dof(&unit(&s), &unit(&t), &lim_unit, false);
        n += usize::from(agree(ours, theirs, &s, &t, &lim, false));
    }
    assert!(n > total / 3, "compared only {n}");
}

fn plan(s: State, t: State, lim: &Limits) -> Profile {
    to_state(s, t, lim, Shape::JerkLimited).expect("plans")
}

/// Count the constant-acceleration holds in each half of a rest-to-rest-like profile
/// (split at the longest zero-acceleration point): D = none, T = one.
fn holds(p: &Profile) -> Vec<f64> {
    p.iter()
        .filter(|(_, s, seg)| {
            matches!(seg, Segment::Jerk { jerk, .. } if *jerk == 0.0) && s.a.abs() > 1e-9
        })
        .map(|(_, _, seg)| seg.duration_s())
        .collect()
}

#[test]
fn no_cruise_and_brake_cases_known_values() {
    let lim = Limits::new(10.0, 1.0, Some(1.0)).expect("limits");
    let rest = |p| State { p, v: 0.0, a: 0.0 };
    // DD: d = 2, jmax 1: four jerk phases of (d/(2j))^(1/3) = 1 s -> T = 4 s, no holds.
    let p = plan(rest(0.0), rest(2.0), &lim);
    assert!(
        (p.duration_s() - 4.0).abs() < 1e-12 && holds(&p).is_empty(),
        "{p:?}"
    );
    // TT: d = 3 (> 2 amax^3/j^2 = 2): peak speed (-1 + sqrt 13)/2, T = 2 v + 2.
    let p = plan(rest(0.0), rest(3.0), &lim);
    let v = (13f64.sqrt() - 1.0) / 2.0;
    assert!(
        (p.duration_s() - (2.0 * v + 2.0)).abs() < 1e-12 && holds(&p).len() == 2,
        "{p:?}"
    );
    // DT: start moving at 1.5 m/s towards a target at rest: the (short) speed-up phase stays
    // triangular, the long stop reaches amax. TD: the mirror (start at rest, arrive at
    // speed). Known values from rsruckig, with the phase structure checked.
    let start = State {
        p: 0.0,
        v: 0.45,
        a: 0.0,
    };
    let p = plan(start, rest(3.0), &lim);
    let t = ruckig_1dof(&start, &rest(3.0), &lim, false).expect("rsruckig");
    assert!((p.duration_s() - t).abs() < 1e-9 * t);
    let h = holds(&p);
    assert_eq!(h.len(), 1, "DT: one hold, in the stop: {p:?}");
    let target = State {
        p: 3.0,
        v: 0.45,
        a: 0.0,
    };
    let p = plan(rest(0.0), target, &lim);
    let t = ruckig_1dof(&rest(0.0), &target, &lim, false).expect("rsruckig");
    assert!((p.duration_s() - t).abs() < 1e-9 * t);
    assert_eq!(holds(&p).len(), 1, "TD: one hold, in the speed-up: {p:?}");
    // a0 > amax: first a jerk of -jmax for (a0 - amax)/jmax = 1.5 s.
    let start = State {
        p: 0.0,
        v: 0.0,
        a: 2.5,
    };
    let lim2 = Limits::new(100.0, 1.0, Some(1.0)).expect("limits");
    let p = plan(start, rest(50.0), &lim2);
    match p.segments()[0] {
        Segment::Jerk { duration_s, jerk } => {
            assert!((duration_s - 1.5).abs() < 1e-12 && jerk == -1.0)
        }
        other => panic!("expected the acceleration brake first, got {other:?}"),
    }
    let t = ruckig_1dof(&start, &rest(50.0), &lim2, false).expect("rsruckig");
    assert!(
        (p.duration_s() - t).abs() < 1e-9 * t,
        "{} vs {t}",
        p.duration_s()
    );
    // Velocity overshoot: v0 = 0.9 < vmax = 1 but a0 = 1 would carry it to 0.9 + 1/2 = 1.4.
    // The brake lowers vz = v + a|a|/(2j) to vmax and the profile never exceeds it after.
    let lim3 = Limits::new(1.0, 2.0, Some(1.0)).expect("limits");
    let start = State {
        p: 0.0,
        v: 0.9,
        a: 1.0,
    };
    let p = plan(start, rest(10.0), &lim3);
    check_limits(&p, &lim3).expect("within limits after the brake");
    let vpeak = (0..=100_000)
        .map(|k| p.state_at(p.duration_s() * k as f64 / 100_000.0).v)
        .fold(0.9f64, f64::max);
    assert!(
        (vpeak - 1.4).abs() < 1e-6,
        "peak {vpeak}: the overshoot is unavoidable, and no more"
    );
    let t = ruckig_1dof(&start, &rest(10.0), &lim3, false).expect("rsruckig");
    assert!(
        p.duration_s() <= t * (1.0 + 1e-9),
        "{} vs {t}",
        p.duration_s()
    );
}

/// Positions near the f64 range (their difference overflows) and limits near underflow
/// come back as errors, not as an empty or hold-only profile that never reaches the
/// target; every returned profile ends on its target.
#[test]
fn inputs_beyond_f64_resolution_are_errors_not_wrong_profiles() {
    let big = Limits::new(1e308, 1e308, Some(1e308)).expect("limits");
    let r = to_state(
        State {
            p: 1e308,
            v: 0.0,
            a: 0.0,
        },
        State {
            p: -1e308,
            v: 0.0,
            a: 0.0,
        },
        &big,
        Shape::JerkLimited,
    );
    assert!(
        matches!(r, Err(settle_planner::PlanError::NoSolution { .. })),
        "{r:?}"
    );
    let tiny = Limits::new(1e-300, 1e-300, Some(1e-300)).expect("limits");
    let r = to_state(
        State::default(),
        State {
            p: 1e-300,
            v: 0.0,
            a: 0.0,
        },
        &tiny,
        Shape::JerkLimited,
    );
    match r {
        Ok(p) => assert!((p.end().p - 1e-300).abs() <= 1e-8 * 1e-300, "{p:?}"),
        Err(e) => assert!(matches!(e, settle_planner::PlanError::NoSolution { .. })),
    }
}
