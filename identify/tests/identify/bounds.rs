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
        writeln!(psd, "{k},1,1,1,3").expect("a string");
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
