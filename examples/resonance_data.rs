//! Writes the example resonance recordings of the book's "Your machine" chapter:
//! `examples/data/raw_data_x_example.csv` and `raw_data_y_example.csv`, Klipper raw
//! accelerometer files of a short resonance test (`TEST_RESONANCES AXIS=X FREQ_START=30
//! FREQ_END=90 HZ_PER_SEC=10 OUTPUT=raw_data`, the default accel_per_hz and sweeping
//! motion) at 800 Hz on a printer with known modes:
//!
//! - X: 45 Hz, damping ratio 0.05, weight 0.8; 75 Hz, 0.07, 0.2
//! - Y: 39 Hz, damping ratio 0.05, weight 1
//!
//! `cargo run --example resonance_data` (from the repository root) rewrites them; the
//! output is the same bit for bit every time (seeded noise).
//!
//! `cargo run --example resonance_data -- --full FILE` writes instead one full-length X
//! recording of Klipper's default test (5-135 Hz at 1 Hz/s, 130 s) at 3,200 Hz, about
//! 420,000 samples (24 MB), to measure `settle identify`'s time and memory on it.

#[path = "../tests/all/support/resonance.rs"]
mod resonance;

/// The example machine's modes per axis: (axis name, axis index, modes).
const MACHINE: [(&str, usize, &[resonance::Truth]); 2] = [
    ("x", 0, &[(45.0, 0.05, 0.8), (75.0, 0.07, 0.2)]),
    ("y", 1, &[(39.0, 0.05, 1.0)]),
];

fn main() -> std::io::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    if let [_, flag, out] = args.as_slice()
        && flag == "--full"
    {
        let test = settle_identify::SweepTest::klipper();
        let text = resonance::recording(MACHINE[0].2, &test, 0, 3200.0, 0.5, 1);
        std::fs::write(out, &text)?;
        println!("wrote {out} ({} bytes)", text.len());
        return Ok(());
    }
    let test = settle_identify::SweepTest {
        freq_start_hz: 30.0,
        freq_end_hz: 90.0,
        hz_per_sec: 10.0,
        ..settle_identify::SweepTest::klipper()
    };
    let dir = std::path::Path::new("examples/data");
    std::fs::create_dir_all(dir)?;
    for (seed, (name, axis, modes)) in MACHINE.iter().enumerate() {
        let text = resonance::recording(modes, &test, *axis, 800.0, 0.25, seed as u64 + 1);
        let path = dir.join(format!("raw_data_{name}_example.csv"));
        std::fs::write(&path, &text)?;
        println!("wrote {} ({} bytes)", path.display(), text.len());
    }
    Ok(())
}
