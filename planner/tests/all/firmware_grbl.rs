//! GRBL's planner (settle_planner::firmware::grbl) against plans computed by hand from
//! grbl/planner.c's rules: junction deviation `v^2 = a_j $11 sin(theta/2) / (1 -
//! sin(theta/2))` with the acceleration limited along `u - u_prev`, entries capped by
//! both nominal speeds, the newest block ending at rest, each block a trapezoid at its
//! acceleration along its direction (`limit_value_by_axis_maximum`).

use settle_planner::firmware::grbl::{GrblConfig, GrblPlanner};
use settle_planner::firmware::{FirmwarePlanner, LinearMove, PlannedMove};

use super::firmware_common::{MM, assert_rel, plan_with, xy};

/// 100 mm/s^2 and 6000 mm/min (100 mm/s) on every axis, junction deviation 0.01 mm,
/// 1000 steps/mm (so the test points lie on the step grid).
fn cfg() -> GrblConfig {
    GrblConfig {
        steps_per_m: [1e6; 3],
        max_rate_m_s: [0.1; 3],
        accel_m_s2: [0.1; 3],
        junction_deviation_m: 0.01e-3,
        block_buffer_size: 16,
    }
}

fn plan(cfg: GrblConfig, moves: &[LinearMove]) -> (Vec<PlannedMove>, f64) {
    plan_with(&mut GrblPlanner::new(cfg).expect("config"), moves)
}

/// Time of a block of length `l` from `v0` to `v1` through `vn` at `a` (mm, mm/s).
fn block_time(l: f64, v0: f64, vn: f64, v1: f64, a: f64) -> f64 {
    let (da, dd) = (
        (vn * vn - v0 * v0) / (2.0 * a),
        (vn * vn - v1 * v1) / (2.0 * a),
    );
    (vn - v0) / a + (l - da - dd) / vn + (vn - v1) / a
}

#[test]
fn a_square_corner_passes_at_the_junction_deviation_speed() {
    // 10 mm along X, then 10 mm along Y, at F600 (10 mm/s). The junction: cos theta = 0,
    // sin(theta/2) = sqrt(1/2); u - u_prev = (-1, 1)/sqrt 2, so the acceleration allowed
    // along it is 100 / (1/sqrt 2) = 141.42 mm/s^2; v^2 = 141.42 * 0.01 * 0.70711 /
    // (1 - 0.70711) = 3.41421 mm^2/s^2, v = 1.84776 mm/s.
    let a_j = 100.0 * 2f64.sqrt();
    let s = 0.5f64.sqrt();
    let vj = (a_j * 0.01 * s / (1.0 - s)).sqrt();
    assert!((vj - 1.847759).abs() < 1e-6, "{vj}");
    let (moves, t) = plan(
        cfg(),
        &[
            xy([0.0, 0.0], [10.0, 0.0], 10.0),
            xy([10.0, 0.0], [10.0, 10.0], 10.0),
        ],
    );
    assert_eq!(moves.len(), 2);
    assert_rel("junction", moves[0].end_speed_m_s / MM, vj, 1e-9);
    assert_rel(
        "entry of the second",
        moves[1].start_speed_m_s / MM,
        vj,
        1e-9,
    );
    assert_eq!(moves[0].start_speed_m_s, 0.0);
    assert_eq!(moves[1].end_speed_m_s, 0.0);
    let want = block_time(10.0, 0.0, 10.0, vj, 100.0) + block_time(10.0, vj, 10.0, 0.0, 100.0);
    assert_rel("print time", t, want, 1e-12);
    // 0.1 + 0.081522 + 0.901707 = 1.083229 s per leg.
    assert_rel("print time by hand", t, 2.166459, 1e-6);
}

