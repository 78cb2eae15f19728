//! Every firmware's shapers at the top of the damping range its command takes, against
//! impulse trains computed by hand from the firmware's formulas (the numbers below were
//! worked out from the closed forms in the comments, not by settle): the impulse times
//! increase and the weights sum to 1. Damping 0.9 at 40 Hz for the families whose
//! command takes it (Klipper's `zv`, `zvd`, `mzv` to 0.99, shaper_defs.py
//! `max_damping_ratio`; Marlin's M493 `I` to 1, M493.cpp; Prusa-Firmware-Buddy's M593 `D`
//! below 1, `input_shaper::get`), Klipper's `ei`, `2hump_ei` and `3hump_ei` at their own
//! maxima (0.4, 0.3, 0.2). A vibration tolerance at which a firmware's formula is no
//! number (Marlin's 2HEI at `Q0`, Buddy's 2HUMP_EI at `R` below 1) is refused.
//!
//! At damping 0.9: `df = sqrt(1 - 0.81) = 0.43588989`, `K = exp(-0.9 pi / df) =
//! 0.0015237558`, the damped period `t_d = 1 / (40 df) = 57.353933 ms`; MZV's decay
//! `K_m = exp(-0.75 * 0.9 pi / df)`.

use settle_planner::shaper::{MarlinShaper, PrusaShaper, Shaper, ShaperType};

fn assert_train(s: &Shaper, weights: &[f64], times_s: &[f64], time_tol_s: f64) {
    let what = format!(
        "{} at {} Hz, damping {}",
        s.shaper_type(),
        s.frequency_hz(),
        s.damping_ratio()
    );
    let w: Vec<f64> = s.weights().collect();
    assert_eq!(w.len(), weights.len(), "{what}: {w:?}");
    for (got, want) in w.iter().zip(weights) {
        assert!((got - want).abs() <= 1e-6, "{what}: weight {got} vs {want}");
    }
    assert!(
        (w.iter().sum::<f64>() - 1.0).abs() <= 1e-12,
        "{what}: {w:?}"
    );
    for (got, want) in s.times_s().iter().zip(times_s) {
        assert!(
            (got - want).abs() <= time_tol_s,
            "{what}: T {got} vs {want}"
        );
    }
    assert!(s.times_s().windows(2).all(|t| t[0] < t[1]), "{what}");
}

/// Klipper's formulas in double precision: times to 1e-12 s.
#[test]
fn klipper_at_the_top_of_each_damping_range() {
    let klipper = |kind, z| Shaper::new(kind, 40.0, z).expect("Klipper takes it");
    // zv: [1, K] at [0, t_d/2].
    assert_train(
        &klipper(ShaperType::Zv, 0.9),
        &[9.984785625e-01, 1.521437521e-03],
        &[0.0, 2.867696673e-02],
        1e-11,
    );
    // zvd: [1, 2K, K^2] at [0, t_d/2, t_d].
    assert_train(
        &klipper(ShaperType::Zvd, 0.9),
        &[9.969594397e-01, 3.038245498e-03, 2.314772131e-06],
        &[0.0, 2.867696673e-02, 5.735393347e-02],
        1e-11,
    );
    // mzv (n 3, t 0.75): [1 - sqrt2/2, (sqrt2 - 1) K_m, (1 - sqrt2/2) K_m^2] at
    // [0, 0.375, 0.75] t_d.
    assert_train(
        &klipper(ShaperType::Mzv { n: 3, t: 0.75 }, 0.9),
        &[9.891525718e-01, 1.078859315e-02, 5.883508034e-05],
        &[0.0, 2.150772505e-02, 4.301545010e-02],
        1e-11,
    );
    // ei at 0.4: a1, a3 and t2 the damping polynomials of shaper_defs.py with v_tol 0.05.
    assert_train(
        &klipper(ShaperType::Ei { v_tol: 0.05 }, 0.4),
        &[7.116017800e-01, 2.337855400e-01, 5.461268000e-02],
        &[0.0, 1.549029574e-02, 2.727723628e-02],
        1e-11,
    );
    // 2hump_ei at 0.3 and 3hump_ei at 0.2: the cubics of shaper_defs.py, times in 1/f.
    assert_train(
        &klipper(ShaperType::TwoHumpEi, 0.3),
        &[
            5.611107512e-01,
            2.888183882e-01,
            1.057587348e-01,
            4.431212586e-02,
        ],
        &[0.0, 1.663107000e-02, 2.827013500e-02, 3.739866250e-02],
        1e-11,
    );
    assert_train(
        &klipper(ShaperType::ThreeHumpEi, 0.2),
        &[
            3.861285576e-01,
            2.949863316e-01,
            1.772319595e-01,
            9.321823118e-02,
            4.843492012e-02,
        ],
        &[
            0.0,
            1.662519000e-02,
            2.876785000e-02,
            3.937530000e-02,
            5.027471000e-02,
        ],
        1e-11,
    );
    // Just past each maximum, Klipper refuses (`Too high value of damping_ratio`).
    for (kind, z) in [
        (ShaperType::Ei { v_tol: 0.05 }, 0.41),
        (ShaperType::TwoHumpEi, 0.31),
        (ShaperType::ThreeHumpEi, 0.21),
        (ShaperType::Zv, 0.995),
    ] {
        assert!(Shaper::new(kind, 40.0, z).is_err(), "{kind} at {z}");
    }
}

