//! RepRapFirmware's planner (settle_planner::firmware::rrf) against hand-computed plans.

use settle_planner::firmware::rrf::{RrfConfig, RrfPlanner};
use settle_planner::firmware::{FirmwarePlanner, Kinematics, LinearMove, PlannedMove};

use super::firmware_common::{MM, assert_rel, leg, plan_with, xye as mv};

fn plan(cfg: RrfConfig, moves: &[LinearMove]) -> (Vec<PlannedMove>, f64) {
    plan_with(&mut RrfPlanner::new(cfg).expect("config"), moves)
}

#[test]
fn straight_line_with_the_defaults() {
    // M201 X1000 and M203 X100 mm/s (defaults); M204 does not bind (50000).
    let (out, t) = plan(
        RrfConfig::new(),
        &[mv([0.0, 0.0], [100.0, 0.0], 0.0, 150.0)],
    );
    assert_rel("print time", t, 0.1 / 0.1 + 0.1 / 1.0, 1e-12);
    assert_rel("top speed", out[0].cruise_speed_m_s, 0.1, 1e-12);
}

#[test]
fn corner_jerk_and_reversal_jerk() {
    let (l, v, a) = (50.0 * MM, 100.0 * MM, 1.0);
    // 90 degrees: X changes by 1 x v, Y by 1 x v: both within 15 mm/s at v = 15 mm/s.
    let corner = [
        mv([0.0, 0.0], [50.0, 0.0], 0.0, 100.0),
        mv([50.0, 0.0], [50.0, 50.0], 0.0, 100.0),
    ];
    let (out, t) = plan(RrfConfig::new(), &corner);
    let vj = 15.0 * MM;
    assert_rel("corner", out[0].end_speed_m_s, vj, 1e-12);
    assert_rel("print time", t, 2.0 * leg(l, v, a, 0.0, vj), 1e-12);
    // Reversal: X changes from +v to -v, twice the speed: v = 15 / 2 mm/s.
    let rev = [
        mv([0.0, 0.0], [50.0, 0.0], 0.0, 100.0),
        mv([50.0, 0.0], [0.0, 0.0], 0.0, 100.0),
    ];
    let (out, t) = plan(RrfConfig::new(), &rev);
    let vr = 7.5 * MM;
    assert_rel("reversal", out[1].start_speed_m_s, vr, 1e-12);
    assert_rel("print time", t, 2.0 * leg(l, v, a, 0.0, vr), 1e-12);
    // 45 degrees: X drops by v (1 - cos45), Y rises by v sin45: Y binds, v = 15/sin45.
    let diag = [
        mv([0.0, 0.0], [50.0, 0.0], 0.0, 100.0),
        mv([50.0, 0.0], [100.0, 50.0], 0.0, 100.0),
    ];
    let (out, _) = plan(RrfConfig::new(), &diag);
    assert_rel(
        "45 degrees",
        out[0].end_speed_m_s,
        vj / std::f64::consts::FRAC_1_SQRT_2,
        1e-12,
    );
}

#[test]
fn printing_and_travel_moves_are_not_joined() {
    // Jerk policy 0: a printing move followed by a travel stops in between, even in a
    // straight line. Policy 1 joins them.
    let (l, v, a) = (50.0 * MM, 100.0 * MM, 1.0);
    let moves = [
        mv([0.0, 0.0], [50.0, 0.0], 2.0, 100.0),
        mv([50.0, 0.0], [100.0, 0.0], 0.0, 100.0),
    ];
    let (out, t) = plan(RrfConfig::new(), &moves);
    assert_eq!(out[0].end_speed_m_s, 0.0);
    assert_rel("policy 0", t, 2.0 * leg(l, v, a, 0.0, 0.0), 1e-12);
    let cfg = RrfConfig {
        jerk_policy: 1,
        ..RrfConfig::new()
    };
    let (out, t) = plan(cfg, &moves);
    // Straight on, only the extruder changes speed: E drops from 2/50 v = 4 mm/s to 0,
    // within its 5 mm/s jerk, so the junction runs at full speed: one trapezoid.
    assert_rel("policy 1 junction", out[0].end_speed_m_s, v, 1e-12);
    assert_rel("policy 1", t, 2.0 * l / v + v / a, 1e-12);
}

