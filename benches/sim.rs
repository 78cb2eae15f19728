//! Simulation speed per backend on the printer preset, at validated accuracy (each
//! backend's default step size, the one `settle validate` checks).
//!
//! Throughput is reported in elements per second with one element = one simulated
//! microsecond, so criterion's "Melem/s" reads directly as *simulated seconds per wall
//! second* (1 Melem/s = real time). Targets per core: rapier and MuJoCo >= 20, modal >= 2000.
//! MuJoCo runs with `cargo bench --features mujoco --bench sim`.
//!
//! The run: `printer_xy`, both axes simulated, a 10 mm S-curve on Y (0.149 s) and the
//! 0.5 s observation window, sampled at 10 kHz, metrics streaming.
//!
//! On a shared machine wall time overstates the cost per core, so after criterion's
//! measurement each case also runs for a few seconds timed by the thread's own CPU clock
//! (`/proc/thread-self/schedstat`, Linux) and prints simulated seconds per CPU second;
//! with a filter (`cargo bench --bench sim -- modal`) only the cases it selects.

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use settle::execute::{Observe, SimOptions, run_motion};
use settle::spec::backend::Backend;
use settle::studies::Motion;
use settle_planner::{Limits, Profile, ProfileKind, State, Trajectory};
use settle_sim::DriverMode;

/// The backends and driver models measured (MuJoCo with `--features mujoco`).
const CASES: &[(&str, Backend, DriverMode)] = &[
    ("modal_linear_driver", Backend::Modal, DriverMode::Linear),
    ("rapier_linear_driver", Backend::Rapier, DriverMode::Linear),
    ("rapier_full_driver", Backend::Rapier, DriverMode::Full),
    #[cfg(feature = "mujoco")]
    ("mujoco_linear_driver", Backend::Mujoco, DriverMode::Linear),
    #[cfg(feature = "mujoco")]
    ("mujoco_full_driver", Backend::Mujoco, DriverMode::Full),
];

fn bench(c: &mut Criterion) {
    let (_, path, text) = settle::input::machine_file::PRESETS[0];
    let (machine, _) =
        settle::input::machine_file::parse(text, std::path::Path::new(path)).expect("preset");
    let lim = Limits::new(0.3, 3.0, Some(100.0)).expect("limits");
    let y = ProfileKind::SCurve
        .rest_to_rest(0.0, 0.01, &lim)
        .expect("plan");
    let traj = Trajectory::new(vec![Profile::empty(State::default()), y]).expect("trajectory");
    let observe = Observe {
        window_s: 0.5,
        sample_rate_hz: 10_000.0,
        bands_um: vec![10.0, 50.0],
    };
    let simulated_us = ((traj.duration_s() + observe.window_s) * 1e6).round() as u64;
    let mut motion = Motion::Whole(traj);
    let mut group = c.benchmark_group("printer_xy_10mm_scurve_y");
    group.throughput(Throughput::Elements(simulated_us));
    for &(name, backend, driver) in CASES {
        let axes = machine.compile(driver).expect("compile");
        group.bench_function(name, |b| {
            b.iter(|| {
                black_box(
                    run_motion(
                        axes.clone(),
                        backend,
                        &SimOptions::default(),
                        black_box(&mut motion),
                        &observe,
                        None,
                    )
                    .expect("plans")
                    .expect("runs"),
                )
            })
        });
    }
    group.finish();
    let filter = filter_arg();
    for &(name, backend, driver) in CASES {
        let id = format!("printer_xy_10mm_scurve_y/{name}");
        if filter.as_deref().is_some_and(|f| !id.contains(f)) {
            continue;
        }
        let axes = machine.compile(driver).expect("compile");
        let Some(start) = thread_cpu_ns() else {
            return;
        };
        let wall = std::time::Instant::now();
        let mut runs = 0u32;
        while wall.elapsed().as_secs_f64() < 3.0 {
            black_box(
                run_motion(
                    axes.clone(),
                    backend,
                    &SimOptions::default(),
                    &mut motion,
                    &observe,
                    None,
                )
                .expect("plans")
                .expect("runs"),
            );
            runs += 1;
        }
        let cpu_s = (thread_cpu_ns().unwrap_or(start) - start) as f64 * 1e-9;
        let simulated = f64::from(runs) * simulated_us as f64 * 1e-6;
        eprintln!(
            "{name}: {runs} runs, {:.0}x real time per CPU second ({:.0}x per wall second)",
            simulated / cpu_s,
            simulated / wall.elapsed().as_secs_f64()
        );
    }
}

/// The benchmark filter given on the command line (`cargo bench --bench sim -- modal`),
/// if any: the first argument that is neither an option nor an option's value. The CPU
/// clock loop runs the cases whose id contains it (criterion reads it as a regular
/// expression; a plain name such as `modal` or `rapier_full` means the same to both).
fn filter_arg() -> Option<String> {
    // Criterion's options that take a value.
    const VALUED: &[&str] = &[
        "--warm-up-time",
        "--measurement-time",
        "--sample-size",
        "--save-baseline",
        "--baseline",
        "--baseline-lenient",
        "--load-baseline",
        "--noise-threshold",
        "--confidence-level",
        "--significance-level",
        "--nresamples",
        "--output-format",
        "--color",
        "--profile-time",
        "--plotting-backend",
        "--format",
        "--logfile",
        "-c",
        "-s",
        "-b",
    ];
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        if VALUED.contains(&a.as_str()) {
            args.next();
        } else if !a.starts_with('-') {
            return Some(a);
        }
    }
    None
}

#[path = "support/cpu.rs"]
mod cpu;
use cpu::thread_cpu_ns;

criterion_group!(benches, bench);
criterion_main!(benches);
