//! A real file written by FullControl, a G-code generator that is not a slicer
//! (gcode/prints/fullcontrol/PROVENANCE.md): a rippled vase printed as one continuous
//! spiral, no layer marker. No printing move of the spiral is planar, so the Z fallback
//! starts one layer at the primer line and the whole vase is that layer; the layer's
//! extruding moves span the vase's height, from the primer's Z to the spiral's top, as a
//! scan of the file's extruding lines gives them.

use settle_gcode::job::{Job, JobConfig};
use settle_gcode::{Reader, ReaderOptions};
use settle_planner::firmware::Firmware;

/// The lowest and highest Z of the file's extruding lines (`G0`/`G1` with a positive `E`
/// and an X or Y; the file extrudes relative, `M83`), each line's start and end.
fn extruding_z(text: &str) -> [f64; 2] {
    let (mut z, mut span) = (0.0_f64, [f64::INFINITY, f64::NEG_INFINITY]);
    for line in text.lines() {
        let code = line.split(';').next().unwrap_or("");
        let mut words = code.split_whitespace();
        if !matches!(words.next(), Some("G0" | "G1")) {
            continue;
        }
        let (start, mut e, mut xy) = (z, 0.0, false);
        for w in words {
            let v: f64 = w[1..].parse().expect("a number");
            match &w[..1] {
                "Z" => z = v,
                "E" => e = v,
                "X" | "Y" => xy = true,
                _ => {}
            }
        }
        if e > 0.0 && xy {
            span = [span[0].min(start).min(z), span[1].max(start).max(z)];
        }
    }
    span
}

#[test]
fn a_spiral_vase_without_markers_is_one_layer_over_its_height() {
    let path = super::print_path("fullcontrol/ripple_vase.gcode");
    let text = std::fs::read_to_string(&path).expect("print");
    assert!(text.contains("GCode created with FullControl"));
    let span = extruding_z(&text);
    // The primer line at Z 0.288, the spiral's last line at Z 60.0444.
    assert_eq!(span, [0.288, 60.0444]);
    let cfg = JobConfig::defaults(Firmware::Klipper).expect("defaults");
    let reader = Reader::open(&path, ReaderOptions::new(cfg.dialect)).expect("opens");
    let mut job = Job::new(reader, cfg).expect("job");
    job.run_to_end().expect("plans");
    let layers = job.summary().layers;
    let spans: Vec<_> = layers.iter().map(|l| (l.layer, l.print_z_mm)).collect();
    // Layer 0: the start G-code before the primer, which prints nothing.
    assert_eq!(spans, [(0, None), (1, Some(span))]);
    assert_eq!(layers[1].z_mm, Some(0.288));
}
