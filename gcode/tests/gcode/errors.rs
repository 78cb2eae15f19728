//! Bad G-code: a clear error with its line, or counted and skipped.

use settle_gcode::{Dialect, EventKind, GcodeError, Reader, ReaderOptions};

use crate::error;

fn skipping(dialect: Dialect) -> ReaderOptions {
    ReaderOptions {
        skip_bad_lines: true,
        ..ReaderOptions::new(dialect)
    }
}

#[test]
fn binary_garbage() {
    let mut bytes = b"G1 X1\nG1 X2\n".to_vec();
    bytes.extend_from_slice(&[0x00, 0xff, 0x13, 0x37, 0xfe, b'\n']); // line 3: not UTF-8
    bytes.extend_from_slice(b"\x01\x02\x03garbage\n"); // line 4: control bytes
    bytes.extend_from_slice(b"#@!\n"); // line 5: not a command
    bytes.extend_from_slice(b"G1 X3\n");
    let all: Vec<_> = Reader::new(&bytes[..], ReaderOptions::new(Dialect::Marlin)).collect();
    assert_eq!(all.len(), 3, "two moves, then the error ends the stream");
    let e = all[2].as_ref().expect_err("an error");
    assert!(matches!(e, GcodeError::InvalidUtf8 { .. }), "{e}");
    assert_eq!(e.line(), Some(3));
    assert!(e.to_string().starts_with("<input>:3:"), "{e}");

    let mut r = Reader::new(&bytes[..], skipping(Dialect::Marlin));
    let moves = r
        .by_ref()
        .map(|e| e.expect("test value"))
        .filter(|e| matches!(e.kind, EventKind::Move(_)))
        .count();
    assert_eq!(moves, 3);
    let s = r.skipped();
    assert_eq!(s.count, 3);
    let lines: Vec<_> = s
        .first
        .iter()
        .map(|e| e.line().expect("test value"))
        .collect();
    assert_eq!(lines, [3, 4, 5]);
    assert!(matches!(
        s.first[1],
        GcodeError::ControlCharacter { byte: 0, .. } | GcodeError::ControlCharacter { byte: 1, .. }
    ));
    assert!(matches!(s.first[2], GcodeError::Syntax { .. }));
}

/// Lines that end in CR alone (classic Mac OS) read as one line, which GRBL would have
/// read as several (it ends a line at CR as at LF, grbl/protocol.c): refused at the
/// first CR with what it most likely is, not as binary data. CR LF reads as LF.
#[test]
fn a_file_of_lines_ended_by_cr_alone_is_named_so() {
    let crlf = "G90\r\nM4 S300\r\nG1 X10 F3000\r\nM5\r\n";
    assert_eq!(crate::moves(crlf, Dialect::Grbl).len(), 1);
    let e = error("G90\rM4 S300\rG1 X10 F3000\rM5\r", Dialect::Grbl);
    let text = e.to_string();
    assert!(
        matches!(e, GcodeError::ControlCharacter { byte: b'\r', .. }),
        "{e}"
    );
    assert!(
        text.starts_with("<input>:1:4: carriage return (0x0d) inside the line"),
        "{text}"
    );
    assert!(
        text.contains("CR alone") && text.contains("convert them to LF"),
        "{text}"
    );
    assert!(!text.contains("binary data"), "{text}");
    // Any other control character is still binary data.
    let e = error("G1 X1\x07\n", Dialect::Grbl).to_string();
    assert!(e.contains("control character 0x07 (binary data?)"), "{e}");
}

