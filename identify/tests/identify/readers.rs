//! Every reader: good input read right, bad input rejected naming the file and line.

use settle_identify::IdentifyError;
use settle_identify::read::{klipper_psd, klipper_raw, rrf, stdata};

fn line_of(e: &IdentifyError) -> (String, usize) {
    match e {
        IdentifyError::Format { file, line, .. }
        | IdentifyError::NotFinite { file, line, .. }
        | IdentifyError::NotMonotonic { file, line, .. }
        | IdentifyError::TooFewSamples { file, line, .. } => (file.clone(), *line),
        other => panic!("unexpected error {other:?}"),
    }
}

fn raw(rows: usize) -> String {
    let mut s = String::from("#time,accel_x,accel_y,accel_z\n");
    for i in 0..rows {
        s.push_str(&format!("{:.6},1.0,2.0,9806.65\n", 1.0 + i as f64 / 100.0));
    }
    s
}

#[test]
fn klipper_raw_reads_and_rejects() {
    let rec = klipper_raw::parse("a.csv", &raw(100)).expect("good file");
    assert_eq!(rec.len(), 100);
    assert!((rec.sample_rate_hz - 100.0 / 0.99).abs() < 1e-9);
    let cases = [
        ("time,x,y,z\n".to_string() + &raw(100)[31..], 1),
        (raw(100).replace("1.500000,1.0", "1.500000,abc"), 52),
        (raw(100).replace("1.500000,1.0", "1.500000,nan"), 52),
        (raw(100).replace("1.500000,1.0", "1.490000,1.0"), 52),
        (
            raw(100).replace("1.500000,1.0,2.0,9806.65", "1.500000,1.0,2.0"),
            52,
        ),
        (raw(10), 11),
    ];
    for (text, line) in cases {
        let e = klipper_raw::parse("a.csv", &text).expect_err("bad file");
        assert_eq!(line_of(&e), ("a.csv".to_string(), line), "{e}");
        assert!(e.to_string().starts_with(&format!("a.csv:{line}")), "{e}");
    }
}

fn m956(rows: usize, rate: bool) -> String {
    let mut s = String::from("Sample,X,Z\n");
    for i in 0..rows {
        s.push_str(&format!("{i},0.0123,-0.9900\n"));
    }
    if rate {
        s.push_str("Rate 1344, overflows 0\n");
    }
    s
}

#[test]
fn rrf_reads_and_rejects() {
    let rec = rrf::parse("m.csv", &m956(100, true)).expect("good file");
    assert_eq!(rec.sample_rate_hz, 1344.0);
    assert!(rec.accel_mm_s2[1].is_none());
    let z = rec.accel_mm_s2[2].as_ref().expect("z");
    assert!((z[0] + 0.99 * 9806.65).abs() < 1e-9);
    let cases = [
        (m956(100, false), 101),
        (m956(100, true).replace("Sample,X,Z", "Sample,Z,X"), 1),
        (m956(100, true).replace("\n50,", "\n51,"), 52),
        (m956(100, true).replace("\n50,0.0123", "\n50,x"), 52),
        (m956(100, true).replace("Rate 1344", "Rate fast"), 102),
        (
            m956(100, true) + "Failed to collect data from accelerometer\n",
            103,
        ),
        (m956(10, true), 11),
    ];
    for (text, line) in cases {
        let e = rrf::parse("m.csv", &text).expect_err("bad file");
        assert_eq!(line_of(&e), ("m.csv".to_string(), line), "{e}");
    }
}

fn psd(rows: usize, shapers: bool) -> String {
    let mut s = String::from("freq,psd_x,psd_y,psd_z,psd_xyz");
    if shapers {
        s.push_str(",shapers:,zv(40.2)");
    }
    s.push('\n');
    for k in 0..rows {
        let low = shapers && (k as f64) * 1.5625 < 5.0;
        let v = if low { 0.0 } else { 1.0 + k as f64 };
        s.push_str(&format!(
            "{:.1},{v:.3e},{v:.3e},{v:.3e},{:.3e}",
            k as f64 * 1.5625,
            3.0 * v
        ));
        if shapers {
            s.push_str(",,0.500");
        }
        s.push('\n');
    }
    s
}

#[test]
fn klipper_processed_reads_and_rejects() {
    let p = klipper_psd::parse("r.csv", &psd(64, false)).expect("good file");
    assert_eq!(p.normalisation, klipper_psd::Normalisation::Raw);
    assert_eq!(p.sum()[2], 9.0);
    let c = klipper_psd::parse("c.csv", &psd(64, true)).expect("good file");
    assert_eq!(
        c.normalisation,
        klipper_psd::Normalisation::ByFrequencyZeroBelow5Hz
    );
    assert_eq!(c.shapers, vec!["zv(40.2)".to_string()]);
    let cases = [
        (psd(64, false).replace("freq,psd_x", "frequency,psd_x"), 1),
        (psd(64, false).replace("\n3.1,", "\n1.0,"), 4),
        (psd(64, false).replace("\n3.1,3.000e0", "\n3.1,-3.000e0"), 4),
        (
            psd(64, true).replace(
                "\n3.1,0.000e0,0.000e0,0.000e0,0.000e0,,",
                "\n3.1,0.000e0,0.000e0,0.000e0,0.000e0,1,",
            ),
            4,
        ),
        (psd(64, false).replace("\n3.1,3.000e0,", "\n3.1,"), 4),
        (psd(8, false), 9),
    ];
    for (text, line) in cases {
        let e = klipper_psd::parse("r.csv", &text).expect_err("bad file");
        assert_eq!(line_of(&e), ("r.csv".to_string(), line), "{e}");
    }
}

