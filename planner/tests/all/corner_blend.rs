//! The jerk-limited corner blend (`planner/src/path/blend.rs`): the closed forms against an
//! independent numerical minimisation, and the blend integrated numerically against the
//! limits and both segments.

use std::f64::consts::PI;

use settle_planner::Segment;
use settle_planner::path::blend::{self, Blend, BlendCase};

type V2 = [f64; 2];

fn cross(a: V2, b: V2) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

fn dot(a: V2, b: V2) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

/// The corner `p0 -> p1 -> p2` at interior angle `theta`: travel along +x into the
/// origin, leave along `u_out`.
fn directions(theta: f64) -> (V2, V2) {
    let turn = PI - theta;
    ([1.0, 0.0], [turn.cos(), turn.sin()])
}

/// Largest velocity change (along the acceleration direction) that a blend of duration
/// `t` can make with |a| <= a_lim, |jerk| <= j_lim and zero acceleration at both ends, on a
/// grid of `n` steps with piecewise-linear acceleration; returns the change and the grid
/// accelerations. The constraints (upper bound, Lipschitz bound, zero ends) are closed
/// under pointwise maximum, so the greatest feasible grid function exists and maximises
/// the integral; a forward and a backward sweep compute it.
fn best_accel(t: f64, a_lim: f64, j_lim: f64, n: usize) -> (f64, Vec<f64>) {
    let h = t / n as f64;
    let mut u = vec![a_lim; n + 1];
    u[0] = 0.0;
    u[n] = 0.0;
    for k in 1..=n {
        u[k] = u[k].min(u[k - 1] + j_lim * h);
    }
    for k in (0..n).rev() {
        u[k] = u[k].min(u[k + 1] + j_lim * h);
    }
    let dv = (0..n).map(|k| 0.5 * h * (u[k] + u[k + 1])).sum();
    (dv, u)
}

