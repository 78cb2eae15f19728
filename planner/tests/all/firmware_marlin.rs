//! Marlin's planner (settle_planner::firmware::marlin) against hand-computed step plans.
//!
//! Every expected value is computed here from planner.cpp's rules: rates in steps/s
//! (`ceil`), `MINIMAL_STEP_RATE` 120, acceleration steps `ceil`, deceleration steps
//! `floor`, and the stepper's ramps in continuous time between those step counts.

use settle_planner::firmware::marlin::{JdSmallSegments, MarlinConfig, MarlinJerk, MarlinPlanner};
use settle_planner::firmware::{Kinematics, LinearMove, PlannedMove, RampShape};

use super::firmware_common::{MM, assert_rel, plan_with, xy};

fn plan(cfg: MarlinConfig, moves: &[LinearMove]) -> (Vec<PlannedMove>, f64) {
    plan_with(&mut MarlinPlanner::new(cfg).expect("config"), moves)
}

/// The defaults: 80 steps/mm on X and Y, 3000 mm/s^2, junction deviation 0.013 mm.
fn defaults() -> MarlinConfig {
    MarlinConfig::new()
}

/// Stepper time of a linear ramp from `r0` by `a` (steps/s^2, signed) over `n` steps,
/// reaching `n` before the target rate: `n = r0 t + a t^2 / 2`.
fn ramp_time(r0: f64, a: f64, n: f64) -> f64 {
    2.0 * n / (r0 + (r0 * r0 + 2.0 * a * n).sqrt())
}

/// Time of a block of `n` steps at nominal rate `rn`, accelerating at `a` from `r0` for
/// `na` steps and decelerating towards `rf` for `nd` steps, as the stepper runs it.
fn trapezoid_time(n: f64, rn: f64, a: f64, r0: f64, rf: f64, na: f64, nd: f64) -> f64 {
    // Accelerate: the full ramp to rn (distance d_up), then hold rn for the rest of na.
    let d_up = (rn * rn - r0 * r0) / (2.0 * a);
    let t_acc = if na >= d_up {
        (rn - r0) / a + (na - d_up) / rn
    } else {
        ramp_time(r0, a, na)
    };
    let peak = if na >= d_up {
        rn
    } else {
        (r0 * r0 + 2.0 * a * na).sqrt()
    };
    let t_cruise = (n - na - nd) / rn;
    let d_down = (peak * peak - rf * rf) / (2.0 * a);
    let t_dec = if nd >= d_down {
        (peak - rf) / a + (nd - d_down) / rf
    } else {
        ramp_time(peak, -a, nd)
    };
    t_acc + t_cruise + t_dec
}

/// Steps to change rate from `from` to `to` at `a` (estimate_acceleration_distance).
fn steps(from: f64, to: f64, a: f64) -> f64 {
    (to * to - from * from) / (2.0 * a)
}

/// Two 50 mm blocks at 100 mm/s (4000 steps at 8000 steps/s, 240000 steps/s^2 each) from
/// rest to rest through a junction at rate `rj`: acceleration steps `ceil`ed,
/// deceleration steps `floor`ed, 120 steps/s at both ends.
fn two_blocks(rj: f64) -> f64 {
    let (n, rn, a) = (4000.0, 8000.0, 240_000.0);
    let t1 = trapezoid_time(
        n,
        rn,
        a,
        120.0,
        rj,
        steps(120.0, rn, a).ceil(),
        steps(rj, rn, a).floor(),
    );
    let t2 = trapezoid_time(
        n,
        rn,
        a,
        rj,
        120.0,
        steps(rj, rn, a).ceil(),
        steps(120.0, rn, a).floor(),
    );
    t1 + t2
}

