//! Recordings a sensor clipped are refused by the readers, naming the file, line, axis,
//! time and value of the first sample at the sensor's full scale; a recording whose axis
//! passes that full scale elsewhere was read at another range and is read.
//!
//! The full scales are the firmwares' (see `settle_identify::read::KLIPPER_FULL_SCALES`
//! and `M956_FULL_SCALE_G`): an ADXL345 as Klipper reads it (`klippy/extras/adxl345.py`:
//! `REG_DATA_FORMAT` 0x0B, 13-bit counts from -4096 to 4095 of `SCALE_XY` = 0.003774 g),
//! an ICM-20948 (`icm20948.py`: +-16 g, 16-bit counts of 1/2048 g), and RepRapFirmware's
//! M956 (`Accelerometers.cpp`: `count / 2^(bits - 2)` g, +-2 g, 4 decimals for 14 bits).

use settle_identify::IdentifyError;
use settle_identify::read::{klipper_raw, rrf, stdata};

/// One ADXL345 x/y count (mm/s^2): 0.003774 g x 9806.65 mm/s^2/g.
const ADXL_XY: f64 = 0.003774 * 9806.65;

/// `n` samples at 3,200 Hz from t = 2 s: x the counts `x(i)` of [`ADXL_XY`], y and z a
/// few counts of noise and gravity.
fn samples(n: usize, x: impl Fn(usize) -> f64) -> Vec<[f64; 4]> {
    (0..n)
        .map(|i| {
            [
                2.0 + i as f64 / 3200.0,
                x(i) * ADXL_XY,
                (i % 3) as f64 * ADXL_XY,
                (265 + i % 2) as f64 * ADXL_XY,
            ]
        })
        .collect()
}

fn raw_text(rows: &[[f64; 4]]) -> String {
    let mut s = String::from("#time,accel_x,accel_y,accel_z\n");
    for [t, x, y, z] in rows {
        s.push_str(&format!("{t:.6},{x:.6},{y:.6},{z:.6}\n"));
    }
    s
}

fn stdata_bytes(rows: &[[f64; 4]]) -> Vec<u8> {
    let v: Vec<String> = rows
        .iter()
        .map(|[t, x, y, z]| format!("[{t:.6}, {x:.6}, {y:.6}, {z:.6}]"))
        .collect();
    let line = format!("{{\"name\": \"m\", \"samples\": [{}]}}\n", v.join(", "));
    zstd::stream::encode_all(line.as_bytes(), 3).expect("zstd")
}

fn format_error(e: &IdentifyError) -> (usize, &str, &str) {
    match e {
        IdentifyError::Format {
            line,
            found,
            expected,
            ..
        } => (*line, found, expected),
        other => panic!("unexpected error {other:?}"),
    }
}

/// A ramp of counts from 0 up by 10 a sample reaches the ADXL345's 4095 at sample 410
/// (4100, clamped), on line 412 (after the header), at 2 + 410 / 3200 = 2.128125 s; negated
/// (Klipper's `axes_map` `-x`) it reaches -4096 there.
#[test]
fn a_clipped_klipper_recording_names_its_first_clipped_sample() {
    let ramp = |i: usize| (10.0 * i as f64).min(4095.0);
    let rows = samples(500, ramp);
    let e = klipper_raw::parse("r.csv", &raw_text(&rows)).expect_err("clipped");
    let (line, found, expected) = format_error(&e);
    assert_eq!(line, 412, "{e}");
    assert!(
        found.starts_with(
            "`accel_x` reads 151557.166624 mm/s^2 (15.4545 g) at 2.128125 s, the full scale of an ADXL345's x or y axis"
        ) && found.ends_with("the sensor clipped (90 samples, the first here)"),
        "{found}"
    );
    assert!(
        expected.contains("harmonics that are not modes"),
        "{expected}"
    );
    let negated = samples(500, |i| -(10.0 * i as f64).min(4096.0));
    let e = klipper_raw::parse("r.csv", &raw_text(&negated)).expect_err("clipped");
    assert_eq!(format_error(&e).0, 412, "{e}");
    assert!(e.to_string().contains("reads -151594.176922 mm/s^2"), "{e}");
    // One sample at the full scale is refused too (the sensor did not measure it).
    let one = samples(500, |i| if i == 77 { 4095.0 } else { (i % 5) as f64 });
    let e = klipper_raw::parse("r.csv", &raw_text(&one)).expect_err("clipped");
    assert_eq!(format_error(&e).0, 79, "{e}");
    assert!(e.to_string().contains("(1 sample, this one)"), "{e}");
    // Shake&Tune: the line of the measurement, the sample by its index.
    let e = stdata::parse("s.stdata", &stdata_bytes(&rows)).expect_err("clipped");
    let (line, found, _) = format_error(&e);
    assert_eq!(line, 1, "{e}");
    assert!(
        found.starts_with("`samples[410] x` reads 151557.166624 mm/s^2 (15.4545 g) at 2.128125 s"),
        "{found}"
    );
}