#[test]
fn an_oblique_corner_takes_the_acceleration_along_the_change_of_direction() {
    // GRBL's junction deviation (grbl/planner.c plan_buffer_line) with X at 100 and Y at
    // 400 mm/s^2: 10 mm along X, then 45 degrees up to (20, 10), at F1200 (20 mm/s).
    // junction_cos_theta = -(u_prev . u) = -1/sqrt 2; the junction unit vector is
    // u - u_prev = (1/sqrt 2 - 1, 1/sqrt 2) normalised = (-0.382683, 0.923880), and
    // limit_value_by_axis_maximum gives min(100 / 0.382683, 400 / 0.923880) = 261.313
    // mm/s^2 (X binds); sin(theta/2) = sqrt((1 - cos theta) / 2) = 0.923880, so
    // v^2 = 261.313 * 0.01 * 0.923880 / (1 - 0.923880) = 31.716 and v = 5.6317 mm/s. Neither
    // pass binds: from rest over 10 mm at 100 mm/s^2 and to rest over 14.14 mm at 141.4
    // mm/s^2 (the second block's acceleration along (1, 1)/sqrt 2) both allow more.
    let c = GrblConfig {
        accel_m_s2: [0.1, 0.4, 0.1],
        ..cfg()
    };
    let u = [0.5f64.sqrt() - 1.0, 0.5f64.sqrt()];
    let n = u[0].hypot(u[1]);
    let a_j = (100.0 / (u[0] / n).abs()).min(400.0 / (u[1] / n).abs());
    assert!((a_j - 261.313).abs() < 1e-3, "{a_j}");
    let s = (0.5 * (1.0 + 0.5f64.sqrt())).sqrt();
    let vj = (a_j * 0.01 * s / (1.0 - s)).sqrt();
    assert!((vj - 5.6317).abs() < 1e-4, "{vj}");
    let (moves, t) = plan(
        c,
        &[
            xy([0.0, 0.0], [10.0, 0.0], 20.0),
            xy([10.0, 0.0], [20.0, 10.0], 20.0),
        ],
    );
    assert_rel("junction", moves[0].end_speed_m_s / MM, vj, 1e-9);
    let a2 = 100.0 * 2f64.sqrt();
    assert_rel(
        "second block's acceleration",
        moves[1].accel_m_s2 / MM,
        a2,
        1e-12,
    );
    let want =
        block_time(10.0, 0.0, 20.0, vj, 100.0) + block_time(10.0 * 2f64.sqrt(), vj, 20.0, 0.0, a2);
    assert_rel("print time", t, want, 1e-12);
}

#[test]
fn a_corner_before_a_short_last_block_is_capped_by_the_stop_after_it() {
    // The square corner of the first test (junction deviation allows 1.8478 mm/s), but the
    // leg after it is 0.01 mm and the newest block ends at rest: the reverse pass caps the
    // corner at sqrt(2 a d) = sqrt(2 * 100 * 0.01) = 1.4142 mm/s.
    let (moves, _) = plan(
        cfg(),
        &[
            xy([0.0, 0.0], [10.0, 0.0], 10.0),
            xy([10.0, 0.0], [10.0, 0.01], 10.0),
        ],
    );
    assert_rel(
        "corner",
        moves[0].end_speed_m_s / MM,
        (2.0f64 * 100.0 * 0.01).sqrt(),
        1e-9,
    );
}

#[test]
fn targets_are_rounded_to_whole_steps_as_grbl_does() {
    // grbl/planner.c: target_steps = lround(target * steps_per_mm) and the block is the
    // step delta over steps_per_mm. At 80 steps/mm, X 10.01 mm is 800.8 steps -> 801 ->
    // 10.0125 mm; from rest to rest at 10 mm/s and 100 mm/s^2 that block takes
    // 0.1 + (10.0125 - 1) / 10 + 0.1 = 1.10125 s.
    let c = GrblConfig {
        steps_per_m: [80e3; 3],
        ..cfg()
    };
    let (_, t) = plan(c, &[xy([0.0, 0.0], [10.01, 0.0], 10.0)]);
    assert_rel("rounded block", t, 1.10125, 1e-12);
}

#[test]
fn a_diagonal_move_accelerates_and_rapids_at_the_limit_along_its_direction() {
    // A 45-degree move: each axis carries 1/sqrt 2 of it, so the box allows
    // 100 * sqrt 2 mm/s^2 and 100 * sqrt 2 mm/s along the path. A rapid (G0) runs at that
    // rate whatever F says (200 mm each way: long enough to reach it); a feed move at its F.
    let (l, r2) = (200.0 * 2f64.sqrt(), 2f64.sqrt());
    let to = [200.0 * MM, 200.0 * MM, 0.0];
    let g0 = LinearMove::new([0.0; 3], to, 0.0, 1.0 * MM).as_rapid();
    let (moves, t) = plan(cfg(), &[g0]);
    assert_rel("acceleration", moves[0].accel_m_s2 / MM, 100.0 * r2, 1e-12);
    assert_rel(
        "rapid rate",
        moves[0].cruise_speed_m_s / MM,
        100.0 * r2,
        1e-12,
    );
    let want = block_time(l, 0.0, 100.0 * r2, 0.0, 100.0 * r2);
    assert_rel("rapid time", t, want, 1e-12);
    // By hand: 1 s up, 1 s down (141.42 mm), 141.42 mm at 141.42 mm/s.
    assert_rel("rapid time by hand", t, 3.0, 1e-12);
    let g1 = LinearMove::new([0.0; 3], to, 0.0, 10.0 * MM);
    let (moves, t) = plan(cfg(), &[g1]);
    assert_rel("feed", moves[0].cruise_speed_m_s / MM, 10.0, 1e-12);
    assert_rel(
        "feed time",
        t,
        block_time(l, 0.0, 10.0, 0.0, 100.0 * r2),
        1e-12,
    );
}