#[test]
fn a_ten_megabyte_line_is_an_error_and_is_skipped_unread() {
    let mut bytes = b"G1 X1\n".to_vec();
    bytes.resize(bytes.len() + 10 * 1024 * 1024, b'7');
    bytes.extend_from_slice(b"\nG1 X2\n");
    match error(
        std::str::from_utf8(&bytes).expect("test value"),
        Dialect::Klipper,
    ) {
        GcodeError::LineTooLong { at, limit_bytes } => {
            assert_eq!((at.line, limit_bytes), (2, 65536))
        }
        e => panic!("{e}"),
    }
    let mut r = Reader::new(&bytes[..], skipping(Dialect::Klipper));
    let ev: Vec<_> = r.by_ref().map(|e| e.expect("valid G-code")).collect();
    assert_eq!(ev.iter().map(|e| e.line).collect::<Vec<_>>(), [1, 3]);
    assert_eq!(r.skipped().count, 1);
    assert_eq!(r.bytes_read(), bytes.len() as u64);
}

#[test]
fn nan_infinite_and_huge_values() {
    for text in ["G1 XNaN", "G1 X1 Ynan", "G1 Xinf", "G1 E-inf"] {
        match error(text, Dialect::Marlin) {
            GcodeError::NotANumber { at, .. } => assert_eq!(at.line, 1),
            e => panic!("{text}: {e}"),
        }
    }
    // 1e308 written out: finite, but far beyond any machine.
    let huge = format!("G1 X1{}", "0".repeat(308));
    match error(&huge, Dialect::Marlin) {
        GcodeError::OutOfRange { param, value, .. } => {
            assert_eq!((param.as_str(), value), ("X", 1e308))
        }
        e => panic!("{e}"),
    }
    // Digits beyond the f64 range read as infinity.
    let inf = format!("G1 Y1{}", "0".repeat(400));
    assert!(matches!(
        error(&inf, Dialect::Marlin),
        GcodeError::OutOfRange { .. }
    ));
    // A coordinate past the reader's 1e5 mm limit, also when reached by relative moves.
    assert!(matches!(
        error("G1 Z100001", Dialect::Rrf),
        GcodeError::OutOfRange { .. }
    ));
    match error("G91\nG1 X60000\nG1 X60000", Dialect::Rrf) {
        GcodeError::OutOfRange { at, value, .. } => assert_eq!((at.line, value), (3, 120000.0)),
        e => panic!("{e}"),
    }
    // Klipper-style values: nan and 1e308 are refused too.
    assert!(matches!(
        error("SET_VELOCITY_LIMIT ACCEL=nan", Dialect::Klipper),
        GcodeError::OutOfRange { .. }
    ));
    assert!(matches!(
        error("SET_VELOCITY_LIMIT ACCEL=1e308", Dialect::Klipper),
        GcodeError::OutOfRange { .. }
    ));
}

/// A velocity, acceleration or feed below 1e-9 (mm/s, mm/s^2, mm/min) is refused at its
/// line, naming the command and the word, in every dialect: the planners' arithmetic
/// leaves the range of `f64` below it (`VELOCITY=1e-200` planned a segment of infinite
/// duration, `M204 P1e-300` in RepRapFirmware moves out of time order), and a move at
/// 1e-9 already lasts longer than a replay runs.
#[test]
fn a_limit_below_1e_9_is_refused_at_its_line() {
    let tiny = format!("0.{}1", "0".repeat(299)); // 1e-300 without an exponent
    let cases: Vec<(String, Dialect, &str, &str)> = vec![
        (
            "SET_VELOCITY_LIMIT VELOCITY=1e-200".into(),
            Dialect::Klipper,
            "SET_VELOCITY_LIMIT",
            "VELOCITY",
        ),
        (
            "SET_VELOCITY_LIMIT ACCEL=5e-324".into(),
            Dialect::Klipper,
            "SET_VELOCITY_LIMIT",
            "ACCEL",
        ),
        (
            "SET_VELOCITY_LIMIT ACCEL_TO_DECEL=1e-300".into(),
            Dialect::Klipper,
            "SET_VELOCITY_LIMIT",
            "ACCEL_TO_DECEL",
        ),
        (format!("M204 S{tiny}"), Dialect::Klipper, "M204", "S"),
        (format!("M201 X{tiny}"), Dialect::Marlin, "M201", "X"),
        (format!("M203 Y{tiny}"), Dialect::Marlin, "M203", "Y"),
        (format!("M204 P{tiny}"), Dialect::Marlin, "M204", "P"),
        (format!("M205 J{tiny}"), Dialect::Marlin, "M205", "J"),
        ("M201 X1e-300".into(), Dialect::Rrf, "M201", "X"),
        ("M204 P1e-300 T1e-300".into(), Dialect::Rrf, "M204", "P"),
        ("M203 X1e-12".into(), Dialect::Rrf, "M203", "X"),
        (format!("G1 X1 F{tiny}"), Dialect::Marlin, "G1", "F"),
    ];
    for (text, dialect, command, word) in cases {
        match error(&text, dialect) {
            GcodeError::OutOfRange {
                at,
                command: c,
                param,
                value,
                allowed,
            } => {
                assert_eq!(
                    (at.line, c.as_str(), param.as_str(), allowed),
                    (1, command, word, "from 1e-9 to 1e9"),
                    "{text}"
                );
                assert!(value > 0.0 && value < 1e-9, "{text}: {value}");
            }
            e => panic!("{text}: {e}"),
        }
    }
    // 1e-9 itself is read.
    let text = "SET_VELOCITY_LIMIT VELOCITY=1e-9 ACCEL=1e-9\nM204 S0.000000001\n";
    assert_eq!(crate::limits(text, Dialect::Klipper).len(), 2);
}

