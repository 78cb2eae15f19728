//! Klipper's shaper choice against Klipper's own code, on synthetic calibration files.
//!
//! The files in planner/tests/data/klipper_*.csv are synthetic processed calibration
//! files in Klipper's format (header `freq,psd_x,psd_y,psd_z,psd_xyz`, `%.1f` frequencies,
//! `%.3e` PSDs, bins of 3200/2048 Hz below 200 Hz): one, two and three resonances of
//! various damping over seeded random noise, raw PSDs rising with frequency as a resonance
//! test's do. The expected numbers come from running Klipper (commit
//! 84104bbbd7625d28b4eaaad83f4562972460ecd9) under Python 3.11 and numpy 2.4 outside this
//! repository: `scripts/calibrate_shaper.py`'s `parse_log` (which normalises the PSD) and
//! `klippy/extras/shaper_calibrate.py`'s `find_best_shaper` with the options shown, printing
//! `repr()` of each fitted shaper's name, freq, vibrs, smoothing, score and max_accel. The
//! comment above each case is what `calibrate_shaper.py FILE [options]` printed.
//!
//! settle sums as numpy does and evaluates the shapers in the Python's order, so the
//! numbers agree to 1e-12 relative (1e-15 absolute for vibrations that are exactly zero);
//! the recommended shaper and frequency are the same.

use settle_planner::shaper::ShaperType;
use settle_planner::shaper_select::{
    CalibrationData, SelectOptions, ShaperFreqs, find_best_shaper,
};

struct Case {
    name: &'static str,
    file: &'static str,
    opts: fn() -> SelectOptions,
    recommended: (&'static str, f64),
    /// (shaper, freq, vibrs, smoothing, score, max_accel) per shaper tried.
    fits: &'static [(&'static str, f64, f64, f64, f64, f64)],
}

fn kinds(names: &[&str]) -> Vec<ShaperType> {
    names
        .iter()
        .map(|n| ShaperType::parse(n).expect("shaper name"))
        .collect()
}

/// A processed calibration file as calibrate_shaper.py's `parse_log` reads it.
fn read(file: &str) -> CalibrationData {
    let path = format!("{}/tests/data/{file}", crate::manifest_dir());
    let text = std::fs::read_to_string(&path).expect("calibration file");
    let mut cols: [Vec<f64>; 5] = Default::default();
    for line in text.lines().skip(1) {
        for (col, v) in cols.iter_mut().zip(line.split(',')) {
            col.push(v.parse().expect("number"));
        }
    }
    let [freq_hz, x, y, z, sum] = cols;
    let mut data = CalibrationData {
        freq_hz,
        psd_sum: sum,
        psd_x: Some(x),
        psd_y: Some(y),
        psd_z: Some(z),
    };
    data.normalize_to_frequencies();
    data
}

fn close(got: f64, want: f64) -> bool {
    (got - want).abs() <= 1e-12 * want.abs() + 1e-15
}

