//! Paths through waypoints and control points, planned with look-ahead: random paths
//! (seeded; `SETTLE_PATH_CASES` sets the count) against every limit, every waypoint and
//! every control point; the incremental behaviour of appending points; junction speeds in
//! a planned corner.

use std::sync::Arc;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use settle_planner::path::junction::Junction;
use settle_planner::path::law::{FourJerkLaw, SCurveLaw, SpeedLaw, TrapezoidLaw};
use settle_planner::path::{
    CornerStrategy, CornerTransition, Lookahead, Path, PathOptions, PathPoint, PointKind, plan_path,
};
use settle_planner::{Limits, ProfileKind, Sample, Segment, State, Trajectory};

fn cases() -> usize {
    std::env::var("SETTLE_PATH_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1000)
}

type V3 = [f64; 3];

fn norm(v: V3) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// Position, velocity, acceleration and jerk vectors of the trajectory at `t`.
fn at(tr: &Trajectory, t: f64) -> [V3; 4] {
    let mut s = [Sample::default(); 3];
    tr.state_at(t, &mut s[..tr.dof()]);
    let pick = |f: fn(&Sample) -> f64| [f(&s[0]), f(&s[1]), f(&s[2])];
    [pick(|x| x.p), pick(|x| x.v), pick(|x| x.a), pick(|x| x.j)]
}

struct Case {
    path: Path,
    opts: PathOptions,
    /// Limits the law promises (accel, jerk) and the path's vmax.
    vmax: f64,
    amax: f64,
    jmax: f64,
    label: String,
}

fn draw(rng: &mut ChaCha8Rng) -> Case {
    let dim = if rng.random_bool(0.5) { 2 } else { 3 };
    let n = rng.random_range(2..=7);
    let mut pts = Vec::with_capacity(n);
    let mut p = [0.0; 3];
    for i in 0..n {
        let kind = if i == 0 || i == n - 1 || rng.random_bool(0.8) {
            PointKind::Control
        } else {
            PointKind::Waypoint
        };
        pts.push(PathPoint { position: p, kind });
        // Segment length log-uniform in 0.1 mm .. 200 mm, random direction.
        let len = 10f64.powf(rng.random_range(-4.0..-0.7));
        let mut d = [
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            0.0,
        ];
        if dim == 3 {
            d[2] = rng.random_range(-1.0..1.0);
        }
        if rng.random_bool(0.1) && i > 0 {
            // Sometimes straight on, or straight back.
            let prev: V3 = sub(p, pts[i - 1].position);
            let k = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
            d = [k * prev[0], k * prev[1], k * prev[2]];
        }
        let nd = norm(d).max(1e-9);
        p = [
            p[0] + len * d[0] / nd,
            p[1] + len * d[1] / nd,
            p[2] + len * d[2] / nd,
        ];
    }
    let path = Path::new(dim, pts).expect("valid random path");
    let vmax = rng.random_range(0.02..0.5);
    let amax = rng.random_range(0.5..30.0);
    let jmax = rng.random_range(50.0..5000.0);
    let limits = Limits::new(vmax, amax, Some(jmax)).expect("limits");
    let law: Arc<dyn SpeedLaw> = match rng.random_range(0..3) {
        0 => Arc::new(TrapezoidLaw { amax }),
        1 => Arc::new(SCurveLaw { amax, jmax }),
        _ => Arc::new(FourJerkLaw {
            amax: amax * rng.random_range(0.3..1.0),
            dmax: amax * rng.random_range(0.3..1.0),
            jerks: [
                jmax * rng.random_range(0.1..1.0),
                jmax * rng.random_range(0.1..1.0),
                jmax * rng.random_range(0.1..1.0),
                jmax * rng.random_range(0.1..1.0),
            ],
        }),
    };
    let corners = match rng.random_range(0..4) {
        0 => CornerStrategy::ExactStop,
        1 => CornerStrategy::Junction(Junction::Grbl {
            deviation_m: 10f64.powf(rng.random_range(-6.0..-4.0)),
        }),
        2 => CornerStrategy::Junction(Junction::Klipper {
            square_corner_velocity: rng.random_range(0.001..0.02),
        }),
        _ => CornerStrategy::Blend {
            max_deviation_m: 10f64.powf(rng.random_range(-6.0..-3.0)),
        },
    };
    let label = format!(
        "dim {dim}, {n} points, {} law, {corners:?}, vmax {vmax:.3} amax {amax:.2} jmax {jmax:.0}",
        law.name()
    );
    Case {
        path,
        opts: PathOptions {
            limits,
            law,
            corners,
            velocity_jump_s: settle_planner::path::lookahead::DEFAULT_VELOCITY_JUMP_S,
        },
        vmax,
        amax,
        jmax,
        label,
    }
}

/// Real roots in `[0, t]` of `c0 + c1 x + c2 x^2 + c3 x^3`: split at the derivative's
/// roots into monotone pieces, bisect each sign change.
fn cubic_roots(c: [f64; 4], t: f64) -> Vec<f64> {
    let f = |x: f64| c[0] + x * (c[1] + x * (c[2] + x * c[3]));
    let mut knots = vec![0.0, t];
    let (a, b, cc) = (3.0 * c[3], 2.0 * c[2], c[1]);
    if a != 0.0 {
        let disc = b * b - 4.0 * a * cc;
        if disc >= 0.0 {
            let r = disc.sqrt();
            knots.extend([(-b - r) / (2.0 * a), (-b + r) / (2.0 * a)]);
        }
    } else if b != 0.0 {
        knots.push(-cc / b);
    }
    knots.retain(|x| *x >= 0.0 && *x <= t);
    knots.sort_by(f64::total_cmp);
    let mut out = Vec::new();
    for w in knots.windows(2) {
        let (mut lo, mut hi) = (w[0], w[1]);
        let (flo, fhi) = (f(lo), f(hi));
        if flo == 0.0 {
            out.push(lo);
            continue;
        }
        if flo.signum() == fhi.signum() {
            continue;
        }
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            if f(mid).signum() == flo.signum() {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        out.push(0.5 * (lo + hi));
    }
    out
}

/// Time windows of velocity jumps (where the limits do not apply by design).
fn jump_windows(tr: &Trajectory) -> Vec<(f64, f64)> {
    let g = tr.path().expect("geometry");
    g.corners()
        .iter()
        .filter_map(|c| match c.transition {
            CornerTransition::Jump { duration_s, .. } => {
                Some((c.time_s - 0.5 * duration_s, c.time_s + 0.5 * duration_s))
            }
            _ => None,
        })
        .collect()
}

fn check(case: &Case, tr: &Trajectory) {
    let tag = &case.label;
    let g = tr.path().expect("the plan carries its geometry");
    let pts = case.path.points();
    let dim = case.path.dim();
    assert_eq!(tr.dof(), dim);
    let tol = 1.0 + 1e-9;
    // Every axis has the same segment boundaries.
    let n_seg = tr.axes()[0].segments().len();
    for ax in tr.axes() {
        assert_eq!(ax.segments().len(), n_seg, "{tag}");
        assert!((ax.duration_s() - tr.duration_s()).abs() <= 1e-12 * tr.duration_s().max(1.0));
    }
    // Start and end at rest on the first and last point (a trapezoid's acceleration
    // steps up at t = 0 already: the evaluator is right-continuous).
    let [p0, v0, _, _] = at(tr, 0.0);
    assert!(norm(sub(p0, pts[0].position)) == 0.0 && norm(v0) == 0.0);
    let end = at(tr, tr.duration_s() + 1.0);
    let last = pts[pts.len() - 1].position;
    assert!(norm(sub(end[0], last)) < 1e-11, "{tag}: end {:?}", end[0]);
    assert!(
        norm(end[1]) < 1e-11 && norm(end[2]) < 1e-9,
        "{tag}: end state"
    );

    let jumps = jump_windows(tr);
    let in_jump = |t: f64| jumps.iter().any(|&(a, b)| t >= a - 1e-12 && t <= b + 1e-12);

    // Points: waypoints hit at rest, control points passed within the strategy's
    // tolerance; the plan's own deviation matches the trajectory.
    let max_dev = match case.opts.corners {
        CornerStrategy::Blend { max_deviation_m } => max_deviation_m,
        _ => 0.0,
    };
    assert_eq!(g.corners().len(), pts.len());
    for c in g.corners() {
        let point = pts[c.index].position;
        let [p, v, _, _] = at(tr, c.time_s);
        let d = norm(sub(p, point));
        match c.transition {
            CornerTransition::Stop | CornerTransition::Pass => {
                assert!(d < 1e-11, "{tag}: point {} missed by {d}", c.index);
                if c.transition == CornerTransition::Stop {
                    assert!(norm(v) < 1e-11, "{tag}: not at rest at {}", c.index);
                }
            }
            CornerTransition::Blend { duration_s, .. }
            | CornerTransition::Jump { duration_s, .. } => {
                assert_eq!(
                    c.kind,
                    PointKind::Control,
                    "{tag}: a waypoint was not stopped at"
                );
                assert!(
                    (d - c.deviation_m).abs() < 1e-11,
                    "{tag}: {d} vs {}",
                    c.deviation_m
                );
                // Dense samples over the transition never come closer than the plan says.
                for i in 0..=400 {
                    let t = c.time_s + duration_s * (i as f64 / 400.0 - 0.5);
                    let di = norm(sub(at(tr, t)[0], point));
                    assert!(
                        di >= c.deviation_m - 1e-11,
                        "{tag}: {di} < {}",
                        c.deviation_m
                    );
                }
                let allowed = match c.transition {
                    // |dv| <= 2 vmax: the cut of a jump is at most vmax T / 4.
                    CornerTransition::Jump { dv, duration_s } => {
                        assert!(dv <= 2.0 * case.vmax * tol, "{tag}: jump {dv}");
                        case.vmax * duration_s / 4.0
                    }
                    _ => max_dev,
                };
                assert!(c.deviation_m <= allowed * tol + 1e-15, "{tag}: deviation");
            }
        }
        if pts[c.index].kind == PointKind::Waypoint || c.index == 0 || c.index == pts.len() - 1 {
            assert_eq!(
                c.transition,
                CornerTransition::Stop,
                "{tag}: waypoint {}",
                c.index
            );
        }
        if case.opts.corners == CornerStrategy::ExactStop {
            assert!(matches!(
                c.transition,
                CornerTransition::Stop | CornerTransition::Pass
            ));
        }
    }

    // Dense sampling: vector limits everywhere except inside velocity jumps; the motion
    // stays on its own geometry and within the planned deviation of the sharp path.
    let samples = 3000;
    let mut times: Vec<f64> = (0..=samples)
        .map(|i| tr.duration_s() * i as f64 / samples as f64)
        .collect();
    for b in tr.breakpoints() {
        times.extend([b - 1e-9, b + 1e-9]);
    }
    let sharp_allow = g.max_planned_deviation_m() + 1e-11;
    for &t in &times {
        let [p, v, a, j] = at(tr, t);
        let ce = g.contour_error(&p[..dim]);
        assert!(ce < 1e-11, "{tag}: t {t}: {ce} off the planned path");
        let se = g.sharp_error(&p[..dim]);
        assert!(se <= sharp_allow, "{tag}: t {t}: {se} off the sharp path");
        if in_jump(t) {
            continue;
        }
        assert!(
            norm(v) <= case.vmax * tol,
            "{tag}: t {t}: speed {}",
            norm(v)
        );
        assert!(
            norm(a) <= case.amax * tol,
            "{tag}: t {t}: accel {}",
            norm(a)
        );
        assert!(norm(j) <= case.jmax * tol, "{tag}: t {t}: jerk {}", norm(j));
    }

    // Analytic, per segment (all axes share the boundaries): the jerk is constant, the
    // acceleration linear (its norm is largest at an end), the speed's extrema are at the
    // ends or where v . a = 0 (a cubic in the segment's time).
    let axes = tr.axes();
    for i in 0..n_seg {
        let (t0, _, seg0) = axes[0].iter().nth(i).expect("segment");
        let dur = seg0.duration_s();
        if in_jump(t0 + 0.5 * dur) && dur > 0.0 {
            // A velocity jump: its velocity change is the corner's.
            continue;
        }
        let mut a0 = [0.0; 3];
        let mut jv = [0.0; 3];
        let mut vv = [0.0; 3];
        for (k, ax) in axes.iter().enumerate() {
            let (_, s, seg) = ax.iter().nth(i).expect("segment");
            assert_eq!(seg.duration_s(), dur, "{tag}: boundaries differ");
            let (a, j) = seg.accel_and_jerk(&s);
            a0[k] = a;
            jv[k] = j;
            vv[k] = s.v;
        }
        let a1 = [
            a0[0] + dur * jv[0],
            a0[1] + dur * jv[1],
            a0[2] + dur * jv[2],
        ];
        assert!(
            norm(jv) <= case.jmax * tol,
            "{tag}: segment {i} jerk {}",
            norm(jv)
        );
        if matches!(seg0, Segment::Jerk { .. }) || dur > 0.0 {
            assert!(
                norm(a0) <= case.amax * tol && norm(a1) <= case.amax * tol,
                "{tag}: segment {i} accel"
            );
        }
        // v(x) = vv + a0 x + jv x^2/2; v . a = sum over axes of the cubic's coefficients.
        let mut c = [0.0; 4];
        for k in 0..3 {
            c[0] += vv[k] * a0[k];
            c[1] += a0[k] * a0[k] + vv[k] * jv[k];
            c[2] += 1.5 * a0[k] * jv[k];
            c[3] += 0.5 * jv[k] * jv[k];
        }
        let mut xs = cubic_roots(c, dur);
        xs.extend([0.0, dur]);
        for x in xs {
            let v = [
                vv[0] + x * (a0[0] + 0.5 * x * jv[0]),
                vv[1] + x * (a0[1] + 0.5 * x * jv[1]),
                vv[2] + x * (a0[2] + 0.5 * x * jv[2]),
            ];
            assert!(
                norm(v) <= case.vmax * tol,
                "{tag}: segment {i} speed {}",
                norm(v)
            );
        }
    }
}

#[test]
fn random_paths_respect_limits_and_points() {
    let n = cases();
    let mut by_strategy = [0usize; 4];
    for case_no in 0..n {
        let mut rng = ChaCha8Rng::seed_from_u64(0x5e771e ^ case_no as u64);
        let mut case = draw(&mut rng);
        case.label = format!("case {case_no}: {}", case.label);
        let tr = plan_path(&case.path, &case.opts)
            .unwrap_or_else(|e| panic!("case {case_no} ({}): {e}", case.label));
        by_strategy[match case.opts.corners {
            CornerStrategy::ExactStop => 0,
            CornerStrategy::Junction(Junction::Grbl { .. }) => 1,
            CornerStrategy::Junction(_) => 2,
            CornerStrategy::Blend { .. } => 3,
        }] += 1;
        check(&case, &tr);
    }
    if n >= 40 {
        assert!(by_strategy.iter().all(|&k| k > 0), "{by_strategy:?}");
    }
}

fn square_path(n: usize, side_m: f64) -> Vec<PathPoint> {
    (0..n)
        .map(|i| {
            let c = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]][i % 4];
            let lift = (i / 4) as f64 * 0.1 * side_m;
            PathPoint::control([c[0] * side_m + lift, c[1] * side_m, 0.0])
        })
        .collect()
}

