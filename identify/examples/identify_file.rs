//! Identify the modes in an accelerometer file and print them; `--write-sweep PATH`
//! first writes a synthetic 130 s, 3.2 kHz Klipper raw sweep (two modes) to PATH.
//!
//! Peak memory of the identification alone:
//! `/usr/bin/time -v target/release/examples/identify_file PATH`.

#[path = "../tests/identify/synth.rs"]
mod synth;

use settle_identify::{Options, SweepTest, identify_file};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    if args.len() == 3 && args[1] == "--write-sweep" {
        let text = synth::klipper_raw_csv(&synth::default_sweep_axes(), 100.0, 3200.0);
        std::fs::write(&args[2], text)?;
        return Ok(());
    }
    let Some(path) = args.get(1) else {
        return Err("usage: identify_file FILE | --write-sweep FILE".into());
    };
    let opts = Options {
        test: SweepTest::klipper(),
        ..Options::default()
    };
    for id in identify_file(std::path::Path::new(path), &opts)? {
        println!(
            "{} ({:?}, direction {:?})",
            id.source,
            id.method,
            id.direction.map(|d| d.describe())
        );
        for m in &id.modes {
            println!(
                "  f = {:.3} +- {:.3} Hz, zeta = {:.4} +- {:.4}, weight = {:?}",
                m.frequency_hz.value,
                m.frequency_hz.sigma,
                m.damping_ratio.value,
                m.damping_ratio.sigma,
                m.weight
            );
        }
    }
    Ok(())
}