#[rustfmt::skip]
const CASES: &[Case] = &[
    // one_peak: Recommended shaper is mzv @ 47.2 Hz
    Case {
        name: "one_peak",
        file: "klipper_one_peak.csv",
        opts: || SelectOptions::default(),
        recommended: ("mzv", 47.19999999999992),
        fits: &[
            ("zv", 45.999999999999915, 0.014919802297726086, 0.07834243532067692, 0.0011599666311162581, 8246.343937833142),
            ("mzv", 47.19999999999992, 0.0, 0.09142074090152724, 0.0009142074090152724, 6563.062102569528),
            ("ei", 57.9999999999999, 3.254908724580663e-05, 0.09794701314997499, 0.0009801259372811783, 6125.761069213036),
            ("2hump_ei", 74.80000000000051, 0.0003134120704990021, 0.10120659867309485, 0.0010189714028690639, 5928.467193507551),
            ("3hump_ei", 94.00000000000065, 0.00036426668065268805, 0.1023250060119742, 0.0010314161734112483, 5863.669335423695),
        ],
    },
    // two_peaks: Recommended shaper is mzv @ 39.0 Hz
    Case {
        name: "two_peaks",
        file: "klipper_two_peaks.csv",
        opts: || SelectOptions::default(),
        recommended: ("mzv", 38.99999999999994),
        fits: &[
            ("zv", 59.19999999999986, 0.24420558432198167, 0.05056472841626308, 0.009077409609248549, 13658.065604102772),
            ("mzv", 38.99999999999994, 0.00021952948885083957, 0.13390584050628426, 0.0013453732120103118, 4480.760493572492),
            ("ei", 49.19999999999993, 0.0049766120261461174, 0.13611844480654522, 0.001544454053964642, 4407.925765330592),
            ("2hump_ei", 61.800000000000324, 0.0004190597985194873, 0.14826378228126913, 0.0014963359895588779, 4046.8413173264216),
            ("3hump_ei", 77.60000000000042, 0.0003854552521741209, 0.1501460956799684, 0.001514172129909244, 3996.1079059874155),
        ],
    },
    // two_peaks_max_smoothing: Recommended shaper is mzv @ 45.2 Hz
    Case {
        name: "two_peaks_max_smoothing",
        file: "klipper_two_peaks.csv",
        opts: || SelectOptions { max_smoothing_mm: Some(0.1), ..SelectOptions::default() },
        recommended: ("mzv", 45.19999999999992),
        fits: &[
            ("zv", 47.9999999999999, 0.2268449029991773, 0.07270213142970498, 0.011880343288024741, 8979.005875599312),
            ("mzv", 45.19999999999992, 0.04902056228155254, 0.09969006157983125, 0.0030562533493961996, 6018.654121496497),
            ("ei", 57.599999999999895, 0.05819953404065118, 0.09931211185755326, 0.0035434859167968306, 6041.5591691432855),
            ("2hump_ei", 75.40000000000052, 0.061497983800662764, 0.09960229225561155, 0.003740101013557809, 6023.957746475157),
            ("3hump_ei", 95.20000000000067, 0.061509502776848135, 0.09976164213352291, 0.003746741971411755, 6014.335642112047),
        ],
    },
    // low_peak: Recommended shaper is mzv @ 25.6 Hz
    Case {
        name: "low_peak",
        file: "klipper_low_peak.csv",
        opts: || SelectOptions::default(),
        recommended: ("mzv", 25.59999999999999),
        fits: &[
            ("zv", 26.99999999999998, 0.07552181689132145, 0.21119223247746782, 0.009684999091617257, 2544.7724620983954),
            ("mzv", 25.59999999999999, 0.012342545303755335, 0.3107769522248198, 0.004301068773876643, 1884.090135831655),
            ("ei", 29.599999999999998, 0.0018499460428380067, 0.37606573255628517, 0.003929720396896013, 1525.7695268901043),
            ("2hump_ei", 39.80000000000001, 0.002312035754286179, 0.35747516971788595, 0.0037797916720630387, 1550.7746273577686),
            ("3hump_ei", 49.20000000000002, 0.0014904391137922008, 0.37351434047269133, 0.0038679755706971957, 1473.9782073711795),
        ],
    },
    // high_peak_custom_shapers: Recommended shaper is ei @ 117.4 Hz
    Case {
        name: "high_peak_custom_shapers",
        file: "klipper_high_peak.csv",
        opts: || SelectOptions { shapers: kinds(&["zv", "ei", "mzv(n=4,t=0.8)", "ei(v_tol=0.02)"]), ..SelectOptions::default() },
        recommended: ("ei", 117.3999999999997),
        fits: &[
            ("zv", 91.99999999999974, 0.005219382746168312, 0.024295167730951438, 0.0002774739541793494, 32985.37575132909),
            ("ei", 117.3999999999997, 8.236520954160285e-05, 0.0265688305099043, 0.0002661458349647402, 25098.06618142643),
            ("mzv(n=4,t=0.8)", 95.59999999999974, 4.8373374261163035e-05, 0.026291788942217335, 0.0002631810995806489, 26977.717575666436),
            ("ei(v_tol=0.02)", 111.9999999999997, 6.848987956679027e-05, 0.027498495806823498, 0.00027537721829922916, 23813.538806746823),
        ],
    },
    // spread_peaks: Recommended shaper is 3hump_ei @ 53.4 Hz
    Case {
        name: "spread_peaks",
        file: "klipper_spread_peaks.csv",
        opts: || SelectOptions::default(),
        recommended: ("3hump_ei", 53.40000000000008),
        fits: &[
            ("zv", 52.999999999999886, 0.26930184049801054, 0.06117426308393021, 0.012455855283818278, 10947.06054885402),
            ("mzv", 34.39999999999996, 0.06407496813657008, 0.17211227640790475, 0.00671828429363835, 3486.096474477232),
            ("ei", 46.999999999999936, 0.05976994310377091, 0.14915968865392287, 0.005454244750267093, 4022.534542768968),
            ("2hump_ei", 42.200000000000045, 0.01002737660638425, 0.3179707148536191, 0.004136666922046394, 1784.9725633939743),
            ("3hump_ei", 53.40000000000008, 0.00989686757321211, 0.3170698681149314, 0.0041104758892660355, 1797.210929011755),
        ],
    },
    // one_peak_options: Recommended shaper is 2hump_ei @ 71.5 Hz
    Case {
        name: "one_peak_options",
        file: "klipper_one_peak.csv",
        opts: || SelectOptions {
            damping_ratio: 0.15,
            scv_mm_s: 10.0,
            test_damping_ratios: vec![0.05, 0.1],
            shaper_freqs: ShaperFreqs::Range { start_hz: Some(30.0), end_hz: Some(80.0), step_hz: Some(0.5) },
            max_vibrations: Some(0.005),
            ..SelectOptions::default()
        },
        recommended: ("2hump_ei", 71.5),
        fits: &[
            ("zv", 48.0, 0.09321784605553533, 0.09243245078075155, 0.005278305834474104, 7408.886836152479),
            ("mzv", 46.5, 0.023178716830900892, 0.10848458628487477, 0.001970579177767173, 5804.904859859863),
            ("ei", 56.0, 0.007562665774304492, 0.1189470438087967, 0.001447610467700952, 5066.321004448714),
            ("2hump_ei", 71.5, 0.004607105676928984, 0.1243176241028491, 0.0013966005356199035, 4751.241353243782),
            ("3hump_ei", 61.5, 0.004526428301529058, 0.25171156762829205, 0.002821640870287211, 1579.2957356090446),
        ],
    },
    // low_peak_freq_list: Recommended shaper is mzv @ 25.5 Hz
    Case {
        name: "low_peak_freq_list",
        file: "klipper_low_peak.csv",
        opts: || SelectOptions {
            shaper_freqs: ShaperFreqs::List(vec![24.0, 25.5, 27.0, 30.0]),
            max_freq_hz: Some(150.0),
            ..SelectOptions::default()
        },
        recommended: ("mzv", 25.5),
        fits: &[
            ("zv", 27.0, 0.07552181689132156, 0.21119223247746743, 0.009684999091617253, 2544.7724620983954),
            ("mzv", 25.5, 0.011961486406123961, 0.31321919786244945, 0.004291262148129826, 1866.6448272749803),
            ("ei", 25.5, 0.000408033712991921, 0.5067185732203225, 0.005112713869071832, 1054.8009504661422),
            ("2hump_ei", 30.0, 0.0, 0.6291721864888004, 0.006291721864888003, 760.5422739060814),
            ("3hump_ei", 30.0, 0.0, 1.0046041701353514, 0.010046041701353514, 391.78726074613223),
        ],
    },
];