#[test]
fn appending_removes_the_terminal_stop_and_replans_only_the_tail() {
    let lim = Limits::new(0.2, 5.0, Some(500.0)).expect("limits");
    for corners in [
        CornerStrategy::Blend {
            max_deviation_m: 1e-4,
        },
        CornerStrategy::Junction(Junction::Klipper {
            square_corner_velocity: 0.005,
        }),
    ] {
        let opts = PathOptions::new(lim, ProfileKind::SCurve, corners).expect("options");
        let all = square_path(12, 0.05);
        let path = Path::new(2, all[..6].to_vec()).expect("path");
        let mut la = Lookahead::new(path, opts.clone()).expect("plan");
        let before = la.speeds().to_vec();
        assert_eq!(before[5], 0.0, "the last point is a stop");
        let tr = la.plan().expect("trajectory");
        let end = at(&tr, tr.duration_s());
        assert!(norm(sub(end[0], all[5].position)) < 1e-12 && norm(end[1]) < 1e-12);
        for (k, p) in all.iter().enumerate().skip(6) {
            la.push(*p).expect("push");
            let fresh = Lookahead::new(
                Path::new(2, all[..=k].to_vec()).expect("path"),
                opts.clone(),
            )
            .expect("plan");
            // Same speeds as planning the longer path from scratch, bit for bit.
            assert_eq!(la.speeds(), fresh.speeds());
            assert_eq!(
                la.plan().expect("trajectory"),
                fresh.plan().expect("trajectory")
            );
            // The old terminal stop is now passed with speed; the new end stops.
            assert!(
                la.speeds()[k - 1] > 0.0,
                "{corners:?}: point {} still stops",
                k - 1
            );
            assert_eq!(la.speeds()[k], 0.0);
            // Long segments: the backward pass stops early; the first corners keep their
            // speeds.
            assert!(
                la.replanned_from() >= k - 2,
                "replanned from {}",
                la.replanned_from()
            );
        }
        assert_eq!(&la.speeds()[..4], &before[..4]);
    }
}

