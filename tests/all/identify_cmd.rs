//! `settle identify`: a synthetic Klipper raw recording made from known modes
//! (`support::resonance`, the exact free response of each mode under Klipper's resonance
//! test, with ADXL345 noise and quantisation) is identified, the machine file it writes
//! holds exactly the identified modes, and a sweep runs on it; a bad file is an input error
//! naming the file and line (exit 2).

use std::path::{Path, PathBuf};

use settle::input::machine_file::parse_any;
use settle::input::machine_form::MachineForm;
use settle::spec::backend::Backend;
use settle::workflows::identify::{IdentifyOptions, identify};

use crate::support::{resonance, settle, write};

/// The short test of the book's example (30-70 Hz at 10 Hz/s).
fn short_test() -> settle_identify::SweepTest {
    settle_identify::SweepTest {
        freq_start_hz: 30.0,
        freq_end_hz: 70.0,
        hz_per_sec: 10.0,
        ..settle_identify::SweepTest::klipper()
    }
}

/// [`short_test`] on the command line.
const SHORT_TEST: [&str; 6] = [
    "--freq-start",
    "30",
    "--freq-end",
    "70",
    "--hz-per-sec",
    "10",
];

const TRUTH: (f64, f64, f64) = (47.0, 0.06, 1.0);

#[test]
fn identified_modes_go_into_a_machine_file_that_a_sweep_takes() {
    let dir = tempfile::tempdir().expect("tempdir");
    let test = short_test();
    let text = resonance::recording(&[TRUTH], &test, 1, 1600.0, 0.25, 7);
    let file = write(dir.path(), "raw_data_y_20260101.csv", &text);
    let out = dir.path().join("machine.toml");
    let mut opts = IdentifyOptions::new(vec![file]);
    opts.out = Some(out.clone());
    opts.identify.test = test;
    let got = identify(&opts).expect("identifies");
    assert_eq!(got.axes.len(), 1);
    assert_eq!(got.axes[0].axis, "y");
    let modes = &got.axes[0].id.modes;
    assert_eq!(modes.len(), 1, "{modes:?}");
    let (f, z) = (modes[0].frequency_hz, modes[0].damping_ratio);
    assert!((f.value - TRUTH.0).abs() < 0.005 * TRUTH.0, "{f:?}");
    assert!((z.value - TRUTH.1).abs() < 0.15 * TRUTH.1, "{z:?}");
    // The machine file holds the identified modes, bit for bit.
    let written = std::fs::read_to_string(&out).expect("machine file");
    let d = parse_any(&written, &out).expect("parses");
    let MachineForm::Modes(axes) = d.form else {
        panic!("modes form expected: {written}");
    };
    assert_eq!(axes, got.modes);
    assert_eq!(axes[0].modes[0].frequency_hz, f.value);
    assert_eq!(axes[0].modes[0].damping_ratio, z.value);
    // With the standard deviations, which `settle tune` takes as the frequency's band.
    assert_eq!(axes[0].modes[0].frequency_sigma_hz, Some(f.sigma));
    assert_eq!(axes[0].modes[0].damping_ratio_sigma, Some(z.sigma));
    assert!(written.contains("frequency_sigma_hz = "), "{written}");
    for fig in &got.figures {
        assert!(
            fig.exists() && fig.with_extension("png").exists(),
            "{fig:?}"
        );
    }
    // A sweep on it: the Y move rings at the identified mode.
    let scenario = write(
        dir.path(),
        "s.toml",
        "name = \"s\"\n[machine]\npreset = \"machine.toml\"\n[move]\ndistance_mm = 5.0\naxis = \"y\"\nprofile = \"trapezoid\"\n[limits]\nvmax_mm_s = 100.0\namax_mm_s2 = 2000.0\n[sweep]\n\"limits.amax_mm_s2\" = [1000.0, 2000.0]\n",
    );
    let (_, mut runs) = settle::load_runs(&scenario).expect("expands");
    assert_eq!(runs[0].machine.modes(), got.modes);
    settle::execute::set_backend(&scenario, &mut runs, Backend::Modal).expect("modal");
    for r in &runs {
        let m = settle::execute::execute(r, None).expect("runs");
        assert!(m.is_ok() && m.residual_peak_um > 0.0, "{m:?}");
    }
}