#[test]
fn recommendations_equal_calibrate_shaper_py() {
    for case in CASES {
        let data = read(case.file);
        let sel = find_best_shaper(&[data], &(case.opts)()).expect(case.name);
        let (name, freq) = case.recommended;
        assert_eq!(
            sel.recommended.shaper_type,
            ShaperType::parse(name).expect("name"),
            "{}",
            case.name
        );
        // calibrate_shaper.py prints the frequency with one decimal.
        assert_eq!(
            format!("{:.1}", sel.recommended.frequency_hz),
            format!("{freq:.1}"),
            "{}",
            case.name
        );
        assert!(close(sel.recommended.frequency_hz, freq), "{}", case.name);
        assert_eq!(sel.per_shaper.len(), case.fits.len(), "{}", case.name);
        for (got, want) in sel.per_shaper.iter().zip(case.fits) {
            let what = format!("{} {}", case.name, want.0);
            assert_eq!(
                got.shaper_type,
                ShaperType::parse(want.0).expect("name"),
                "{what}"
            );
            assert!(
                close(got.frequency_hz, want.1),
                "{what}: freq {} vs {}",
                got.frequency_hz,
                want.1
            );
            assert!(
                close(got.vibrations, want.2),
                "{what}: vibrs {} vs {}",
                got.vibrations,
                want.2
            );
            assert!(
                close(got.smoothing_mm, want.3),
                "{what}: smoothing {} vs {}",
                got.smoothing_mm,
                want.3
            );
            assert!(
                close(got.score, want.4),
                "{what}: score {} vs {}",
                got.score,
                want.4
            );
            assert!(
                close(got.max_accel_mm_s2, want.5),
                "{what}: max_accel {} vs {}",
                got.max_accel_mm_s2,
                want.5
            );
        }
    }
}