#[test]
fn square_corner_at_klipper_scv_and_grbl_speed() {
    // Two 50 mm legs at 90 degrees, a = 3 m/s^2: Klipper's corner speed is exactly scv; the
    // velocity vector jumps from scv along x to scv along y within the jump time.
    let lim = Limits::new(0.3, 3.0, Some(300.0)).expect("limits");
    let path = Path::corner(std::f64::consts::FRAC_PI_2, 0.05).expect("path");
    let scv = 0.005;
    let opts = PathOptions::new(
        lim,
        ProfileKind::SCurve,
        CornerStrategy::Junction(Junction::Klipper {
            square_corner_velocity: scv,
        }),
    )
    .expect("options");
    let la = Lookahead::new(path.clone(), opts.clone()).expect("plan");
    assert!((la.speeds()[1] - scv).abs() < 1e-15, "{}", la.speeds()[1]);
    let tr = la.plan().expect("trajectory");
    let c = tr.path().expect("geometry").corners()[1];
    let tj = opts.velocity_jump_s;
    let [_, v_before, _, _] = at(&tr, c.time_s - 0.5 * tj - 1e-9);
    let [_, v_after, _, _] = at(&tr, c.time_s + 0.5 * tj + 1e-9);
    assert!(norm(sub(v_before, [scv, 0.0, 0.0])) < 1e-9, "{v_before:?}");
    assert!(norm(sub(v_after, [0.0, scv, 0.0])) < 1e-9, "{v_after:?}");
    // GRBL with deviation 0.01 mm at 90 degrees: v^2 = a delta (1 + sqrt 2).
    let grbl = PathOptions {
        corners: CornerStrategy::Junction(Junction::Grbl { deviation_m: 1e-5 }),
        ..opts
    };
    let la = Lookahead::new(path, grbl).expect("plan");
    let want = (3.0 * 1e-5 * (1.0 + 2f64.sqrt())).sqrt();
    assert!(
        (la.speeds()[1] - want).abs() < 1e-15,
        "{} vs {want}",
        la.speeds()[1]
    );
}

