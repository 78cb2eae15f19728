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
    let (code, _, err) = run(&[
        "identify",
        path_str(&unnamed),
        "--freq-start",
        "30",
        "--freq-end",
        "70",
        "--hz-per-sec",
        "10",
    ]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("--axis"), "{err}");
    let (code, _, err) = run(&["identify", path_str(&unnamed), "--axis", "w"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("allowed: x, y, z"), "{err}");
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