/// Marlin FT_MOTION (shaping.cpp `set_axis_shaping_A`/`_N`): the amplitudes normalised,
/// impulse `i` at `i N1` samples of `FTM_FS` = 1 kHz, `N1 = lroundf(base / f / df *
/// 1000)`: 28.677 -> 29 samples (base 0.5), 21.508 -> 22 (MZV's 0.375).
#[test]
fn marlin_ft_motion_at_damping_0_9() {
    let marlin = |shaper| Shaper::new(ShaperType::marlin(shaper), 40.0, 0.9).expect("M493 I0.9");
    let zv = [9.984785625e-01, 1.521437521e-03];
    let zvd = [9.969594397e-01, 3.038245498e-03, 2.314772131e-06];
    let n = |k: usize, samples: f64| -> Vec<f64> {
        (0..k).map(|i| i as f64 * samples / 1000.0).collect()
    };
    assert_train(&marlin(MarlinShaper::Zv), &zv, &n(2, 29.0), 1e-12);
    assert_train(&marlin(MarlinShaper::Zvd), &zvd, &n(3, 29.0), 1e-12);
    // ZVDD [1, 3K, 3K^2, K^3] and ZVDDD [1, 4K, 6K^2, 4K^3, K^4].
    assert_train(
        &marlin(MarlinShaper::Zvdd),
        &[
            9.954426282e-01,
            4.550434496e-03,
            6.933751050e-06,
            3.521781173e-09,
        ],
        &n(4, 29.0),
        1e-12,
    );
    assert_train(
        &marlin(MarlinShaper::Zvddd),
        &[
            9.939281245e-01,
            6.058015059e-03,
            1.384640356e-05,
            1.406569201e-08,
            5.358170019e-12,
        ],
        &n(5, 29.0),
        1e-12,
    );
    // MZV: [1, sqrt2 K, K^2] with ZV's K.
    assert_train(
        &marlin(MarlinShaper::Mzv),
        &[9.978474057e-01, 2.150277487e-03, 2.316833839e-06],
        &n(3, 22.0),
        1e-12,
    );
    // EI, 2HEI, 3HEI with Q 0.05: the closed forms (Buddy's, below).
    assert_train(
        &marlin(MarlinShaper::Ei),
        &[9.972480001e-01, 2.749684424e-03, 2.315442120e-06],
        &n(3, 29.0),
        1e-12,
    );
    assert_train(
        &marlin(MarlinShaper::TwoHei),
        &[
            9.967615508e-01,
            3.233518608e-03,
            4.927092799e-06,
            3.526447396e-09,
        ],
        &n(4, 29.0),
        1e-12,
    );
    assert_train(
        &marlin(MarlinShaper::ThreeHei),
        &[
            9.967839026e-01,
            3.209906720e-03,
            6.183207188e-06,
            7.452863498e-09,
            5.373565241e-12,
        ],
        &n(5, 29.0),
        1e-12,
    );
    // M493 takes Q0, where the 2HEI amplitude is 0 / 0: refused, not shaped with NaN.
    let q0 = ShaperType::Marlin {
        shaper: MarlinShaper::TwoHei,
        v_tol: 0.0,
        ftm_fs_hz: 1000,
    };
    let e = Shaper::new(q0, 40.0, 0.1)
        .expect_err("NaN amplitudes")
        .to_string();
    assert!(e.contains("Q") && e.contains("shaping.cpp"), "{e}");
    // The other EI shapers are numbers at Q0 and at Q1.
    for shaper in [MarlinShaper::Ei, MarlinShaper::ThreeHei] {
        for v_tol in [0.0, 1.0] {
            let kind = ShaperType::Marlin {
                shaper,
                v_tol,
                ftm_fs_hz: 1000,
            };
            let s = Shaper::new(kind, 40.0, 0.1).expect("a number");
            assert!((s.weights().sum::<f64>() - 1.0).abs() <= 1e-12, "{kind}");
        }
    }
}