/// A value with units glued to it (`M204 S3000mm`) is named as the value that is not a
/// number, not as the second `m` seen twice; a letter given twice still is.
#[test]
fn units_after_a_value_name_the_value() {
    for d in [Dialect::Klipper, Dialect::Marlin, Dialect::Rrf] {
        let e = error("M204 S3000mm", d);
        assert_eq!(
            e.to_string(),
            "<input>:1:6: `M204` parameter S: `3000mm` is not a number (allowed: decimal like -12.5)",
            "{d:?}"
        );
    }
    assert!(matches!(
        error("M204 S3000 S4000", Dialect::Marlin),
        GcodeError::DuplicateParameter { .. }
    ));
    assert!(matches!(
        error("G1X10X20", Dialect::Marlin),
        GcodeError::DuplicateParameter { .. }
    ));
}

#[test]
fn feed_must_be_positive() {
    for text in ["G1 X1 F0", "G1 X1 F-100", "G0 F0"] {
        match error(text, Dialect::Klipper) {
            GcodeError::OutOfRange {
                at,
                param,
                value,
                allowed,
                ..
            } => {
                assert_eq!((at.line, param.as_str()), (1, "F"));
                assert!(value <= 0.0);
                assert_eq!(allowed, "from 1e-9 to 1e9");
            }
            e => panic!("{text}: {e}"),
        }
    }
    // The message names file, line, column, command and parameter.
    let e = error("G1 X1\nG1 X2 F0", Dialect::Klipper).to_string();
    assert_eq!(
        e,
        "<input>:2:7: `G1` parameter F = 0: out of range (allowed: from 1e-9 to 1e9)"
    );
}

#[test]
fn arcs_with_inconsistent_radii() {
    let text = "G1 X10 Y0\nG3 X0 Y9 I-10 J0\n";
    match error(text, Dialect::Marlin) {
        GcodeError::ArcRadiusMismatch {
            at,
            start_radius_mm,
            end_radius_mm,
            ..
        } => {
            assert_eq!((at.line, start_radius_mm, end_radius_mm), (2, 10.0, 9.0));
        }
        e => panic!("{e}"),
    }
}

