//! Seeded random property tests of the rest-to-rest planners, and the S-curve duration
//! cross-check against rsruckig (an independent implementation of Ruckig).
//!
//! The case count comes from `SETTLE_PLANNER_CASES` (default 100,000).

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Gamma, Normal};
use rsruckig::prelude::*;
use settle_planner::{Limits, Profile, ProfileKind, Segment, scurve, trapezoid};

fn cases() -> usize {
    std::env::var("SETTLE_PLANNER_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(100_000)
}

/// Log-uniform draw in [lo, hi].
fn log_uniform(rng: &mut ChaCha8Rng, lo: f64, hi: f64) -> f64 {
    (rng.random_range(lo.ln()..hi.ln())).exp()
}

/// Check a rest-to-rest profile: target reached, limits respected, p/v (and a, for
/// jerk-limited kinds) continuous at every segment boundary, nothing NaN.
fn check(kind: ProfileKind, prof: &Profile, p0: f64, d: f64, lim: &Limits) {
    let tol = 1e-9;
    let scale = d.abs().max(p0.abs()).max(f64::MIN_POSITIVE);
    let end = prof.end();
    let ctx = format!("{kind} p0={p0} d={d} {lim:?}");
    assert!(
        (end.p - (p0 + d)).abs() <= tol * scale,
        "target missed by {}: {ctx}",
        end.p - (p0 + d)
    );
    assert!(end.v.abs() <= tol * lim.vmax(), "end v {}: {ctx}", end.v);
    assert!(end.a.abs() <= tol * lim.amax(), "end a {}: {ctx}", end.a);
    let vlim = lim.vmax() * (1.0 + tol);
    let alim = lim.amax() * (1.0 + tol);
    let jlim = lim.jmax().map_or(0.0, |j| j * (1.0 + tol));
    for (t, s, seg) in prof.iter() {
        assert!(t.is_finite() && s.p.is_finite() && s.v.is_finite() && s.a.is_finite());
        let e = seg.end_state(&s);
        // |a| is linear in each segment; |v| is extremal at the ends or where a = 0.
        let (a0, j) = seg.accel_and_jerk(&s);
        if j != 0.0 {
            let tau = -a0 / j;
            if tau > 0.0 && tau < seg.duration_s() {
                let v = seg.sample(&s, tau).v;
                assert!(v.abs() <= vlim, "vmax violated inside a segment: {ctx}");
            }
        }
        assert!(
            s.v.abs() <= vlim && e.v.abs() <= vlim,
            "vmax violated: {ctx}"
        );
        assert!(
            a0.abs() <= alim && e.a.abs() <= alim,
            "amax violated: {ctx}"
        );
        match (kind, seg) {
            (ProfileKind::SCurve, Segment::Jerk { .. }) => {
                assert!(j.abs() <= jlim, "jmax violated: {ctx}")
            }
            (ProfileKind::Trapezoid, Segment::Accel { .. }) => {}
            // A jerk-limited profile may hold an acceleration it already has (the cruise).
            (ProfileKind::SCurve, Segment::Accel { accel, .. }) => assert!(
                (accel - s.a).abs() <= 1e-9 * lim.amax(),
                "acceleration jump in an S-curve: {ctx}"
            ),
            _ => panic!("unexpected segment {seg:?} for {ctx}"),
        }
    }
    // Continuity of the evaluator across each boundary: the change over a window of
    // 2*delta is bounded by the next derivative's limit.
    let delta = 1e-7 * prof.duration_s();
    for (t, _, _) in prof.iter().skip(1) {
        let (l, r) = (prof.state_at(t - delta), prof.state_at(t + delta));
        let slack = 1.0 + 1e-6;
        let dp_tol = 2.0 * delta * lim.vmax() * slack + 1e-15 * scale;
        let dv_tol = 2.0 * delta * lim.amax() * slack + 1e-15 * lim.vmax();
        assert!((r.p - l.p).abs() <= dp_tol, "p jumps at {t}: {ctx}");
        assert!((r.v - l.v).abs() <= dv_tol, "v jumps at {t}: {ctx}");
        if let (ProfileKind::SCurve, Some(j)) = (kind, lim.jmax()) {
            let da_tol = 2.0 * delta * j * slack + 1e-12 * lim.amax();
            assert!((r.a - l.a).abs() <= da_tol, "a jumps at {t}: {ctx}");
        }
    }
}

#[test]
fn random_moves_reach_target_within_limits_across_scales() {
    let mut rng = ChaCha8Rng::seed_from_u64(0x5e771e);
    for _ in 0..cases() {
        let vmax = log_uniform(&mut rng, 1e-3, 1e6);
        let amax = log_uniform(&mut rng, 1e-3, 1e6);
        let jmax = log_uniform(&mut rng, 1e-3, 1e6);
        let lim = Limits::new(vmax, amax, Some(jmax)).expect("limits");
        // Very short to very long moves, both directions.
        let sign = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
        let d = sign * log_uniform(&mut rng, 1e-9, 1e6);
        let p0 = rng.random_range(-100.0..100.0);
        for kind in [ProfileKind::Trapezoid, ProfileKind::SCurve] {
            let prof = kind.rest_to_rest(p0, d, &lim).expect("plan");
            check(kind, &prof, p0, d, &lim);
            // The any-state planner equals the closed-form rest-to-rest planner (given the
            // distance it actually sees: the target p0 + d as rounded in f64, minus p0).
            let d_seen = (p0 + d) - p0;
            let closed = match kind {
                ProfileKind::SCurve => scurve::rest_to_rest(p0, d_seen, &lim),
                ProfileKind::Trapezoid => trapezoid::rest_to_rest(p0, d_seen, &lim),
                other => unreachable!("{other} has no closed form here"),
            }
            .expect("closed form");
            let rel = (prof.duration_s() - closed.duration_s()).abs() / closed.duration_s();
            assert!(
                rel <= 1e-9,
                "{kind} d={d} {lim:?}: {} vs closed form {}",
                prof.duration_s(),
                closed.duration_s()
            );
        }
    }
}

fn ruckig_duration(d: f64, vmax: f64, amax: f64, jmax: f64) -> f64 {
    let mut otg = Ruckig::<1, ThrowErrorHandler>::new(None, 0.001);
    let mut input = InputParameter::new(None);
    input.current_position[0] = 0.0;
    input.target_position[0] = d;
    input.max_velocity[0] = vmax;
    input.max_acceleration[0] = amax;
    input.max_jerk[0] = jmax;
    let mut traj = Trajectory::new(None);
    otg.calculate(&input, &mut traj).expect("rsruckig solves");
    traj.get_duration()
}

#[test]
fn scurve_durations_equal_rsruckig() {
    // Drawn like the Ruckig paper: target ~ N(0, 4), limits ~ Gamma(2, 2) + 0.05.
    let mut rng = ChaCha8Rng::seed_from_u64(0xd07a7e);
    let target = Normal::new(0.0, 4.0).expect("normal");
    let gamma = Gamma::new(2.0, 2.0).expect("gamma");
    let n = cases();
    let mut worst = 0.0f64;
    for _ in 0..n {
        let d: f64 = target.sample(&mut rng);
        let vmax = gamma.sample(&mut rng) + 0.05;
        let amax = gamma.sample(&mut rng) + 0.05;
        let jmax = gamma.sample(&mut rng) + 0.05;
        let lim = Limits::new(vmax, amax, Some(jmax)).expect("limits");
        let ours = ProfileKind::SCurve
            .rest_to_rest(0.0, d, &lim)
            .expect("plan")
            .duration_s();
        let theirs = ruckig_duration(d, vmax, amax, jmax);
        let rel = (ours - theirs).abs() / theirs.max(f64::MIN_POSITIVE);
        worst = worst.max(rel);
        assert!(
            rel <= 1e-9,
            "d={d} vmax={vmax} amax={amax} jmax={jmax}: ours {ours} rsruckig {theirs}"
        );
    }
    eprintln!("{n} S-curves: worst relative duration difference to rsruckig {worst:.3e}");
}