#[test]
fn a_short_block_runs_a_triangle_and_a_straight_line_does_not_slow() {
    // Two collinear 1 mm blocks at 100 mm/s: the junction has no limit (cos theta = -1),
    // the plan is one triangle over 2 mm: peak sqrt(2 a 1 mm) = 14.142 mm/s at the joint.
    let (moves, t) = plan(
        cfg(),
        &[
            xy([0.0, 0.0], [1.0, 0.0], 100.0),
            xy([1.0, 0.0], [2.0, 0.0], 100.0),
        ],
    );
    let peak = (2.0f64 * 100.0 * 1.0).sqrt();
    assert_rel("peak", moves[0].end_speed_m_s / MM, peak, 1e-12);
    assert_rel("triangle time", t, 2.0 * peak / 100.0, 1e-12);
}

#[test]
fn a_reversal_stops_and_the_entry_is_capped_by_the_slower_nominal_speed() {
    // Out and back: cos theta = 1 > 0.999999, MINIMUM_JUNCTION_SPEED (0).
    let (moves, _) = plan(
        cfg(),
        &[
            xy([0.0, 0.0], [5.0, 0.0], 50.0),
            xy([5.0, 0.0], [0.0, 0.0], 50.0),
        ],
    );
    assert_eq!(moves[0].end_speed_m_s, 0.0);
    // Straight on from 50 mm/s to 5 mm/s: the junction is capped at the slower nominal
    // speed, 5 mm/s.
    let (moves, _) = plan(
        cfg(),
        &[
            xy([0.0, 0.0], [20.0, 0.0], 50.0),
            xy([20.0, 0.0], [40.0, 0.0], 5.0),
        ],
    );
    assert_rel("capped junction", moves[0].end_speed_m_s / MM, 5.0, 1e-12);
}

#[test]
fn the_buffer_holds_fifteen_blocks() {
    // 40 collinear 1 mm blocks at 100 mm/s from rest. The buffer holds 15 blocks: block
    // k runs with blocks k..k+14 planned, the last ending at rest, so the next block's
    // entry is what 14 mm of deceleration allows: sqrt(2 a 14 mm) = 52.92 mm/s.
    let moves: Vec<LinearMove> = (0..40)
        .map(|i| xy([f64::from(i), 0.0], [f64::from(i + 1), 0.0], 100.0))
        .collect();
    let (planned, _) = plan(cfg(), &moves);
    let steady = (2.0 * 100.0 * 14.0f64).sqrt();
    assert_rel(
        "entry of block 20",
        planned[20].start_speed_m_s / MM,
        steady,
        1e-9,
    );
    // A 3-block buffer (2 blocks held) leaves 1 mm: sqrt(2 a 1 mm) = 14.14 mm/s.
    let small = GrblConfig {
        block_buffer_size: 3,
        ..cfg()
    };
    let (planned, _) = plan(small, &moves);
    let steady = (2.0 * 100.0 * 1.0f64).sqrt();
    assert_rel(
        "entry with 2 blocks",
        planned[20].start_speed_m_s / MM,
        steady,
        1e-9,
    );
}

#[test]
fn extrusion_and_bad_settings_are_refused() {
    let mut p = GrblPlanner::new(cfg()).expect("config");
    let e = LinearMove::new([0.0; 3], [MM, 0.0, 0.0], 0.1 * MM, 10.0 * MM);
    assert!(p.push(&e).is_err());
    let bad = GrblConfig {
        junction_deviation_m: -1.0,
        ..cfg()
    };
    assert!(GrblPlanner::new(bad).is_err());
}