#[test]
fn syntax_errors() {
    assert!(matches!(
        error("G1 X1 X2", Dialect::Marlin),
        GcodeError::DuplicateParameter { .. }
    ));
    assert!(matches!(
        error("G1 X1.2.3", Dialect::Marlin),
        GcodeError::NotANumber { .. }
    ));
    assert!(matches!(
        error("G1 X", Dialect::Marlin),
        GcodeError::MissingValue { .. }
    ));
    assert!(matches!(
        error("G1 X1 S0", Dialect::Marlin),
        GcodeError::UnknownParameter { .. }
    ));
    assert!(matches!(
        error("G1 X1 ?", Dialect::Marlin),
        GcodeError::Syntax { .. }
    ));
    assert!(matches!(
        error("G1 X{1+1}", Dialect::Rrf),
        GcodeError::Syntax { .. }
    ));
    assert!(matches!(
        error("G20", Dialect::Marlin),
        GcodeError::Unsupported { .. }
    ));
    assert!(matches!(
        error("N3 G1 X1*0", Dialect::Marlin),
        GcodeError::Checksum { .. }
    ));
    assert!(matches!(
        error("G1 X1 (open", Dialect::Marlin),
        GcodeError::Syntax { .. }
    ));
    assert!(matches!(
        error("SET_VELOCITY_LIMIT ACCELL=3000", Dialect::Klipper),
        GcodeError::UnknownParameter { .. }
    ));
    assert!(matches!(
        error("SET_VELOCITY_LIMIT ACCEL", Dialect::Klipper),
        GcodeError::Syntax { .. }
    ));
    assert!(matches!(
        error("M204 S-1", Dialect::Marlin),
        GcodeError::OutOfRange { .. }
    ));
    // Unknown commands are not errors, whatever their parameters.
    let r = Reader::new(
        "M117 Hello (world) #1\nM104 S{temp}\n".as_bytes(),
        ReaderOptions::new(Dialect::Rrf),
    );
    assert_eq!(r.count(), 0);
}

#[test]
fn io_errors_name_the_file() {
    let e = Reader::open(
        "/nonexistent/part.gcode",
        ReaderOptions::new(Dialect::Marlin),
    )
    .expect_err("an error");
    assert!(
        e.to_string()
            .starts_with("/nonexistent/part.gcode: cannot read"),
        "{e}"
    );
}

/// Files that hold G-code but are not its text, by their first bytes: a binary G-code file
/// (PrusaSlicer's `.bgcode`: its 10-byte file header as libbgcode's doc/specifications.md
/// gives it, magic `GCDE`, version 1, checksum type 1 = CRC32, little-endian, then the
/// start of a block header), a gzip stream (RFC 1952's ID1 ID2 = 1f 8b, then CM = 8 and
/// flags, as Cura's .gcode.gz starts) and a zip archive (a local file header, PK 3 4: a
/// 3MF, Bambu Studio's .gcode.3mf, an UltiMaker .ufp). Each is named for what it is with
/// the way to its text, at line 1 column 1, and not skipped as a bad line.
#[test]
fn packaged_gcode_is_named_and_never_skipped() {
    let mut bgcode = b"GCDE".to_vec();
    bgcode.extend_from_slice(&1u32.to_le_bytes());
    bgcode.extend_from_slice(&1u16.to_le_bytes());
    bgcode.extend_from_slice(&[0, 0, 0, 0, 0x1a, 0, 0, 0, b'\n', b'G', b'1', b'\n']);
    let gzip = vec![0x1f, 0x8b, 8, 0, 0, 0, 0, 0, 0, 3, b'\n', b'G'];
    let zip = b"PK\x03\x04\x14\x00\x00\x00\x08\x00Metadata/plate_1.gcode\n".to_vec();
    let cases = [
        (
            bgcode,
            "binary G-code (bgcode",
            "Convert binary G-code to ASCII",
        ),
        (gzip, "gzip-compressed", "gunzip -k FILE"),
        (zip, "a zip archive", "Metadata/plate_1.gcode"),
    ];
    for (bytes, what, instead) in cases {
        for options in [
            ReaderOptions::new(Dialect::Klipper),
            skipping(Dialect::Klipper),
        ] {
            let all: Vec<_> = Reader::new(&bytes[..], options).collect();
            assert_eq!(all.len(), 1, "the error alone");
            let e = all[0].as_ref().expect_err("an error");
            assert!(matches!(e, GcodeError::Packaged { .. }), "{e}");
            let at = e.location().expect("a location");
            assert_eq!((at.line, at.column), (1, Some(1)));
            let text = e.to_string();
            assert!(text.contains(what) && text.contains(instead), "{text}");
        }
    }
    // A text file whose first line merely contains the letters is G-code.
    let text = b"; GCDE PK\nG1 X1\n";
    let moves = Reader::new(&text[..], ReaderOptions::new(Dialect::Klipper))
        .map(|e| e.expect("text G-code"))
        .filter(|e| matches!(e.kind, EventKind::Move(_)))
        .count();
    assert_eq!(moves, 1);
}