#[test]
fn single_segment_equals_the_rest_to_rest_planners() {
    // A two-point path is one rest-to-rest move along the line: its duration is the
    // time-optimal S-curve's (closed form in `scurve`) and trapezoid's.
    let lim = Limits::new(0.25, 4.0, Some(200.0)).expect("limits");
    for (kind, reference) in [
        (
            ProfileKind::SCurve,
            settle_planner::scurve::rest_to_rest(0.0, 0.13, &lim).expect("plan"),
        ),
        (
            ProfileKind::Trapezoid,
            settle_planner::trapezoid::rest_to_rest(0.0, 0.13, &lim).expect("plan"),
        ),
    ] {
        let path = Path::new(
            3,
            vec![
                PathPoint::waypoint([0.0, 0.0, 0.0]),
                PathPoint::waypoint([0.05, 0.12, 0.0]),
            ],
        )
        .expect("path");
        let opts = PathOptions::new(lim, kind, CornerStrategy::ExactStop).expect("options");
        let tr = plan_path(&path, &opts).expect("plan");
        assert!(
            (tr.duration_s() - reference.duration_s()).abs() < 1e-12,
            "{kind}: {} vs {}",
            tr.duration_s(),
            reference.duration_s()
        );
        // Mid-move, position along the line is the 1-D profile's.
        let t = 0.37 * tr.duration_s();
        let [p, _, _, _] = at(&tr, t);
        let s = reference.state_at(t).p;
        assert!(norm(sub(p, [0.05 * s / 0.13, 0.12 * s / 0.13, 0.0])) < 1e-12);
    }
    let _ = State::default();
}

