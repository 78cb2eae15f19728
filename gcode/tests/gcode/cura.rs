//! A real Cura file (gcode/prints/cura/PROVENANCE.md) against what Cura wrote in its
//! header: the bounding box of the extruding moves (`;MINX:` .. `;MAXZ:`), the filament
//! used (`;Filament used:`, in metres) and the number of layers (`;LAYER_COUNT:`).

use settle_gcode::{Bounds, Dialect, EventKind, Reader, ReaderOptions};

/// The number after `;<key>:` in Cura's header (`m` of `;Filament used:` taken off).
pub(crate) fn header(text: &str, key: &str) -> f64 {
    let line = text
        .lines()
        .find_map(|l| l.strip_prefix(&format!(";{key}:")))
        .unwrap_or_else(|| panic!("no {key}"));
    line.trim().trim_end_matches('m').parse().expect("a number")
}

/// Cura prints its box (`;MINX:` .. `;MAXZ:`) with up to three decimals, as the file's
/// coordinates: `bounds` holds the same numbers.
pub(crate) fn assert_cura_box(text: &str, bounds: &Bounds) {
    for (k, axis) in ["X", "Y", "Z"].iter().enumerate() {
        assert_eq!(
            bounds.min_mm[k],
            header(text, &format!("MIN{axis}")),
            "MIN{axis}"
        );
        assert_eq!(
            bounds.max_mm[k],
            header(text, &format!("MAX{axis}")),
            "MAX{axis}"
        );
    }
}

#[test]
fn a_cura_files_extent_filament_and_layers_are_curas() {
    let path = super::print_path("cura/Kreistest.gcode");
    let text = std::fs::read_to_string(&path).expect("print");
    let (mut bounds, mut extruded_mm, mut layers) = (Bounds::empty(), 0.0, 0);
    for e in Reader::open(&path, ReaderOptions::new(Dialect::Marlin)).expect("opens") {
        match e.expect("Marlin reads every line").kind {
            EventKind::Move(m) => {
                extruded_mm += m.extrusion_mm().max(0.0);
                if m.is_working() {
                    bounds.union(&m.bounds());
                }
            }
            EventKind::Layer(_) => layers += 1,
            _ => {}
        }
    }
    assert_cura_box(&text, &bounds);
    // Metres to five decimals (8.36128 m).
    let used_m = header(&text, "Filament used");
    assert!(
        (extruded_mm / 1e3 - used_m).abs() <= 5e-6,
        "{extruded_mm} mm vs {used_m} m"
    );
    assert_eq!(f64::from(layers), header(&text, "LAYER_COUNT"));
}