/// Marlin's `M92` in a job is not followed (the configuration's steps hold), but a value
/// no machine has is refused at its line, with the range and why: at 1e-7 steps/mm a
/// 50 mm move is not one whole step (the old reader listed it as not followed and the
/// job replayed as if it were not there), at 2e6 a 32-bit step count overflows within
/// 1.07 m (2^31 / 2e6 mm). 1 and 1e6 themselves, and a real printer's values, are read.
#[test]
fn marlin_m92_steps_per_mm_are_bounded_at_their_line() {
    for (text, dialect, word, value) in [
        ("G90\nM92 X0.0000001", Dialect::Marlin, "X", 1e-7),
        ("G90\nM92 X80 Y80 Z400 E0.5", Dialect::Marlin, "E", 0.5),
        ("G90\nM92 Z2000000", Dialect::Prusa, "Z", 2e6),
    ] {
        match error(text, dialect) {
            GcodeError::OutOfRange {
                at,
                command,
                param,
                value: v,
                allowed,
            } => {
                assert_eq!(
                    (at.line, command.as_str(), param.as_str(), v),
                    (2, "M92", word, value),
                    "{text}"
                );
                assert!(allowed.starts_with("1 to 1e6 steps/mm"), "{allowed}");
                assert!(allowed.contains("32-bit step count"), "{allowed}");
            }
            e => panic!("{text}: {e}"),
        }
    }
    for dialect in [Dialect::Marlin, Dialect::Prusa] {
        let text = "M92 X80.29 Y80.29 Z399.21 E425.35\nM92 X1 E1000000\nM92\n";
        assert_eq!(crate::ignored(text, dialect), ["M92 x3"]);
        assert_eq!(
            crate::moves(&format!("{text}G1 X10 F600\n"), dialect).len(),
            1
        );
    }
}

/// Marlin's `text` (one line) is refused at its word `word` of value `value`, the range
/// given starting with `allowed` and citing `source`.
fn refused_at_word(text: &str, word: &str, value: f64, allowed: &str, source: &str) {
    match error(text, Dialect::Marlin) {
        GcodeError::OutOfRange {
            at,
            param,
            value: v,
            allowed: a,
            ..
        } => {
            assert_eq!((at.line, param.as_str(), v), (1, word, value), "{text}");
            assert!(a.starts_with(allowed) && a.contains(source), "{text}: {a}");
        }
        e => panic!("{text}: {e}"),
    }
}