#[test]
fn contour_error_is_exact_and_hint_independent() {
    // Against brute force over a fine polyline of the planned motion itself.
    let lim = Limits::new(0.2, 5.0, Some(500.0)).expect("limits");
    let opts = PathOptions::new(
        lim,
        ProfileKind::SCurve,
        CornerStrategy::Blend {
            max_deviation_m: 2e-4,
        },
    )
    .expect("options");
    let path = Path::new(2, square_path(9, 0.02)).expect("path");
    let tr = plan_path(&path, &opts).expect("plan");
    let g = tr.path().expect("geometry");
    let n = 40_000;
    let trace: Vec<V3> = (0..=n)
        .map(|i| at(&tr, tr.duration_s() * i as f64 / n as f64)[0])
        .collect();
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut hint = 0;
    for _ in 0..300 {
        let q = [
            rng.random_range(-0.005..0.03),
            rng.random_range(-0.005..0.025),
        ];
        let exact = g.contour_error(&q);
        assert_eq!(g.contour_error_hinted(&q, &mut hint), exact);
        let brute = trace
            .iter()
            .map(|p| ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)).sqrt())
            .fold(f64::INFINITY, f64::min);
        // The trace's spacing is at most vmax T / n; the exact distance is never larger
        // than the trace's and at most that spacing smaller.
        let spacing = 0.2 * tr.duration_s() / n as f64;
        assert!(
            exact <= brute + 1e-12 && brute - exact <= spacing,
            "{exact} vs {brute}"
        );
    }
}

