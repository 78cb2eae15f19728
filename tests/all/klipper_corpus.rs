//! `settle tune --criterion klipper` on the corpus of real files
//! (`identify/tests/corpus/MANIFEST.md`): every line equal to what Klipper's
//! `scripts/calibrate_shaper.py` printed for the same file
//! (`identify/tests/corpus/klipper_calibrate_shaper.txt`, Klipper 84104bbbd762; for a
//! Shake&Tune `.stdata` recording, on its samples written as a Klipper raw CSV; for a
//! `SHAPER_CALIBRATE` file, on its PSD as written, which the script of today would
//! normalise a second time), and `--out` writing the `[input_shaper]` lines of the
//! recommendation per axis.

use std::path::PathBuf;

use settle::workflows::tune::klipper_criterion::{KlipperCriterion, report};

fn corpus_dir() -> PathBuf {
    crate::support::root().join("identify/tests/corpus")
}

/// The script's output per file: `(file, lines after "Processing resonances from ...")`.
/// The file is the first word after the command; what follows it says how the script was
/// run when not as it is.
fn script_output() -> Vec<(String, Vec<String>)> {
    let text = std::fs::read_to_string(corpus_dir().join("klipper_calibrate_shaper.txt"))
        .expect("reads the recorded output");
    let mut out: Vec<(String, Vec<String>)> = Vec::new();
    for line in text.lines() {
        if let Some(rest) = line.strip_prefix("$ calibrate_shaper.py ") {
            let file = rest.split_whitespace().next().expect("a file name");
            out.push((file.to_string(), Vec::new()));
        } else if !line.starts_with("Processing resonances from")
            && let Some(last) = out.last_mut()
        {
            last.1.push(line.to_string());
        }
    }
    out
}

#[test]
fn klipper_criterion_equals_calibrate_shaper_on_the_corpus() {
    let expected = script_output();
    // 22 processed spectra, 4 `SHAPER_CALIBRATE` files, 4 Klipper raw recordings and 2
    // Shake&Tune `.stdata`.
    assert_eq!(expected.len(), 32);
    for (file, want) in expected {
        let c = KlipperCriterion::from_args(vec![corpus_dir().join(&file)], None, None, None, None)
            .expect("options");
        let r = report(&c).expect("chooses");
        let got: Vec<&str> = r.stdout.lines().skip(1).collect();
        assert_eq!(got, want, "{file}");
    }
}

#[test]
fn klipper_criterion_writes_input_shaper_lines_per_axis() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("shaper");
    let files = vec![
        corpus_dir().join("voronpi_resonances_x_20221029_162131.csv"),
        corpus_dir().join("voronpi_resonances_y_20221029_162350.csv"),
    ];
    let r = crate::support::settle()
        .args(["tune", "--criterion", "klipper"])
        .args(&files)
        .arg("--out")
        .arg(&out)
        .output()
        .expect("runs");
    assert!(r.status.success(), "{r:?}");
    let stdout = String::from_utf8_lossy(&r.stdout);
    // calibrate_shaper.py on each file: mzv @ 69.2 Hz (X), mzv @ 46.8 Hz (Y).
    assert!(
        stdout.contains("Recommended shaper is mzv @ 69.2 Hz"),
        "{stdout}"
    );
    assert!(
        stdout.contains("Recommended shaper is mzv @ 46.8 Hz"),
        "{stdout}"
    );
    let cfg = std::fs::read_to_string(out.join("input_shaper.cfg")).expect("cfg written");
    for want in [
        "[input_shaper]",
        "shaper_type_x: mzv",
        "shaper_freq_x: 69.2",
        "shaper_type_y: mzv",
        "shaper_freq_y: 46.8",
    ] {
        assert!(cfg.lines().any(|l| l == want), "missing `{want}` in\n{cfg}");
    }
    for axis in ["x", "y"] {
        let svg = out.join(format!("klipper-shapers-{axis}.svg"));
        assert!(svg.is_file(), "{}", svg.display());
    }
}

/// A raw recording (`examples/data/raw_data_x_example.csv`): settle computes the PSD as
/// Klipper does, and every line equals what calibrate_shaper.py printed for the same file
/// (Klipper 84104bbbd762, numpy 2).
#[test]
fn klipper_criterion_on_a_raw_recording_equals_calibrate_shaper() {
    let want = [
        "Fitted shaper 'zv' frequency = 45.0 Hz (vibrations = 0.9%, smoothing ~= 0.081)",
        "To avoid too much smoothing with 'zv', suggested max_accel <= 7900 mm/sec^2",
        "Fitted shaper 'mzv' frequency = 46.6 Hz (vibrations = 0.0%, smoothing ~= 0.094)",
        "To avoid too much smoothing with 'mzv', suggested max_accel <= 6400 mm/sec^2",
        "Fitted shaper 'ei' frequency = 57.0 Hz (vibrations = 0.0%, smoothing ~= 0.101)",
        "To avoid too much smoothing with 'ei', suggested max_accel <= 5900 mm/sec^2",
        "Fitted shaper '2hump_ei' frequency = 73.4 Hz (vibrations = 0.0%, smoothing ~= 0.105)",
        "To avoid too much smoothing with '2hump_ei', suggested max_accel <= 5700 mm/sec^2",
        "Fitted shaper '3hump_ei' frequency = 92.0 Hz (vibrations = 0.0%, smoothing ~= 0.107)",
        "To avoid too much smoothing with '3hump_ei', suggested max_accel <= 5600 mm/sec^2",
        "Recommended shaper is mzv @ 46.6 Hz",
    ];
    let file = crate::support::root().join("examples/data/raw_data_x_example.csv");
    let c = KlipperCriterion::from_args(vec![file], None, None, None, None).expect("options");
    let r = report(&c).expect("chooses");
    let got: Vec<&str> = r.stdout.lines().skip(1).collect();
    assert_eq!(got, want);
}

