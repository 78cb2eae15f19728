//! Klipper's choice next to settle's: the spectrum settle builds from a machine's modes
//! gives Klipper the choice it makes on a recording of that machine.

use settle::workflows::tune::klipper_choice::spectrum_of;
use settle_identify::welch::Welch;
use settle_identify::{FileData, SweepTest, read_file};
use settle_planner::shaper_select::{CalibrationData, SelectOptions, find_best_shaper};

use crate::support::root;

/// The example recordings' test (examples/resonance_data.rs): 30-90 Hz at 10 Hz/s, the
/// default acceleration and sweeping motion, at 800 samples per second.
fn example_test() -> SweepTest {
    SweepTest {
        freq_start_hz: 30.0,
        freq_end_hz: 90.0,
        hz_per_sec: 10.0,
        ..SweepTest::klipper()
    }
}

/// Klipper's calibration data of a raw recording: the sum of the three axes' Welch PSDs
/// (`psd_xyz`, as shaper_calibrate.py computes it), normalised.
fn recorded(file: &str) -> CalibrationData {
    let FileData::Recordings(r) = read_file(&root().join(file)).expect("reads") else {
        panic!("{file} is a recording");
    };
    let rec = &r[0];
    let welch = Welch::klipper(rec.sample_rate_hz);
    let mut sum = vec![0.0; welch.freqs_hz().len()];
    for a in rec.accel_mm_s2.iter().flatten() {
        for (s, p) in sum.iter_mut().zip(welch.psd(a).expect("long enough")) {
            *s += p;
        }
    }
    let mut d = CalibrationData {
        freq_hz: welch.freqs_hz(),
        psd_sum: sum,
        ..CalibrationData::default()
    };
    d.normalize_to_frequencies();
    d
}

#[test]
fn klippers_choice_on_the_modes_is_its_choice_on_the_recording() {
    // The modes the example recordings were made from (examples/resonance_data.rs).
    for (file, modes) in [
        (
            "examples/data/raw_data_x_example.csv",
            vec![(45.0, 0.05, 0.8), (75.0, 0.07, 0.2)],
        ),
        (
            "examples/data/raw_data_y_example.csv",
            vec![(39.0, 0.05, 1.0)],
        ),
    ] {
        let opts = SelectOptions::default();
        let from_recording = find_best_shaper(&[recorded(file)], &opts).expect("chooses");
        let model = spectrum_of(&modes, &example_test(), 800.0);
        let from_modes = find_best_shaper(&[model], &opts).expect("chooses");
        let (r, m) = (from_recording.recommended, from_modes.recommended);
        eprintln!(
            "{file}: recording {} @ {:.2} Hz (v {:.4}, max_accel {:.0}); modes {} @ {:.2} Hz (v {:.4}, max_accel {:.0})",
            r.kind.name(),
            r.frequency_hz,
            r.vibrations,
            r.max_accel_mm_s2,
            m.kind.name(),
            m.frequency_hz,
            m.vibrations,
            m.max_accel_mm_s2
        );
        assert_eq!(r.kind, m.kind, "{file}");
        assert!((r.frequency_hz - m.frequency_hz).abs() <= 0.41, "{file}");
    }
}