#[test]
fn straight_line_block_in_steps() {
    // X 100 mm at 100 mm/s, 80 steps/mm: N = 8000 steps, nominal 8000 steps/s,
    // acceleration ceil(3000 * 80) = 240000 steps/s^2. Entry and exit at
    // MINIMUM_PLANNER_SPEED (0.05 mm/s -> 4 steps/s) are raised to 120 steps/s.
    let (out, t) = plan(defaults(), &[xy([0.0, 0.0], [100.0, 0.0], 100.0)]);
    let (n, rn, a, r0): (f64, f64, f64, f64) = (8000.0, 8000.0, 240_000.0, 120.0);
    let na = ((rn * rn - r0 * r0) / (2.0 * a)).ceil(); // 134
    let nd = ((rn * rn - r0 * r0) / (2.0 * a)).floor(); // 133
    assert_eq!((na, nd), (134.0, 133.0));
    assert_rel(
        "print time",
        t,
        trapezoid_time(n, rn, a, r0, r0, na, nd),
        1e-12,
    );
    // The deceleration ends one-third of a step early, at sqrt(8000^2 - 2 a 133) = 400
    // steps/s = 5 mm/s: the stepper then stops.
    assert_rel("end speed", out[0].end_speed_m_s, 400.0 / 80.0 * MM, 1e-12);
    assert_rel(
        "start speed",
        out[0].start_speed_m_s,
        120.0 / 80.0 * MM,
        1e-12,
    );
}

fn corner(cfg: MarlinConfig) -> (Vec<PlannedMove>, f64) {
    plan(
        cfg,
        &[
            xy([0.0, 0.0], [50.0, 0.0], 100.0),
            xy([50.0, 0.0], [50.0, 50.0], 100.0),
        ],
    )
}

#[test]
fn ninety_degree_corner_junction_deviation() {
    // vmax^2 = a jd sin(45)/(1 - sin(45)) with a = 3000 mm/s^2 (the junction vector
    // (-1, 1)/sqrt2 is within both axes' limits), jd = 0.013 mm: 9.70 mm/s.
    let (out, t) = corner(defaults());
    let s = std::f64::consts::FRAC_1_SQRT_2;
    let vj = (3.0 * 0.013e-3 * s / (1.0 - s)).sqrt();
    // Both blocks: N = 4000 steps in 0.5 s, nominal 8000 steps/s. The corner rate:
    // ceil(8000 vj / 0.1).
    let rj = (8000.0 * vj / 0.1).ceil();
    assert_eq!(rj, 777.0);
    assert_rel("print time", t, two_blocks(rj), 1e-12);
    assert_rel(
        "corner entry",
        out[1].start_speed_m_s,
        rj / 80.0 * MM,
        1e-12,
    );
}

fn classic(jerk_mm_s: f64) -> MarlinConfig {
    let mut c = defaults();
    c.jerk = MarlinJerk::Classic {
        max_jerk_m_s: [jerk_mm_s * MM, jerk_mm_s * MM, 0.3 * MM, 5.0 * MM],
        travel_extra_xy_jerk_m_s: 0.0,
    };
    c
}

#[test]
fn ninety_degree_corner_classic_jerk() {
    // X jumps from 100 to 0 mm/s: the junction scales to jerk / 100 of the nominal
    // speed, 10 mm/s; both blocks' safe speeds (10 mm/s) are above 0.99 of it, so the
    // safe speed is taken: 10 mm/s, 800 steps/s.
    let (out, t) = corner(classic(10.0));
    assert_eq!(steps(800.0, 8000.0, 240_000.0), 132.0);
    assert_rel("print time", t, two_blocks(800.0), 1e-12);
    assert_rel("corner", out[0].end_speed_m_s, 10.0 * MM, 1e-12);
    // Classic jerk passes this corner faster than junction deviation 0.013 mm (9.70).
    let (_, t_jd) = corner(defaults());
    assert!(t < t_jd);
}

#[test]
fn reversal_junction_deviation_stops_classic_jerk_does_not() {
    let moves = [
        xy([0.0, 0.0], [50.0, 0.0], 100.0),
        xy([50.0, 0.0], [0.0, 0.0], 100.0),
    ];
    // Junction deviation: cos(theta) > 0.999999 -> MINIMUM_PLANNER_SPEED, 120 steps/s.
    let (_, t) = plan(defaults(), &moves);
    assert_rel("jd reversal", t, two_blocks(120.0), 1e-12);
    // Classic jerk: the reversal counts the larger of the two speeds as the jump, 100
    // mm/s on X -> factor 0.1 -> 10 mm/s, and the safe speeds take it: the toolhead
    // reverses from +10 to -10 mm/s at once.
    let (out, t) = plan(classic(10.0), &moves);
    assert_rel("classic reversal", t, two_blocks(800.0), 1e-12);
    assert_eq!(out[1].axes_r[0], -1.0);
    assert_rel("reversal speed", out[1].start_speed_m_s, 10.0 * MM, 1e-12);
}

