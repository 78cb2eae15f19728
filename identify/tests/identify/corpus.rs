//! settle identify on the corpus of real files (`identify/tests/corpus/MANIFEST.md`): a
//! file either gives modes that include every main resonance its owner published (some
//! mode's natural frequency or own peak, `IdentifiedMode::peak_hz`, within 3 % or one
//! frequency bin of it; no mode outside the band the data cover, which ends below the
//! Nyquist frequency), or is refused with the reason stated here. The peak is compared
//! too because a spectrum shows a mode below its natural frequency by its damping; the
//! natural frequency too because `peak_hz` leaves out the test's excitation, which rises
//! with frequency and lifts a broad mode's peak in the measured spectrum (the Neptune 4
//! Pro's X mode, zeta 0.15: natural frequency 75.8 Hz, own peak 74.5 Hz, Shake&Tune's
//! graph 77.1 Hz). Which files are refused is part of the expectation: a change that
//! makes one of them fit, or one of the others fail, shows here.

use std::path::PathBuf;
use std::sync::OnceLock;

use settle_identify::{AxisIdentification, IdentifyError, Options, SweepTest, identify_file};

/// What `identify_file` answered for one file.
pub type Answer = Result<Vec<AxisIdentification>, IdentifyError>;

/// The test that produced a file, as settle is told it.
#[derive(Clone, Copy)]
enum Test {
    /// Klipper's pulse-only test before December 2024 (`accel_per_hz` 75, `max_freq`
    /// 133.3 Hz): the older `resonances_*.csv` and `calibration_data_*.csv`.
    KlipperLegacy,
    /// The Neptune 4 Pro's sweeping test, from the owner's `[resonance_tester]` and
    /// Shake&Tune's graph: 10 to 140 Hz at 1 Hz/s, `accel_per_hz` 60, sweeping accel 200
    /// mm/s^2 every 1.2 s.
    Neptune4Pro,
    /// Klipper's pulse-only test (before December 2024) as Shake&Tune 2.5 and 2.6 start
    /// it (`AXES_SHAPER_CALIBRATION`: 5 to 133.3 Hz at 1 Hz/s), with the owner's
    /// `accel_per_hz`: a raw recording (`resonances_<date>_<axis>.csv`).
    ShakeTuneAxes(f64),
    /// An M956 capture (RepRapFirmware): a free decay, no test parameters.
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
/// `psd_xyz / (f + 0.1)` between 5 and 135 Hz (a `SHAPER_CALIBRATE` file's `psd_xyz` as
/// written: Klipper divided it already); files with a Shake&Tune graph (`.stdata`
/// and the raw `resonances_<date>_<axis>.csv`), the `w0` of the owner's graph; M956
/// captures, the owner's M593 frequency. A bin: Klipper's grid (about 1.53 Hz, rounded
/// to `%.1f`), Klipper's half-second Welch segment (256 samples at 391 Hz: 1.53 Hz; 2,048
/// at 3.2 kHz: 1.56 Hz), one over an M956 capture's length (1.61 Hz).
#[rustfmt::skip]
const CORPUS: [(&str, Test, &[f64], f64, Expect); 34] = {
    use Expect::{Modes, Refused};
    use Test::{FreeDecay as M956, KlipperLegacy as L, Neptune4Pro as N4P};
    const ST75: Test = Test::ShakeTuneAxes(75.0);
    const ST125: Test = Test::ShakeTuneAxes(125.0);
    const NOT_MAIN: Expect = Refused("does not explain this spectrum's main peak");
    // The captures hold the move itself: the vibration lasts to the last sample.
    const NO_DECAY: Expect = Refused("the free decay after the move holds");
    [
        ("bassco_calibration_data_x_20220611_200739.csv", L, &[46.8], 1.6, NOT_MAIN),
        ("bassco_calibration_data_x_20230306_225431.csv", L, &[51.8], 1.6, Modes),
        ("bassco_calibration_data_y_20220611_200739.csv", L, &[57.4], 1.6, NOT_MAIN),
        ("bassco_calibration_data_y_20230306_225431.csv", L, &[41.4], 1.6, Modes),
        ("bassco_resonances_x_20230306_224517.csv", L, &[51.8], 1.6, Modes),
        ("bassco_resonances_y_20230306_224919.csv", L, &[41.4], 1.6, Modes),
        ("metis_resonances_20240206_200114_X.csv", ST125, &[64.1], 1.5, Modes),
        ("metis_resonances_20240206_200335_Y.csv", ST125, &[55.0], 1.5, Modes),
        ("metis_resonances_x_20220520_114736.csv", L, &[57.6], 1.6, Modes),
        ("metis_resonances_y_20220520_114956.csv", L, &[38.9], 1.6, Modes),
        ("neptune4pro_inputshaper_20250707_143713_axis_X.stdata", N4P, &[77.1], 1.6, Modes),
        ("neptune4pro_inputshaper_20250804_210218_axis_Y.stdata", N4P, &[81.6], 1.6, Modes),
        ("porklander_resonances_x_20230316_091341.csv", L, &[52.4], 1.6, Modes),
        ("porklander_resonances_y_20230316_091517.csv", L, &[38.1], 1.6, Modes),
        ("railcore_2-T0-X42-201-0-none.csv", M956, &[42.0], 1.7, NO_DECAY),
        ("railcore_3-T0-X42-201-0-none.csv", M956, &[42.0], 1.7, NO_DECAY),
        ("voronpi_resonances_x_20211217_070942.csv", L, &[63.5], 1.6, Modes),
        ("voronpi_resonances_x_20220213_155340.csv", L, &[61.5], 1.6, Modes),
        ("voronpi_resonances_x_20220430_191517.csv", L, &[62.7], 1.6, Modes),
        ("voronpi_resonances_x_20220919_172212.csv", L, &[66.5], 1.6, Modes),
        ("voronpi_resonances_x_20221029_162131.csv", L, &[67.1], 1.6, Modes),
        ("voronpi_resonances_x_20221127_190547.csv", L, &[67.1], 1.6, Modes),
        ("voronpi_resonances_x_20221231_212825.csv", L, &[60.6], 1.6, Modes),
        ("voronpi_resonances_y_20211217_071158.csv", L, &[40.3], 1.6, NOT_MAIN),
        ("voronpi_resonances_y_20220213_155556.csv", L, &[44.5], 1.6, Modes),
        ("voronpi_resonances_y_20220430_191733.csv", L, &[43.9], 1.6, Modes),
        ("voronpi_resonances_y_20220919_172429.csv", L, &[45.3], 1.6, Modes),
        ("voronpi_resonances_y_20221029_162350.csv", L, &[45.2], 1.6, Modes),
        ("voronpi_resonances_y_20221127_190804.csv", L, &[45.2], 1.6, Modes),
        ("voronpi_resonances_y_20221231_213042.csv", L, &[42.0], 1.6, Modes),
        ("vt627_resonances_20240226_202625_X.csv", ST75, &[68.8], 1.5, Modes),
        ("vt627_resonances_20240226_202846_Y.csv", ST75, &[61.1], 1.5, NOT_MAIN),
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
        Test::ShakeTuneAxes(accel_per_hz) => SweepTest {
            freq_end_hz: 133.3,
            accel_per_hz,
            ..SweepTest::klipper_legacy()
        },
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

/// settle's answer for every file of [`CORPUS`], in its order: identified once for all
/// the tests that read it, the files shared out over the machine's cores (each answer
/// depends on its file alone).
fn answers() -> &'static [Answer] {
    static ANSWERS: OnceLock<Vec<Answer>> = OnceLock::new();
    ANSWERS.get_or_init(|| {
        let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
        let mut done: Vec<(usize, Answer)> = std::thread::scope(|s| {
            let workers: Vec<_> = (0..threads)
                .map(|t| {
                    s.spawn(move || {
                        (t..CORPUS.len())
                            .step_by(threads)
                            .map(|i| {
                                let (file, test, ..) = CORPUS[i];
                                (i, identify_file(&corpus(file), &options(test)))
                            })
                            .collect::<Vec<_>>()
                    })
                })
                .collect();
            workers
                .into_iter()
                .flat_map(|w| w.join().expect("a corpus worker"))
                .collect()
        });
        done.sort_by_key(|d| d.0);
        done.into_iter().map(|d| d.1).collect()
    })
}

/// settle's answer for the corpus file `file` (a name of [`CORPUS`]).
pub fn answer(file: &str) -> &'static Answer {
    let i = CORPUS
        .iter()
        .position(|c| c.0 == file)
        .unwrap_or_else(|| panic!("{file} is not in the corpus"));
    &answers()[i]
}

/// Every corpus file that gives modes: its name, its first published main resonance
/// (Hz) and settle's identification.
pub fn identified() -> impl Iterator<Item = (&'static str, f64, &'static AxisIdentification)> {
    CORPUS
        .iter()
        .zip(answers())
        .filter_map(|((file, _, mains, ..), answer)| {
            let id = answer.as_ref().ok()?.first()?;
            Some((*file, mains[0], id))
        })
}

/// One line per file for the table of `docs/guide/real-recordings.md` (shown with
/// `--nocapture`): each mode's natural frequency, own peak and damping ratio, or the
/// refusal.
fn outcome(file: &str, result: &Answer) -> String {
    match result {
        Ok(ids) => {
            let modes: Vec<String> = ids
                .iter()
                .flat_map(|id| &id.modes)
                .map(|m| {
                    format!(
                        "{:.1} (peak {:.1}), {:.3}",
                        m.frequency_hz.value, m.peak_hz, m.damping_ratio.value
                    )
                })
                .collect();
            format!("{file} | {}", modes.join("; "))
        }
        Err(e) => format!("{file} | refused: {e}"),
    }
}

#[test]
fn corpus_modes_include_the_published_main_resonances() {
    let mut failures = Vec::new();
    for ((file, _, mains, bin, expect), result) in CORPUS.into_iter().zip(answers()) {
        println!("{}", outcome(file, result));
        let ids = match (result, expect) {
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
        let found: Vec<(f64, f64)> = id
            .modes
            .iter()
            .map(|m| (m.frequency_hz.value, m.peak_hz))
            .collect();
        for &main in mains {
            let tolerance = (0.03 * main).max(bin);
            let near = |f: f64| (f - main).abs() <= tolerance;
            if !found.iter().any(|&(f, p)| near(f) || near(p)) {
                failures.push(format!(
                    "{file}: no mode (natural frequency, peak) within {tolerance:.2} Hz of {main} Hz: {found:?}"
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

/// Every refusal is one of the fit (a fit settle cannot stand behind, or no free decay
/// to fit), never a reader's: every corpus file is read.
#[test]
fn corpus_refusals_are_fits_not_reading_errors() {
    for ((file, .., expect), result) in CORPUS.into_iter().zip(answers()) {
        if let (Expect::Refused(_), Err(e)) = (expect, result) {
            assert!(
                matches!(
                    e,
                    IdentifyError::Unreliable { .. } | IdentifyError::NoRingDown { .. }
                ),
                "{file}: {e}"
            );
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
