//! Reading throughput: events per MB of slicer-like G-code held in memory (no disk), and
//! the same with the summary statistics. Run `cargo bench -p settle-gcode --bench read`;
//! the file-size and memory measurement is `examples/read_throughput.rs`.

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use settle_gcode::{Dialect, Reader, ReaderOptions, Summary};

mod synth;

fn read(c: &mut Criterion) {
    let mut text = Vec::new();
    let n = synth::write_gcode(&mut text, 4 << 20).expect("in-memory write");
    let mut g = c.benchmark_group("read_4MiB");
    g.throughput(Throughput::Bytes(n));
    g.sample_size(20);
    for d in [Dialect::Klipper, Dialect::Marlin] {
        g.bench_function(format!("events_{d}"), |b| {
            b.iter(|| {
                let events = Reader::new(black_box(&text[..]), ReaderOptions::new(d))
                    .fold(0u64, |n, e| n + u64::from(e.is_ok()));
                black_box(events)
            })
        });
    }
    g.bench_function("summary_marlin", |b| {
        b.iter(|| {
            black_box(
                Summary::read(Reader::new(
                    black_box(&text[..]),
                    ReaderOptions::new(Dialect::Marlin),
                ))
                .expect("valid"),
            )
        })
    });
    g.finish();
}

criterion_group!(benches, read);
criterion_main!(benches);