/// Prusa-Firmware-Buddy (`input_shaper::get`, input_shaper.cpp) in single precision, its
/// times `[0, 1/2, 1, 3/2, 2] t_d` not rounded to a clock: to 5e-8 s (the damping 0.9 is
/// 0.89999998 as a float, which moves `t_d` by 1.1e-7 of itself, and each float product
/// rounds by 6e-8 of itself).
#[test]
fn prusa_ei_family_at_damping_0_9() {
    let prusa = |shaper| Shaper::new(ShaperType::prusa(shaper), 40.0, 0.9).expect("M593 D0.9");
    let t_d = 5.735393347e-02;
    assert_train(
        &prusa(PrusaShaper::Ei),
        &[9.972480001e-01, 2.749684424e-03, 2.315442120e-06],
        &[0.0, 0.5 * t_d, t_d],
        5e-8,
    );
    assert_train(
        &prusa(PrusaShaper::TwoHumpEi),
        &[
            9.967615508e-01,
            3.233518608e-03,
            4.927092799e-06,
            3.526447396e-09,
        ],
        &[0.0, 0.5 * t_d, t_d, 1.5 * t_d],
        5e-8,
    );
    assert_train(
        &prusa(PrusaShaper::ThreeHumpEi),
        &[
            9.967839026e-01,
            3.209906720e-03,
            6.183207188e-06,
            7.452863498e-09,
            5.373565241e-12,
        ],
        &[0.0, 0.5 * t_d, t_d, 1.5 * t_d, 2.0 * t_d],
        5e-8,
    );
    // M593 takes any R above 0; below 1 the tolerance 1/R is above 1 and 2HUMP_EI's
    // sqrt(1 - v^2) is no number: refused. EI and 3HUMP_EI stay numbers (EI's middle
    // impulse turns negative: (1 - v) K / 2 with v 2), and Buddy runs them so.
    let r_half = |shaper| ShaperType::Prusa { shaper, v_tol: 2.0 };
    let e = Shaper::new(r_half(PrusaShaper::TwoHumpEi), 40.0, 0.1)
        .expect_err("NaN amplitudes")
        .to_string();
    assert!(
        e.contains("M593 R") && e.contains("input_shaper.cpp"),
        "{e}"
    );
    let ei = Shaper::new(r_half(PrusaShaper::Ei), 40.0, 0.1).expect("a number");
    assert!(ei.amplitudes()[1] < 0.0, "{:?}", ei.amplitudes());
    assert!(Shaper::new(r_half(PrusaShaper::ThreeHumpEi), 40.0, 0.1).is_ok());
    // Damping 1 halts the printer (`bsod`): refused.
    assert!(Shaper::new(ShaperType::prusa(PrusaShaper::Ei), 40.0, 1.0).is_err());
}
