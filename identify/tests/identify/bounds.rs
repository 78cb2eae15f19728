//! Every input is bounded before it is read: a file that is not a regular file, that
//! holds more than `MAX_FILE_BYTES` (on disk, or once a `.stdata` file is decompressed),
//! or a recording of more than `MAX_SAMPLES` samples (a spectrum of more than
//! `MAX_SPECTRUM_ROWS` rows) is refused, naming the file and the limit, before its data
//! are held.

use std::fmt::Write as _;

use settle_identify::IdentifyError;
use settle_identify::read::{
    MAX_FILE_BYTES, MAX_SAMPLES, MAX_SPECTRUM_ROWS, klipper_psd, klipper_raw, read_file, rrf,
    stdata,
};

/// `e` is the readers' refusal of `file`, saying `found`.
fn assert_refused(e: &IdentifyError, file: &str, found: &str) {
    // The readers' own limits, or settle-files' reader (not a regular file, too large).
    assert!(
        matches!(
            e,
            IdentifyError::NotAccepted { .. } | IdentifyError::File(_)
        ),
        "unexpected error {e:?}"
    );
    let text = e.to_string();
    assert!(text.starts_with(file), "{text}");
    assert!(text.contains(found), "{text}");
}

#[test]
fn folders_devices_and_oversized_files_are_refused_before_reading() {
    let dir = tempfile::tempdir().expect("tempdir");
    let folder = dir.path().display().to_string();
    let e = read_file(dir.path()).expect_err("a folder");
    assert_refused(&e, &folder, "not a regular file");
    // A device that never ends: refused without reading it.
    #[cfg(unix)]
    {
        let e = read_file(std::path::Path::new("/dev/zero")).expect_err("a device");
        assert_refused(&e, "/dev/zero", "not a regular file");
    }
    // One byte over the limit (a sparse file: nothing is written).
    let big = dir.path().join("raw_data_x_big.csv");
    std::fs::File::create(&big)
        .and_then(|f| f.set_len(MAX_FILE_BYTES + 1))
        .expect("sparse file");
    let e = read_file(&big).expect_err("too large");
    assert_refused(
        &e,
        &big.display().to_string(),
        &format!("{} bytes", MAX_FILE_BYTES + 1),
    );
}

/// A recording gzipped or zipped (RFC 1952's 1f 8b, a zip's PK 3 4) is named as such,
/// with what to do; other binary data is "not UTF-8 text".
#[test]
fn compressed_recordings_are_named() {
    let dir = tempfile::tempdir().expect("tempdir");
    let cases: [(&str, &[u8], &str); 3] = [
        (
            "x.csv.gz",
            &[0x1f, 0x8b, 8, 0, 0, 0, 0, 0, 0, 3, 0xe3],
            "gzip-compressed, not UTF-8 text: unpack it",
        ),
        (
            "x.zip",
            b"PK\x03\x04\x14\x00\xe3",
            "a zip archive, not UTF-8 text: unpack it",
        ),
        (
            "x.csv",
            b"#time,accel_x\n\xff",
            "bytes that are not UTF-8 text",
        ),
    ];
    for (name, bytes, found) in cases {
        let file = dir.path().join(name);
        std::fs::write(&file, bytes).expect("writes");
        let e = read_file(&file).expect_err("not a recording");
        assert!(matches!(e, IdentifyError::Format { line: 1, .. }), "{e:?}");
        let text = e.to_string();
        assert!(text.starts_with(&file.display().to_string()), "{text}");
        assert!(text.contains(found), "{text}");
    }
}

#[test]
fn recordings_and_spectra_beyond_the_limits_are_refused() {
    let too_many = format!("more than {MAX_SAMPLES} samples");
    let mut raw = String::from("#time,accel_x,accel_y,accel_z\n");
    raw.push_str(&"0,0,0,0\n".repeat(MAX_SAMPLES + 1));
    let e = klipper_raw::parse("r.csv", &raw).expect_err("too many samples");
    assert_refused(&e, "r.csv", &too_many);
    let mut m956 = String::from("Sample,X\n");
    for i in 0..=MAX_SAMPLES {
        writeln!(m956, "{i},0").expect("a string");
    }
    m956.push_str("Rate 1000, overflows 0\n");
    let e = rrf::parse("m.csv", &m956).expect_err("too many samples");
    assert_refused(&e, "m.csv", &too_many);
    let mut psd = String::from("freq,psd_x,psd_y,psd_z,psd_xyz\n");
    for k in 0..=MAX_SPECTRUM_ROWS {
        writeln!(psd, "{:.1},1,1,1,3", k as f64 * 0.1).expect("a string");
    }
    let e = klipper_psd::parse("p.csv", &psd).expect_err("too many rows");
    assert_refused(
        &e,
        "p.csv",
        &format!("more than {MAX_SPECTRUM_ROWS} frequency rows"),
    );
    let pack = |text: &str| zstd::stream::encode_all(text.as_bytes(), 1).expect("zstd");
    let line = format!(
        "{{\"name\": \"a\", \"samples\": [{}[0,0,0,0]]}}\n",
        "[0,0,0,0],".repeat(MAX_SAMPLES)
    );
    let e = stdata::parse("s.stdata", &pack(&line)).expect_err("too many samples");
    assert_refused(&e, "s.stdata", &too_many);
    let bomb = " ".repeat(MAX_FILE_BYTES as usize + 1);
    let e = stdata::parse("s.stdata", &pack(&bomb)).expect_err("too much text");
    assert_refused(
        &e,
        "s.stdata",
        &format!("more than {MAX_FILE_BYTES} bytes of text"),
    );
}

/// A processed spectrum's frequency beyond the Nyquist frequency of any recording settle
/// reads (a last row of `1e308` Hz) is refused at its line as out of bounds; it was told
/// "which no bin width fitting the rows before it rounds to", a puzzle rather than a bound.
#[test]
fn a_spectrum_frequency_beyond_any_recording_is_refused_at_its_line() {
    let mut psd = String::from("freq,psd_x,psd_y,psd_z,psd_xyz\n");
    for k in 0..20 {
        writeln!(psd, "{:.1},1,1,1,3", k as f64 * 1.6).expect("a string");
    }
    for (last, found) in [
        ("1e308", "frequency 1e308 Hz in column `freq`"),
        ("50000.1", "frequency 50000.1 Hz in column `freq`"),
    ] {
        let text = format!("{psd}{last},1,1,1,3\n");
        let e = klipper_psd::parse("p.csv", &text).expect_err(last);
        let text = e.to_string();
        assert!(text.starts_with("p.csv:22: "), "{text}");
        assert!(text.contains(found), "{text}");
        assert!(text.contains("a frequency from 0 to 50000 Hz"), "{text}");
    }
    let e =
        klipper_psd::parse("p.csv", &psd.replacen("\n0.0,", "\n-1.0,", 1)).expect_err("negative");
    assert!(
        e.to_string().starts_with("p.csv:2: frequency -1.0 Hz"),
        "{e}"
    );
}