/// Marlin's `M493` (FT_MOTION): a frequency `A` outside 10 to 500 Hz and a damping `I`
/// outside 0.01 to below 1 are refused at their word, as Marlin's M493.cpp refuses them
/// (`WITHIN(baseFreqVal, FTM_MIN_SHAPE_FREQ, FTM_FS / 2)`, `WITHIN(zetaVal, 0.01, 1)`); the
/// old reader shaped at 5 Hz, which Marlin never runs. `D1`/`D2` (a frequency that moves
/// with Z or the extruded filament) is refused: settle shapes at a fixed frequency.
#[test]
fn marlin_m493_values_are_bounded_at_their_line() {
    for (text, word, value, allowed) in [
        ("M493 S1 X C1 A5", "A", 5.0, "10 to 500 Hz"),
        ("M493 S1 X C1 A9.99", "A", 9.99, "10 to 500 Hz"),
        ("M493 S1 X C1 A500.5", "A", 500.5, "10 to 500 Hz"),
        ("M493 S1 X C1 A40 I0.001", "I", 0.001, "0.01 to below 1"),
        ("M493 S1 X C1 A40 I1", "I", 1.0, "0.01 to below 1"),
    ] {
        refused_at_word(text, word, value, allowed, "M493.cpp");
    }
    for d in ["D1", "D2"] {
        let text = format!("M493 S1 X C1 A40 {d} F0.5");
        match error(&text, Dialect::Marlin) {
            GcodeError::Unsupported { at, why, .. } => {
                assert_eq!(at.line, 1);
                assert!(why.contains("fixed frequency"), "{why}");
            }
            e => panic!("{text}: {e}"),
        }
    }
    // The ends of the ranges, and D0, are read.
    let text = "M493 S1 X C1 A10 I0.01 D0\nM493 Y C8 A500 I0.99 Q1\n";
    assert_eq!(crate::limits(text, Dialect::Marlin).len(), 2);
}

/// RepRapFirmware's `M593 F` outside `StepClockRate / (2 * 65535)` = 750000 / 131070 =
/// 5.72213 Hz (Duet 3) to 1000 Hz is refused at its word whatever the type, as
/// `AxisShaper::Configure` (src/Movement/AxisShaper.cpp) throws "parameter 'F' too low"
/// from `GetLimitedFValue` before it looks at `P`. The old reader took any positive `F`
/// and refused it only when it built a shaper, so `M593 P"none" F3` was read.
#[test]
fn rrf_m593_frequency_is_bounded_at_its_word() {
    for (text, value) in [
        ("M593 P\"none\" F3", 3.0),
        ("M593 P\"zvd\" F5.722", 5.722),
        ("M593 F1000.01", 1000.01),
    ] {
        match error(text, Dialect::Rrf) {
            GcodeError::OutOfRange {
                at,
                param,
                value: v,
                allowed,
                ..
            } => {
                assert_eq!((at.line, param.as_str(), v), (1, "F", value), "{text}");
                assert!(
                    allowed.starts_with("5.722 to 1000 Hz") && allowed.contains("AxisShaper.cpp"),
                    "{text}: {allowed}"
                );
            }
            e => panic!("{text}: {e}"),
        }
    }
    // 5.7222 is above 5.72213, and 1000 is the top.
    let text = "M593 P\"zvd\" F5.7222\nM593 F1000\n";
    assert_eq!(crate::limits(text, Dialect::Rrf).len(), 2);
}

/// Marlin's `M494` (FT_MOTION's trajectory and smoothing): an overshoot `O` outside 1.25
/// to 1.875 and a smoothing time `X Y Z E` outside 0 to 0.1 s (`FTM_MAX_SMOOTHING_TIME`)
/// are refused at their word, as Marlin's M494.cpp refuses them (`WITHIN(val, 1.25f,
/// 1.875f)`, `WITHIN(val, 0.0f, FTM_MAX_SMOOTHING_TIME)`); the old reader took any
/// positive overshoot and any smoothing time up to 1e9 s.
#[test]
fn marlin_m494_values_are_bounded_at_their_line() {
    for (text, word, value, allowed) in [
        ("M494 T2 O1.2", "O", 1.2, "1.25 to 1.875"),
        ("M494 T2 O1.876", "O", 1.876, "1.25 to 1.875"),
        ("M494 O1000000000", "O", 1e9, "1.25 to 1.875"),
        ("M494 X0.11", "X", 0.11, "0 to 0.1 s"),
        ("M494 Y1000000", "Y", 1e6, "0 to 0.1 s"),
        ("M494 Z0.2", "Z", 0.2, "0 to 0.1 s"),
        ("M494 X0.01 E0.5", "E", 0.5, "0 to 0.1 s"),
    ] {
        refused_at_word(text, word, value, allowed, "M494.cpp");
    }
    // A negative time and a trajectory type above 2 were refused before and still are.
    for text in ["M494 X-0.01", "M494 T3"] {
        assert!(matches!(
            error(text, Dialect::Marlin),
            GcodeError::OutOfRange { .. }
        ));
    }
    // The ends of the ranges are read.
    let text = "M494 T2 O1.25 X0 Y0.1\nM494 O1.875 Z0.1 E0\n";
    assert_eq!(crate::limits(text, Dialect::Marlin).len(), 2);
}