#[test]
fn first_block_is_planned_with_three_blocks_known() {
    // The stepper takes the first block once three are queued: a 10 mm move followed by
    // two 0.2 mm moves must then be able to stop within 0.4 mm, so the 10 mm block
    // decelerates to v^2 = MIN^2 + 2 a 0.4 mm although more moves follow.
    let mut c = defaults();
    c.slowdown = false;
    let moves = [
        xy([0.0, 0.0], [10.0, 0.0], 200.0),
        xy([10.0, 0.0], [10.2, 0.0], 200.0),
        xy([10.2, 0.0], [10.4, 0.0], 200.0),
        xy([10.4, 0.0], [30.4, 0.0], 200.0),
    ];
    let (out, _) = plan(c, &moves);
    let v_min = 0.05 * MM;
    let v_exit = (v_min * v_min + 2.0 * 3.0 * 0.4 * MM).sqrt();
    // N = 800, nominal 200 mm/s = 16000 steps/s; exit rate ceil(16000 v / 0.2).
    let (n, rn, a) = (800.0, 16000.0, 240_000.0);
    let rf = (rn * v_exit / 0.2).ceil();
    let (na, nd) = (steps(120.0, rn, a).ceil(), steps(rf, rn, a).floor());
    assert!(na + nd > n, "no cruise in this block");
    // A triangle: accelerate ceil(intersection_distance) steps, then decelerate.
    let na = ((2.0 * a * n - 120.0 * 120.0 + rf * rf) / (4.0 * a)).ceil();
    let want = trapezoid_time(n, rn, a, 120.0, rf, na, n - na);
    assert_rel("first block", out[0].duration_s(), want, 1e-12);
    assert!(out[0].end_speed_m_s < 0.06);
}

#[test]
fn slowdown_stretches_short_blocks_while_the_queue_is_short() {
    // Three 1 mm blocks at 200 mm/s (5 ms each; M205 B 20 ms): the third is added with
    // two blocks queued, so its time becomes 5000 + 2 (20000 - 5000) / 2 = 20000 us:
    // 50 mm/s, nominal rate ceil(80 * 50) = 4000 steps/s.
    let moves: Vec<_> = (0..3)
        .map(|i| xy([f64::from(i), 0.0], [f64::from(i + 1), 0.0], 200.0))
        .collect();
    let (out, _) = plan(defaults(), &moves);
    assert_rel("slowed nominal", out[2].cruise_speed_m_s, 50.0 * MM, 1e-12);
    assert!(out[2].cruise_t_s > 0.0);
    let mut c = defaults();
    c.slowdown = false;
    let (out, _) = plan(c, &moves);
    assert!(out[2].cruise_speed_m_s > 50.0 * MM);
}

#[test]
fn s_curve_keeps_phase_times_and_follows_the_bezier() {
    let mv = [xy([0.0, 0.0], [100.0, 0.0], 100.0)];
    let (lin, _) = plan(defaults(), &mv);
    let mut c = defaults();
    c.s_curve = true;
    let (bez, _) = plan(c, &mv);
    let (l, b) = (&lin[0], &bez[0]);
    assert!(b.s_curve);
    // The acceleration phase lasts (cruise - initial) / A in both (the Bezier covers the
    // same distance in the same time), as does the cruise.
    assert_rel("accel time", b.accel_t_s, l.accel_t_s, 1e-12);
    assert_rel("cruise time", b.cruise_t_s, l.cruise_t_s, 1e-12);
    let ramp = b.phases()[0];
    assert_eq!(ramp.shape, RampShape::Bezier);
    // Peak acceleration 1.875 dv / T at mid-ramp: dv = (8000 - 120) / 80 mm/s.
    let (dv, t_ramp) = (7880.0 / 80.0 * MM, 7880.0 / 240_000.0);
    assert_rel(
        "peak accel",
        ramp.state_at(0.5 * t_ramp).a_m_s2,
        1.875 * dv / t_ramp,
        1e-12,
    );
    // The deceleration is cut at its 133rd step: the Bezier from 8000 towards 120 steps/s
    // has covered exactly 133 steps (m here) when the block ends.
    let dec = b.phases()[3];
    assert_eq!(dec.shape, RampShape::Bezier);
    assert_rel("decel steps", dec.distance_m(), 133.0 / 80.0 * MM, 1e-9);
}

