//! Sweep throughput: one quickstart run (plan + exact modal simulation + streaming metrics)
//! per iteration. Simulated seconds per wall second = (move + window) / time per run.

use std::hint::black_box;
use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};

fn bench(c: &mut Criterion) {
    let path = Path::new(manifest_dir()).join("scenarios/quickstart.toml");
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

/// The package's directory: the `CARGO_MANIFEST_DIR` cargo sets when it runs this
/// binary, else the one it was compiled with. The run-time value is the one that is right
/// when a target directory is shared between clones at different paths: cargo reuses a
/// test binary whose sources are unchanged, with the other clone's path compiled in.
fn manifest_dir() -> &'static str {
    static DIR: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    DIR.get_or_init(|| {
        std::env::var("CARGO_MANIFEST_DIR")
            .unwrap_or_else(|_| env!("CARGO_MANIFEST_DIR").to_owned())
    })
}