#[test]
fn shaketune_stdata_reads_and_rejects() {
    let line = |n: usize, t_back: bool| {
        let mut s = String::from("{\"name\": \"a\", \"samples\": [");
        for i in 0..n {
            let t = if t_back && i == 40 {
                0.0
            } else {
                i as f64 * 0.01
            };
            s.push_str(&format!(
                "{}[{t}, 1.0, 2.0, 3.0]",
                if i > 0 { ", " } else { "" }
            ));
        }
        s + "]}\n"
    };
    let pack = |text: &str| zstd::stream::encode_all(text.as_bytes(), 3).expect("zstd");
    let two = stdata::parse("s.stdata", &pack(&(line(100, false) + &line(80, false))))
        .expect("good file");
    assert_eq!(two.len(), 2);
    assert_eq!(two[1].len(), 80);
    let cases = [
        (pack(&(line(100, false) + "{\"name\": \"b\"}\n")), 2),
        (pack(&(line(100, false) + &line(100, true))), 2),
        (pack(&line(100, false).replace("[0.5, 1.0", "[NaN, 1.0")), 1),
        (pack(&line(10, false)), 1),
        (b"not zstd at all".to_vec(), 1),
    ];
    for (bytes, l) in cases {
        let e = stdata::parse("s.stdata", &bytes).expect_err("bad file");
        assert_eq!(line_of(&e), ("s.stdata".to_string(), l), "{e}");
    }
    // An acceleration beyond +-1e9 mm/s^2 (a unit or scale mistake) in the second
    // measurement: refused at its line, naming the sample and the axis; 1e9 itself reads.
    let huge = line(100, false) + &line(80, false).replace("[0.5, 1.0, 2.0", "[0.5, 1.0, -2e9");
    let e = stdata::parse("s.stdata", &pack(&huge)).expect_err("too large");
    assert_eq!(line_of(&e), ("s.stdata".to_string(), 2), "{e}");
    let m = e.to_string();
    assert!(
        m.contains("samples[50] y") && m.contains("1e9 mm/s^2"),
        "{m}"
    );
    let edge = line(100, false).replace("[0.5, 1.0, 2.0", "[0.5, 1.0, -1e9");
    stdata::parse("s.stdata", &pack(&edge)).expect("1e9 mm/s^2 is within the bound");
}

/// Raw samples at `first_ms` apart up to sample 600, then `then_ms` apart, 1,000 in all.
fn raw_two_rates(first_ms: f64, then_ms: f64) -> String {
    let mut s = String::from("#time,accel_x,accel_y,accel_z\n");
    for i in 0..1000 {
        let t = if i <= 600 {
            i as f64 * first_ms
        } else {
            600.0 * first_ms + (i - 600) as f64 * then_ms
        };
        s.push_str(&format!(
            "{:.6},1.0,{}.0,9806.65\n",
            1.0 + t / 1000.0,
            i % 7
        ));
    }
    s
}

/// A recording whose sample rate changes is refused: every sample is read at the mean
/// rate, so a stretch at another rate shows its frequencies moved. 1 ms apart, then 2 ms
/// apart after sample 600: 999 intervals over 1.398 s, a mean rate of 714.59 Hz, and the
/// first of the nine stretches of 111 intervals runs at 1000 Hz, 39.9 % above it. A rate
/// that moves by 0.5 % (1 ms, then 1.005 ms) stays within the 1 % allowed.
#[test]
fn klipper_raw_refuses_a_rate_that_changes() {
    let e = klipper_raw::parse("a.csv", &raw_two_rates(1.0, 2.0)).expect_err("two rates");
    assert_eq!(line_of(&e), ("a.csv".to_string(), 2), "{e}");
    let text = e.to_string();
    assert!(
        text.contains(
            "samples 0 to 111 (1.000000 to 1.111000 s) at 1000.00 Hz, +39.9 % off the recording's mean rate of 714.59 Hz"
        ),
        "{text}"
    );
    assert!(
        text.contains("every stretch within 1 % of the mean rate"),
        "{text}"
    );
    let rec = klipper_raw::parse("a.csv", &raw_two_rates(1.0, 1.005)).expect("0.5 % apart");
    assert_eq!(rec.len(), 1000);
}