#[test]
fn small_segments_take_the_arc_speed() {
    // A zigzag of 0.9 x 0.025 mm chords (72 and 2 steps: on the step grid), 0.9003 mm
    // long, turning by theta = acos(0.80938 / 0.81063) = 3.2 degrees. Junction deviation
    // alone would allow v^2 = a jd s / (1 - s) = 0.101 m^2/s^2 (318 mm/s); a block under
    // 1 mm at a junction flatter than 135 degrees is also held to the speed of the arc
    // through it, v^2 = L a / theta (220 mm/s), with the junction vector along Y (its
    // acceleration is Y's limit, 3000 mm/s^2). Without that limit, block 20's entry is
    // set by look-ahead: when block 19 starts, blocks up to 32 are known and the last
    // ends at MINIMUM_PLANNER_SPEED, so v^2 = MIN^2 + 13 (2 a_b L) with the block's own
    // acceleration a_b = ceil(3000 mm/s^2 * 72 / L) / (72 / L).
    let mut c = defaults();
    c.slowdown = false;
    let exact = MarlinConfig {
        jerk: MarlinJerk::JunctionDeviation {
            deviation_m: 0.013e-3,
            small_segments: JdSmallSegments::Acos,
        },
        ..c
    };
    let off = MarlinConfig {
        jerk: MarlinJerk::JunctionDeviation {
            deviation_m: 0.013e-3,
            small_segments: JdSmallSegments::Off,
        },
        ..c
    };
    let pt = |k: usize| [0.9 * k as f64, if k % 2 == 1 { 0.025 } else { 0.0 }];
    let moves: Vec<_> = (0..40).map(|k| xy(pt(k), pt(k + 1), 300.0)).collect();
    let l = (0.81f64 + 0.000625).sqrt() * MM;
    let a = 3.0;
    let theta = ((0.81 - 0.000625) / 0.810625f64).acos();
    let s = (0.5 * (1.0 + (0.81 - 0.000625) / 0.810625f64)).sqrt();
    let v_jd2 = a * 0.013e-3 * s / (1.0 - s);
    let v_arc2 = l * a / theta;
    let steps_per_m = 72.0 / l;
    let a_b = (a * steps_per_m).ceil() / steps_per_m;
    let v_min = 0.05 * MM;
    let v_ahead2 = (0..13).fold(v_min * v_min, |v2, _| v2 + 2.0 * a_b * l);
    assert!(v_arc2 < v_ahead2 && v_ahead2 < v_jd2.min(0.09));
    // Block 20's entry, as the stepper's start rate: nominal 300 mm/s is
    // ceil(72 * 0.3 / L) steps/s; the entry rate ceil(nominal_rate v / 0.3).
    let rn = (72.0 * 0.3 / l).ceil();
    let start = |v2: f64| (rn * v2.sqrt() / 0.3).ceil() * l / 72.0;
    let (with_arc, _) = plan(exact, &moves);
    assert_rel(
        "arc-limited entry",
        with_arc[20].start_speed_m_s,
        start(v_arc2),
        1e-12,
    );
    let (without, _) = plan(off, &moves);
    assert_rel(
        "look-ahead entry",
        without[20].start_speed_m_s,
        start(v_ahead2),
        1e-12,
    );
}

#[test]
fn corexy_diagonal_runs_one_motor_like_a_straight_line() {
    // CoreXY, X and Y +50 mm at 100 mm/s: motor A turns 100 mm (8000 steps), B stays.
    // With M203 A/B at 100 mm/s, motor A at sqrt2 x the path speed is too fast: factor
    // 1/sqrt2, nominal
    // rate floor(ceil(8000 sqrt2) / sqrt2) = 8000 steps/s; the acceleration is A's
    // limit, 240000 steps/s^2. In steps this is the straight-line block exactly, at a
    // path speed of 100/sqrt2 mm/s.
    let mut c = defaults();
    c.kinematics = Kinematics::CoreXy;
    c.max_feedrate_m_s[0] = 0.1;
    c.max_feedrate_m_s[1] = 0.1;
    let (out, t) = plan(c, &[xy([0.0, 0.0], [50.0, 50.0], 100.0)]);
    let (line, t_line) = plan(defaults(), &[xy([0.0, 0.0], [100.0, 0.0], 100.0)]);
    assert_rel("print time", t, t_line, 1e-12);
    assert_rel(
        "cruise",
        out[0].cruise_speed_m_s,
        line[0].cruise_speed_m_s * std::f64::consts::FRAC_1_SQRT_2,
        1e-12,
    );
}
