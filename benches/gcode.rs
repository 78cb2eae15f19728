//! `settle gcode` speed: shipped prints through Klipper's planner with MZV shaping on X
//! and Y on the printer_xy machine (linear driver), streaming: on the modal backend the
//! ringing tower and a real sliced print, the 3DBenchy of `gcode/prints/benchy/`
//! (PrusaSlicer, 60,070 moves, 3,816 s of print; its provenance is in
//! `gcode/prints/benchy/PROVENANCE.md`), both whole, and the benchy on a machine given by
//! its modes as `settle identify` writes one; on rapier one layer of the tower.
//!
//! Throughput is in elements per second with one element = one simulated microsecond of
//! print, so criterion's "Melem/s" reads as *simulated seconds per wall second*. Targets
//! per core: modal >= 5,000 on the benchy, rapier >= 20. After criterion's measurement
//! each case also runs timed by the thread's own CPU clock (`/proc/thread-self/schedstat`,
//! Linux) and prints simulated seconds per CPU second (wall time overstates the cost on a
//! shared machine). A name filter on the command line (`cargo bench --bench gcode --
//! benchy`) runs the matching cases only.
//!
//! With `SETTLE_SYNTH_GCODE=PATH` (and optionally `SETTLE_SYNTH_MB`, default 100) the bench
//! first writes settle-gcode's synthetic slicer-like file of that size to PATH, for
//! measuring the peak memory of `settle gcode` on it with `/usr/bin/time -v`.

use std::hint::black_box;
use std::path::PathBuf;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use settle::spec::backend::Backend;
use settle::workflows::gcode::{GcodeOptions, measure, parse_shaper};
use settle_planner::firmware::Firmware;

#[path = "../gcode/benches/synth/mod.rs"]
mod synth;

/// A machine given by its modes, as `settle identify` writes one (from the example
/// recordings in examples/data it finds 45 and 75 Hz on X, 39 Hz on Y, zeta 0.05-0.07),
/// written into the system's temporary folder: its path.
fn identified_machine() -> String {
    let path = std::env::temp_dir().join("settle-bench-identified.toml");
    std::fs::write(
        &path,
        "name = \"identified\"\n\
         [axis.x]\nmodes = [{ frequency_hz = 45.0, damping_ratio = 0.05, weight = 0.8 },\
         { frequency_hz = 75.0, damping_ratio = 0.07, weight = 0.2 }]\n\
         [axis.y]\nmodes = [{ frequency_hz = 39.0, damping_ratio = 0.05 }]\n",
    )
    .expect("machine file");
    path.display().to_string()
}

fn options(file: &str, backend: Backend, layers: Option<(u32, u32)>) -> GcodeOptions {
    on(file, "printer_xy", backend, layers)
}

fn on(file: &str, machine: &str, backend: Backend, layers: Option<(u32, u32)>) -> GcodeOptions {
    let file = PathBuf::from(manifest_dir()).join(file);
    let shaper = parse_shaper("mzv@48").expect("shaper");
    GcodeOptions {
        backend,
        layers,
        ..GcodeOptions::new(file, machine, Firmware::Klipper)
            .expect("options")
            .with_shaper(Some(shaper))
    }
}

fn bench(c: &mut Criterion) {
    if let Ok(path) = std::env::var("SETTLE_SYNTH_GCODE") {
        let mb: u64 = std::env::var("SETTLE_SYNTH_MB")
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(100);
        let mut w = std::io::BufWriter::new(std::fs::File::create(&path).expect("create"));
        let n = synth::write_gcode(&mut w, mb * 1_000_000).expect("write");
        println!("wrote {path}: {:.1} MB", n as f64 / 1e6);
    }
    const TOWER: &str = "gcode/prints/ringing_tower.gcode";
    const BENCHY: &str = "gcode/prints/benchy/3DBenchy.gcode";
    let identified = identified_machine();
    let cases = [
        ("modal_ringing_tower", options(TOWER, Backend::Modal, None)),
        ("modal_benchy", options(BENCHY, Backend::Modal, None)),
        (
            "modal_benchy_identified",
            on(BENCHY, &identified, Backend::Modal, None),
        ),
        (
            "rapier_ringing_tower_layer_1",
            options(TOWER, Backend::Rapier, Some((1, 1))),
        ),
    ];
    let filter: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with('-'))
        .collect();
    let wanted = |name: &str| filter.is_empty() || filter.iter().any(|f| name.contains(f.as_str()));
    let mut group = c.benchmark_group("gcode");
    group.sample_size(10);
    for (name, opts) in cases.iter().filter(|(n, _)| wanted(n)) {
        let sim_s = measure(opts).expect("job").streamed.simulated_s;
        group.throughput(Throughput::Elements((sim_s * 1e6).round() as u64));
        group.bench_function(*name, |b| b.iter(|| black_box(measure(opts).expect("job"))));
    }
    group.finish();
    for (name, opts) in cases.iter().filter(|(n, _)| wanted(n)) {
        let (Some(a), mut sim, mut runs) = (thread_cpu_ns(), 0.0, 0) else {
            continue;
        };
        let mut b = a;
        while b - a < 3_000_000_000 {
            sim += measure(opts).expect("job").streamed.simulated_s;
            runs += 1;
            b = thread_cpu_ns().unwrap_or(u64::MAX);
        }
        let cpu_s = (b - a) as f64 * 1e-9;
        println!(
            "gcode/{name}: {runs} runs, {sim:.1} s simulated in {cpu_s:.2} CPU s: {:.0} simulated s per CPU s",
            sim / cpu_s
        );
    }
}

#[path = "support/cpu.rs"]
mod cpu;
use cpu::thread_cpu_ns;

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