/// Marlin's `M205 B` (minimum segment time, µs) in a job: 0 to 1000000 µs. Marlin keeps
/// any whole number in a `uint32_t` (`GcodeSuite::M205`) and SLOWDOWN stretches a short
/// block to as long as B (`Planner::_populate_block`); the old reader took up to 1e9 µs
/// and planned blocks of 1000 s.
#[test]
fn marlin_m205_b_is_bounded_at_its_line() {
    for dialect in [Dialect::Marlin, Dialect::Prusa] {
        for (text, value) in [
            ("M205 B1000001", 1_000_001.0),
            ("M205 B1000000000 S0", 1e9),
            ("M205 B-1", -1.0),
        ] {
            match error(text, dialect) {
                GcodeError::OutOfRange {
                    at,
                    command,
                    param,
                    value: v,
                    allowed,
                } => {
                    assert_eq!(
                        (at.line, command.as_str(), param.as_str(), v),
                        (1, "M205", "B", value),
                        "{text}"
                    );
                    assert!(allowed.starts_with("0 to 1000000 us"), "{allowed}");
                }
                e => panic!("{text}: {e}"),
            }
        }
        let text = "M205 B0\nM205 B1000000 S0\nM205 B20000.00 S0.00 T0.00 J0.08\n";
        assert_eq!(crate::limits(text, dialect).len(), 3);
    }
}

/// A shaper frequency in a job is held to what printer.cfg's `shaper_freq_*` and an
/// `M503` reply's `M593 F` are held to: 0 (off), or 1 to 1000 Hz. The old reader took
/// Marlin's `M593 X F1000000000` and Klipper's `SHAPER_FREQ_X=1e9` and replayed the job
/// as if unshaped, where the same value in the configuration was refused.
#[test]
fn a_jobs_shaper_frequency_is_held_to_the_configurations_range() {
    for (text, dialect, word, value) in [
        ("G90\nM593 X F1000000000", Dialect::Marlin, "F", 1e9),
        ("G90\nM593 Y F1000.5 D0.1", Dialect::Marlin, "F", 1000.5),
        ("G90\nM593 F0.5", Dialect::Marlin, "F", 0.5),
        (
            "G90\nSET_INPUT_SHAPER SHAPER_TYPE=mzv SHAPER_FREQ_X=1e9",
            Dialect::Klipper,
            "SHAPER_FREQ_X",
            1e9,
        ),
        (
            "G90\nSET_INPUT_SHAPER SHAPER_FREQ_Y=0.2",
            Dialect::Klipper,
            "SHAPER_FREQ_Y",
            0.2,
        ),
    ] {
        match error(text, dialect) {
            GcodeError::OutOfRange {
                at,
                param,
                value: v,
                allowed,
                ..
            } => {
                assert_eq!((at.line, param.as_str(), v), (2, word, value), "{text}");
                assert!(allowed.starts_with("0 (off) or 1 to 1000 Hz"), "{allowed}");
            }
            e => panic!("{text}: {e}"),
        }
    }
    let ok = "M593 X F0\nM593 Y F1 D0.1\nM593 X F1000\n";
    assert_eq!(crate::limits(ok, Dialect::Marlin).len(), 3);
    let ok = "SET_INPUT_SHAPER SHAPER_FREQ_X=0 SHAPER_FREQ_Y=1000\n";
    assert_eq!(crate::limits(ok, Dialect::Klipper).len(), 1);
}