/// Values at an ADXL345's full scale on an axis that also passes it were read at another
/// range (the corpus's LIS2DW recordings are written at the ADXL345's scale and reach 15,072
/// counts): read. So are values one count short of it.
#[test]
fn an_axis_past_the_full_scale_or_short_of_it_is_read() {
    let past = samples(500, |i| match i {
        100 => 4095.0,
        200 => 15_072.0,
        _ => (i % 5) as f64,
    });
    let rec = klipper_raw::parse("r.csv", &raw_text(&past)).expect("read at another range");
    assert_eq!(rec.len(), 500);
    let short = samples(500, |i| if i == 100 { 4094.0 } else { (i % 5) as f64 });
    klipper_raw::parse("r.csv", &raw_text(&short)).expect("4094 counts is a measurement");
    stdata::parse("s.stdata", &stdata_bytes(&past)).expect("read at another range");
}

/// An ICM-20948 as Klipper reads it: 32767 counts of 9806.65 / 2048 mm/s^2 =
/// 156901.611597 mm/s^2 (15.9995 g) on z from sample 6 (line 8, 2 + 6 / 3200 = 2.001875 s).
#[test]
fn an_icm20948_at_its_full_scale_is_refused() {
    let count = 9806.65 / 2048.0;
    let mut rows = samples(200, |i| (i % 4) as f64);
    for r in rows.iter_mut().skip(6).take(3) {
        r[3] = 32767.0 * count;
    }
    let e = klipper_raw::parse("i.csv", &raw_text(&rows)).expect_err("clipped");
    let (line, found, _) = format_error(&e);
    assert_eq!(line, 8, "{e}");
    assert!(
        found.starts_with("`accel_z` reads 156901.611597 mm/s^2 (15.9995 g) at 2.001875 s")
            && found.contains("an ICM-20948 or BMI160")
            && found.ends_with("(3 samples, the first here)"),
        "{found}"
    );
}

/// M956 with 4 decimals (an LIS2DW's 14 bits): -2.0000 g is the most negative count,
/// 1.9998 the largest positive one (8191 / 4096 = 1.99976); 1.9995 (8190 counts) is a
/// measurement. The value on line 40 is sample 38, at 38 / 1600 = 0.023750 s.
#[test]
fn a_clipped_m956_capture_names_its_line() {
    // X and Y with `decimals` decimals, Y holding `value` at sample 38.
    let capture = |decimals: usize, value: &str| {
        let mut s = String::from("Sample,X,Y\n");
        for i in 0..100 {
            let x = format!("{:.*}", decimals, 0.02 + (i % 10) as f64 * 0.01);
            let y = if i == 38 {
                value.to_string()
            } else {
                format!("{:.*}", decimals, (i % 7) as f64 * 0.01)
            };
            s.push_str(&format!("{i},{x},{y}\n"));
        }
        s.push_str("Rate 1600, overflows 0\n");
        s
    };
    for value in ["-2.0000", "1.9998", "1.9999"] {
        let e = rrf::parse("m.csv", &capture(4, value)).expect_err("clipped");
        let (line, found, _) = format_error(&e);
        assert_eq!(line, 40, "{e}");
        assert!(
            found.starts_with(&format!("`Y` reads {:.6} mm/s^2", value.parse::<f64>().expect("g") * 9806.65))
                && found.contains("at 0.023750 s")
                && found.contains("RepRapFirmware's accelerometers (+-2 g; 4 decimals: counts of 1/4096 g or finer)"),
            "{found}"
        );
    }
    rrf::parse("m.csv", &capture(4, "1.9995")).expect("8190 counts is a measurement");
    // 2 decimals (8 bits, counts of 1/64 g): 1.98 is the largest count (127 / 64 =
    // 1.984), 1.97 one below it (126 / 64 = 1.969).
    rrf::parse("m.csv", &capture(2, "1.97")).expect("126 counts of 1/64 g is a measurement");
    let e = rrf::parse("m.csv", &capture(2, "1.98")).expect_err("clipped");
    assert_eq!(format_error(&e).0, 40, "{e}");
}
