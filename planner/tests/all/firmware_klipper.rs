//! Klipper's planner (settle_planner::firmware::klipper) against hand-computed plans and
//! against Klipper's own toolhead.py.

use settle_planner::firmware::klipper::{KlipperConfig, KlipperPlanner};
use settle_planner::firmware::{FirmwarePlanner, LinearMove, PlannedMove};

use super::firmware_common::{MM, assert_rel, leg, plan_with, xy};

fn plan(cfg: KlipperConfig, moves: &[LinearMove]) -> (Vec<PlannedMove>, f64) {
    plan_with(&mut KlipperPlanner::new(cfg).expect("config"), moves)
}

fn cfg(v_mm_s: f64, a_mm_s2: f64, mcr: f64) -> KlipperConfig {
    let mut c = KlipperConfig::new(v_mm_s * MM, a_mm_s2 * MM);
    c.minimum_cruise_ratio = mcr;
    c
}

#[test]
fn junction_deviation_of_klippers_worked_example() {
    // Klipper docs/Kinematics.md: scv 5 mm/s, accel 3000 -> jd = 25 (sqrt2 - 1) / 3000.
    let c = cfg(300.0, 3000.0, 0.5);
    let jd_mm = c.junction_deviation_m() / MM;
    assert_rel("jd", jd_mm, 25.0 * (2f64.sqrt() - 1.0) / 3000.0, 1e-12);
    assert!((jd_mm - 0.003452).abs() < 5e-7, "jd {jd_mm} mm");
}

#[test]
fn ninety_degree_corner_passes_at_square_corner_velocity() {
    let (v, a, l) = (100.0 * MM, 3000.0 * MM, 50.0 * MM);
    let (out, t) = plan(
        cfg(100.0, 3000.0, 0.5),
        &[
            xy([0.0, 0.0], [50.0, 0.0], 100.0),
            xy([50.0, 0.0], [50.0, 50.0], 100.0),
        ],
    );
    // v_j^2 = a jd sin(45)/(1 - sin(45)) = scv^2: the corner at exactly 5 mm/s.
    let vj = 5.0 * MM;
    assert_rel("corner speed", out[0].end_speed_m_s, vj, 1e-12);
    assert_rel("corner speed", out[1].start_speed_m_s, vj, 1e-12);
    // Each leg: a ramp between rest and v, a ramp between v and v_j, a cruise between.
    assert_rel("print time", t, 2.0 * leg(l, v, a, 0.0, vj), 1e-9);
    assert_rel("accel time", out[0].accel_t_s, v / a, 1e-12);
    assert_rel("decel time", out[0].decel_t_s, (v - vj) / a, 1e-12);
}

#[test]
fn reversal_stops() {
    let (v, a, l) = (100.0 * MM, 3000.0 * MM, 50.0 * MM);
    let (out, t) = plan(
        cfg(100.0, 3000.0, 0.5),
        &[
            xy([0.0, 0.0], [50.0, 0.0], 100.0),
            xy([50.0, 0.0], [0.0, 0.0], 100.0),
        ],
    );
    assert_eq!(out[0].end_speed_m_s, 0.0);
    // Two rest-to-rest trapezoids: L/v + v/a each.
    assert_rel("print time", t, 2.0 * (l / v + v / a), 1e-9);
}

#[test]
fn straight_line_and_minimum_cruise_ratio() {
    // A long move reaches its speed: L/v + v/a.
    let (_, t) = plan(
        cfg(100.0, 3000.0, 0.5),
        &[xy([0.0, 0.0], [100.0, 0.0], 100.0)],
    );
    assert_rel("long move", t, 0.1 / 0.1 + 0.1 / 3.0, 1e-12);
    // A 2 mm move at 100 mm/s: without the ratio the peak is v^2 = a L (a triangle);
    // with ratio r the planner's peak is v^2 = a (1 - r) L, leaving r L of cruise.
    let (l, a) = (2.0 * MM, 3000.0 * MM);
    let trapezoid = |vc: f64| 2.0 * vc / a + (l - vc * vc / a) / vc;
    for (r, vc2) in [(0.0, a * l), (0.5, 0.5 * a * l), (0.8, 0.2 * a * l)] {
        let (out, t) = plan(cfg(100.0, 3000.0, r), &[xy([0.0, 0.0], [2.0, 0.0], 100.0)]);
        assert_rel("peak speed", out[0].cruise_speed_m_s, vc2.sqrt(), 1e-12);
        assert_rel("print time", t, trapezoid(vc2.sqrt()), 1e-12);
    }
}

