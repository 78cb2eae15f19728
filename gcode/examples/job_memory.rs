//! Runs the whole job pipeline (read, plan, profiles, shaping, chunks) on a generated
//! slicer-like G-code file of a given size (default 100 MB) and reports throughput and
//! the process's peak memory.
//!
//! Run: `cargo run --release -p settle-gcode --example job_memory [-- MB [FIRMWARE]]`
//! (FIRMWARE: klipper, marlin, rrf or settle; default klipper). Run one firmware per
//! process: the peak RSS (Linux `VmHWM`) is the process's, and under `/usr/bin/time -v`
//! "Maximum resident set size" measures it from outside. X and Y are shaped.

use std::io::{BufWriter, Write};
use std::time::Instant;

use settle_gcode::job::{Job, JobConfig, ShaperSetting};
use settle_planner::firmware::Firmware;
use settle_planner::shaper::ShaperType;

#[path = "../benches/synth/mod.rs"]
mod synth;

#[path = "support/mod.rs"]
mod support;
use support::peak_rss_kb;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let mb: u64 = args.next().map(|s| s.parse()).transpose()?.unwrap_or(100);
    let fw: Firmware = args
        .next()
        .map(|s| settle_gcode::job::parse_firmware(&s))
        .transpose()?
        .unwrap_or(Firmware::Klipper);
    let dir = tempfile::tempdir()?;
    let path = dir.path().join("synthetic.gcode");
    let mut w = BufWriter::new(std::fs::File::create(&path)?);
    let bytes = synth::write_gcode(&mut w, mb * 1_000_000)?;
    w.flush()?;
    drop(w);
    println!(
        "generated {:.1} MB; peak RSS so far {:?} kB",
        bytes as f64 / 1e6,
        peak_rss_kb()
    );
    let mut cfg = JobConfig::defaults(fw)?;
    let name = match fw {
        Firmware::Marlin => "marlin:zvd",
        Firmware::Rrf => "rrf:zvd",
        _ => "mzv",
    };
    for (i, f) in [48.0, 41.0].into_iter().enumerate() {
        cfg.shapers[i] = Some(ShaperSetting {
            shaper_type: ShaperType::parse(name)?,
            frequency_hz: f,
            damping_ratio: 0.1,
        });
    }
    let t = Instant::now();
    let mut job = Job::open(&path, cfg)?;
    let (mut chunks, mut segments) = (0u64, 0u64);
    while let Some(c) = job.next_chunk()? {
        chunks += 1;
        segments += c.trajectory.axes()[0].segments().len() as u64;
    }
    let secs = t.elapsed().as_secs_f64();
    let s = job.summary();
    println!(
        "{fw}: {} moves, {} layers, {:.0} s of print time in {secs:.1} s: {:.0} moves/s, {:.0} simulated s per wall s; {chunks} chunks, {segments} X segments; peak RSS {:?} kB",
        s.moves,
        s.layers.len(),
        s.print_time_s,
        s.moves as f64 / secs,
        s.print_time_s / secs,
        peak_rss_kb()
    );
    Ok(())
}
