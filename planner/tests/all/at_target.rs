//! An axis already at its target. At rest there (same position, velocity and acceleration
//! zero) it is a zero-length profile, stretched by time and phase synchronisation to the
//! common duration as a hold (position constant, v = a = j = 0 throughout); moving or
//! accelerating there it still needs a real profile. Durations are checked against closed
//! forms and against the official Ruckig library (`ruckig` crate), which accepts such
//! inputs in every synchronisation mode.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use settle_planner::position::{Shape, to_state};
use settle_planner::sync::{Axis, Sync, plan};
use settle_planner::{Limits, Profile, State};

use crate::common::{braked, check_limits, draw_axis};

fn rest(p: f64) -> State {
    State { p, v: 0.0, a: 0.0 }
}

fn axis(start: State, target: State, jmax: Option<f64>) -> Axis {
    Axis {
        start,
        target,
        limits: Limits::new(1.0, 2.0, jmax).expect("limits"),
    }
}

/// The official Ruckig's duration for `axes` (jerk limited) under `sync`.
fn official(axes: &[Axis], sync: Sync) -> Option<f64> {
    let n = axes.len();
    let mut otg = ruckig::Ruckig::new_direct_and_offline(n);
    let mut input = ruckig::InputParameter::new(n);
    input.synchronization = match sync {
        Sync::Time => ruckig::Synchronization::Time,
        Sync::Phase => ruckig::Synchronization::Phase,
        Sync::None => ruckig::Synchronization::None,
    };
    for (i, a) in axes.iter().enumerate() {
        input.current_position[i] = a.start.p;
        input.current_velocity[i] = a.start.v;
        input.current_acceleration[i] = a.start.a;
        input.target_position[i] = a.target.p;
        input.target_velocity[i] = a.target.v;
        input.target_acceleration[i] = a.target.a;
        input.max_velocity[i] = a.limits.vmax();
        input.max_acceleration[i] = a.limits.amax();
        input.max_jerk[i] = a.limits.jmax().expect("jerk");
    }
    let mut traj = ruckig::Trajectory::new_direct(n);
    match otg.calculate(&mut input, &mut traj) {
        ruckig::Result::Working | ruckig::Result::Finished => Some(traj.get_duration()),
        _ => None,
    }
}

/// The profile stands still at `p` for its whole duration, checked at its segment ends and
/// at 101 points: position `p`, velocity, acceleration and jerk exactly zero.
fn stands_still(prof: &Profile, p: f64) {
    let d = prof.duration_s();
    for k in 0..=100 {
        let s = prof.state_at(d * f64::from(k) / 100.0);
        assert_eq!(
            (s.p, s.v, s.a, s.j),
            (p, 0.0, 0.0, 0.0),
            "at {k}%: {prof:?}"
        );
    }
    assert_eq!(prof.end(), rest(p));
}

const SYNCS: [Sync; 3] = [Sync::Time, Sync::Phase, Sync::None];

/// One axis alone at rest on its target: no segments, duration 0, as Ruckig's.
#[test]
fn one_axis_at_rest_on_its_target_is_a_zero_length_profile() {
    for (shape, jmax) in [(Shape::JerkLimited, Some(10.0)), (Shape::Trapezoid, None)] {
        for p in [0.0, 3.25, -1e6] {
            let a = axis(rest(p), rest(p), jmax);
            let prof = to_state(a.start, a.target, &a.limits, shape).expect("plans");
            assert!(prof.segments().is_empty(), "{prof:?}");
            assert_eq!(prof.duration_s(), 0.0);
            assert_eq!(prof.end(), rest(p));
            for sync in SYNCS {
                let profs = plan(&[a], shape, sync).expect("plans");
                assert_eq!(profs[0].duration_s(), 0.0, "{sync:?}");
                let both = plan(&[a, a], shape, sync).expect("plans");
                assert!(both.iter().all(|p| p.duration_s() == 0.0), "{sync:?}");
                if jmax.is_some() {
                    assert_eq!(official(&[a], sync), Some(0.0), "{sync:?}");
                }
            }
            assert_eq!(
                settle_planner::duration::with_duration(a.start, a.target, &a.limits, shape, 0.5)
                    .expect("valid")
                    .map(|p| p.duration_s()),
                Some(0.5)
            );
        }
    }
}