#[test]
fn corner_rounding_of_the_commanded_motion_is_the_planned_deviation() {
    use settle_planner::path::CornerRounding;
    let lim = Limits::new(0.2, 5.0, Some(500.0)).expect("limits");
    let path = Path::new(2, square_path(6, 0.02)).expect("path");
    for (corners, zero) in [
        (
            CornerStrategy::Blend {
                max_deviation_m: 5e-5,
            },
            false,
        ),
        (CornerStrategy::ExactStop, true),
    ] {
        let opts = PathOptions::new(lim, ProfileKind::SCurve, corners).expect("options");
        let tr = plan_path(&path, &opts).expect("plan");
        let g = tr.path().expect("geometry");
        let mut acc = CornerRounding::new(g);
        // 10 kHz samples of the commanded motion, plus each point's planned passing time.
        let mut times: Vec<f64> = (0..=(tr.duration_s() * 1e4) as usize)
            .map(|i| i as f64 * 1e-4)
            .collect();
        times.extend(g.corners().iter().map(|c| c.time_s));
        times.sort_by(f64::total_cmp);
        for t in times {
            let p = at(&tr, t)[0];
            acc.update(t, &p[..2]);
        }
        let mins = acc.min_distances_m();
        for c in &g.corners()[1..g.corners().len() - 1] {
            let m = mins[c.index];
            assert!(
                (m - c.deviation_m).abs() < 1e-12,
                "{corners:?}: {m} vs {}",
                c.deviation_m
            );
            if zero {
                assert!(m < 1e-12);
            } else {
                // Square corners at 5e-5 tolerance: the tolerance or half the leg binds.
                assert!(m > 1e-6 && m <= 5e-5 * (1.0 + 1e-9), "{m}");
            }
        }
        assert!((acc.max_corner_rounding_m() - g.max_planned_deviation_m()).abs() < 1e-12);
        // A toolhead that cuts every corner by 1 mm more along the bisector: the rounding
        // grows accordingly (measured, not planned).
        let mut cut = CornerRounding::new(g);
        for c in g.corners() {
            cut.update(
                c.time_s,
                &[
                    pts_shift(&path, c.index, 1e-3)[0],
                    pts_shift(&path, c.index, 1e-3)[1],
                ],
            );
        }
        for (k, m) in cut.min_distances_m().iter().enumerate() {
            assert!((m - 1e-3).abs() < 1e-15, "point {k}: {m}");
        }
    }
}

/// Point `k` of `path` moved by `by` metres along +x+y/sqrt2.
fn pts_shift(path: &Path, k: usize, by: f64) -> V3 {
    let p = path.points()[k].position;
    let s = by / 2f64.sqrt();
    [p[0] + s, p[1] + s, p[2]]
}
