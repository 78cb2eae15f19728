//! Binary G-code (gcode/prints/bgcode/PROVENANCE.md): libbgcode's two test files decode to
//! the G-code of the reference text libbgcode's own binary-to-ASCII conversion gives for
//! them (its tests/convert/convert_tests.cpp compares that conversion with `_ref.gcode`),
//! and a damaged file is refused with its byte offset.

use std::io::Read;

use settle_gcode::job::{Job, JobConfig};
use settle_gcode::{
    AxisFlags, Bgcode, Dialect, EventKind, GcodeError, LimitChange, Reader, ReaderOptions,
};
use settle_planner::firmware::Firmware;

fn decoded(name: &str) -> String {
    let file = std::fs::File::open(super::print_path(name)).expect("print");
    let mut text = String::new();
    Bgcode::new(std::io::BufReader::new(file))
        .expect("header")
        .read_to_string(&mut text)
        .expect("decodes");
    text
}

/// The command lines (not blank, not a comment line), spaces removed: MeatPack's "no
/// spaces" mode drops them and libbgcode's conversion writes them back.
fn commands(text: &str) -> Vec<String> {
    text.lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with(';'))
        .map(|l| l.replace(' ', ""))
        .collect()
}

/// The comment lines the reader takes layers and features from.
fn markers(text: &str) -> Vec<&str> {
    text.lines()
        .filter(|l| {
            l.starts_with(";LAYER_CHANGE") || l.starts_with(";Z:") || l.starts_with(";TYPE:")
        })
        .collect()
}

#[test]
fn both_files_decode_to_their_references_commands_and_markers() {
    for (bgcode, reference, lines) in [
        (
            "bgcode/mini_cube_b.bgcode",
            "bgcode/mini_cube_b_ref.gcode",
            23_557,
        ),
        (
            "bgcode/mini_cube_ps2.8.1.bgcode",
            "bgcode/mini_cube_ps2.8.1_ref.gcode",
            2_147,
        ),
    ] {
        let text = decoded(bgcode);
        let want = std::fs::read_to_string(super::print_path(reference)).expect("reference");
        let got = commands(&text);
        assert_eq!(got.len(), lines, "{bgcode}");
        assert_eq!(got, commands(&want), "{bgcode}");
        assert!(!markers(&want).is_empty());
        assert_eq!(markers(&text), markers(&want), "{bgcode}");
    }
    // The file metadata block as a header comment.
    assert!(
        decoded("bgcode/mini_cube_ps2.8.1.bgcode").starts_with("; Producer = PrusaSlicer 2.8.1\n")
    );
}

/// The reader's layers from the binary file are those from its reference text.
#[test]
fn the_reader_finds_the_references_layers() {
    let layers = |name: &str| -> Vec<String> {
        let mut options = ReaderOptions::new(Dialect::Marlin);
        options.skip_bad_lines = true;
        Reader::open(super::print_path(name), options)
            .expect("opens")
            .filter_map(|e| match e.expect("reads").kind {
                EventKind::Layer(l) => Some(format!("{:?} {:?}", l.source, l.z_mm)),
                _ => None,
            })
            .collect()
    };
    for (bgcode, reference) in [
        ("bgcode/mini_cube_b.bgcode", "bgcode/mini_cube_b_ref.gcode"),
        (
            "bgcode/mini_cube_ps2.8.1.bgcode",
            "bgcode/mini_cube_ps2.8.1_ref.gcode",
        ),
    ] {
        let got = layers(bgcode);
        assert!(got.len() > 10, "{bgcode}: {}", got.len());
        assert_eq!(got, layers(reference), "{bgcode}");
    }
}

/// `bytes` written to a file and read to the end: the error.
fn refused(bytes: &[u8]) -> String {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("print.bgcode");
    std::fs::write(&path, bytes).expect("write");
    let e = match Reader::open(&path, ReaderOptions::new(Dialect::Marlin)) {
        Err(e) => e,
        Ok(r) => r.filter_map(Result::err).next().expect("an error"),
    };
    assert!(matches!(e, GcodeError::Bgcode { .. }), "{e}");
    let text = e.to_string();
    assert!(
        text.contains("print.bgcode: binary G-code, byte "),
        "{text}"
    );
    text
}

/// A file of one uncompressed G-code block, checksums on.
fn one_block(compression: u16, text: &[u8]) -> Vec<u8> {
    let mut f = b"GCDE".to_vec();
    f.extend_from_slice(&1u32.to_le_bytes());
    f.extend_from_slice(&1u16.to_le_bytes());
    let start = f.len();
    f.extend_from_slice(&1u16.to_le_bytes());
    f.extend_from_slice(&compression.to_le_bytes());
    f.extend_from_slice(&(text.len() as u32).to_le_bytes());
    if compression != 0 {
        f.extend_from_slice(&(text.len() as u32).to_le_bytes());
    }
    f.extend_from_slice(&0u16.to_le_bytes());
    f.extend_from_slice(text);
    let crc = crc32(&f[start..]);
    f.extend_from_slice(&crc.to_le_bytes());
    f
}

/// CRC-32 bit by bit (the check value of "123456789" is cbf43926).
fn crc32(bytes: &[u8]) -> u32 {
    let mut c = !0u32;
    for &b in bytes {
        c ^= u32::from(b);
        for _ in 0..8 {
            c = if c & 1 == 1 {
                (c >> 1) ^ 0xEDB8_8320
            } else {
                c >> 1
            };
        }
    }
    !c
}

