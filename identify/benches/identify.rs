//! Identifying a 130 s, 3.2 kHz Klipper raw sweep recording (~419,000 samples, 3 axes):
//! parsing the CSV text, Klipper's PSD, the direction and the sweep fit.

#[path = "../tests/identify/synth.rs"]
mod synth;

use criterion::{Criterion, criterion_group, criterion_main};
use settle_identify::read::klipper_raw;
use settle_identify::{Options, identify_recording};

fn bench(c: &mut Criterion) {
    let text = synth::klipper_raw_csv(&synth::default_sweep_axes(), 100.0, 3200.0);
    let rec = klipper_raw::parse("bench.csv", &text).expect("parse");
    let opts = Options::default();
    let id = identify_recording(&rec, &opts).expect("identify");
    eprintln!("{:?}", id.modes);
    let mut g = c.benchmark_group("identify");
    g.sample_size(10);
    g.bench_function("parse_130s_3200hz_csv", |b| {
        b.iter(|| klipper_raw::parse("bench.csv", &text).expect("parse"))
    });
    g.bench_function("identify_130s_3200hz", |b| {
        b.iter(|| identify_recording(&rec, &opts).expect("identify"))
    });
    g.bench_function("parse_and_identify_130s_3200hz", |b| {
        b.iter(|| {
            let rec = klipper_raw::parse("bench.csv", &text).expect("parse");
            identify_recording(&rec, &opts).expect("identify")
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
