//! `settle identify` on recordings a sensor could not measure faithfully: the example
//! recording (`examples/data/raw_data_x_example.csv`, quantised at an ADXL345's x/y count
//! as Klipper scales it, `SCALE_XY` = 0.003774 g in `klippy/extras/adxl345.py`) made ten
//! times stronger and clipped at the ADXL345's 13-bit counts (-4096 to 4095), as the chip
//! saturates; the same recording with one axis zeroed or divided far below any sensor's
//! count. Each is refused (exit 2) with the file, line, axis and what was seen, and nothing
//! is written; the recording as it is still gives its modes.

use std::path::Path;

use crate::support::{EXAMPLE_TEST as TEST, root, settle, write};

/// One ADXL345 x/y count in mm/s^2 as Klipper scales it: 0.003774 g x 9806.65 mm/s^2/g.
const COUNT_MM_S2: f64 = 0.003774 * 9806.65;

fn identify(file: &Path, figures: &Path) -> (Option<i32>, String, String) {
    let out = settle()
        .arg("identify")
        .arg(file)
        .args(TEST)
        .arg("--figures")
        .arg(figures)
        .output()
        .expect("runs");
    (
        out.status.code(),
        String::from_utf8(out.stdout).expect("utf-8"),
        String::from_utf8(out.stderr).expect("utf-8"),
    )
}

fn example() -> String {
    std::fs::read_to_string(root().join("examples/data/raw_data_x_example.csv")).expect("reads")
}

/// The example with every value `k` times larger in counts, clamped to the ADXL345's
/// -4096 to 4095 when `clamp`, written as Klipper writes (`%.6f`), and the first sample at
/// the full scale (4095 or -4096 counts): its line, its time text, its column and the value
/// it holds.
fn scaled(k: f64, clamp: bool) -> (String, Option<(usize, String, &'static str, String)>) {
    let columns = ["accel_x", "accel_y", "accel_z"];
    let mut out = String::new();
    let mut first = None;
    for (i, l) in example().lines().enumerate() {
        if l.starts_with('#') {
            out.push_str(l);
            out.push('\n');
            continue;
        }
        let f: Vec<&str> = l.split(',').collect();
        out.push_str(f[0]);
        for (c, v) in f[1..].iter().enumerate() {
            let mut counts = (v.parse::<f64>().expect("number") / COUNT_MM_S2 * k).round();
            if clamp {
                counts = counts.clamp(-4096.0, 4095.0);
            }
            let text = format!("{:.6}", counts * COUNT_MM_S2);
            if (counts == 4095.0 || counts == -4096.0) && first.is_none() {
                first = Some((i + 1, f[0].to_string(), columns[c], text.clone()));
            }
            out.push(',');
            out.push_str(&text);
        }
        out.push('\n');
    }
    (out, first)
}

#[test]
fn a_clipped_recording_is_refused_naming_its_first_clipped_sample() {
    let dir = tempfile::tempdir().expect("tempdir");
    // The example as it is gives its two modes (45 and 75 Hz,
    // `docs/guide/your-machine.md`), and so does the example ten times stronger unclipped:
    // its x axis passes the ADXL345's full scale (it was read at another range), so its
    // samples near that full scale are measurements.
    let (code, out, err) = identify(
        &root().join("examples/data/raw_data_x_example.csv"),
        &dir.path().join("f0"),
    );
    assert_eq!(code, Some(0), "{out}{err}");
    assert!(
        out.contains("45.0016 ± 0.0019") && out.contains("75.014 ± 0.011"),
        "{out}"
    );
    let (strong, _) = scaled(10.0, false);
    let strong = write(dir.path(), "raw_data_x_strong.csv", &strong);
    let (code, out, err) = identify(&strong, &dir.path().join("f1"));
    assert_eq!(code, Some(0), "{out}{err}");
    assert!(out.contains(" 45.00") && out.contains(" 75.0"), "{out}");

    let (text, first) = scaled(10.0, true);
    let (line, time, column, value) = first.expect("ten times the example passes 16 g");
    // 4095 or -4096 counts of 37.0102971 mm/s^2: 151557.166624 or -151594.176922.
    assert!(
        ["151557.166624", "-151594.176922"].contains(&value.as_str()),
        "{value}"
    );
    let name = "raw_data_x_clipped.csv";
    let file = write(dir.path(), name, &text);
    let figures = dir.path().join("figures");
    let (code, out, err) = identify(&file, &figures);
    assert_eq!(code, Some(2), "{out}{err}");
    assert!(out.is_empty(), "{out}");
    assert!(
        err.contains(&format!("{name}:{line}: `{column}` reads {value} mm/s^2"))
            && err.contains(&format!("at {time} s"))
            && err.contains("the full scale of an ADXL345's x or y axis")
            && err.contains("the sensor clipped")
            && err.contains("accel_per_hz"),
        "{err}"
    );
    assert!(!figures.exists(), "nothing is written");
    // Klipper's own `calibrate_shaper.py` would tune it: `settle tune` refuses it too.
    let out = settle()
        .arg("tune")
        .arg("--criterion")
        .arg("klipper")
        .arg(&file)
        .arg("--out")
        .arg(dir.path().join("tune"))
        .output()
        .expect("runs");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains(&format!("{name}:{line}: `{column}`")), "{err}");
}

