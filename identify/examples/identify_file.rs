//! Identify the modes in an accelerometer file and print them; `--write-sweep PATH
//! [RATE_HZ]` instead writes a synthetic 130 s Klipper raw sweep (two modes) to PATH,
//! sampled at RATE_HZ (default 3,200; 10,500 gives 65.1 MB and 1.38 million samples,
//! about the largest file the readers take).
//!
//! Peak memory of the identification alone:
//! `/usr/bin/time -v target/release/examples/identify_file PATH`.

#[path = "../tests/identify/synth.rs"]
mod synth;

use settle_identify::{Options, SweepTest, identify_file};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    if (3..=4).contains(&args.len()) && args[1] == "--write-sweep" {
        let fs: f64 = match args.get(3) {
            Some(r) => r.parse()?,
            None => 3200.0,
        };
        let text = synth::klipper_raw_csv(&synth::sweep_axes_at(fs), 100.0, fs);
        std::fs::write(&args[2], text)?;
        return Ok(());
    }
    let Some(path) = args.get(1) else {
        return Err("usage: identify_file FILE | --write-sweep FILE [RATE_HZ]".into());
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
