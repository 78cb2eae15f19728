//! Path planning and contour-error queries: a 1000-segment random polyline, planned with
//! look-ahead and jerk-limited blends; the contour error of 10,000 samples (one second at
//! 10 kHz) near the path, with the bounding-box tree, with the hint, and by brute force (1,000 samples: it is slow).

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use settle_planner::path::{CornerStrategy, Path, PathOptions, PathPoint, plan_path};
use settle_planner::{Limits, ProfileKind, Sample};

fn path(segments: usize) -> Path {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let mut p = [0.0, 0.0, 0.0];
    let mut pts = vec![PathPoint::waypoint(p)];
    for _ in 0..segments {
        let len = rng.random_range(0.001..0.02);
        let ang: f64 = rng.random_range(0.0..std::f64::consts::TAU);
        p = [p[0] + len * ang.cos(), p[1] + len * ang.sin(), 0.0];
        pts.push(PathPoint::control(p));
    }
    Path::new(2, pts).expect("path")
}

fn bench(c: &mut Criterion) {
    let path = path(1000);
    let lim = Limits::new(0.3, 5.0, Some(500.0)).expect("limits");
    let opts = PathOptions::new(
        lim,
        ProfileKind::SCurve,
        CornerStrategy::Blend {
            max_deviation_m: 5e-5,
        },
    )
    .expect("options");
    let mut g = c.benchmark_group("path_1000_segments");
    g.bench_function("plan", |b| {
        b.iter(|| black_box(plan_path(black_box(&path), &opts).expect("plan")))
    });
    let tr = plan_path(&path, &opts).expect("plan");
    let geom = tr.path().expect("geometry");
    // 10,000 samples spread over the whole motion, offset by up to 20 um (a toolhead).
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let mut s = [Sample::default(); 2];
    let samples: Vec<[f64; 2]> = (0..10_000)
        .map(|i| {
            tr.state_at(tr.duration_s() * i as f64 / 10_000.0, &mut s);
            [
                s[0].p + rng.random_range(-2e-5..2e-5),
                s[1].p + rng.random_range(-2e-5..2e-5),
            ]
        })
        .collect();
    g.bench_function("contour_error_10k_samples", |b| {
        b.iter(|| {
            let mut worst: f64 = 0.0;
            for q in &samples {
                worst = worst.max(geom.contour_error(q));
            }
            black_box(worst)
        })
    });
    g.bench_function("contour_error_hinted_10k_samples", |b| {
        b.iter(|| {
            let (mut worst, mut hint): (f64, usize) = (0.0, 0);
            for q in &samples {
                worst = worst.max(geom.contour_error_hinted(q, &mut hint));
            }
            black_box(worst)
        })
    });
    g.bench_function("contour_error_brute_force_1k_samples", |b| {
        b.iter(|| {
            let mut worst: f64 = 0.0;
            for q in &samples[..1000] {
                let qq = [q[0], q[1], 0.0];
                let d = geom
                    .primitives()
                    .iter()
                    .map(|p| p.distance(qq))
                    .fold(f64::INFINITY, f64::min);
                worst = worst.max(d);
            }
            black_box(worst)
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