#[test]
fn a_hand_made_file_reads_and_damage_is_refused_with_its_offset() {
    assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
    let good = one_block(0, b"G1 X1\n");
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("ok.bgcode");
    std::fs::write(&path, &good).expect("write");
    let moves = Reader::open(&path, ReaderOptions::new(Dialect::Marlin))
        .expect("opens")
        .filter(|e| matches!(e.as_ref().expect("reads").kind, EventKind::Move(_)))
        .count();
    assert_eq!(moves, 1);

    let mut bad_crc = good.clone();
    bad_crc[22] = b'2';
    let e = refused(&bad_crc);
    assert!(
        e.contains("byte 10: block checksum") && e.contains("does not match"),
        "{e}"
    );

    let e = refused(&good[..good.len() - 2]);
    assert!(
        e.contains("truncated: the block's CRC32 needs 4 bytes, the file ends at byte"),
        "{e}"
    );
    let e = refused(&good[..15]);
    assert!(
        e.contains("byte 11: truncated: a block header needs 7 bytes"),
        "{e}"
    );

    let e = refused(&one_block(4, b"G1 X1\n"));
    assert!(
        e.contains("byte 12: compression 4 (allowed: 0 none, 1 deflate"),
        "{e}"
    );
    let mut unknown_type = good.clone();
    unknown_type[10] = 9;
    let e = refused(&unknown_type);
    assert!(e.contains("byte 10: block type 9 (allowed: 0 to 5"), "{e}");
    let mut unknown_encoding = good.clone();
    unknown_encoding[18] = 3;
    let e = refused(&unknown_encoding);
    assert!(
        e.contains("byte 18: G-code encoding 3 (allowed: 0 none, 1 MeatPack"),
        "{e}"
    );
    let mut version = good.clone();
    version[4] = 2;
    assert!(refused(&version).contains("byte 4: version 2 (allowed: 1)"));
}

/// A block is held whole while it is decoded: one that claims more than 64 MiB
/// decompressed (a few MiB of deflate can hold gigabytes of G-code) or stored is refused
/// before it is read, however much of the file's text bound is left.
#[test]
fn a_block_past_64_mib_is_refused_before_decompressing_it() {
    let mut f = one_block(1, b"G1 X1\n");
    f[14..18].copy_from_slice(&((64u32 << 20) + 1).to_le_bytes());
    let e = refused(&f);
    assert!(
        e.contains("byte 14: a block of 67108865 bytes decompressed, past the 67108864 bytes (64 MiB) a block may hold"),
        "{e}"
    );
    let mut f = one_block(1, b"G1 X1\n");
    f[18..22].copy_from_slice(&((64u32 << 20) + 1).to_le_bytes());
    let e = refused(&f);
    assert!(
        e.contains("byte 18: a block of 67108865 bytes stored, past the 67108864 bytes"),
        "{e}"
    );
    // At the bound, the block is read (and here found short).
    let mut f = one_block(0, b"G1 X1\n");
    f[14..18].copy_from_slice(&(64u32 << 20).to_le_bytes());
    let e = refused(&f);
    assert!(e.contains("truncated"), "{e}");
}

/// A block's declared size is checked against the bound before anything is allocated:
/// a block of 4 GiB - 1 in a file of 30 bytes.
#[test]
fn a_block_past_the_bound_is_refused_before_reading_it() {
    let mut f = one_block(0, b"G1 X1\n");
    f[14..18].copy_from_slice(&u32::MAX.to_le_bytes());
    let e = refused(&f);
    assert!(
        e.contains(
            "byte 14: a G-code block of 4294967295 bytes would take the text past 2147483648 bytes"
        ),
        "{e}"
    );
    // The bound counts the text of every block so far.
    let text = b"G1 X1\n".repeat(10);
    let mut two = one_block(0, &text);
    two.extend_from_slice(&one_block(0, &text)[10..]);
    let mut r = Bgcode::with_limit(&two[..], 100).expect("header");
    let e = r.read_to_end(&mut Vec::new()).expect_err("past the bound");
    assert!(
        e.to_string()
            .contains("a G-code block of 60 bytes would take the text past 100 bytes"),
        "{e}"
    );
}

/// The MK4S file read as Prusa's firmware reads it, without skipping a line: its only
/// shaper lines are PrusaSlicer's end G-code, `M593 X T2 F0` and `M593 Y T2 F0` ("disable
/// IS": type 2, MZV, frequency 0, off), so the print runs on the printer's own shapers and
/// the job changes them twice, at its end.
#[test]
fn the_mk4s_file_turns_prusas_shapers_off_at_its_end() {
    let path = super::print_path("bgcode/mini_cube_ps2.8.1.bgcode");
    let changes: Vec<LimitChange> = Reader::open(&path, ReaderOptions::new(Dialect::Prusa))
        .expect("opens")
        .map(|e| e.expect("reads every line"))
        .filter_map(|e| match e.kind {
            EventKind::Limits(c @ LimitChange::PrusaInputShaping { .. }) => Some(c),
            _ => None,
        })
        .collect();
    let off = |x: bool, y: bool| LimitChange::PrusaInputShaping {
        axes: AxisFlags {
            x,
            y,
            z: false,
            e: false,
        },
        shaper_type: Some(2),
        frequency_hz: Some(0.0),
        damping_ratio: None,
        vibration_reduction: None,
        weight_frequency_delta_hz: None,
        weight_mass_limit_g: None,
        save: false,
    };
    assert_eq!(changes, [off(true, false), off(false, true)]);
    let cfg = JobConfig::defaults(Firmware::Prusa).expect("defaults");
    let mut job = Job::open(&path, cfg).expect("job");
    job.run_to_end().expect("plans");
    assert_eq!(job.summary().shaper_changes, 2);
}
