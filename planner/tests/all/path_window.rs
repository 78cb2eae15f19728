//! settle's look-ahead in bounded windows (settle_planner::path::window) against
//! `plan_path` on the whole path: exactly equal when the path fits one window, equal to
//! rounding when every commit is at a capped point, and slower but continuous and
//! stopping where it must when the window forces commits.

use settle_planner::path::junction::Junction;
use settle_planner::path::window::{PathChunk, WindowedPath};
use settle_planner::path::{CornerStrategy, Path, PathOptions, PathPoint, plan_path};
use settle_planner::{Limits, ProfileKind, Sample, Trajectory};

type V3 = [f64; 3];

fn opts(corners: CornerStrategy) -> PathOptions {
    let limits = Limits::new(0.2, 5.0, Some(200.0)).expect("limits");
    PathOptions::new(limits, ProfileKind::SCurve, corners).expect("options")
}

const STRATEGIES: [CornerStrategy; 3] = [
    CornerStrategy::Junction(Junction::Klipper {
        square_corner_velocity: 0.005,
    }),
    CornerStrategy::Blend {
        max_deviation_m: 0.05e-3,
    },
    CornerStrategy::ExactStop,
];

/// Plan `points` (the first is the start) through a window of `window` points, every move
/// at `speed`; the chunks.
fn windowed(o: &PathOptions, window: usize, points: &[V3], speed: f64) -> Vec<PathChunk> {
    let mut w = WindowedPath::new(o.clone(), window, points[0]).expect("windowed");
    let mut out = Vec::new();
    for (i, p) in points[1..].iter().enumerate() {
        w.push(*p, speed, i as u64).expect("push");
        out.extend(std::iter::from_fn(|| w.pop()));
    }
    w.stop(0.0).expect("stop");
    out.extend(std::iter::from_fn(|| w.pop()));
    out
}

fn whole(o: &PathOptions, points: &[V3]) -> Trajectory {
    let n = points.len();
    let pts = points
        .iter()
        .enumerate()
        .map(|(i, p)| {
            if i == 0 || i + 1 == n {
                PathPoint::waypoint(*p)
            } else {
                PathPoint::control(*p)
            }
        })
        .collect();
    plan_path(&Path::new(3, pts).expect("path"), o).expect("plan")
}

fn at_chunks(chunks: &[PathChunk], t: f64) -> [Sample; 3] {
    let i = chunks.partition_point(|c| c.start_time_s <= t).max(1) - 1;
    let c = &chunks[i];
    let mut out = [Sample::default(); 3];
    c.trajectory.state_at(t - c.start_time_s, &mut out);
    out
}

fn zigzag(n: usize) -> Vec<V3> {
    (0..n)
        .map(|k| {
            let x = 0.004 * k as f64 + 0.001 * ((k * 7) % 5) as f64;
            let y = if k % 2 == 1 { 0.003 } else { 0.0 } + 0.0005 * ((k * 3) % 4) as f64;
            [x, y, 0.0]
        })
        .collect()
}

#[test]
fn one_window_is_plan_path_exactly() {
    let corner = vec![[-0.05, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.05, 0.0]];
    let line = vec![[0.0, 0.0, 0.0], [0.1, 0.0, 0.0]];
    for s in STRATEGIES {
        let o = opts(s);
        for pts in [&corner, &line, &zigzag(12)] {
            let chunks = windowed(&o, 64, pts, 1.0);
            assert_eq!(chunks.len(), 1, "{s:?}");
            let want = whole(&o, pts);
            let got = &chunks[0].trajectory;
            assert_eq!(got.duration_s(), want.duration_s(), "{s:?}");
            for (g, w) in got.axes().iter().zip(want.axes()) {
                assert_eq!(g.start(), w.start());
                assert_eq!(g.segments(), w.segments(), "{s:?}");
            }
            assert_eq!(chunks[0].moves.len(), pts.len() - 1);
        }
    }
}

#[test]
fn commits_at_capped_points_reproduce_the_whole_plan() {
    // 80 zigzag points through a window of 8: every corner is held at its junction speed
    // (or blend limit), so each commit is final and the plan is the whole path's.
    let pts = zigzag(80);
    for s in &STRATEGIES[..2] {
        let o = opts(*s);
        let chunks = windowed(&o, 8, &pts, 1.0);
        assert!(chunks.len() > 5, "{s:?}: {} chunks", chunks.len());
        let want = whole(&o, &pts);
        let end = chunks
            .last()
            .map(|c| c.start_time_s + c.trajectory.duration_s());
        let end = end.expect("chunks");
        assert!(
            (end - want.duration_s()).abs() < 1e-12 * end,
            "{s:?}: {end}"
        );
        let mut w = [Sample::default(); 3];
        for k in 0..=5000 {
            let t = end * k as f64 / 5000.0;
            want.state_at(t, &mut w);
            let g = at_chunks(&chunks, t);
            for i in 0..2 {
                assert!((g[i].p - w[i].p).abs() < 1e-12, "{s:?} t {t}: {g:?} {w:?}");
                assert!((g[i].v - w[i].v).abs() < 1e-9, "{s:?} t {t}: {g:?} {w:?}");
            }
        }
        // Every move appears once, in order, its span inside the plan.
        let spans: Vec<_> = chunks.iter().flat_map(|c| c.moves.clone()).collect();
        assert_eq!(spans.len(), pts.len() - 1);
        for (i, m) in spans.iter().enumerate() {
            assert_eq!(m.seq, i as u64);
            assert!(m.end_time_s > m.start_time_s && m.end_time_s <= end + 1e-12);
        }
    }
}

#[test]
fn forced_commits_stay_feasible_and_continuous() {
    // 400 collinear 0.5 mm moves: no point is ever at its cap (vmax is never reached
    // within 8 points), so the window commits half of itself each time and the speed
    // is held to what can stop within the window: slower than the whole plan, ending at
    // rest on the last point.
    let pts: Vec<V3> = (0..=400).map(|k| [0.0005 * k as f64, 0.0, 0.0]).collect();
    let o = opts(STRATEGIES[0]);
    let chunks = windowed(&o, 8, &pts, 1.0);
    let want = whole(&o, &pts);
    let end = chunks
        .last()
        .map(|c| c.start_time_s + c.trajectory.duration_s())
        .expect("chunks");
    assert!(
        end > want.duration_s() * 1.5,
        "{end} vs {}",
        want.duration_s()
    );
    for w in chunks.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        assert!((a.start_time_s + a.trajectory.duration_s() - b.start_time_s).abs() < 1e-12);
        for (pa, pb) in a.trajectory.axes().iter().zip(b.trajectory.axes()) {
            let (ea, sb) = (pa.end(), pb.start());
            assert!((ea.p - sb.p).abs() < 1e-12 && (ea.v - sb.v).abs() < 1e-9);
        }
    }
    let last = chunks.last().expect("last").trajectory.axes()[0].end();
    assert!((last.p - 0.2).abs() < 1e-12 && last.v.abs() < 1e-12);
}
