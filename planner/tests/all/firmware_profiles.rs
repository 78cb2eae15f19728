//! Planned firmware moves as per-axis profile chunks (settle_planner::firmware::profiles):
//! exact where the motion is piecewise constant acceleration, within the stated bounds at
//! speed jumps and on Marlin's Bezier ramps, continuous and bounded across chunks.

use settle_planner::firmware::klipper::{KlipperConfig, KlipperPlanner};
use settle_planner::firmware::marlin::{MarlinConfig, MarlinPlanner};
use settle_planner::firmware::profiles::{ProfileChunk, ProfileOptions, ProfileStream};
use settle_planner::firmware::{FirmwarePlanner, LinearMove, PlannedMove};

use super::firmware_common::{MM, xy};

fn run(
    planner: &mut dyn FirmwarePlanner,
    moves: &[LinearMove],
    opts: ProfileOptions,
) -> (Vec<PlannedMove>, Vec<ProfileChunk>) {
    let mut stream = ProfileStream::new(opts).expect("options");
    let (mut planned, mut chunks) = (Vec::new(), Vec::new());
    let take = |p: &mut dyn FirmwarePlanner,
                s: &mut ProfileStream,
                planned: &mut Vec<PlannedMove>,
                chunks: &mut Vec<ProfileChunk>| {
        while let Some(m) = p.pop() {
            s.push(&m).expect("push");
            planned.push(m);
        }
        chunks.extend(std::iter::from_fn(|| s.pop()));
    };
    for m in moves {
        planner.push(m).expect("move");
        take(planner, &mut stream, &mut planned, &mut chunks);
    }
    planner.finish();
    take(planner, &mut stream, &mut planned, &mut chunks);
    stream.finish().expect("finish");
    chunks.extend(std::iter::from_fn(|| stream.pop()));
    (planned, chunks)
}

/// Exact position and velocity of `axis` at print time `t` from the planned moves (at
/// rest before the first and after the last, holding position between them).
fn exact(planned: &[PlannedMove], axis: usize, t: f64) -> (f64, f64) {
    let i = planned.partition_point(|m| m.start_time_s <= t);
    if i == 0 {
        let m = &planned[0];
        return (m.start_m[axis], 0.0);
    }
    let m = &planned[i - 1];
    if t < m.end_time_s() {
        let (p, v, _) = m.axis_at(axis, t - m.start_time_s);
        (p, v)
    } else {
        (m.axis_at(axis, m.duration_s()).0, 0.0)
    }
}

/// Profile position and velocity of `axis` at print time `t`.
fn profile(chunks: &[ProfileChunk], axis: usize, t: f64) -> (f64, f64) {
    let i = chunks.partition_point(|c| c.start_time_s <= t).max(1) - 1;
    let s = chunks[i].trajectory.axes()[axis].state_at(t - chunks[i].start_time_s);
    (s.p, s.v)
}

#[test]
fn klipper_corner_is_exact_outside_the_jump_window() {
    let opts = ProfileOptions::default();
    let w = opts.jump_window_s;
    let mut k = KlipperPlanner::new(KlipperConfig::new(0.1, 3.0)).expect("config");
    let moves = [
        xy([0.0, 0.0], [50.0, 0.0], 100.0),
        xy([50.0, 0.0], [50.0, 50.0], 100.0),
    ];
    let (planned, chunks) = run(&mut k, &moves, opts);
    let t_corner = planned[1].start_time_s;
    let t_end = planned[1].end_time_s();
    // At the corner X drops from 5 mm/s to 0 and Y jumps from 0 to 5 mm/s, while the
    // acceleration jumps by 3000 mm/s^2 on each.
    let (dv, da) = (5.0 * MM, 3.0);
    let bound = dv * w / 8.0 + da * w * w / 8.0;
    let n = 20_000;
    let mut worst_in_window: f64 = 0.0;
    for j in 0..=n {
        let t = t_end * f64::from(j) / f64::from(n);
        for axis in 0..2 {
            let (pe, ve) = exact(&planned, axis, t);
            let (pp, vp) = profile(&chunks, axis, t);
            if (t - t_corner).abs() > 0.5 * w && t > 0.5 * w && t < t_end - 0.5 * w {
                assert!((pp - pe).abs() < 1e-12, "t {t} axis {axis}: p {pp} vs {pe}");
                assert!((vp - ve).abs() < 1e-10, "t {t} axis {axis}: v {vp} vs {ve}");
            } else {
                worst_in_window = worst_in_window.max((pp - pe).abs());
                assert!(
                    (pp - pe).abs() <= bound + 1e-12,
                    "t {t}: {} > {bound}",
                    (pp - pe).abs()
                );
            }
        }
    }
    assert!(worst_in_window > 0.0);
    // The chunks end at rest at the corner path's end, a window after the last move.
    let last = chunks.last().expect("a chunk");
    let dur = last.trajectory.duration_s();
    assert!((last.start_time_s + dur - (t_end + w)).abs() < 1e-12);
    let end = last.trajectory.axes()[1].end();
    assert!((end.p - 50.0 * MM).abs() < 1e-15 && end.v.abs() < 1e-12);
}