#[test]
fn extruder_jerk_limits_a_straight_junction() {
    // Straight on, extrusion ratio 0.1 then 0.02 (E per mm): E changes by 0.08 v, within
    // 5 mm/s only up to v = 62.5 mm/s.
    let moves = [
        mv([0.0, 0.0], [50.0, 0.0], 5.0, 100.0),
        mv([50.0, 0.0], [100.0, 0.0], 1.0, 100.0),
    ];
    let (out, t) = plan(RrfConfig::new(), &moves);
    let vj = 5.0 * MM / 0.08;
    assert_rel("junction", out[0].end_speed_m_s, vj, 1e-12);
    let (l, v, a) = (50.0 * MM, 100.0 * MM, 1.0);
    assert_rel("print time", t, 2.0 * leg(l, v, a, 0.0, vj), 1e-12);
}

#[test]
fn chain_of_short_moves_reaches_the_triangle_peak() {
    // Ten collinear 1 mm travels at 100 mm/s with M201 X500: the look-ahead raises every
    // junction until the chain is one triangle, v_p^2 = a D, t = 2 sqrt(D / a).
    let cfg = RrfConfig {
        max_accel_m_s2: [0.5, 0.5, 0.2, 0.5],
        ..RrfConfig::new()
    };
    let moves: Vec<_> = (0..10)
        .map(|i| mv([f64::from(i), 0.0], [f64::from(i + 1), 0.0], 0.0, 100.0))
        .collect();
    let (out, t) = plan(cfg, &moves);
    let (d, a) = (10.0 * MM, 0.5);
    assert_rel("triangle", t, 2.0 * (d / a).sqrt(), 1e-9);
    let peak = out.iter().map(|m| m.cruise_speed_m_s).fold(0.0, f64::max);
    assert_rel("peak", peak, (a * d).sqrt(), 1e-9);
}

#[test]
fn corexy_limits_each_motor() {
    // A diagonal moves motor A by sqrt2 per mm of path: speed 100 / sqrt2 mm/s and
    // acceleration 1000 / sqrt2 mm/s^2 keep motor A within its M203/M201 limits.
    let cfg = RrfConfig {
        kinematics: Kinematics::CoreXy,
        ..RrfConfig::new()
    };
    let l = 100.0 * std::f64::consts::SQRT_2 * MM;
    let (out, t) = plan(cfg, &[mv([0.0, 0.0], [100.0, 100.0], 0.0, 200.0)]);
    let (v, a) = (
        0.1 / std::f64::consts::SQRT_2,
        1.0 / std::f64::consts::SQRT_2,
    );
    assert_rel("speed", out[0].cruise_speed_m_s, v, 1e-12);
    assert_rel("print time", t, l / v + v / a, 1e-12);
}

#[test]
fn the_ring_bounds_look_ahead_on_tiny_segments() {
    // 2000 collinear 0.05 mm moves at 100 mm/s: stopping from 100 mm/s takes 5 mm, 100
    // moves, but the ring holds 60 moves of which at most half are prepared. In the
    // steady state a move is frozen as the 30th prepared one, with 29 provisional moves
    // behind it that must end at rest: its top speed is v^2 = 2 a (30 L), 54.8 mm/s.
    // Every move starts at the speed the previous one ends with.
    let moves: Vec<_> = (0..2000)
        .map(|i| {
            let x = f64::from(i) * 0.05;
            mv([x, 0.0], [x + 0.05, 0.0], 0.0, 100.0)
        })
        .collect();
    let mut p = RrfPlanner::new(RrfConfig::new()).expect("config");
    let mut out = Vec::new();
    let mut most = 0;
    for m in &moves {
        p.push(m).expect("move");
        most = most.max(p.queued());
        out.extend(std::iter::from_fn(|| p.pop()));
    }
    p.finish();
    out.extend(std::iter::from_fn(|| p.pop()));
    assert_eq!(out.len(), 2000);
    assert!(most <= 60);
    let peak = out.iter().map(|m| m.cruise_speed_m_s).fold(0.0, f64::max);
    assert_rel(
        "ring-limited peak",
        peak,
        (2.0 * 1.0 * 30.0 * 0.05 * MM).sqrt(),
        1e-9,
    );
    for w in out.windows(2) {
        assert_rel(
            "junction",
            w[1].start_speed_m_s.max(1e-12),
            w[0].end_speed_m_s.max(1e-12),
            1e-9,
        );
        assert!((w[1].start_time_s - w[0].end_time_s()).abs() < 1e-12);
    }
}
