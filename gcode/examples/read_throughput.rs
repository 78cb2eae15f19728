//! Reads a generated G-code file of a given size (default 100 MB) from a temporary
//! directory and reports throughput and the process's peak memory.
//!
//! Run: `cargo run --release -p settle-gcode --example read_throughput [-- MB]`, and under
//! `/usr/bin/time -v` for an outside measurement of the peak RSS ("Maximum resident set
//! size"). The file is written to a temporary directory and removed afterwards.

use std::io::{BufWriter, Write};
use std::time::Instant;

use settle_gcode::{Dialect, Reader, ReaderOptions, Summary};

#[path = "../benches/synth/mod.rs"]
mod synth;

#[path = "support/mod.rs"]
mod support;
use support::peak_rss_kb;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mb: u64 = std::env::args()
        .nth(1)
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(100);
    let dir = tempfile::tempdir()?;
    let path = dir.path().join("synthetic.gcode");
    let t = Instant::now();
    let mut w = BufWriter::new(std::fs::File::create(&path)?);
    let bytes = synth::write_gcode(&mut w, mb * 1_000_000)?;
    w.flush()?;
    drop(w);
    println!(
        "generated {:.1} MB in {:.2} s; peak RSS so far {:?} kB",
        bytes as f64 / 1e6,
        t.elapsed().as_secs_f64(),
        peak_rss_kb()
    );

    for d in [Dialect::Klipper, Dialect::Marlin, Dialect::Rrf] {
        let t = Instant::now();
        let reader = Reader::open(&path, ReaderOptions::new(d))?;
        let s = Summary::read(reader)?;
        let secs = t.elapsed().as_secs_f64();
        println!(
            "{d}: {} lines, {} moves, {} layers in {secs:.2} s: {:.0} MB/s; peak RSS so far {:?} kB",
            s.lines,
            s.moves(),
            s.layers,
            s.bytes as f64 / 1e6 / secs,
            peak_rss_kb()
        );
    }
    Ok(())
}
