//! Synthetic slicer-like G-code of any size, for throughput and memory measurements
//! (shared by `benches/read.rs` and `examples/read_throughput.rs`).
//!
//! Each layer: a layer marker, an acceleration change, a travel, a square wall of 64
//! straight printing moves, a rounded corner pair (G2/G3), a retract and a temperature
//! command, numbers with slicer precision (3 decimals, 5 for E).

use std::io::{self, Write};

/// Writes layers until at least `bytes` are written; returns the bytes written.
pub fn write_gcode(out: &mut impl Write, bytes: u64) -> io::Result<u64> {
    let mut written = 0u64;
    let mut line = String::new();
    let emit = |out: &mut dyn Write, line: &mut String| -> io::Result<u64> {
        line.push('\n');
        out.write_all(line.as_bytes())?;
        let n = line.len() as u64;
        line.clear();
        Ok(n)
    };
    use std::fmt::Write as _;
    let mut layer = 0u64;
    written += {
        line.push_str("; synthetic G-code for settle-gcode measurements\nG21\nG90\nM83\nG28");
        emit(out, &mut line)?
    };
    while written < bytes {
        layer += 1;
        let z = 0.2 * layer as f64;
        let _ = write!(
            line,
            ";LAYER_CHANGE\n;Z:{z:.3}\nM204 S{}\nG0 Z{z:.3} F600\nG0 X100.000 Y100.000 F9000",
            3000 + layer % 7 * 500
        );
        written += emit(out, &mut line)?;
        for k in 0..64u64 {
            let t = (k + 1) as f64 / 64.0;
            let (x, y) = match k / 16 {
                0 => (100.0 + 40.0 * 4.0 * t, 100.0),
                1 => (140.0, 100.0 + 40.0 * (4.0 * t - 1.0)),
                2 => (140.0 - 40.0 * (4.0 * t - 2.0), 140.0),
                _ => (100.0, 140.0 - 40.0 * (4.0 * t - 3.0)),
            };
            let _ = write!(
                line,
                "G1 X{x:.3} Y{y:.3} E{:.5}{}",
                0.09356 + (k % 5) as f64 * 1e-5,
                if k == 0 { " F3000" } else { "" }
            );
            written += emit(out, &mut line)?;
        }
        let _ = write!(
            line,
            "G2 X102.000 Y102.000 I2.000 J0 E0.11760\nG3 X100.000 Y100.000 I-2.000 J0 E0.11760\nG1 E-0.8 F2100\nM104 S{}",
            200 + layer % 10
        );
        written += emit(out, &mut line)?;
    }
    Ok(written)
}
