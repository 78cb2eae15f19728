//! Klipper's own PSD code as the reference for [`settle_identify::welch`].
//!
//! The expected numbers were obtained by running Klipper's
//! `klippy/extras/shaper_calibrate.py` (`ShaperCalibrate.calc_freq_response`, numpy 2)
//! outside this repository on the CSV that [`reference_csv`] writes (the same formula in
//! Python, rows formatted `%.6f`), and `scripts/calibrate_shaper.py raw.csv -c cal.csv`
//! for the normalised rows.

use settle_identify::read::klipper_raw;
use settle_identify::welch::Welch;

/// 8,000 samples at 3,200 Hz from t = 10 s: a 47.3 Hz sine plus LCG noise on x, a 91 Hz
/// cosine plus gravity on y, a 12.5 Hz sine plus noise on z.
fn reference_csv() -> String {
    let fs = 3200.0;
    let mut s = String::from("#time,accel_x,accel_y,accel_z\n");
    let mut state: u64 = 12345;
    for i in 0..8000 {
        let t = 10.0 + i as f64 / fs;
        state = (state * 1_103_515_245 + 12345) % 2_147_483_648;
        let u = state as f64 / 2_147_483_648.0 - 0.5;
        let tau = i as f64 / fs;
        let x = 1500.0 * (2.0 * std::f64::consts::PI * 47.3 * tau).sin() + 200.0 * u;
        let y = 400.0 * (2.0 * std::f64::consts::PI * 91.0 * tau + 0.4).cos() + 9806.65;
        let z = -300.0 * (2.0 * std::f64::consts::PI * 12.5 * tau).sin() + 50.0 * u;
        s.push_str(&format!("{t:.6},{x:.6},{y:.6},{z:.6}\n"));
    }
    s
}

#[test]
fn psd_matches_klippers_calc_freq_response() {
    let rec = klipper_raw::parse("raw.csv", &reference_csv()).expect("parse");
    // Klipper: N 8000, fs 3200.3994098463477, 1025 bins of 1.562695024339037 Hz.
    assert!((rec.sample_rate_hz - 3200.3994098463477).abs() < 1e-9);
    let welch = Welch::klipper(rec.sample_rate_hz);
    assert_eq!(welch.nfft(), 2048);
    assert!((welch.bin_hz() - 1.562695024339037).abs() < 1e-12);
    let axes: Vec<&[f64]> = rec
        .accel_mm_s2
        .iter()
        .flatten()
        .map(Vec::as_slice)
        .collect();
    let psd: Vec<Vec<f64>> = axes.iter().map(|a| welch.psd(a).expect("psd")).collect();
    assert_eq!(psd[0].len(), 1025);
    // (bin, psd_x, psd_y, psd_z) from Klipper.
    let expected = [
        (
            0,
            34.646353291018556,
            0.36128871452767036,
            0.013185460416960566,
        ),
        (
            1,
            19.989892965306137,
            0.1978207824594623,
            0.05855082600277256,
        ),
        (
            8,
            2.2798874452757443,
            0.0005864089180358914,
            19648.825379236394,
        ),
        (
            30,
            442640.3206468313,
            0.0010395913707729792,
            0.1728209074036102,
        ),
        (
            31,
            231714.77900107656,
            0.0010853736300221867,
            0.15017711792071553,
        ),
        (
            58,
            2.7030335415743623,
            32229.77599613633,
            0.16047898502983585,
        ),
        (
            59,
            2.0691385070589905,
            15397.278729606738,
            0.135735948304977,
        ),
        (
            200,
            1.8638567740000787,
            0.00011923038656433231,
            0.11902083043568257,
        ),
        (
            1024,
            1.4928120858304734,
            4.183500599434755e-06,
            0.09231877923276172,
        ),
    ];
    for &(k, x, y, z) in &expected {
        for (got, want) in [(psd[0][k], x), (psd[1][k], y), (psd[2][k], z)] {
            // Tiny values are differences of large ones (gravity on y): compare to the scale.
            assert!(
                (got - want).abs() <= 1e-7 * want.abs() + 1e-9,
                "bin {k}: {got} vs {want}"
            );
        }
    }
    // calibrate_shaper.py's normalised psd_x at 46.9 Hz (bin 30): 9.422e+03.
    let f = welch.freqs_hz()[30];
    assert_eq!(format!("{:.3e}", psd[0][30] / (f + 0.1)), "9.422e3");
}