fn run(args: &[&str]) -> (Option<i32>, String, String) {
    let out = settle().args(args).output().expect("runs");
    (
        out.status.code(),
        String::from_utf8(out.stdout).expect("utf-8"),
        String::from_utf8(out.stderr).expect("utf-8"),
    )
}

fn path_str(p: &Path) -> &str {
    p.to_str().expect("utf-8")
}

#[test]
fn bad_files_and_options_exit_2_naming_the_file_and_line() {
    let dir = tempfile::tempdir().expect("tempdir");
    let bad = write(
        dir.path(),
        "raw_data_x_bad.csv",
        "#time,accel_x,accel_y,accel_z\n0.0,1.0,2.0,3.0\n0.001,1.0,2.0\n",
    );
    let (code, _, err) = run(&["identify", path_str(&bad)]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("raw_data_x_bad.csv:3"), "{err}");
    let header = write(dir.path(), "x.csv", "time,x,y,z\n0,1,2,3\n");
    let (code, _, err) = run(&["identify", path_str(&header)]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("x.csv:1"), "{err}");
    let unnamed: PathBuf = write(
        dir.path(),
        "recording.csv",
        &resonance::recording(&[TRUTH], &short_test(), 0, 800.0, 0.1, 3),
    );
    let (code, _, err) = run(&[&["identify", path_str(&unnamed)][..], &SHORT_TEST].concat());
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("--axis"), "{err}");
    let (code, _, err) = run(&["identify", path_str(&unnamed), "--axis", "w"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("allowed: x, y, z"), "{err}");
    // A processed spectrum (Klipper's calibrate_shaper CSV) whose last frequency is 1e308
    // Hz: out of bounds at its line, not a puzzle about bin widths.
    let mut spectrum = String::from("freq,psd_x,psd_y,psd_z,psd_xyz\n");
    for k in 0..40 {
        spectrum.push_str(&format!("{:.1},1,1,1,3\n", f64::from(k) * 1.6));
    }
    spectrum.push_str("1e308,1,1,1,3\n");
    let far = write(dir.path(), "resonances_x_far.csv", &spectrum);
    let (code, _, err) = run(&["identify", path_str(&far)]);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("resonances_x_far.csv:42: frequency 1e308 Hz in column `freq`; expected a frequency from 0 to 50000 Hz"),
        "{err}"
    );
}

/// What a new user runs first, and what the firmwares write that cannot be trusted: each
/// is exit 2 with the reason, never a number.
#[test]
fn missing_test_parameters_and_unusable_files_exit_2_with_the_reason() {
    let dir = tempfile::tempdir().expect("tempdir");
    // A resonance test of 30-70 Hz at 10 Hz/s (4 s) identified without its parameters:
    // Klipper's default test lasts 130 s, and the file does not say which test it holds.
    let short = write(
        dir.path(),
        "raw_data_x_short.csv",
        &resonance::recording(&[TRUTH], &short_test(), 0, 800.0, 0.1, 3),
    );
    let (code, out, err) = run(&["identify", path_str(&short)]);
    assert_eq!(code, Some(2), "{out}{err}");
    for want in [
        "raw_data_x_short.csv",
        "--freq-start",
        "--hz-per-sec",
        "lasts",
    ] {
        assert!(err.contains(want), "missing `{want}` in {err}");
    }
    // Time stamps in milliseconds: a sample rate of 1 Hz, refused at the last line.
    let mut ms = String::from("#time,accel_x,accel_y,accel_z\n");
    for i in 0..200 {
        ms.push_str(&format!("{}.000000,1.0,2.0,9806.65\n", 1000 + i));
    }
    let ms = write(dir.path(), "raw_data_x_ms.csv", &ms);
    let (code, _, err) = run(&["identify", path_str(&ms)]);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("raw_data_x_ms.csv:201") && err.contains("seconds"),
        "{err}"
    );
    // A gap in the time column, refused at the sample after it.
    let mut gap = String::from("#time,accel_x,accel_y,accel_z\n");
    for i in 0..200 {
        let t = i as f64 / 1000.0 + if i >= 100 { 5.0 } else { 0.0 };
        gap.push_str(&format!("{t:.6},1.0,2.0,9806.65\n"));
    }
    let gap = write(dir.path(), "raw_data_x_gap.csv", &gap);
    let (code, _, err) = run(&["identify", path_str(&gap)]);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("raw_data_x_gap.csv:102") && err.contains("gap"),
        "{err}"
    );
    // RepRapFirmware's rate line out of any accelerometer's range.
    let mut rrf = String::from("Sample,Y\n");
    for i in 0..200 {
        rrf.push_str(&format!("{i},0.01\n"));
    }
    let huge = write(dir.path(), "m956.csv", &(rrf + "Rate 1e300, overflows 0\n"));
    let (code, _, err) = run(&["identify", path_str(&huge)]);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("m956.csv:202") && err.contains("Rate"),
        "{err}"
    );
}

