//! Klipper's choice next to settle's: the spectrum settle builds from a machine's modes
//! gives Klipper the choice it makes on a recording of that machine.

use settle::workflows::tune::klipper_choice::spectrum_of;
use settle::workflows::tune::klipper_criterion::load;
use settle_gcode::config::KlipperConfig;
use settle_identify::SweepTest;
use settle_planner::shaper_select::{SelectOptions, find_best_shaper};

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

/// Also: the example printer.cfg's SAVE_CONFIG block holds what Klipper chooses on the
/// example recordings.
#[test]
fn klippers_choice_on_the_modes_is_its_choice_on_the_recording() {
    let cfg = root().join("examples/klipper/printer.cfg");
    let text = std::fs::read_to_string(&cfg).expect("example printer.cfg");
    let saved = KlipperConfig::parse(&text, &cfg)
        .expect("reads")
        .input_shaper
        .expect("[input_shaper]");
    // The modes the example recordings were made from (examples/resonance_data.rs).
    for (file, modes, saved) in [
        (
            "examples/data/raw_data_x_example.csv",
            vec![(45.0, 0.05, 0.8), (75.0, 0.07, 0.2)],
            &saved.x,
        ),
        (
            "examples/data/raw_data_y_example.csv",
            vec![(39.0, 0.05, 1.0)],
            &saved.y,
        ),
    ] {
        let opts = SelectOptions::default();
        // The recording's data as `settle tune --criterion klipper` reads it (Klipper's
        // PSD of the three axes, summed and normalised: calibrate_shaper.py's).
        let recorded = load(&root().join(file)).expect("reads");
        let from_recording = find_best_shaper(&recorded, &opts).expect("chooses");
        let model = spectrum_of(&modes, &example_test(), 800.0);
        let from_modes = find_best_shaper(&[model], &opts).expect("chooses");
        let (r, m) = (from_recording.recommended, from_modes.recommended);
        eprintln!(
            "{file}: recording {} @ {:.2} Hz (v {:.4}, max_accel {:.0}); modes {} @ {:.2} Hz (v {:.4}, max_accel {:.0})",
            r.shaper_type.name(),
            r.frequency_hz,
            r.vibrations,
            r.max_accel_mm_s2,
            m.shaper_type.name(),
            m.frequency_hz,
            m.vibrations,
            m.max_accel_mm_s2
        );
        assert_eq!(r.shaper_type, m.shaper_type, "{file}");
        assert!((r.frequency_hz - m.frequency_hz).abs() <= 0.41, "{file}");
        // SHAPER_CALIBRATE saves the frequency to 0.1 Hz.
        assert_eq!(
            (saved.name.as_str(), saved.frequency_hz),
            (
                r.shaper_type.name().as_str(),
                (r.frequency_hz * 10.0).round() / 10.0
            ),
            "{file}"
        );
    }
}

/// `input_shaper.cfg` holds only keys Klipper's `[input_shaper]` reads (`shaper_type_x`,
/// `shaper_freq_x`, `_y`): Klipper refuses an option it does not read, so the
/// recommendation for a file that names no axis, or names z, is a comment saying where it
/// goes, never `shaper_freq:` or `shaper_freq_z:`.
#[test]
fn input_shaper_cfg_holds_only_keys_klipper_reads() {
    use settle::workflows::tune::klipper_criterion::{KlipperCriterion, choose, input_shaper_cfg};
    let dir = tempfile::tempdir().expect("tempdir");
    let corpus = root().join("identify/tests/corpus/zippy_resonances_x_20220317_143228.csv");
    let mut files = Vec::new();
    for name in ["resonances_x_1.csv", "resonances_z_1.csv", "spectrum.csv"] {
        let f = dir.path().join(name);
        std::fs::copy(&corpus, &f).expect("copy");
        files.push(f);
    }
    let c = KlipperCriterion::from_args(files, None, None, None, None).expect("options");
    let choices = choose(&c).expect("chooses");
    let cfg = input_shaper_cfg(&choices);
    let r = &choices[0].selection.recommended;
    let keys: Vec<&str> = cfg
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with('['))
        .filter_map(|l| l.split(':').next())
        .collect();
    assert_eq!(keys, ["shaper_type_x", "shaper_freq_x"], "{cfg}");
    assert!(
        cfg.contains(&format!("shaper_freq_x: {:.1}\n", r.frequency_hz)),
        "{cfg}"
    );
    for name in [
        "resonances_z_1.csv names axis z",
        "spectrum.csv names no axis",
    ] {
        let line = cfg
            .lines()
            .find(|l| l.contains(name))
            .unwrap_or_else(|| panic!("no comment on {name} in {cfg}"));
        assert!(line.starts_with("# "), "{line}");
        assert!(
            line.contains(&format!(
                "{} @ {:.1} Hz goes under the keys of the axis the test shook",
                r.shaper_type.name(),
                r.frequency_hz
            )),
            "{line}"
        );
    }
}