/// The script's options: `--shapers` with a parameterised shaper, `--max-smoothing`
/// (calibrate_shaper.py `--shapers "mzv(n=4,t=0.8),ei" --max_smoothing 0.08` on the same
/// file printed these lines, Klipper 84104bbbd762), and values out of range refused
/// naming the option.
#[test]
fn klipper_criterion_takes_the_scripts_options() {
    let file = corpus_dir().join("voronpi_resonances_y_20221029_162350.csv");
    let c = KlipperCriterion::from_args(
        vec![file.clone()],
        None,
        Some("mzv(n=4,t=0.8),ei"),
        None,
        Some(0.08),
    )
    .expect("options");
    let r = report(&c).expect("chooses");
    let got: Vec<&str> = r.stdout.lines().skip(1).collect();
    assert_eq!(got, MAX_SMOOTHING_LINES);
    for (shapers, scv, smoothing, name) in [
        (Some("mzv,foo"), None, None, "--shapers"),
        (None, Some(0.0), None, "--scv"),
        (None, None, Some(0.01), "--max-smoothing"),
    ] {
        let e = KlipperCriterion::from_args(vec![file.clone()], None, shapers, scv, smoothing)
            .expect_err("refused");
        assert!(e.to_string().contains(name), "{e}");
    }
}

const MAX_SMOOTHING_LINES: [&str; 5] = [
    "Fitted shaper 'mzv(n=4,t=0.8)' frequency = 50.6 Hz (vibrations = 2.3%, smoothing ~= 0.079)",
    "To avoid too much smoothing with 'mzv(n=4,t=0.8)', suggested max_accel <= 7600 mm/sec^2",
    "Fitted shaper 'ei' frequency = 64.2 Hz (vibrations = 3.2%, smoothing ~= 0.080)",
    "To avoid too much smoothing with 'ei', suggested max_accel <= 7500 mm/sec^2",
    "Recommended shaper is mzv(n=4,t=0.8) @ 50.6 Hz",
];

/// `SHAPER_CALIBRATE` files of before October 2025 (shaper columns straight after
/// `psd_xyz`, no `shapers:` column) hold the PSD Klipper fitted, already normalised.
/// settle fits them as written: its `zv` and `mzv` lines equal, word for word, the lines
/// Klipper printed when it wrote each file, which the owner pasted into `v24/README.md`
/// of bassco/klipper-configs in the same commit (identify/tests/corpus/MANIFEST.md).
/// Normalised a second time, as today's calibrate_shaper.py does, the 2022 X file would
/// give `mzv` at 45.8 Hz and the Y file `zv` at 50.4 Hz and `mzv` at 35.0 Hz.
#[test]
fn klipper_criterion_fits_shaper_calibrate_files_as_written() {
    let published: [(&str, &[&str]); 3] = [
        (
            "bassco_calibration_data_x_20220611_200739.csv",
            &["Fitted shaper 'mzv' frequency = 48.4 Hz (vibrations = 1.3%, smoothing ~= 0.087)"],
        ),
        (
            "bassco_calibration_data_y_20220611_200739.csv",
            &[
                "Fitted shaper 'zv' frequency = 59.8 Hz (vibrations = 31.2%, smoothing ~= 0.050)",
                "Fitted shaper 'mzv' frequency = 37.2 Hz (vibrations = 5.8%, smoothing ~= 0.147)",
            ],
        ),
        (
            "bassco_calibration_data_y_20230306_225431.csv",
            &[
                "Fitted shaper 'zv' frequency = 44.0 Hz (vibrations = 2.3%, smoothing ~= 0.085)",
                "Fitted shaper 'mzv' frequency = 43.4 Hz (vibrations = 0.0%, smoothing ~= 0.108)",
            ],
        ),
    ];
    for (file, lines) in published {
        let c = KlipperCriterion::from_args(vec![corpus_dir().join(file)], None, None, None, None)
            .expect("options");
        let r = report(&c).expect("chooses");
        for want in lines {
            assert!(
                r.stdout.lines().any(|l| l == *want),
                "{file}: no `{want}` in\n{}",
                r.stdout
            );
        }
    }
}