/// An M956 capture of one axis (`Sample,Y`, RepRapFirmware names files by date) is that
/// machine axis without `--axis`: a free decay of 80 Hz, zeta 0.03 at 1,400 Hz.
#[test]
fn a_single_axis_m956_capture_names_its_axis() {
    let dir = tempfile::tempdir().expect("tempdir");
    let (fs, f, zeta) = (1400.0, 80.0, 0.03);
    let w = std::f64::consts::TAU * f;
    let wd = w * (1.0f64 - zeta * zeta).sqrt();
    let mut text = String::from("Sample,Y\n");
    for i in 0..1000 {
        let t = i as f64 / fs;
        let g = 0.5 * (-zeta * w * t).exp() * (wd * t).cos();
        text.push_str(&format!("{i},{g:.4}\n"));
    }
    text.push_str("Rate 1400, overflows 0\n");
    let file = write(dir.path(), "20240714_111434.csv", &text);
    let (code, out, err) = run(&[
        "identify",
        path_str(&file),
        "--figures",
        path_str(dir.path()),
    ]);
    assert_eq!(code, Some(0), "{out}{err}");
    let row = out.lines().nth(1).expect("a mode row");
    assert!(row.starts_with("y "), "{out}");
    // The command above wrote its figures there: --force replaces them.
    let got = identify(&IdentifyOptions {
        figures: Some(dir.path().to_path_buf()),
        force: true,
        ..IdentifyOptions::new(vec![file])
    })
    .expect("identifies");
    let m = &got.axes[0].id.modes[0];
    assert!((m.frequency_hz.value - f).abs() < 0.002 * f, "{m:?}");
    assert!((m.damping_ratio.value - zeta).abs() < 0.05 * zeta, "{m:?}");
}

/// `text` (a Klipper raw recording) with every acceleration times `k`.
fn scaled(text: &str, k: f64) -> String {
    let mut out = String::new();
    for l in text.lines() {
        if l.starts_with('#') {
            out.push_str(l);
        } else {
            let mut fields = l.split(',');
            out.push_str(fields.next().expect("time"));
            for v in fields {
                let v: f64 = v.parse().expect("number");
                out.push_str(&format!(",{:e}", v * k));
            }
        }
        out.push('\n');
    }
    out
}

