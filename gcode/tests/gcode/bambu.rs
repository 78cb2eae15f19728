//! A real Bambu Studio 2.4 file for a Bambu Lab A1 mini (gcode/prints/bambu/PROVENANCE.md):
//! what settle reads of it, and where it stops and why. Bambu's start G-code and its
//! spiral lift (`G17` then `G3 Z.6 I1.217 J0 P1 F42000`, an arc that ends where it starts
//! and counts its turns in `P`) are written for Bambu's own firmware; settle refuses the
//! lines whose motion it cannot stand behind, naming the line, the word and what the
//! firmware takes.

use settle_gcode::{Dialect, EventKind, GcodeError, Reader, ReaderOptions};

use crate::print_path;

const FILE: &str = "bambu/plate_1Or.gcode";

/// The events read before the first error, and that error.
fn read_until_error(dialect: Dialect) -> (Vec<u64>, GcodeError) {
    let mut layers = Vec::new();
    for e in Reader::open(print_path(FILE), ReaderOptions::new(dialect)).expect("opens") {
        match e {
            Ok(e) => {
                if let EventKind::Layer(_) = e.kind {
                    layers.push(e.line);
                }
            }
            Err(err) => return (layers, err),
        }
    }
    panic!("{dialect:?} read the whole file");
}

#[test]
fn a_bambu_studio_file_is_refused_at_its_spiral_lift_under_marlin_and_its_relative_arcs_under_klipper()
 {
    let text = std::fs::read_to_string(print_path(FILE)).expect("print");
    let lines: Vec<&str> = text.lines().collect();
    // What the file says of itself.
    assert_eq!(lines[1], "; BambuStudio 02.04.00.70");
    assert!(text.contains("\n; gcode_flavor = marlin\n"));
    assert!(text.contains("\n; printer_model = Bambu Lab A1 mini\n"));
    // Its one layer (`; total layer number: 1`) starts at line 989, `; CHANGE_LAYER`.
    assert_eq!(lines[988], "; CHANGE_LAYER");
    assert_eq!(text.matches("\n; CHANGE_LAYER\n").count(), 1);

    // Under Marlin every line of the start G-code reads (Bambu's own codes are passed
    // over as commands settle does not follow), the layer marker too; the spiral lift, line 1038, is
    // refused at its P: a Marlin built with ARC_P_CIRCLES turns once more for it, others
    // pass over it.
    assert_eq!(lines[1037], "G3 Z.6 I1.217 J0 P1  F42000");
    let (layers, err) = read_until_error(Dialect::Marlin);
    assert_eq!(layers, [989]);
    match &err {
        GcodeError::UnknownParameter { param, .. } => assert_eq!(param, "P"),
        other => panic!("{other}"),
    }
    let msg = err.to_string();
    assert!(msg.contains(":1038:"), "{msg}");
    assert!(msg.contains("ARC_P_CIRCLES"), "{msg}");

    // Klipper refuses G2/G3 in relative mode (klippy/extras/gcode_arcs.py): the start
    // G-code's nozzle wipe, `G91` (line 755) then `G2 I1 J0 X2 Y0 F2000.1` (line 757).
    assert_eq!(lines[754], "G91");
    assert_eq!(lines[756], "G2 I1 J0 X2 Y0 F2000.1");
    let (layers, err) = read_until_error(Dialect::Klipper);
    assert!(layers.is_empty());
    let msg = err.to_string();
    assert!(msg.contains(":757:") && msg.contains("relative"), "{msg}");
}