/// A hand-made recording: a 50 Hz sine of 5,000 counts on x at 3,200 samples per second
/// clipped at 4095 counts. `5000 sin(2 pi 50 i / 3200)` is 3865.05 at sample 9 and 4157.35
/// at sample 10: the first clipped sample is sample 10, on line 12 (after the header), at
/// 1 + 10 / 3200 = 1.003125 s, and it reads 4095 x 37.0102971 = 151557.166624 mm/s^2.
#[test]
fn a_hand_made_clipped_sine_names_line_12() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mut text = String::from("#time,accel_x,accel_y,accel_z\n");
    for i in 0..3200_u32 {
        let x = (5000.0 * (std::f64::consts::TAU * 50.0 * i as f64 / 3200.0).sin()).round();
        let x = x.clamp(-4096.0, 4095.0) * COUNT_MM_S2;
        let y = f64::from(i % 3) * COUNT_MM_S2;
        let z = (265.0 + f64::from(i % 2)) * COUNT_MM_S2;
        text.push_str(&format!(
            "{:.6},{x:.6},{y:.6},{z:.6}\n",
            1.0 + f64::from(i) / 3200.0
        ));
    }
    let file = write(dir.path(), "adxl345-sine.csv", &text);
    let (code, out, err) = identify(&file, &dir.path().join("f"));
    assert_eq!(code, Some(2), "{out}{err}");
    assert!(
        err.contains(
            "adxl345-sine.csv:12: `accel_x` reads 151557.166624 mm/s^2 (15.4545 g) at 1.003125 s"
        ),
        "{err}"
    );
    // Every sample at 4095 or -4096 counts is at the full scale: counted in the text.
    let at_full_scale = text
        .lines()
        .skip(1)
        .filter(|l| {
            let x = l.split(',').nth(1).expect("x");
            x == "151557.166624" || x == "-151594.176922"
        })
        .count();
    assert!(
        err.contains(&format!("({at_full_scale} samples, the first here)")),
        "{err}"
    );
}

/// A recording without a measured vibration: the example divided by 100,000 (its largest
/// deviation, 23,946 mm/s^2, becomes 0.24, a tenth of an MPU-9250's count of 1/4096 g =
/// 2.394 mm/s^2, the finest Klipper reads) gave the example's modes to four digits; an
/// axis zeroed (a sensor axis that does not measure) gave modes from the other two.
#[test]
fn no_measured_vibration_and_a_dead_axis_are_refused() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mut tiny = String::new();
    let mut dead = String::new();
    for l in example().lines() {
        if l.starts_with('#') {
            tiny.push_str(&format!("{l}\n"));
            dead.push_str(&format!("{l}\n"));
            continue;
        }
        let f: Vec<&str> = l.split(',').collect();
        let v: Vec<f64> = f[1..].iter().map(|v| v.parse().expect("number")).collect();
        tiny.push_str(&format!(
            "{},{:.6},{:.6},{:.6}\n",
            f[0],
            v[0] * 1e-5,
            v[1] * 1e-5,
            v[2] * 1e-5
        ));
        dead.push_str(&format!("{},0.000000,{},{}\n", f[0], f[2], f[3]));
    }
    let file = write(dir.path(), "raw_data_x_tiny.csv", &tiny);
    let (code, out, err) = identify(&file, &dir.path().join("f0"));
    assert_eq!(code, Some(2), "{out}{err}");
    assert!(
        err.contains("raw_data_x_tiny.csv: no vibration to identify")
            && err.contains("varies by at least 2.394 mm/s^2")
            && err.contains("MPU-9250's 1/4096 g"),
        "{err}"
    );
    let file = write(dir.path(), "raw_data_x_dead.csv", &dead);
    let (code, out, err) = identify(&file, &dir.path().join("f1"));
    assert_eq!(code, Some(2), "{out}{err}");
    let samples = example().lines().filter(|l| !l.starts_with('#')).count();
    assert!(
        err.contains(&format!(
            "raw_data_x_dead.csv: a sensor axis that does not measure: sensor axis x reads 0 mm/s^2 in all {samples} samples"
        )),
        "{err}"
    );
}

/// A time column not in seconds: the example's times in milliseconds (its 5,200 samples
/// over 6.49875 s are 5,199 / 6.49875 = 800 samples per second), and sample numbers.
/// Both were refused with the rate they give; the message now says what the times read as.
#[test]
fn a_time_column_not_in_seconds_says_what_it_reads_as() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mut ms = String::new();
    let mut numbers = String::new();
    let mut i = 0;
    for l in example().lines() {
        if l.starts_with('#') {
            ms.push_str(&format!("{l}\n"));
            numbers.push_str(&format!("{l}\n"));
            continue;
        }
        let (t, rest) = l.split_once(',').expect("fields");
        let t: f64 = t.parse().expect("time");
        ms.push_str(&format!("{:.6},{rest}\n", t * 1000.0));
        numbers.push_str(&format!("{i},{rest}\n"));
        i += 1;
    }
    let last = i + 1;
    let file = write(dir.path(), "raw_data_x_ms.csv", &ms);
    let (code, out, err) = identify(&file, &dir.path().join("f0"));
    assert_eq!(code, Some(2), "{out}{err}");
    assert!(
        err.contains(&format!(
            "raw_data_x_ms.csv:{last}: time stamps 0.000000 to 6498.750000 for {i} samples, a sample rate of 0.8000 Hz (read as milliseconds, the times give 800.0 Hz); expected times in seconds"
        )),
        "{err}"
    );
    let file = write(dir.path(), "raw_data_x_numbers.csv", &numbers);
    let (code, out, err) = identify(&file, &dir.path().join("f1"));
    assert_eq!(code, Some(2), "{out}{err}");
    assert!(
        err.contains("a sample rate of 1.0000 Hz (the times count one a sample: sample numbers, or milliseconds at 1000.0 Hz); expected times in seconds"),
        "{err}"
    );
}
