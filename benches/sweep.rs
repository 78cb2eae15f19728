//! Sweep throughput: one quickstart run (plan + exact modal simulation + streaming metrics)
//! per iteration. Simulated seconds per wall second = (move + window) / time per run.

use std::hint::black_box;
use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};

fn bench(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/quickstart.toml");
    let (_, mut runs) = settle::load_runs(&path).expect("quickstart");
    // The exact modal backend (what this bench has always measured); rapier, the sweep
    // default, is measured per backend in `benches/sim.rs`.
    settle::execute::set_backend(&path, &mut runs, settle::spec::backend::Backend::Modal)
        .expect("modal");
    // The 10 mm S-curve: 0.5 s window + ~0.08 s move, 10 kHz samples.
    let spec = runs
        .iter()
        .find(|r| r.distance_mm == 10.0 && r.profile.name() == "scurve")
        .expect("10 mm S-curve run");
    c.bench_function("quickstart_run_10mm_scurve", |b| {
        b.iter(|| black_box(settle::execute::execute(black_box(spec), None).expect("runs")))
    });
    c.bench_function("quickstart_sweep_16_runs_1_thread", |b| {
        b.iter(|| {
            black_box(
                settle::execute::pool::run_all(&runs, Some(1), &settle::execute::pool::quiet)
                    .expect("runs"),
            )
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
