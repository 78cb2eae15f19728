//! PVT moves: the segment formulas against exact integration, a worked turnaround example,
//! continuity and limits of the turnarounds and step moves, the step moves' closed forms
//! checked against the PVT equations, and violations reported with limit and knot.
//!
//! Case count: `SETTLE_PLANNER_CASES` (default 100,000; this suite uses a twentieth).

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use settle_planner::pvt::step::{AsymShape, asymmetric, symmetric};
use settle_planner::pvt::turnaround::{four_plus_one, two_segment};
use settle_planner::pvt::{Knot, Pvt, PvtLimit, PvtLimits, check, segment, violations};
use settle_planner::{Limits, Segment, State, scurve};

fn cases() -> usize {
    std::env::var("SETTLE_PLANNER_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(100_000usize)
        .div_ceil(20)
}

fn log_uniform(rng: &mut ChaCha8Rng, lo: f64, hi: f64) -> f64 {
    rng.random_range(lo.ln()..hi.ln()).exp()
}

fn strict(amax: f64, jmax: Option<f64>, vmax: f64) -> PvtLimits {
    PvtLimits {
        vmax,
        amax,
        jmax,
        accel_jump_tol: 0.0,
    }
}

#[test]
fn segment_formulas_against_integration() {
    let mut rng = ChaCha8Rng::seed_from_u64(20);
    for _ in 0..cases() {
        let (x0, v0) = (rng.random_range(-1.0..1.0), rng.random_range(-2.0..2.0));
        let (a0, a1) = (rng.random_range(-5.0..5.0), rng.random_range(-5.0..5.0));
        let t = rng.random_range(0.01..2.0);
        let (x1, v1) = segment::end(x0, v0, a0, a1, t);
        let e = Segment::Jerk {
            duration_s: t,
            jerk: (a1 - a0) / t,
        }
        .end_state(&State {
            p: x0,
            v: v0,
            a: a0,
        });
        assert!((e.p - x1).abs() < 1e-12 && (e.v - v1).abs() < 1e-12);
        let (b0, b1) = segment::accels(x0, v0, x1, v1, t);
        assert!(
            (b0 - a0).abs() < 1e-9 && (b1 - a1).abs() < 1e-9,
            "{a0} {a1} {b0} {b1}"
        );
        // `durations_given_a0`: the duration from (x0, v0, a0) to (x1, v1) is among its roots,
        // and its end acceleration is 2 (v1 - v0)/t - a0.
        let ts = segment::durations_given_a0(x0, v0, a0, x1, v1);
        let hit = ts.iter().find(|&&s| (s - t).abs() < 1e-9 * t.max(1.0));
        assert!(hit.is_some(), "t={t} not in {ts:?}");
        assert!((2.0 * (v1 - v0) / t - a0 - a1).abs() < 1e-9);
    }
}

/// A worked turnaround (hand-calculated values): fly-axis scan speed `v0 = 0.5` at the
/// edge of the scan region, fly-axis acceleration `a1 = -500` at the apex of the symmetric
/// 2-segment turnaround (its PVT segment starts with `a0 = 0` and ends at rest with `a1`),
/// step-axis peak acceleration 2 and step 0.002. One half of the turnaround lasts
/// `t_out = -2 v0/a1 = 0.002`, the overtravel beyond the edge is
/// `-4 v0^2/(3 a1) = 6.667e-4`. With a 30 ms step window (an assumption of the example,
/// not derived from the step axis) the step axis's constant-velocity time is
/// `0.03 - t_out = 0.028`; the step axis's peak acceleration and step size enter only its
/// rise time `t_in`.
#[test]
fn turnaround_worked_numbers() {
    let tw = two_segment(0.5, 500.0).expect("turnaround");
    assert_eq!(tw.t_out_s, 0.002);
    assert!((tw.d_out - 6.667e-4).abs() < 5e-8 && (tw.d_out - 1.0 / 1500.0).abs() < 1e-18);
    let t_edge_total = 0.03 - tw.t_out_s;
    assert!((t_edge_total - 0.028).abs() < 1e-15);
    // The fly axis through the turnaround: acceleration 0 -> -500 -> 0, at rest at the
    // apex 0.6667 mm beyond the edge.
    let fly = Pvt::new(tw.knots(0.0, 0.0, 0.5, 1.0).to_vec(), 0.0, 0.0).expect("pvt");
    let (acc0, acc1) = (fly.accels[0], fly.accels[1]);
    assert!(
        acc0.0.abs() < 1e-9 && (acc0.1 + 500.0).abs() < 1e-9,
        "{acc0:?}"
    );
    assert!(
        (acc1.0 + 500.0).abs() < 1e-9 && acc1.1.abs() < 1e-9,
        "{acc1:?}"
    );
    let apex = fly.profile.state_at(0.002);
    assert!((apex.p - 1.0 / 1500.0).abs() < 1e-15 && apex.v.abs() < 1e-15);
    assert!(check(&fly, &strict(500.0, Some(tw.jerk), 0.5)).is_ok());
    // What the step axis's peak acceleration and step give with those times: the
    // 4+1-segment step's t_in, rederived here from its defining quadratic
    // t_in^2 + (3 t_out + 3/2 t_edge) t_in + 2 t_out^2 + 3/2 t_out t_edge - 3 d/a = 0.
    let st = four_plus_one(0.002, 2.0, tw.t_out_s, t_edge_total).expect("step");
    let (b, c) = (
        3.0 * 0.002 + 1.5 * 0.028,
        2.0 * 0.002f64.powi(2) + 1.5 * 0.002 * 0.028 - 3.0 * 0.002 / 2.0,
    );
    let t_in = (-b + (b * b - 4.0 * c).sqrt()) / 2.0;
    assert!((st.t_in_s - t_in).abs() < 1e-15, "{} vs {t_in}", st.t_in_s);
    assert!((st.t_in_s - 0.035_025_4).abs() < 1e-7);
    let m = st.pvt(0.0).expect("pvt");
    assert!((m.profile.end().p - 0.002).abs() < 1e-15 && m.profile.end().v.abs() < 1e-15);
    assert!(check(&m, &strict(2.0 * (1.0 + 1e-12), None, 1.0)).is_ok());
    assert!((st.duration_s() - (2.0 * (t_in + 0.002) + 0.028)).abs() < 1e-15);
}

#[test]
fn four_plus_one_step_matches_its_knot_formulas() {
    let mut rng = ChaCha8Rng::seed_from_u64(21);
    let mut done = 0;
    while done < cases() {
        let (a, t_out, t_edge) = (
            log_uniform(&mut rng, 0.1, 100.0),
            log_uniform(&mut rng, 1e-4, 1.0),
            if rng.random_bool(0.2) {
                0.0
            } else {
                log_uniform(&mut rng, 1e-4, 1.0)
            },
        );
        let d = log_uniform(&mut rng, 1e-6, 10.0);
        let Ok(st) = four_plus_one(d, a, t_out, t_edge) else {
            // Too short: t_in would be negative.
            assert!(3.0 * d / a < 2.0 * t_out * t_out + 1.5 * t_out * t_edge);
            continue;
        };
        let m = st.pvt(0.0).expect("pvt");
        let p = &m.profile;
        let scale = d;
        let at = |t: f64| p.state_at(t);
        let s1 = at(st.t_in_s);
        assert!(
            (s1.p - st.d_in()).abs() <= 1e-12 * scale
                && (s1.v - st.v_in()).abs() <= 1e-9 * st.v_edge()
        );
        let s2 = at(st.t_in_s + t_out);
        assert!((s2.p - st.d_in() - st.d_out()).abs() <= 1e-12 * scale);
        assert!((s2.v - st.v_edge()).abs() <= 1e-9 * st.v_edge());
        assert!((p.end().p - d).abs() <= 1e-12 * scale && p.end().v.abs() <= 1e-9 * st.v_edge());
        let lim = strict(a * (1.0 + 1e-9), None, st.v_edge() * (1.0 + 1e-9));
        assert!(check(&m, &lim).is_ok(), "{:?}", violations(&m, &lim));
        done += 1;
    }
}

/// The asymmetric step's closed form in `Ki` (`planner/src/pvt/step.rs`) solves the PVT
/// equations: building the knots from it and recomputing each segment's accelerations
/// with `segment::accels` gives `0 -> a0 -> -a0 -> -a0 -> a3 -> 0` with no jump, and
/// `t0 = 3 x0/v0`, `a0 = 2 v0^2/(3 x0)` hold.
#[test]
fn asymmetric_closed_form_solves_the_pvt_equations() {
    let mut rng = ChaCha8Rng::seed_from_u64(22);
    for _ in 0..1000 {
        let ki = rng.random_range(0.34..0.99);
        let s = AsymShape::new(ki).expect("shape");
        let m = Pvt::new(s.knots(0.0, 1.0, 1.0).to_vec(), 0.0, 0.0).expect("pvt");
        let [a0, a3] = s.a;
        let want = [(0.0, a0), (a0, -a0), (-a0, a3), (a3, 0.0)];
        for (k, (got, w)) in m.accels.iter().zip(want).enumerate() {
            let tol = 1e-9 * a0;
            assert!(
                (got.0 - w.0).abs() <= tol && (got.1 - w.1).abs() <= tol,
                "ki={ki} seg {k}: {got:?} vs {w:?}"
            );
        }
        assert!((s.t0 - 3.0 * s.x[0] / s.v[0]).abs() < 1e-12 * s.t0);
        assert!((a0 - 2.0 * s.v[0] * s.v[0] / (3.0 * s.x[0])).abs() < 1e-12);
        assert!((m.profile.end().p - 1.0).abs() < 1e-12);
        // Peak acceleration and peak jerk in the first half of the move.
        let half = m.duration_s() / 2.0;
        let t_peak_a = s.t0; // the knot where a = a0
        assert!(t_peak_a < half && a3.abs() < a0);
        let (_, _, seg) = m
            .profile
            .iter()
            .max_by(|x, y| {
                let jx = x.2.accel_and_jerk(&x.1).1.abs();
                let jy = y.2.accel_and_jerk(&y.1).1.abs();
                jx.total_cmp(&jy)
            })
            .expect("segments");
        let (t_j, _, _) = m.profile.iter().find(|(_, _, g)| *g == seg).expect("seg");
        assert!(t_j < half, "peak jerk at {t_j} of {}", m.duration_s());
    }
    assert!(AsymShape::new(1.0 / 3.0).is_err() && AsymShape::new(1.0).is_err());
}

/// A closed-form 4-segment step for given quarter positions and settling acceleration
/// `a3 = -alpha^2` (knot velocities and accelerations below), at `t1 = 0.01`,
/// `delta^2 = 0.001`, `alpha = -sqrt(0.1)`, solves the PVT equations; the acceleration
/// jumps at knot 0 by design (`a00 != a0`).
#[test]
fn quarter_position_closed_form_at_a_test_case() {
    let (t1, delta, alpha) = (0.01f64, 0.001f64.sqrt(), -(0.1f64.sqrt()));
    let r6 = 6f64.sqrt();
    let v0 = (r6 * alpha * delta * t1 + 6.0 * delta * delta) / (20.0 * t1);
    let a0 = -(5.0 * alpha * alpha * t1 * t1 - 3.0 * r6 * alpha * delta * t1 - 3.0 * delta * delta)
        / (5.0 * t1 * t1);
    let x1 =
        -(10.0 * alpha * alpha * t1 * t1 - 9.0 * r6 * alpha * delta * t1 - 39.0 * delta * delta)
            / 60.0;
    let v3 = -r6 * alpha * delta / 4.0;
    let t4 = -r6 * delta / (2.0 * alpha);
    let x4 = delta * delta;
    let (x0, x3, a3) = (x4 / 4.0, 3.0 * x4 / 4.0, -alpha * alpha);
    let t0 = 3.0 * x0 / v0;
    let a00 = 2.0 * v0 * v0 / (3.0 * x0);
    let knots = vec![
        Knot::new(0.0, 0.0, 0.0),
        Knot::new(t0, x0, v0),
        Knot::new(t0 + t1, x1, v0),
        Knot::new(t0 + 2.0 * t1, x3, v3),
        Knot::new(t0 + 2.0 * t1 + t4, x4, 0.0),
    ];
    let m = Pvt::new(knots, 0.0, 0.0).expect("pvt");
    let tol = 1e-9 * a0.abs();
    let want = [(0.0, a00), (a0, -a0), (-a0, a3), (a3, 0.0)];
    for (k, (got, w)) in m.accels.iter().zip(want).enumerate() {
        assert!(
            (got.0 - w.0).abs() <= tol && (got.1 - w.1).abs() <= tol,
            "seg {k}: {got:?} vs {w:?}"
        );
    }
    assert!((m.accel_jump(1) - (a0 - a00)).abs() <= tol && (a0 - a00).abs() > 1e-3 * a0.abs());
    assert!(t4 > 0.0 && v0 > 0.0 && a3 < 0.0);
}

#[test]
fn step_moves_are_continuous_and_within_limits() {
    let mut rng = ChaCha8Rng::seed_from_u64(23);
    for _ in 0..cases() {
        let lim = Limits::new(
            log_uniform(&mut rng, 1e-2, 1e2),
            log_uniform(&mut rng, 1e-1, 1e3),
            Some(log_uniform(&mut rng, 1.0, 1e5)),
        )
        .expect("limits");
        let d = log_uniform(&mut rng, 1e-6, 1e1) * if rng.random_bool(0.5) { 1.0 } else { -1.0 };
        let x0 = rng.random_range(-1.0..1.0);
        let pl = strict(lim.amax(), lim.jmax(), lim.vmax());
        let sym = symmetric(x0, d, &lim).expect("symmetric");
        assert!(
            check(&sym, &pl).is_ok(),
            "{:?} {lim:?} d={d} x0={x0} {:?} {:?}",
            violations(&sym, &pl),
            sym.knots,
            sym.accels
        );
        let s = scurve::rest_to_rest(x0, d, &lim).expect("s-curve");
        // As close to the target as the closed-form S-curve itself gets.
        let miss = (sym.profile.end().p - (x0 + d)).abs();
        let miss_s = (s.end().p - (x0 + d)).abs();
        assert!(
            miss <= 4.0 * miss_s + 1e-14 * (1.0 + d.abs()),
            "missed by {miss} (s-curve {miss_s}): {lim:?} d={d} x0={x0}"
        );
        assert!((sym.duration_s() - s.duration_s()).abs() <= 1e-12 * s.duration_s());
        for ki in [0.4, 0.5, 0.7] {
            let asy = asymmetric(x0, d, ki, &lim).expect("asymmetric");
            assert!(
                check(&asy, &pl).is_ok(),
                "ki={ki}: {:?}",
                violations(&asy, &pl)
            );
            let e = asy.profile.end();
            assert!(
                (e.p - (x0 + d)).abs() <= 1e-12 * (1.0 + d.abs()) && e.v.abs() < 1e-9 * lim.vmax()
            );
            // Time-scaled to the limits: one of them is reached.
            let loose = strict(
                lim.amax() * 0.999,
                lim.jmax().map(|j| j * 0.999),
                lim.vmax() * 0.999,
            );
            assert!(
                check(&asy, &loose).is_err(),
                "ki={ki}: not time-scaled to its limits"
            );
        }
    }
}

#[test]
fn violations_name_the_limit_and_where() {
    // Rest -> (1 s, 0.5, 1) -> (2 s, 2, 0) -> rest. Segment 0 needs a = 1 throughout (a
    // jump of 1 at knot 0), segment 1 runs 5 -> -7 (jump of 4 at knot 1, jerk 12, the
    // velocity peaks at 1 + 5 (5/12) - 12 (5/12)^2/2 = 49/24 where a = 0), and the return to
    // rest jumps by 7 at knot 2.
    let m = Pvt::new(
        vec![
            Knot::new(0.0, 0.0, 0.0),
            Knot::new(1.0, 0.5, 1.0),
            Knot::new(2.0, 2.0, 0.0),
        ],
        0.0,
        0.0,
    )
    .expect("pvt");
    assert_eq!(m.accels, vec![(1.0, 1.0), (5.0, -7.0)]);
    let lim = strict(6.0, Some(10.0), 2.0);
    let v = violations(&m, &lim);
    let kinds: Vec<(PvtLimit, usize)> = v.iter().map(|x| (x.limit, x.at)).collect();
    assert_eq!(
        kinds,
        vec![
            (PvtLimit::AccelerationJump, 0),
            (PvtLimit::AccelerationJump, 1),
            (PvtLimit::Jerk, 1),
            (PvtLimit::Velocity, 1),
            (PvtLimit::AccelerationJump, 2),
            (PvtLimit::Acceleration, 2),
        ]
    );
    assert!((v[3].value - 49.0 / 24.0).abs() < 1e-12);
    assert_eq!((v[2].value, v[5].value), (12.0, 7.0));
    let e = check(&m, &lim).expect_err("violated");
    assert_eq!(
        e.to_error().to_string(),
        "segment 0: PVT acceleration jumps at the knot with this index"
    );
    // Tolerating jumps leaves the other three.
    let loose = PvtLimits {
        accel_jump_tol: 10.0,
        ..lim
    };
    assert_eq!(violations(&m, &loose).len(), 3);
}