#[test]
fn marlin_bezier_ramps_within_the_trapezoid_rule_bound() {
    // One 100 mm S-curve block: the acceleration ramp is 120 -> 8000 steps/s (98.5 mm/s)
    // in T = 7880 / 240000 s; steps of h = T / ceil(T / 0.5 ms) keep the position within
    // h^2 a_peak / 12 (a_peak = 1.875 dv / T), the speed exact at every step boundary.
    let mut c = MarlinConfig::new();
    c.s_curve = true;
    let mut m = MarlinPlanner::new(c).expect("config");
    let opts = ProfileOptions::default();
    let (planned, chunks) = run(&mut m, &[xy([0.0, 0.0], [100.0, 0.0], 100.0)], opts);
    let t_ramp = 7880.0 / 240_000.0;
    let h = t_ramp / (t_ramp / opts.bezier_step_s).ceil();
    let dv = 7880.0 / 80.0 * MM;
    let bound = h * h * 1.875 * dv / t_ramp / 12.0;
    let w = opts.jump_window_s;
    let mut worst: f64 = 0.0;
    for j in 1..2000 {
        let t = w + (t_ramp - w) * f64::from(j) / 2000.0;
        let (pe, _) = exact(&planned, 0, t);
        let (pp, _) = profile(&chunks, 0, t);
        worst = worst.max((pp - pe).abs());
    }
    assert!(
        worst <= bound * 1.01 + 1e-12,
        "worst {worst} > bound {bound}"
    );
    assert!(
        worst > 0.1 * bound,
        "the bound is far from tight: {worst} vs {bound}"
    );
    // Exact again at the end of the ramp and through the cruise.
    for t in [t_ramp + 1e-3, 0.5, 0.9] {
        let (pe, ve) = exact(&planned, 0, t);
        let (pp, vp) = profile(&chunks, 0, t);
        assert!((pp - pe).abs() < 1e-12 && (vp - ve).abs() < 1e-10, "t {t}");
    }
}

#[test]
fn long_jobs_stream_in_bounded_continuous_chunks() {
    // 3000 moves around a square spiral: many chunks, each at most max_chunk_s long or
    // max_chunk_segments (plus one emission) large, joined without a gap or a jump.
    let opts = ProfileOptions {
        max_chunk_s: 0.5,
        max_chunk_segments: 512,
        ..ProfileOptions::default()
    };
    let mut moves = Vec::new();
    let mut p = [0.0, 0.0];
    for i in 0..3000 {
        let len = 0.5 + f64::from(i % 7) * 0.3;
        let dir = [[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]][i as usize % 4];
        let q = [p[0] + dir[0] * len, p[1] + dir[1] * len];
        moves.push(xy(p, q, 150.0));
        p = q;
    }
    let mut k = KlipperPlanner::new(KlipperConfig::new(0.3, 3.0)).expect("config");
    let (planned, chunks) = run(&mut k, &moves, opts);
    assert!(chunks.len() > 10);
    for w in chunks.windows(2) {
        let d = w[0].trajectory.duration_s();
        assert!(d <= opts.max_chunk_s + 0.05);
        assert!(w[0].trajectory.axes()[0].segments().len() <= opts.max_chunk_segments + 64);
        assert!((w[0].start_time_s + d - w[1].start_time_s).abs() < 1e-9);
        for axis in 0..4 {
            let (a, b) = (
                w[0].trajectory.axes()[axis].end(),
                w[1].trajectory.axes()[axis].start(),
            );
            assert!(
                (a.p - b.p).abs() < 1e-12 && (a.v - b.v).abs() < 1e-12,
                "axis {axis}"
            );
        }
    }
    // The last chunk ends where the job does.
    let end = chunks.last().expect("chunk").trajectory.axes()[0].end().p;
    assert!((end - exact(&planned, 0, 1e9).0).abs() < 1e-12);
}
