//! `settle tune --criterion klipper` on the corpus of real files
//! (`identify/tests/corpus/MANIFEST.md`): every line equal to what Klipper's
//! `scripts/calibrate_shaper.py` printed for the same file
//! (`identify/tests/corpus/klipper_calibrate_shaper.txt`, Klipper 84104bbbd762), and
//! `--out` writing the `[input_shaper]` lines of the recommendation per axis.

use std::path::PathBuf;

use settle::workflows::tune::klipper_criterion::{KlipperCriterion, report};

fn corpus_dir() -> PathBuf {
    crate::support::root().join("identify/tests/corpus")
}

/// The script's output per file: `(file, lines after "Processing resonances from ...")`.
fn script_output() -> Vec<(String, Vec<String>)> {
    let text = std::fs::read_to_string(corpus_dir().join("klipper_calibrate_shaper.txt"))
        .expect("reads the recorded output");
    let mut out: Vec<(String, Vec<String>)> = Vec::new();
    for line in text.lines() {
        if let Some(file) = line.strip_prefix("$ calibrate_shaper.py ") {
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
    assert_eq!(expected.len(), 16);
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
