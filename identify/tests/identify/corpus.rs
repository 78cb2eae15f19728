//! settle identify on the corpus of real files (`identify/tests/corpus/MANIFEST.md`): a
//! file either gives modes that include every main resonance its owner published (some
//! mode's own peak, `IdentifiedMode::peak_hz`, within 3 % or one frequency bin of it; no
//! mode outside the band the data cover or at or above the Nyquist frequency), or is
//! refused with the reason stated here. Which files are refused is part of the
//! expectation: a change that makes one of them fit, or one of the others fail, shows
//! here.

use std::path::PathBuf;

use settle_identify::{IdentifyError, Options, SweepTest, identify_file};

/// The test that produced a file, as settle is told it.
#[derive(Clone, Copy)]
enum Test {
    /// Klipper's pulse-only test before December 2024 (`accel_per_hz` 75, `max_freq`
    /// 133.3 Hz): the older `resonances_*.csv`.
    KlipperLegacy,
    /// The Neptune 4 Pro's sweeping test, from the owner's `[resonance_tester]` and
    /// Shake&Tune's graph: 10 to 140 Hz at 1 Hz/s, `accel_per_hz` 60, sweeping accel 200
    /// mm/s^2 every 1.2 s.
    Neptune4Pro,
    /// A free decay (RepRapFirmware's M956 capture after a move): no test parameters.
    FreeDecay,
}