#[test]
fn chain_of_short_moves_is_planned_as_one_ramp() {
    // Ten collinear 1 mm moves at 200 mm/s, a = 3000: one plan over D = 10 mm.
    let moves: Vec<_> = (0..10)
        .map(|i| xy([f64::from(i), 0.0], [f64::from(i + 1), 0.0], 200.0))
        .collect();
    let (d, a) = (10.0 * MM, 3000.0 * MM);
    // Ratio 0: a triangle, v_p^2 = a D, t = 2 sqrt(D / a).
    let (_, t) = plan(cfg(300.0, 3000.0, 0.0), &moves);
    assert_rel("triangle", t, 2.0 * (d / a).sqrt(), 1e-9);
    // Ratio 0.5: the pseudo-acceleration a/2 sets the peak, v_p^2 = a (1 - r) D, and
    // r D is cruised: t = 2 v_p / a + r D / v_p.
    let (out, t) = plan(cfg(300.0, 3000.0, 0.5), &moves);
    let vp = (a * 0.5 * d).sqrt();
    assert_rel("mcr chain", t, 2.0 * vp / a + 0.5 * d / vp, 1e-9);
    let peak = out.iter().map(|m| m.cruise_speed_m_s).fold(0.0, f64::max);
    assert_rel("peak", peak, vp, 1e-12);
}

#[test]
fn lazy_flush_emits_early_and_keeps_the_optimal_plan() {
    // 400 collinear 1 mm moves at 200 mm/s: 2 s of minimum move time, so the queue
    // flushes lazily long before the end; the plan stays one trapezoid.
    let mut p = KlipperPlanner::new(cfg(300.0, 3000.0, 0.5)).expect("config");
    let mut emitted_before_end = 0;
    let mut most_queued = 0;
    for i in 0..400 {
        p.push(&xy([f64::from(i), 0.0], [f64::from(i + 1), 0.0], 200.0))
            .expect("move");
        most_queued = most_queued.max(p.queued());
        while p.pop().is_some() {
            emitted_before_end += 1;
        }
    }
    p.finish();
    assert!(
        emitted_before_end > 100,
        "only {emitted_before_end} before the end"
    );
    // The queue holds about a flush time of moves (1 s of 5 ms moves), not the job.
    assert!(most_queued <= 210, "queue grew to {most_queued}");
    let (d, v, a) = (400.0 * MM, 200.0 * MM, 3000.0 * MM);
    assert_rel("print time", p.print_time_s(), d / v + v / a, 1e-9);
}

#[test]
fn z_and_extruder_only_moves_take_their_own_limits() {
    let mut c = cfg(300.0, 3000.0, 0.5);
    c.max_z_velocity_m_s = 15.0 * MM;
    c.max_z_accel_m_s2 = 100.0 * MM;
    if let Some(e) = c.extruder.as_mut() {
        e.max_extrude_only_velocity_m_s = 120.0 * MM;
        e.max_extrude_only_accel_m_s2 = 1500.0 * MM;
    }
    // Pure Z: z_ratio = 1, so v = 15 mm/s and a = 100 mm/s^2: L/v + v/a.
    let z = LinearMove::new([0.0; 3], [0.0, 0.0, 10.0 * MM], 0.0, 50.0 * MM);
    let (_, t) = plan(c, &[z]);
    assert_rel("z move", t, 10.0 / 15.0 + 15.0 / 100.0, 1e-12);
    // A 5 mm retraction at 40 mm/s: its own speed (not max_velocity), the extruder's
    // acceleration.
    let r = LinearMove::new([0.0; 3], [0.0; 3], -5.0 * MM, 40.0 * MM);
    let (out, t) = plan(c, &[r]);
    assert_eq!(out[0].axes_r, [0.0, 0.0, 0.0, -1.0]);
    assert_rel("retract", t, 5.0 / 40.0 + 40.0 / 1500.0, 1e-12);
}

/// The move list of the reference driver: an integer LCG picks points on a 0.25 mm grid,
/// speeds, retractions, travels and layer changes.
fn lcg_moves(n: usize, seed: u64) -> Vec<LinearMove> {
    let lcg = |x: u64| (1_664_525 * x + 1_013_904_223) % (1 << 32);
    let (mut x, mut pos, mut moves) = (seed, [0.0, 0.0, 0.25, 0.0f64], Vec::new());
    for i in 0..n {
        x = lcg(x);
        let px = (x % 200) as f64 / 4.0;
        x = lcg(x);
        let py = (x % 200) as f64 / 4.0;
        x = lcg(x);
        let speed = 20.0 + (x % 200) as f64;
        x = lcg(x);
        let kind = x % 10;
        let z = if i % 17 == 16 { pos[2] + 0.25 } else { pos[2] };
        let end = match kind {
            0 => [pos[0], pos[1], pos[2], pos[3] - 0.75],
            1 => [px, py, z, pos[3]],
            _ => {
                let d =
                    ((px - pos[0]).powi(2) + (py - pos[1]).powi(2) + (z - pos[2]).powi(2)).sqrt();
                [px, py, z, pos[3] + d * 0.033]
            }
        };
        moves.push(LinearMove::new(
            [pos[0] * MM, pos[1] * MM, pos[2] * MM],
            [end[0] * MM, end[1] * MM, end[2] * MM],
            (end[3] - pos[3]) * MM,
            speed * MM,
        ));
        pos = end;
    }
    moves
}

fn driver_cfg() -> KlipperConfig {
    let mut c = cfg(300.0, 3000.0, 0.5);
    c.max_z_velocity_m_s = 15.0 * MM;
    c.max_z_accel_m_s2 = 100.0 * MM;
    if let Some(e) = c.extruder.as_mut() {
        e.instantaneous_corner_velocity_m_s = 1.0 * MM;
        e.max_extrude_only_velocity_m_s = 120.0 * MM;
        e.max_extrude_only_accel_m_s2 = 1500.0 * MM;
    }
    c
}

