//! Events written as canonical G-code and read back are the same events.

use settle_gcode::{CanonicalWriter, Dialect, Event, EventKind, Reader, ReaderOptions};

use crate::print_path;

fn read(bytes: &[u8], d: Dialect) -> Vec<Event> {
    Reader::new(bytes, ReaderOptions::new(d))
        .collect::<Result<Vec<_>, _>>()
        .expect("valid G-code")
}

/// Reads, writes canonically, reads again; compares everything but line numbers.
fn round_trip(bytes: &[u8], d: Dialect) -> (Vec<Event>, String) {
    let first = read(bytes, d);
    let mut w = CanonicalWriter::new(Vec::new(), d).expect("test value");
    for e in &first {
        w.write(e).expect("test value");
    }
    let text = String::from_utf8(w.into_inner()).expect("test value");
    let second = read(text.as_bytes(), d);
    let strip = |v: &[Event]| {
        v.iter()
            .map(|e| (e.layer, e.kind.clone()))
            .collect::<Vec<_>>()
    };
    assert_eq!(
        strip(&first),
        strip(&second),
        "{d}: canonical text:\n{text}"
    );
    (first, text)
}

#[test]
fn shipped_prints_round_trip() {
    for (name, dialects) in [
        ("ringing_tower.gcode", &Dialect::PRINTERS[..]),
        ("cube_layer.gcode", &Dialect::PRINTERS[..]),
        ("arc_part.gcode", &[Dialect::Marlin, Dialect::Rrf][..]),
    ] {
        let bytes = std::fs::read(print_path(name)).expect("test value");
        for &d in dialects {
            let (events, _) = round_trip(&bytes, d);
            assert!(
                events
                    .iter()
                    .filter(|e| matches!(e.kind, EventKind::Move(_)))
                    .count()
                    > 10,
                "{name}"
            );
        }
    }
}

#[test]
fn every_kind_of_event_round_trips() {
    let common = "G1 X10.1 Y-3 Z0.3 E1 F1000\nG92 X0 E0\nG91\nG1 X0.1 Y0.2 F777\nG90\nM83\nG1 X1 E0.1\nG28 X Y\n\
                  G1 X1 Y1 F3333.3\nM400\n;LAYER:0\nG1 X2 E0.3\n;LAYER_CHANGE\n;Z:0.5\nG0 X3\n; CHANGE_LAYER\n\
                  ; Z_HEIGHT: 0.7\n; layer 9, Z = 0.900\nG1 Z1\nG1 X5 E1\n";
    let klipper = format!(
        "{common}G4 P123\nG4 S3\nG2 X7 Y1 I1 J0 F1234.5\nG3 Z1.4 I.5 J-1 P1  F30000\nSET_VELOCITY_LIMIT VELOCITY=333.3 ACCEL=4321 ACCEL_TO_DECEL=1000 \
         SQUARE_CORNER_VELOCITY=5.5 MINIMUM_CRUISE_RATIO=0.25\nM204 P500 T700\nM204 P500\n\
         SET_INPUT_SHAPER SHAPER_TYPE=mzv SHAPER_FREQ_X=44.4 SHAPER_FREQ_Y=38.2 DAMPING_RATIO_X=0.07\n\
         SET_INPUT_SHAPER SHAPER_TYPE_Y='ei' SHAPER_FREQ_Z=12\n"
    );
    let marlin = format!(
        "{common}G4 S0.25\nG2 X7 Y1 R3 F1234.5\nM201 X3000 Y3000 Z100 E5000 F60 S47\nM203 X500 E60\n\
         M204 P1500 R800 T3000\nM205 J0.013 X10 Y10 Z0.4 E5 S0 T0 B20000\nM593 X Y F44.1 D0.15\n\
         M493 S1 H1 X Y C8 D0 A40 F0.1 I0.1 Q0.05\nM494 T2 O1.5 X0.004 E0.01\n"
    );
    let rrf = format!(
        "{common}G4 P300\nG3 X7 Y1 R-3 F1234.5\nM201 X3000 Y3000 E1000:1000\nM203 X18000 Y18000 Z1200 I30\n\
         M203 S1 X300\nM204 P2000 T5000\nM566 X900 Y900 Z60 E3000 P1\nM205 X12.5\n\
         M593 P\"zvdd\" F50.2 S0.05 L0.2\nM593 P\"custom\" H0.4:0.7 T0.0125:0.0125\n\
         M92 X80 Y80.5 Z400 E420:415 S16\nM350 X32 Y32 I1\nM350 Z16\nM906 X1200 Y1200 Z800 I30\n\
         M208 X-5:250 Y0:210\nM208 S1 Z0\nM208 S1 X-2 Y-1:200\nM669 K1\nM665 L360\n\
         M98 P\"homeall.g\"\nM501\n"
    );
    for (d, text) in [
        (Dialect::Klipper, klipper),
        (Dialect::Marlin, marlin),
        (Dialect::Rrf, rrf),
    ] {
        let (events, canonical) = round_trip(text.as_bytes(), d);
        let limits = events
            .iter()
            .filter(|e| matches!(e.kind, EventKind::Limits(_)))
            .count();
        assert!(limits >= 4, "{d}: {limits} limit events");
        let settings = events
            .iter()
            .filter(|e| matches!(e.kind, EventKind::Setting(_)))
            .count();
        assert_eq!(settings, if d == Dialect::Rrf { 9 } else { 0 }, "{d}");
        assert!(
            canonical
                .lines()
                .all(|l| !l.contains('e') || l.starts_with(';') || l.contains('"'))
        );
    }
}

#[test]
fn grbl_is_not_written_canonically() {
    let e = CanonicalWriter::new(Vec::new(), Dialect::Grbl).expect_err("refused");
    assert_eq!(e.kind(), std::io::ErrorKind::Unsupported);
}