/// Recordings no accelerometer writes are refused saying what is wrong with them, not
/// with what the analysis then met (a NaN noise floor, no frequency bins in the band): an
/// acceleration so large it is a unit mistake (and whose squares overflow) names its line
/// and column; a recording or spectrum without vibration says so.
#[test]
fn absurd_recordings_say_what_is_wrong_with_them() {
    let dir = tempfile::tempdir().expect("tempdir");
    let text = resonance::recording(&[TRUTH], &short_test(), 0, 800.0, 0.1, 3);
    let band = SHORT_TEST;
    let figures = dir.path().join("figures");
    let ident = |file: &Path| {
        let mut args = vec!["identify", path_str(file), "--figures", path_str(&figures)];
        args.extend(band);
        run(&args)
    };
    for (name, k) in [
        ("raw_data_x_e160.csv", 1e160),
        ("raw_data_x_e150.csv", 1e150),
    ] {
        let file = write(dir.path(), name, &scaled(&text, k));
        let (code, out, err) = ident(&file);
        assert_eq!(code, Some(2), "{out}{err}");
        assert!(
            err.contains(&format!("{name}:2: ")) && err.contains("column `accel_x`"),
            "{err}"
        );
        assert!(err.contains("within +-1e9 mm/s^2"), "{err}");
        assert!(!err.contains("NaN") && !err.contains("bins"), "{err}");
    }
    let mut constant = String::from("#time,accel_x,accel_y,accel_z\n");
    for l in text.lines().skip(1) {
        let t = l.split(',').next().expect("time");
        constant.push_str(&format!("{t},1.0,2.0,9806.65\n"));
    }
    for (name, text) in [
        ("raw_data_x_constant.csv", constant),
        ("raw_data_x_tiny.csv", scaled(&text, 1e-150)),
    ] {
        let file = write(dir.path(), name, &text);
        let (code, out, err) = ident(&file);
        assert_eq!(code, Some(2), "{out}{err}");
        assert!(
            err.contains(&format!("{name}: no vibration to identify")),
            "{err}"
        );
        assert!(!err.contains("NaN") && !err.contains("bins"), "{err}");
    }
    // A processed spectrum of zeros, and one past any accelerometer's PSD.
    let mut zeros = String::from("freq,psd_x,psd_y,psd_z,psd_xyz\n");
    let mut huge = zeros.clone();
    for i in 0..140 {
        let f = i as f64 * 1.5625;
        zeros.push_str(&format!("{f:.1},0.000e+00,0.000e+00,0.000e+00,0.000e+00\n"));
        huge.push_str(&format!(
            "{f:.1},1.000e+200,1.000e+200,1.000e+200,3.000e+200\n"
        ));
    }
    let file = write(dir.path(), "resonances_x_zeros.csv", &zeros);
    let (code, out, err) = ident(&file);
    assert_eq!(code, Some(2), "{out}{err}");
    assert!(
        err.contains("resonances_x_zeros.csv: no vibration to identify")
            && err.contains("`psd_xyz`"),
        "{err}"
    );
    let file = write(dir.path(), "resonances_x_huge.csv", &huge);
    let (code, out, err) = ident(&file);
    assert_eq!(code, Some(2), "{out}{err}");
    assert!(
        err.contains("resonances_x_huge.csv:2: ") && err.contains("`psd_x`"),
        "{err}"
    );
    assert!(!figures.exists(), "no figure of a refused file");
}

/// A test that sweeps past 0.45 x the sample rate (the top of the band analysed) but
/// within the aliasing limit: the output says which band was analysed and that a mode above
/// it is not seen, instead of leaving the modes found to stand for the whole test.
#[test]
fn a_test_past_the_band_analysed_is_noted() {
    let dir = tempfile::tempdir().expect("tempdir");
    // 30-70 Hz at 140 Hz: analysed up to 63 Hz; 70 Hz is below 0.55 x 140 = 77 Hz.
    let text = resonance::recording(&[TRUTH], &short_test(), 0, 140.0, 0.25, 5);
    let file = write(dir.path(), "raw_data_x_140hz.csv", &text);
    let figures = dir.path().join("figures");
    let args = ["identify", path_str(&file), "--figures", path_str(&figures)];
    let (code, out, err) = run(&[&args[..], &SHORT_TEST, &["--max-modes", "1"]].concat());
    assert_eq!(code, Some(0), "{out}{err}");
    let note = out
        .lines()
        .find(|l| l.starts_with("x    note: "))
        .unwrap_or_else(|| panic!("no note in {out}"));
    for want in [
        "analysed 33.9 to 62.3 Hz of a test that swept up to 70 Hz",
        "63.0 Hz, 0.45 x the sample rate of 140.0 Hz",
        "between 62.3 and 70 Hz is not seen",
    ] {
        assert!(note.contains(want), "missing `{want}` in {note}");
    }
    // The full-rate recording of the same test has no such note.
    let text = resonance::recording(&[TRUTH], &short_test(), 0, 800.0, 0.25, 5);
    let file = write(dir.path(), "raw_data_x_800hz.csv", &text);
    let args = [
        "identify",
        path_str(&file),
        "--figures",
        path_str(&figures),
        "--force",
    ];
    let (code, out, err) = run(&[&args[..], &SHORT_TEST].concat());
    assert_eq!(code, Some(0), "{out}{err}");
    assert!(!out.contains("note:"), "{out}");
}