/// `{"p0":[0,0],"pf":[0,1],"vmax":[1,1],"amax":[2,2],"jmax":[10,10]}` in every sync mode:
/// axis 1 takes 1.7 s (jerk 0.2 s to amax 2, hold 0.3 s, jerk 0.2 s to vmax 1, so 0.35 m
/// each way, 0.3 s cruise for the 0.3 m left), 1.5 s as a trapezoid (0.5 s ramps, 0.5 s
/// cruise); axis 0 stands still for that long under time and phase sync, and has no
/// segments without sync. Ruckig gives the same durations.
#[test]
fn an_axis_at_rest_on_its_target_beside_a_moving_one() {
    for (shape, jmax, t1) in [
        (Shape::JerkLimited, Some(10.0), 1.7),
        (Shape::Trapezoid, None, 1.5),
    ] {
        for sync in SYNCS {
            for p in [0.0, -2.5] {
                let axes = [
                    axis(rest(p), rest(p), jmax),
                    axis(rest(0.0), rest(1.0), jmax),
                ];
                let profs =
                    plan(&axes, shape, sync).unwrap_or_else(|e| panic!("{shape:?} {sync:?}: {e}"));
                assert!((profs[1].duration_s() - t1).abs() < 1e-12, "{profs:?}");
                let end = profs[1].end();
                assert!((end.p - 1.0).abs() < 1e-12 && end.v.abs() < 1e-12);
                if sync == Sync::None {
                    assert!(profs[0].segments().is_empty(), "{profs:?}");
                    assert_eq!(profs[0].end(), rest(p));
                } else {
                    assert!(
                        (profs[0].duration_s() - profs[1].duration_s()).abs() < 1e-12,
                        "{sync:?}: {profs:?}"
                    );
                    assert_eq!(profs[0].segments().len(), 1, "one hold: {profs:?}");
                    stands_still(&profs[0], p);
                }
                if jmax.is_some() {
                    let t = official(&axes, sync).expect("Ruckig solves it");
                    assert!((t - t1).abs() < 1e-12, "{sync:?}: Ruckig {t}");
                }
            }
        }
    }
}

/// On the target's position but moving or accelerating: a real profile that leaves and
/// comes back, the fastest one (Ruckig's duration; the start is within the limits, so no
/// brake), reaching the target and keeping the limits.
#[test]
fn at_the_target_position_but_moving_is_an_ordinary_problem() {
    let cases = [
        State {
            p: 0.0,
            v: 0.5,
            a: 0.0,
        },
        State {
            p: 0.0,
            v: -0.5,
            a: 0.0,
        },
        State {
            p: 1.0,
            v: 0.0,
            a: 0.5,
        },
        State {
            p: 1.0,
            v: 0.3,
            a: -1.0,
        },
    ];
    for start in cases {
        let a = axis(start, rest(start.p), Some(10.0));
        let prof = to_state(a.start, a.target, &a.limits, Shape::JerkLimited).expect("plans");
        let t = official(&[a], Sync::Time).expect("Ruckig solves it");
        assert!(t > 0.0);
        assert!(
            ((prof.duration_s() - t) / t).abs() < 1e-9,
            "{start:?}: {} vs Ruckig {t}",
            prof.duration_s()
        );
        let e = prof.end();
        assert!(
            (e.p - start.p).abs() < 1e-9 && e.v.abs() < 1e-9 && e.a.abs() < 1e-9,
            "{e:?}"
        );
        check_limits(&prof, &a.limits).expect("within the limits");
        // With a resting axis beside it, in every sync mode.
        for sync in SYNCS {
            let axes = [a, axis(rest(2.0), rest(2.0), Some(10.0))];
            let profs = plan(&axes, Shape::JerkLimited, sync).expect("plans");
            assert!(((profs[0].duration_s() - t) / t).abs() < 1e-9, "{sync:?}");
            if sync == Sync::None {
                assert!(profs[1].segments().is_empty());
            } else {
                stands_still(&profs[1], 2.0);
            }
        }
    }
}

/// Random problems drawn like the Ruckig paper, with a third axis at rest on its target
/// (at a random position): time and phase synchronised durations equal Ruckig's (or are
/// shorter after a brake, as in `official_ruckig`), and the resting axis stands still.
#[test]
fn random_problems_with_a_resting_axis_vs_the_official_ruckig() {
    let mut rng = ChaCha8Rng::seed_from_u64(18);
    let (mut equal, mut shorter) = (0, 0);
    for _ in 0..2_000 {
        let (a, b) = (draw_axis(&mut rng), draw_axis(&mut rng));
        let mut c = draw_axis(&mut rng);
        c.start = rest(c.start.p);
        c.target = c.start;
        let axes = [a, b, c];
        for sync in [Sync::Time, Sync::Phase] {
            let (profs, t) = match (plan(&axes, Shape::JerkLimited, sync), official(&axes, sync)) {
                (Ok(p), Some(t)) => (p, t),
                (Err(_), None) => continue,
                (o, t) => panic!(
                    "only one solved: ours {:?} Ruckig {t:?}: {axes:?}",
                    o.map(|p| p.len())
                ),
            };
            let d = profs[0].duration_s();
            stands_still(&profs[2], c.start.p);
            assert!((profs[2].duration_s() - d).abs() <= 1e-9 * d.max(1.0));
            let rel = (d - t) / t;
            if rel.abs() <= 1e-9 {
                equal += 1;
            } else if rel < 0.0 && axes.iter().any(braked) {
                shorter += 1;
            } else {
                panic!("{sync:?}: duration {d} vs Ruckig {t}: {axes:?}");
            }
        }
    }
    eprintln!(
        "with a resting axis vs official Ruckig: equal {equal}, shorter after a brake {shorter}"
    );
    assert!(equal > 1_000, "{equal}");
}