/// What settle answers for a file.
#[derive(Clone, Copy)]
enum Expect {
    /// Modes that include every published main resonance.
    Modes,
    /// Exit 2: refused with a reason that contains this text.
    Refused(&'static str),
}

/// `(file, test, published main resonances (Hz), one frequency bin (Hz), expectation)`.
/// Main resonances: Klipper processed files, the largest peak of the published spectrum
/// `psd_xyz / (f + 0.1)` between 5 and 135 Hz; Shake&Tune files, the `w0` of the owner's
/// graph; M956 captures, the owner's M593 frequency. A bin: Klipper's grid (about 1.53
/// Hz, rounded to `%.1f`), Klipper's half-second Welch segment at 3.2 kHz (1.56 Hz), one
/// over an M956 capture's length (1.61 Hz).
const CORPUS: [(&str, Test, &[f64], f64, Expect); 24] = {
    use Expect::{Modes, Refused};
    use Test::{FreeDecay, KlipperLegacy as L, Neptune4Pro};
    const NOT_MAIN: &str = "does not explain this spectrum's main peak";
    [
        ("metis_resonances_x_20220520_114736.csv", L, &[57.6], 1.6, Modes),
        ("metis_resonances_y_20220520_114956.csv", L, &[38.9], 1.6, Modes),
        (
            "neptune4pro_inputshaper_20250707_143713_axis_X.stdata",
            Neptune4Pro,
            &[77.1],
            1.6,
            Modes,
        ),
        (
            "neptune4pro_inputshaper_20250804_210218_axis_Y.stdata",
            Neptune4Pro,
            &[81.6],
            1.6,
            Modes,
        ),
        ("porklander_resonances_x_20230316_091341.csv", L, &[52.4], 1.6, Modes),
        ("porklander_resonances_y_20230316_091517.csv", L, &[38.1], 1.6, Modes),
        ("railcore_2-T0-X42-201-0-none.csv", FreeDecay, &[42.0], 1.7, Modes),
        ("railcore_3-T0-X42-201-0-none.csv", FreeDecay, &[42.0], 1.7, Modes),
        ("voronpi_resonances_x_20211217_070942.csv", L, &[63.5], 1.6, Modes),
        ("voronpi_resonances_x_20220213_155340.csv", L, &[61.5], 1.6, Modes),
        ("voronpi_resonances_x_20220430_191517.csv", L, &[62.7], 1.6, Modes),
        ("voronpi_resonances_x_20220919_172212.csv", L, &[66.5], 1.6, Modes),
        ("voronpi_resonances_x_20221029_162131.csv", L, &[67.1], 1.6, Modes),
        ("voronpi_resonances_x_20221127_190547.csv", L, &[67.1], 1.6, Modes),
        ("voronpi_resonances_x_20221231_212825.csv", L, &[60.6], 1.6, Modes),
        (
            "voronpi_resonances_y_20211217_071158.csv",
            L,
            &[40.3],
            1.6,
            Refused(NOT_MAIN),
        ),
        ("voronpi_resonances_y_20220213_155556.csv", L, &[44.5], 1.6, Modes),
        ("voronpi_resonances_y_20220430_191733.csv", L, &[43.9], 1.6, Modes),
        ("voronpi_resonances_y_20220919_172429.csv", L, &[45.3], 1.6, Modes),
        ("voronpi_resonances_y_20221029_162350.csv", L, &[45.2], 1.6, Modes),
        ("voronpi_resonances_y_20221127_190804.csv", L, &[45.2], 1.6, Modes),
        ("voronpi_resonances_y_20221231_213042.csv", L, &[42.0], 1.6, Modes),
        ("zippy_resonances_x_20220317_143228.csv", L, &[58.3], 1.6, Modes),
        ("zippy_resonances_y_20220317_143943.csv", L, &[42.9], 1.6, Modes),
    ]
};

fn corpus(file: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/corpus")
        .join(file)
}

fn options(test: Test) -> Options {
    let test = match test {
        Test::KlipperLegacy | Test::FreeDecay => SweepTest::klipper_legacy(),
        Test::Neptune4Pro => SweepTest {
            freq_start_hz: 10.0,
            freq_end_hz: 140.0,
            hz_per_sec: 1.0,
            accel_per_hz: 60.0,
            sweeping_accel_mm_s2: 200.0,
            sweeping_period_s: 1.2,
        },
    };
    Options {
        test,
        ..Options::default()
    }
}

#[test]
fn corpus_modes_include_the_published_main_resonances() {
    let mut failures = Vec::new();
    for (file, test, mains, bin, expect) in CORPUS {
        let ids = match (identify_file(&corpus(file), &options(test)), expect) {
            (Ok(ids), Expect::Modes) => ids,
            (Err(e), Expect::Refused(why)) => {
                if !e.to_string().contains(why) {
                    failures.push(format!("{file}: refused for another reason: {e}"));
                }
                continue;
            }
            (Ok(ids), Expect::Refused(_)) => {
                failures.push(format!(
                    "{file}: expected a refusal, got {:?}",
                    ids[0].modes
                ));
                continue;
            }
            (Err(e), Expect::Modes) => {
                failures.push(format!("{file}: {e}"));
                continue;
            }
        };
        assert_eq!(ids.len(), 1, "{file}: one recording");
        let id = &ids[0];
        let peaks: Vec<f64> = id.modes.iter().map(|m| m.peak_hz).collect();
        for &main in mains {
            let tolerance = (0.03 * main).max(bin);
            if !peaks.iter().any(|f| (f - main).abs() <= tolerance) {
                failures.push(format!(
                    "{file}: no mode peaks within {tolerance:.2} Hz of {main} Hz: {peaks:?}"
                ));
            }
        }
        let (lo, hi) = id.diagnostics.span;
        for m in &id.modes {
            let f = m.frequency_hz.value;
            if !(f >= lo && f <= hi) {
                failures.push(format!("{file}: mode {f} Hz outside {lo}-{hi} Hz"));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// No corpus file is refused for a reason other than the expected one, and an
/// untrustworthy fit is never reported as modes: every refusal is `Unreliable` (a fit
/// settle cannot stand behind), not a reader's error.
#[test]
fn corpus_refusals_are_fits_settle_cannot_stand_behind() {
    for (file, test, _, _, expect) in CORPUS {
        if let Expect::Refused(_) = expect {
            let e = identify_file(&corpus(file), &options(test)).expect_err(file);
            assert!(matches!(e, IdentifyError::Unreliable { .. }), "{file}: {e}");
        }
    }
}

/// The per-column fit, when asked: the sensor's x column of a file whose energy lies
/// there gives the same main resonance.
#[test]
fn corpus_per_column_fit() {
    let opts = Options {
        column: settle_identify::SpectrumColumn::Axis(0),
        ..options(Test::KlipperLegacy)
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