/// A file's axis comes from its name by `settle identify`'s rule: in Klipper's names the
/// word after the prefix, whatever follows (`calibration_data_y_x-belt.csv` is y); a name
/// that names two axes otherwise (`z_x.csv`, once read as z) is refused, naming the file.
#[test]
fn a_files_axis_is_read_as_identify_reads_it() {
    use settle::workflows::tune::klipper_criterion::{KlipperCriterion, choose};
    let dir = tempfile::tempdir().expect("tempdir");
    let corpus = root().join("identify/tests/corpus/zippy_resonances_x_20220317_143228.csv");
    let copy = |name: &str| {
        let f = dir.path().join(name);
        std::fs::copy(&corpus, &f).expect("copy");
        vec![f]
    };
    let c = KlipperCriterion::from_args(
        copy("calibration_data_y_x-belt.csv"),
        None,
        None,
        None,
        None,
    );
    let choices = choose(&c.expect("options")).expect("chooses");
    assert_eq!(choices[0].axis, Some('y'));
    let c = KlipperCriterion::from_args(copy("z_x.csv"), None, None, None, None);
    let e = choose(&c.expect("options"))
        .expect_err("two axes named")
        .to_string();
    assert!(
        e.contains("z_x.csv") && e.contains("more than one machine axis"),
        "{e}"
    );
}

/// Klipper's fit names a shaper and a frequency for any spectrum; `--criterion klipper`
/// answers only for one that shows a resonance: its largest PSD (as measured, before the
/// normalisation to the frequencies) at least 10 times its noise floor (the 5th
/// percentile) between 10 and 135 Hz. A flat spectrum (every PSD 100, ratio exactly 1)
/// and 5 s of white noise (uniform, +-500 mm/s^2) recorded at 3,200 Hz (Welch's estimate of a flat spectrum,
/// within a factor of about 3) are refused naming the file, and so is a recording of a
/// sensor that read one value throughout (a spectrum of zeros: no vibration); the corpus's resonance tests
/// reach 71 and more (zippy's X: 101).
#[test]
fn a_spectrum_without_a_resonance_names_no_shaper() {
    use rand::{Rng as _, SeedableRng as _};
    let dir = tempfile::tempdir().expect("tempdir");
    let flat = dir.path().join("calibration_data_x_flat.csv");
    let mut text = String::from("freq,psd_x,psd_y,psd_z,psd_xyz\n");
    for k in 0..128 {
        text.push_str(&format!(
            "{:.1},1.000e+02,1.000e+02,1.000e+02,3.000e+02\n",
            k as f64 * 1.5625
        ));
    }
    std::fs::write(&flat, text).expect("write");
    let e = load(&flat).expect_err("flat").to_string();
    assert!(
        e.contains("calibration_data_x_flat.csv")
            && e.contains("no resonance peak above the noise between 10 and 135 Hz (largest PSD / noise floor is 1.00; at least 10 is needed)"),
        "{e}"
    );
    let noise = dir.path().join("raw_data_x_noise.csv");
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let mut text = String::from("#time,accel_x,accel_y,accel_z\n");
    for i in 0..16_000 {
        let mut g = || rng.random_range(-500.0..500.0_f64);
        let (x, y, z) = (g(), g(), g());
        text.push_str(&format!(
            "{:.6},{x:.6},{y:.6},{z:.6}\n",
            100.0 + i as f64 / 3200.0
        ));
    }
    std::fs::write(&noise, text).expect("write");
    let e = load(&noise).expect_err("noise").to_string();
    assert!(
        e.contains("raw_data_x_noise.csv") && e.contains("no resonance peak above the noise"),
        "{e}"
    );
    // A sensor that read one value throughout: a spectrum of zeros (or rounding).
    let still = dir.path().join("raw_data_x_still.csv");
    let mut text = String::from("#time,accel_x,accel_y,accel_z\n");
    for i in 0..16_000 {
        text.push_str(&format!(
            "{:.6},100.0,200.0,9806.65\n",
            100.0 + i as f64 / 3200.0
        ));
    }
    std::fs::write(&still, text).expect("write");
    let e = load(&still).expect_err("still").to_string();
    assert!(
        e.contains("raw_data_x_still.csv") && e.contains("no vibration between 10 and 135 Hz"),
        "{e}"
    );
    let zippy = root().join("identify/tests/corpus/zippy_resonances_x_20220317_143228.csv");
    load(&zippy).expect("a resonance test");
}