#[test]
fn matches_klippers_toolhead_on_a_mixed_job() {
    // Expected values from Klipper's own klippy/toolhead.py (commit 84104bbbd, 2026-08-07),
    // kinematics/cartesian.py and kinematics/extruder.py, driven outside this repository
    // with the same LCG move list, given in metres as settle passes it (so both sides see
    // the same doubles): `Move`, `check_move`, `add_move`, lazy `flush`, final `flush`,
    // print time summed as `_process_lookahead` does. Per move: start_v, cruise_v, end_v
    // (mm/s), accel_t, cruise_t, decel_t (s).
    let (out, t) = plan(driver_cfg(), &lcg_moves(40, 7));
    assert_eq!(out.len(), 40);
    assert_rel("print time (40 moves)", t, 13.269525672242882, 1e-9);
    let want = [
        (
            0,
            [
                0.0,
                96.0,
                21.599941729724776,
                0.032,
                0.3278923795197541,
                0.024800019423425072,
            ],
        ),
        (
            5,
            [
                1.9665141920194311,
                92.0,
                9.030815146833893,
                0.030011161935993517,
                0.14135100109662152,
                0.027656394951055367,
            ],
        ),
        (
            17,
            [
                2.4773496492438234,
                76.0,
                1.5986473177886644,
                0.024507550116918724,
                0.0677260960651845,
                0.02480045089407044,
            ],
        ),
    ];
    for (i, w) in want {
        let m = &out[i];
        let got = [
            m.start_speed_m_s / MM,
            m.cruise_speed_m_s / MM,
            m.end_speed_m_s / MM,
            m.accel_t_s,
            m.cruise_t_s,
            m.decel_t_s,
        ];
        for (g, w) in got.iter().zip(w) {
            assert!(
                (g - w).abs() <= 1e-9 * w.abs().max(1e-3),
                "move {i}: got {got:?}, want {w:?}"
            );
        }
    }
    // 400 moves (141.7 s): many lazy flushes.
    let (out, t) = plan(driver_cfg(), &lcg_moves(400, 12345));
    assert_eq!(out.len(), 400);
    assert_rel("print time (400 moves)", t, 141.70163830015153, 1e-9);
    // Move 31 reverses move 30 exactly on paper; in doubles the angle is 1e-16 short of
    // a reversal, and Klipper passes it at 0.00033 mm/s, as here.
    assert_rel(
        "move 30 end",
        out[30].end_speed_m_s / MM,
        0.0003303198870833807,
        1e-6,
    );
    let m = &out[100];
    assert_rel(
        "move 100 start",
        m.start_speed_m_s / MM,
        2.6396459306290265,
        1e-9,
    );
    assert_rel("move 100 cruise_t", m.cruise_t_s, 1.261217170624915, 1e-9);
    assert_rel(
        "move 399 decel_t",
        out[399].decel_t_s,
        0.05266666666666667,
        1e-9,
    );
}

#[test]
fn extruder_corner_velocity_limits_a_straight_junction() {
    // Straight on, extrusion 0.05 then 0.01 mm per mm: the extruder's share changes by
    // 0.04, so the junction is instantaneous_corner_velocity / 0.04 = 25 mm/s.
    let (v, a, l) = (100.0 * MM, 3000.0 * MM, 50.0 * MM);
    let e = |from: f64, to: f64, ratio: f64| {
        LinearMove::new(
            [from * MM, 0.0, 0.0],
            [to * MM, 0.0, 0.0],
            (to - from) * ratio * MM,
            100.0 * MM,
        )
    };
    let (out, t) = plan(
        cfg(100.0, 3000.0, 0.5),
        &[e(0.0, 50.0, 0.05), e(50.0, 100.0, 0.01)],
    );
    let vj = 25.0 * MM;
    assert_rel("junction", out[0].end_speed_m_s, vj, 1e-12);
    assert_rel("print time", t, 2.0 * leg(l, v, a, 0.0, vj), 1e-9);
}

#[test]
fn bad_input_is_refused() {
    let mut p = KlipperPlanner::new(cfg(100.0, 3000.0, 0.5)).expect("config");
    let nan = LinearMove::new([0.0; 3], [f64::NAN, 0.0, 0.0], 0.0, 0.1);
    assert!(p.push(&nan).is_err());
    let stop = LinearMove::new([0.0; 3], [0.01, 0.0, 0.0], 0.0, 0.0);
    assert!(p.push(&stop).is_err());
    assert!(p.set_velocity_limit(None, None, None, Some(1.0)).is_err());
    let mut c = cfg(100.0, 3000.0, 0.5);
    c.extruder = None;
    let mut p = KlipperPlanner::new(c).expect("config");
    let extrude = LinearMove::new([0.0; 3], [0.01, 0.0, 0.0], 0.001, 0.1);
    assert!(p.push(&extrude).is_err());
    assert!(p.dwell(-1.0).is_err());
}