/// A spectrum without a positive value (a sensor that read a constant, a file of zeros)
/// leaves Klipper's remaining vibration at 0 / 0: refused, not chosen on as "0 % left".
#[test]
fn a_spectrum_without_vibration_is_refused() {
    let freq_hz: Vec<f64> = (0..128).map(|k| f64::from(k) * 3200.0 / 2048.0).collect();
    let flat = |v: f64| CalibrationData {
        freq_hz: freq_hz.clone(),
        psd_sum: vec![v; freq_hz.len()],
        ..CalibrationData::default()
    };
    let opts = SelectOptions::default();
    for data in [flat(0.0), flat(f64::INFINITY)] {
        let e = find_best_shaper(&[data], &opts).expect_err("no vibration");
        assert!(
            e.to_string()
                .contains("the spectrum holds no vibration to shape"),
            "{e}"
        );
    }
    // One data set of several without vibration is enough to refuse.
    let e = find_best_shaper(&[flat(1.0), flat(0.0)], &opts).expect_err("one empty set");
    assert!(e.to_string().contains("nothing was measured"), "{e}");
    // A flat but positive spectrum is a spectrum: Klipper chooses on it.
    find_best_shaper(&[flat(1.0)], &opts).expect("a positive spectrum");
}

/// A shaper of a few kHz (a configuration's `shaper_freq_x: 4660`, the decimal point of
/// 46.60 lost) allows an acceleration of about 1e9 mm/s^2, where doubles lie further
/// apart than the bisection's 1e-8 mm/s^2: the search ends at two neighbouring doubles
/// (it looped forever), and the answer still keeps the smoothing within the target.
#[test]
fn max_accel_of_a_khz_shaper_ends() {
    use settle_planner::shaper::{Shaper, smoothing_mm};
    use settle_planner::shaper_select::max_accel_mm_s2;
    for f in [4660.0, 5e4] {
        let sh = Shaper::new(kinds(&["mzv"])[0], f, 0.1).expect("shaper");
        let a = max_accel_mm_s2(sh.amplitudes(), sh.times_s(), 5.0, 0.12);
        assert!(a.is_finite() && a > 1e6, "{f} Hz: {a}");
        let s = smoothing_mm(sh.amplitudes(), sh.times_s(), a, 5.0);
        assert!(s <= 0.12, "{f} Hz: {s}");
    }
}
