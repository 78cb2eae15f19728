//! Property tests: the closed-form planner against the bracketing oracle on random
//! problems drawn like the Ruckig paper (p ~ N(0, 4), v and a ~ N(0, 0.8), limits ~
//! Gamma(2, 2) + 0.05), with asymmetric limits, the trapezoid variant and scaled limits
//! mixed in. Count per test: `SETTLE_PLANNER_ORACLE_CASES` (default 20,000; the oracle
//! is the slow part).

#![cfg(test)]

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Gamma, Normal};

use crate::position::{Shape, to_state};
use crate::sync::{Axis, Sync};
use crate::{Limits, Profile, State};

fn cases() -> usize {
    std::env::var("SETTLE_PLANNER_ORACLE_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(20_000)
}

/// One axis: `kind % 5` = 0 symmetric, 1 asymmetric limits, 2 scaled by 10^(-3..6),
/// 3 zero target acceleration, 4 long moves (mostly cruising at a velocity limit).
fn draw(rng: &mut ChaCha8Rng, kind: usize) -> Axis {
    let kind = kind % 5;
    let p = Normal::new(0.0, 4.0).expect("normal");
    let va = Normal::new(0.0, 0.8).expect("normal");
    let g = Gamma::new(2.0, 2.0).expect("gamma");
    let scale = if kind == 2 {
        10f64.powf(rng.random_range(-3.0..6.0))
    } else {
        1.0
    };
    let mut lim = || scale * (g.sample(rng) + 0.05);
    let (vmax, amax, jmax) = (lim(), lim(), lim());
    let limits = if kind == 1 {
        Limits::asymmetric(vmax, Some(-lim()), amax, Some(-lim()), Some(jmax))
    } else {
        Limits::new(vmax, amax, Some(jmax))
    }
    .expect("limits");
    let mut state = || State {
        p: scale * p.sample(rng),
        v: scale * va.sample(rng),
        a: scale * va.sample(rng),
    };
    let (start, mut target) = (state(), state());
    if kind == 3 {
        target.a = 0.0;
    }
    if kind == 4 {
        target.p = start.p + 10.0 * (target.p - start.p);
    }
    Axis {
        start,
        target,
        limits,
    }
}

/// The jerk-unlimited version of an axis (no jerk limit, zero accelerations).
fn trapezoid(a: &Axis) -> Axis {
    let l = &a.limits;
    let limits = Limits::asymmetric(l.vmax(), Some(l.vmin()), l.amax(), Some(l.amin()), None)
        .expect("limits");
    let zero_a = |s: State| State { a: 0.0, ..s };
    Axis {
        start: zero_a(a.start),
        target: zero_a(a.target),
        limits,
    }
}

/// Limits hold (relative 1e-9) from the moment they first can: jerk always, acceleration
/// once inside, velocity once the state is safe (as in the integration tests).
fn within_limits(prof: &Profile, lim: &Limits) -> Result<(), String> {
    let tol = 1e-9;
    let j = lim.jmax().unwrap_or(f64::INFINITY);
    let (vmax, vmin) = (lim.vmax() * (1.0 + tol), lim.vmin() * (1.0 + tol));
    let (amax, amin) = (lim.amax() * (1.0 + tol), lim.amin() * (1.0 + tol));
    let safe = |st: &State| {
        let vz = st.v + st.a * st.a.abs() / (2.0 * j);
        st.v <= vmax && st.v >= vmin && vz <= vmax && vz >= vmin
    };
    let s0 = prof.start();
    let mut a_in = s0.a <= amax && s0.a >= amin;
    let mut v_in = safe(&s0);
    for (t, s, seg) in prof.iter() {
        let (a0, jerk) = seg.accel_and_jerk(&s);
        if jerk.abs() > j * (1.0 + tol) {
            return Err(format!("jerk {jerk} at t={t}"));
        }
        let e = seg.end_state(&s);
        let mut vs = [s.v, e.v, s.v];
        if jerk != 0.0 {
            let tau = -a0 / jerk;
            if tau > 0.0 && tau < seg.duration_s() {
                vs[2] = seg.sample(&s, tau).v;
            }
        }
        for val in [a0, e.a] {
            if a_in && (val > amax || val < amin) {
                return Err(format!("a = {val} at t={t}"));
            }
            a_in |= val <= amax && val >= amin;
        }
        if v_in && vs.iter().any(|v| *v > vmax || *v < vmin) {
            return Err(format!("v = {vs:?} near t={t}"));
        }
        v_in |= safe(&e);
    }
    Ok(())
}

/// Starts outside the limits, or bound to overshoot them (so it is braked).
fn braked(a: &Axis) -> bool {
    let l = &a.limits;
    let j = l.jmax().unwrap_or(f64::INFINITY);
    let vz = a.start.v + a.start.a * a.start.a.abs() / (2.0 * j);
    a.start.a > l.amax()
        || a.start.a < l.amin()
        || [a.start.v, vz]
            .iter()
            .any(|v| *v > l.vmax() || *v < l.vmin())
}

fn reaches(prof: &Profile, a: &Axis) -> bool {
    let e = prof.end();
    let scale = prof
        .iter()
        .map(|(_, s, _)| s.p.abs())
        .fold(1f64.max(a.target.p.abs()), f64::max);
    let lim = &a.limits;
    (e.p - a.target.p).abs() <= 1e-8 * scale
        && (e.v - a.target.v).abs() <= 1e-8 * lim.vmax().max(1.0)
        && (e.a - a.target.a).abs() <= 1e-10 * lim.amax().max(1.0)
}

#[test]
fn step_1_equals_the_oracle() {
    let mut rng = ChaCha8Rng::seed_from_u64(41);
    let (mut equal, mut shorter, mut shorter_braked, mut rejected) = (0, 0, 0, 0);
    for i in 0..cases() {
        let a = draw(&mut rng, i);
        let shape = if i % 7 == 6 {
            Shape::Trapezoid
        } else {
            Shape::JerkLimited
        };
        let a = if shape == Shape::Trapezoid {
            trapezoid(&a)
        } else {
            a
        };
        let (start, target, limits) = (a.start, a.target, a.limits);
        let fast = to_state(start, target, &limits, shape);
        let slow = super::peak::to_state(start, target, &limits, shape);
        match (fast, slow) {
            (Ok(f), Ok(s)) => {
                let (tf, ts) = (f.duration_s(), s.duration_s());
                assert!(reaches(&f, &a), "target missed {:?}: {a:?}", f.end());
                if let Err(e) = within_limits(&f, &limits) {
                    panic!("{e}: {a:?}\n{:?}", f.segments());
                }
                // Equal, or shorter (and, as just checked, exact and feasible): the oracle
                // brackets roots on a grid and can miss close pairs.
                let rel = (tf - ts) / ts.max(1e-300);
                assert!(
                    rel <= 1e-9,
                    "closed form {tf} longer than oracle {ts} ({shape:?}): {a:?}\n{:?}\n{:?}",
                    f.segments(),
                    s.segments()
                );
                if rel.abs() <= 1e-9 {
                    equal += 1;
                } else {
                    shorter += 1;
                    if braked(&a) {
                        shorter_braked += 1;
                    }
                    if shorter <= 3 {
                        eprintln!("shorter: {tf} vs {ts}: {a:?}");
                    }
                }
            }
            (Err(_), Err(_)) => rejected += 1,
            (f, s) => panic!(
                "only one solves ({shape:?}): closed form {:?} oracle {:?}: {a:?}",
                f.map(|p| p.duration_s()),
                s.map(|p| p.duration_s())
            ),
        }
    }
    eprintln!(
        "step 1 vs oracle: {equal} equal, {shorter} shorter ({shorter_braked} after a brake), {rejected} rejected by both"
    );
    assert!(equal > cases() / 2);
}

#[test]
fn time_synchronisation_is_never_longer_than_the_oracles() {
    let mut rng = ChaCha8Rng::seed_from_u64(42);
    let (mut equal, mut shorter, mut rejected) = (0, 0, 0);
    for i in 0..cases() / 10 {
        let axes: [Axis; 3] = std::array::from_fn(|k| draw(&mut rng, i + k));
        let fast = crate::sync::plan(&axes, Shape::JerkLimited, Sync::Time);
        let slow = super::sync::plan_time(&axes, Shape::JerkLimited);
        let (f, s) = match (fast, slow) {
            (Ok(f), Ok(s)) => (f, s),
            (Err(_), Err(_)) => {
                rejected += 1;
                continue;
            }
            (f, s) => panic!(
                "only one solves: closed form {:?} oracle {:?}: {axes:?}",
                f.map(|p| p[0].duration_s()),
                s.map(|p| p[0].duration_s())
            ),
        };
        let (tf, ts) = (f[0].duration_s(), s[0].duration_s());
        for (p, a) in f.iter().zip(&axes) {
            assert!((p.duration_s() - tf).abs() <= 1e-9 * tf, "{axes:?}");
            assert!(reaches(p, a), "target missed {:?}: {axes:?}", p.end());
            if let Err(e) = within_limits(p, &a.limits) {
                panic!("{e}: {axes:?}\n{:?}", p.segments());
            }
        }
        if (tf - ts).abs() <= 1e-9 * ts {
            equal += 1;
        } else {
            assert!(
                tf < ts,
                "closed form {tf} longer than oracle {ts}: {axes:?}"
            );
            shorter += 1;
        }
    }
    eprintln!(
        "3-DoF time sync vs oracle: {equal} equal, {shorter} shorter (feasible), {rejected} rejected by both"
    );
    assert!(equal > 0);
}

/// Step 2 at random durations: wherever the oracle finds a profile of the duration, so does
/// the closed form (it may find more: the oracle lacks some shapes), and every profile is
/// exact and feasible.
#[test]
fn step_2_meets_every_duration_the_oracle_meets() {
    let mut rng = ChaCha8Rng::seed_from_u64(43);
    let (mut both, mut only_fast, mut neither) = (0, 0, 0);
    for i in 0..cases() / 4 {
        let a = draw(&mut rng, i);
        let Ok(fastest) = to_state(a.start, a.target, &a.limits, Shape::JerkLimited) else {
            continue;
        };
        let t = fastest.duration_s() * (1.0 + rng.random_range(0.0..1.0f64).powi(3));
        let fast =
            crate::duration::with_duration(a.start, a.target, &a.limits, Shape::JerkLimited, t)
                .expect("valid input");
        let slow =
            super::duration::with_duration(a.start, a.target, &a.limits, Shape::JerkLimited, t)
                .expect("valid input");
        match (&fast, &slow) {
            (Some(_), Some(_)) => both += 1,
            (Some(_), None) => only_fast += 1,
            (None, None) => neither += 1,
            (None, Some(_)) => panic!("only the oracle lasts {t}: {a:?}"),
        }
        if let Some(p) = fast {
            assert!((p.duration_s() - t).abs() <= 1e-9 * t, "{a:?}");
            assert!(reaches(&p, &a), "target missed {:?}: {a:?}", p.end());
            if let Err(e) = within_limits(&p, &a.limits) {
                panic!("{e}: {a:?} at {t}\n{:?}", p.segments());
            }
        }
    }
    eprintln!("step 2: both {both}, closed form only {only_fast}, neither {neither}");
    assert!(both > 0);
}

#[test]
fn velocity_step_2_equals_the_oracle() {
    let mut rng = ChaCha8Rng::seed_from_u64(44);
    let mut n = 0;
    for i in 0..cases() / 4 {
        let a = draw(&mut rng, i);
        let (vf, af) = (
            a.target.v,
            a.target.a.clamp(a.limits.amin(), a.limits.amax()),
        );
        let Ok(fastest) =
            crate::position::to_velocity(a.start, vf, af, &a.limits, Shape::JerkLimited)
        else {
            continue;
        };
        let t = fastest.duration_s() * (1.0 + rng.random_range(0.0..1.0f64).powi(3));
        let fast = crate::duration::velocity_with_duration(a.start, vf, af, &a.limits, t)
            .expect("valid input");
        let slow = super::duration::velocity_with_duration(a.start, vf, af, &a.limits, t)
            .expect("valid input");
        assert_eq!(fast.is_some(), slow.is_some(), "{a:?} at {t}");
        if let Some(p) = fast {
            let e = p.end();
            assert!((p.duration_s() - t).abs() <= 1e-9 * t);
            assert!((e.v - vf).abs() <= 1e-8 * vf.abs().max(1.0), "{a:?}");
            assert!(
                (e.a - af).abs() <= 1e-10 * a.limits.amax().max(1.0),
                "{a:?}"
            );
            n += 1;
        }
    }
    assert!(n > 0);
}