/// The numerically minimal blend: bisect the shortest duration whose best velocity change
/// reaches the required one, integrate the path exactly for the piecewise-linear
/// acceleration, and intersect its end with the outgoing line. Returns the entry distance,
/// the exit distance, the end velocity error and the peak acceleration.
fn numerical_blend(s: f64, theta: f64, a_lim: f64, j_lim: f64) -> (f64, f64, f64, f64) {
    let (u_in, u_out) = directions(theta);
    let chord = [u_out[0] - u_in[0], u_out[1] - u_in[1]];
    let c = dot(chord, chord).sqrt();
    let e_n = [chord[0] / c, chord[1] / c];
    let dv_needed = s * c;
    let n = 20_000;
    let (mut lo, mut hi) = (0.0, 1.0);
    while best_accel(hi, a_lim, j_lim, n).0 < dv_needed {
        hi *= 2.0;
    }
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if best_accel(mid, a_lim, j_lim, n).0 >= dv_needed {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let t = hi;
    let (_, acc) = best_accel(t, a_lim, j_lim, n);
    let h = t / n as f64;
    // w: position along e_n; exact integration of a piecewise-linear acceleration.
    let (mut w, mut wv) = (0.0, 0.0);
    for k in 0..n {
        w += h * wv + h * h * (2.0 * acc[k] + acc[k + 1]) / 6.0;
        wv += 0.5 * h * (acc[k] + acc[k + 1]);
    }
    // End E = -d u_in + s t u_in + w e_n must lie on the outgoing line: E x u_out = 0.
    let d_in = s * t + w * cross(e_n, u_out) / cross(u_in, u_out);
    let end = [
        -d_in * u_in[0] + s * t * u_in[0] + w * e_n[0],
        -d_in * u_in[1] + s * t * u_in[1] + w * e_n[1],
    ];
    let d_out = dot(end, u_out);
    let v_end = [s * u_in[0] + wv * e_n[0], s * u_in[1] + wv * e_n[1]];
    let v_err = ((v_end[0] - s * u_out[0]).powi(2) + (v_end[1] - s * u_out[1]).powi(2)).sqrt();
    let peak = acc.iter().copied().fold(0.0, f64::max);
    (d_in, d_out, v_err, peak)
}

#[test]
fn closed_forms_equal_the_numerical_minimum() {
    // (speed m/s, alimit m/s^2, jlimit m/s^3) on both sides of the case boundary
    // dv jlimit = alimit^2.
    let mut seen = [false; 2];
    for &(s, a, j) in &[
        (0.05, 3.0, 100.0),
        (0.2, 3.0, 100.0),
        (0.2, 10.0, 5000.0),
        (0.5, 2.0, 20.0),
    ] {
        for deg in [20.0_f64, 45.0, 90.0, 120.0, 160.0] {
            let theta = deg.to_radians();
            let shape = blend::shape(s, theta, a, j);
            let closed = match shape.case {
                BlendCase::Triangle => {
                    seen[0] = true;
                    blend::distance_triangle(s, theta, j)
                }
                BlendCase::Trapezoid => {
                    seen[1] = true;
                    blend::distance_trapezoid(s, theta, a, j)
                }
                other => panic!("unexpected case {other:?}"),
            };
            let (d_in, d_out, v_err, peak) = numerical_blend(s, theta, a, j);
            let rel = |x: f64| (x - closed).abs() / closed;
            assert!(
                rel(d_in) < 5e-8 && rel(d_out) < 5e-8,
                "s {s} a {a} j {j} theta {deg}: closed {closed}, numerical {d_in} / {d_out}"
            );
            assert!(v_err < 1e-9 * s, "end velocity off by {v_err}");
            // Which case: the numerical optimum reaches alimit iff the closed form says
            // trapezoid.
            assert_eq!(
                peak >= a * (1.0 - 1e-9),
                shape.case == BlendCase::Trapezoid,
                "peak {peak}"
            );
        }
    }
    assert_eq!(seen, [true, true], "both cases must be exercised");
}

/// Integrate the blend's jerk numerically (RK4 on the state p, v, a with the jerk as
/// input), from its entry state, and check limits and both ends.
fn integrate_and_check(s: f64, theta: f64, a_lim: f64, j_lim: f64) {
    let (u_in2, u_out2) = directions(theta);
    let u_in = [u_in2[0], u_in2[1], 0.0];
    let u_out = [u_out2[0], u_out2[1], 0.0];
    let corner = [0.3, -0.2, 0.0];
    let b = Blend::new(corner, u_in, u_out, s, a_lim, j_lim);
    let sh = b.shape;
    let segs = sh.normal_segments(j_lim);
    let total: f64 = segs.iter().map(Segment::duration_s).sum();
    assert!((total - sh.duration_s).abs() < 1e-15 * sh.duration_s.max(1.0));
    let entry = b.entry();
    // Entry: on the incoming segment, d before the corner.
    let back = [
        corner[0] - entry[0],
        corner[1] - entry[1],
        corner[2] - entry[2],
    ];
    assert!((back.iter().map(|x| x * x).sum::<f64>().sqrt() - sh.distance_m).abs() < 1e-15);
    assert!((back[0] * u_in[1] - back[1] * u_in[0]).abs() < 1e-15);
    let mut p = entry;
    let mut v = [s * u_in[0], s * u_in[1], 0.0];
    let mut a_n = 0.0_f64; // acceleration along e_n
    let mut max_a: f64 = 0.0;
    let mut max_j: f64 = 0.0;
    let mut max_speed: f64 = 0.0;
    let mut min_corner = f64::INFINITY;
    let e = b.e_n;
    let add =
        |x: [f64; 3], k: f64, y: [f64; 3]| [x[0] + k * y[0], x[1] + k * y[1], x[2] + k * y[2]];
    // Each segment in an even number of RK4 steps (so the blend's middle is a step end),
    // about 20,000 steps in all.
    for seg in &segs {
        let (j, dur) = match *seg {
            Segment::Jerk { duration_s, jerk } => (jerk, duration_s),
            Segment::Accel { duration_s, accel } => {
                a_n = accel;
                (0.0, duration_s)
            }
        };
        if dur == 0.0 {
            continue;
        }
        max_j = max_j.max(j.abs());
        let n = 2 * ((10_000.0 * dur / sh.duration_s).ceil() as usize).max(1);
        let h = dur / n as f64;
        // RK4 for p' = v, v' = a e_n, a' = j (j constant over the segment).
        let f = |v: [f64; 3], a: f64| (v, [a * e[0], a * e[1], a * e[2]], j);
        for _ in 0..n {
            let (k1p, k1v, k1a) = f(v, a_n);
            let (k2p, k2v, k2a) = f(add(v, h / 2.0, k1v), a_n + h / 2.0 * k1a);
            let (k3p, k3v, k3a) = f(add(v, h / 2.0, k2v), a_n + h / 2.0 * k2a);
            let (k4p, k4v, k4a) = f(add(v, h, k3v), a_n + h * k3a);
            for i in 0..3 {
                p[i] += h / 6.0 * (k1p[i] + 2.0 * k2p[i] + 2.0 * k3p[i] + k4p[i]);
                v[i] += h / 6.0 * (k1v[i] + 2.0 * k2v[i] + 2.0 * k3v[i] + k4v[i]);
            }
            a_n += h / 6.0 * (k1a + 2.0 * k2a + 2.0 * k3a + k4a);
            max_a = max_a.max(a_n.abs());
            max_speed = max_speed.max((v[0] * v[0] + v[1] * v[1]).sqrt());
            let dc = ((p[0] - corner[0]).powi(2) + (p[1] - corner[1]).powi(2)).sqrt();
            min_corner = min_corner.min(dc);
        }
    }
    let tag = format!("s {s} theta {:.1} a {a_lim} j {j_lim}", theta.to_degrees());
    assert!(max_a <= a_lim * (1.0 + 1e-9), "{tag}: |a| {max_a}");
    assert!(max_j <= j_lim * (1.0 + 1e-12), "{tag}: |j| {max_j}");
    assert!(max_speed <= s * (1.0 + 1e-9), "{tag}: speed {max_speed}");
    // Meets the outgoing segment d after the corner, at speed s along it, with zero
    // acceleration (position and velocity continuity with the straight run).
    let exit = b.exit();
    let perr = ((p[0] - exit[0]).powi(2) + (p[1] - exit[1]).powi(2)).sqrt();
    assert!(perr < 1e-12, "{tag}: exit position off by {perr}");
    let verr = ((v[0] - s * u_out[0]).powi(2) + (v[1] - s * u_out[1]).powi(2)).sqrt();
    assert!(verr < 1e-12, "{tag}: exit velocity off by {verr}");
    assert!(a_n.abs() < 1e-9 * a_lim, "{tag}: exit acceleration {a_n}");
    let exit_back = [exit[0] - corner[0], exit[1] - corner[1]];
    assert!((exit_back[0] * u_out[1] - exit_back[1] * u_out[0]).abs() < 1e-15);
    // The deviation from the sharp corner: closed form vs the integrated path (sampled
    // every h; the closest point is the middle, a grid point since steps is even).
    assert!(
        (min_corner - sh.deviation_m).abs() < 1e-12 + 1e-9 * sh.deviation_m,
        "{tag}: deviation {min_corner} vs {}",
        sh.deviation_m
    );
}

#[test]
fn blend_integrated_numerically_keeps_limits_and_meets_both_segments() {
    for &(s, a, j) in &[(0.05, 3.0, 100.0), (0.3, 3.0, 100.0), (0.2, 10.0, 5000.0)] {
        for deg in [5.0_f64, 30.0, 60.0, 90.0, 135.0, 170.0] {
            integrate_and_check(s, deg.to_radians(), a, j);
        }
    }
    // Without a jerk limit the acceleration steps (trapezoid profiles).
    integrate_and_check(0.2, 1.0, 3.0, f64::INFINITY);
}

#[test]
fn angle_convention_limits() {
    // Straight: no blend. Square: d and deviation from the closed forms at cos 45.
    let b = blend::shape(0.2, PI, 3.0, 100.0);
    assert_eq!((b.case, b.distance_m), (BlendCase::Straight, 0.0));
    // 90 degrees, s 0.05, j 100: dv = 2 s cos45 = 0.0707 < a^2/j = 0.09: triangle,
    // d = s sqrt(dv/j) = 0.05 sqrt(7.071e-4) = 1.3296e-3 m, T = 2 sqrt(dv/j) = 0.05318 s,
    // deviation = dv T/12 = 3.134e-4 m.
    let b = blend::shape(0.05, PI / 2.0, 3.0, 100.0);
    let dv = 0.1 * (PI / 4.0).cos();
    assert_eq!(b.case, BlendCase::Triangle);
    assert!((b.distance_m - 0.05 * (dv / 100.0).sqrt()).abs() < 1e-17);
    assert!((b.deviation_m - dv * b.duration_s / 12.0).abs() < 1e-17);
    assert!((b.distance_m - 1.3296e-3).abs() < 1e-7);
    // Reversal: the blend is one-dimensional (the speed along the mean direction is zero)
    // and stops short of the corner by the deviation; entry and exit coincide.
    let bl = Blend::new([0.0; 3], [0.0, 1.0, 0.0], [0.0, -1.0, 0.0], 0.1, 3.0, 100.0);
    assert_eq!(bl.entry(), bl.exit());
    assert_eq!(bl.shape.dv, 0.2);
    assert!(bl.shape.deviation_m > 0.0 && bl.shape.deviation_m < bl.shape.distance_m);
    // The distance grows as the corner sharpens (theta from pi down to 0).
    let mut last = 0.0;
    for i in (0..180).rev() {
        let d = blend::shape(0.1, (i as f64).to_radians(), 3.0, 100.0).distance_m;
        assert!(d > last);
        last = d;
    }
}
