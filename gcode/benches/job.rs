//! The whole job pipeline (read, plan, profiles, per-axis shaping, chunks with move
//! metadata) per firmware: G-code moves per second, and by the print time printed at the
//! start, simulated seconds of motion produced per wall second. On the shipped prints
//! (all three, one after the other) and a generated slicer-like file (`synth`, 1 MB).
//! X and Y are shaped with each firmware's own shaper family. Run
//! `cargo bench -p settle-gcode --bench job`; peak memory on a 100 MB file is
//! `examples/job_memory.rs`.

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use settle_gcode::job::{Job, JobConfig, ShaperSetting};
use settle_gcode::{Reader, ReaderOptions};
use settle_planner::firmware::Firmware;
use settle_planner::shaper::ShaperType;

mod synth;

/// The firmware's defaults with X and Y shaped in its own family.
fn config(fw: Firmware) -> JobConfig {
    let mut c = JobConfig::defaults(fw).expect("defaults");
    let name = match fw {
        Firmware::Marlin => "marlin:zvd",
        Firmware::Rrf => "rrf:zvd",
        _ => "mzv",
    };
    for (i, f) in [48.0, 41.0].into_iter().enumerate() {
        c.shapers[i] = Some(ShaperSetting {
            shaper_type: ShaperType::parse(name).expect("name"),
            frequency_hz: f,
            damping_ratio: 0.1,
        });
    }
    // The shipped prints use R-form arcs, which Klipper's dialect refuses.
    c.dialect = settle_gcode::Dialect::Marlin;
    c.arcs = settle_gcode::ArcSegmentation::default_for(c.dialect);
    c
}

/// Run the job on `text`: (G-code moves, print time s, chunk segments).
fn run(text: &[u8], fw: Firmware) -> (u64, f64, usize) {
    let cfg = config(fw);
    let reader = Reader::new(text, ReaderOptions::new(cfg.dialect));
    let mut job = Job::new(reader, cfg).expect("job");
    let mut segments = 0;
    while let Some(c) = job.next_chunk().expect("chunk") {
        segments += c.trajectory.axes()[0].segments().len();
        black_box(&c);
    }
    let s = job.summary();
    (s.moves, s.print_time_s, segments)
}

fn bench(c: &mut Criterion) {
    let dir = std::path::Path::new(manifest_dir()).join("prints");
    let mut prints = Vec::new();
    for name in ["cube_layer.gcode", "ringing_tower.gcode", "arc_part.gcode"] {
        prints.extend(std::fs::read(dir.join(name)).expect("print"));
        prints.push(b'\n');
    }
    let mut synth = Vec::new();
    synth::write_gcode(&mut synth, 1_000_000).expect("in-memory write");
    for (label, text) in [("prints", &prints), ("synth_1MB", &synth)] {
        let mut g = c.benchmark_group(format!("job_{label}"));
        g.sample_size(10);
        for fw in Firmware::PRINTERS {
            let (moves, print_s, segments) = run(text, fw);
            eprintln!(
                "job_{label}/{fw}: {moves} moves, {print_s:.3} s of print time, {segments} X segments"
            );
            g.throughput(Throughput::Elements(moves));
            g.bench_function(fw.name(), |b| b.iter(|| run(black_box(text), fw)));
        }
        g.finish();
    }
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
