//! settle identify on the corpus of real files (`identify/tests/corpus/MANIFEST.md`): a
//! file either gives modes that include the main resonance of the spectrum its owner
//! published (the fitted model, seen as Klipper's graph shows a spectrum, `PSD / (f +
//! 0.1)`, peaks within 3 % or one frequency bin of it; every mode's own peak,
//! `IdentifiedMode::peak_hz`, within 10 % of some peak of the data; no mode outside the
//! band the data cover), or is refused with the reason that the fitted model does not
//! reproduce that peak. Which files are refused is
//! part of the expectation: a change that makes one of them fit, or one of the others
//! fail, shows here.

use std::path::PathBuf;

use settle_identify::{IdentifyError, Options, SpectrumColumn, SweepTest, identify_file};

/// `(file, main resonance, refused)`: the largest peak of `psd_xyz / (f + 0.1)` between 5
/// and 135 Hz (the manifest's table), and whether settle refuses the file (its best modal
/// model peaks elsewhere: one broad mode where the measured peak is sharp with shoulders).
const CORPUS: [(&str, f64, bool); 16] = [
    ("voronpi_resonances_x_20211217_070942.csv", 63.5, false),
    ("voronpi_resonances_x_20220213_155340.csv", 61.5, false),
    ("voronpi_resonances_x_20220430_191517.csv", 62.7, false),
    ("voronpi_resonances_x_20220919_172212.csv", 66.5, false),
    ("voronpi_resonances_x_20221029_162131.csv", 67.1, false),
    ("voronpi_resonances_x_20221127_190547.csv", 67.1, false),
    ("voronpi_resonances_x_20221231_212825.csv", 60.6, false),
    ("voronpi_resonances_y_20211217_071158.csv", 40.3, true),
    ("voronpi_resonances_y_20220213_155556.csv", 44.5, false),
    ("voronpi_resonances_y_20220430_191733.csv", 43.9, false),
    ("voronpi_resonances_y_20220919_172429.csv", 45.3, false),
    ("voronpi_resonances_y_20221029_162350.csv", 45.2, false),
    ("voronpi_resonances_y_20221127_190804.csv", 45.2, false),
    ("voronpi_resonances_y_20221231_213042.csv", 42.0, false),
    ("zippy_resonances_x_20220317_143228.csv", 58.3, false),
    ("zippy_resonances_y_20220317_143943.csv", 42.9, false),
];

fn corpus(file: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/corpus")
        .join(file)
}

#[test]
fn corpus_modes_include_the_published_main_resonance() {
    // The files predate December 2024: Klipper's pulse-only test (`accel_per_hz` 75,
    // `max_freq` 133.3 Hz), the one these spectra were measured with.
    let opts = Options {
        test: SweepTest::klipper_legacy(),
        ..Options::default()
    };
    let mut failures = Vec::new();
    for (file, main_hz, refused) in CORPUS {
        let ids = match (identify_file(&corpus(file), &opts), refused) {
            (Ok(ids), false) => ids,
            (Err(IdentifyError::Unreliable { reason, .. }), true)
                if reason.contains("does not explain this spectrum's main peak") =>
            {
                continue;
            }
            (Ok(ids), true) => {
                failures.push(format!(
                    "{file}: expected a refusal, got {:?}",
                    ids[0].modes
                ));
                continue;
            }
            (Err(e), _) => {
                failures.push(format!("{file}: {e}"));
                continue;
            }
        };
        let id = &ids[0];
        // One bin of the file's grid (about 1.53 Hz).
        let bin = 1.6;
        let tolerance = (0.03 * main_hz).max(bin);
        let fig = &id.figure;
        let model_peak = (0..fig.x.len())
            .filter(|&i| fig.model[i].is_finite())
            .max_by(|&a, &b| {
                (fig.model[a] / (fig.x[a] + 0.1)).total_cmp(&(fig.model[b] / (fig.x[b] + 0.1)))
            })
            .map(|i| fig.x[i])
            .expect("a fitted model");
        if (model_peak - main_hz).abs() > tolerance {
            failures.push(format!(
                "{file}: the model peaks at {model_peak} Hz, not within {tolerance:.2} Hz of {main_hz} Hz"
            ));
        }
        let peaks: Vec<f64> = id.modes.iter().map(|m| m.peak_hz).collect();
        if !peaks.iter().any(|f| (f - main_hz).abs() <= 0.1 * main_hz) {
            failures.push(format!(
                "{file}: no mode peaks within 10 % of {main_hz} Hz: {peaks:?}"
            ));
        }
        let freqs: Vec<f64> = id.modes.iter().map(|m| m.frequency_hz.value).collect();
        let (lo, hi) = id.diagnostics.span;
        for f in &freqs {
            if !(*f >= lo && *f <= hi) {
                failures.push(format!("{file}: mode {f} Hz outside {lo}-{hi} Hz"));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The per-column fit, when asked: the sensor's x column of a file whose energy lies
/// there gives the same main resonance.
#[test]
fn corpus_per_column_fit() {
    let opts = Options {
        test: SweepTest::klipper_legacy(),
        column: SpectrumColumn::Axis(0),
        ..Options::default()
    };
    let ids = identify_file(&corpus("voronpi_resonances_x_20221029_162131.csv"), &opts)
        .expect("fits psd_x");
    let peaks: Vec<f64> = ids[0].modes.iter().map(|m| m.peak_hz).collect();
    assert!(
        peaks.iter().any(|f| (f - 67.1).abs() <= 0.03 * 67.1),
        "{peaks:?}"
    );
    assert_eq!(ids[0].dominant_sensor_axis, Some(0));
}
