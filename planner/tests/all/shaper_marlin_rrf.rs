//! Marlin FT_MOTION and RepRapFirmware M593 shapers against their C++ formulas, written out
//! here independently in double precision (Marlin/src/module/ft_motion/shaping.cpp
//! `set_axis_shaping_A`/`_N`; RepRapFirmware src/Movement/AxisShaper.cpp `Configure`, 3.6
//! line). The firmwares compute the amplitudes in single precision, so the (normalised)
//! amplitudes agree to 1e-6 (RepRapFirmware's last amplitude is `1 - sum` of the others,
//! which collects their rounding); the impulse times are whole periods of the firmware's clock and agree
//! exactly.

use std::f64::consts::{PI, SQRT_2};

use settle_planner::PlanError;
use settle_planner::shaper::{MarlinShaper, RrfShaper, Shaper, ShaperType};

fn normalised(a: &[f64]) -> Vec<f64> {
    let s: f64 = a.iter().sum();
    a.iter().map(|x| x / s).collect()
}

fn assert_train(s: &Shaper, a: &[f64], t: &[f64], what: &str) {
    assert_eq!(s.amplitudes().len(), a.len(), "{what}");
    for (got, want) in s.amplitudes().iter().zip(a) {
        assert!((got - want).abs() <= 1e-6, "{what}: A {got} vs {want}");
    }
    for (got, want) in s.times_s().iter().zip(t) {
        assert!((got - want).abs() <= 1e-12, "{what}: T {got} vs {want}");
    }
}

#[test]
fn marlin_shapers_follow_shaping_cpp() {
    let fs = 1000.0;
    for (f, z, v) in [
        (40.0f64, 0.1f64, 0.05f64),
        (53.3, 0.05, 0.05),
        (71.0, 0.2, 0.1),
    ] {
        let df: f64 = (1.0 - z * z).sqrt();
        let k: f64 = (-z * PI / df).exp();
        // Samples between impulses: lroundf(base / f / df * FTM_FS).
        let n1 = |base: f64| (base / f / df * fs).round();
        for shaper in MarlinShaper::ALL {
            let x = {
                let v2 = v * v;
                (v2 * ((1.0 - v2).sqrt() + 1.0)).cbrt()
            };
            let (a, base) = match shaper {
                MarlinShaper::Zv => (vec![1.0, k], 0.5),
                MarlinShaper::Zvd => (vec![1.0, 2.0 * k, k * k], 0.5),
                MarlinShaper::Zvdd => (vec![1.0, 3.0 * k, 3.0 * k * k, k.powi(3)], 0.5),
                MarlinShaper::Zvddd => (
                    vec![1.0, 4.0 * k, 6.0 * k * k, 4.0 * k.powi(3), k.powi(4)],
                    0.5,
                ),
                MarlinShaper::Ei => (
                    vec![
                        (1.0 + v) / 4.0,
                        (1.0 - v) * k / 2.0,
                        (1.0 + v) * k * k / 4.0,
                    ],
                    0.5,
                ),
                MarlinShaper::TwoHei => {
                    let a1 = (3.0 * x * x + 2.0 * x + 3.0 * v * v) / (16.0 * x);
                    (
                        vec![a1, (0.5 - a1) * k, (0.5 - a1) * k * k, a1 * k.powi(3)],
                        0.5,
                    )
                }
                MarlinShaper::ThreeHei => {
                    let a1 = (1.0 + 3.0 * v + 2.0 * (2.0 * (v + 1.0) * v).sqrt()) / 16.0;
                    (
                        vec![
                            a1,
                            (1.0 - v) * k / 4.0,
                            ((1.0 + v) / 2.0 - 2.0 * a1) * k * k,
                            (1.0 - v) * k.powi(3) / 4.0,
                            a1 * k.powi(4),
                        ],
                        0.5,
                    )
                }
                MarlinShaper::Mzv => (vec![1.0, SQRT_2 * k, k * k], 0.375),
            };
            let t: Vec<f64> = (0..a.len()).map(|i| i as f64 * n1(base) / fs).collect();
            let kind = ShaperType::Marlin {
                shaper,
                v_tol: v,
                ftm_fs_hz: 1000,
            };
            let s = Shaper::new(kind, f, z).expect("marlin shaper");
            assert_train(&s, &normalised(&a), &t, &format!("{kind} {f} Hz zeta {z}"));
        }
    }
}

#[test]
fn marlin_rounds_times_to_its_trajectory_rate() {
    // 40 Hz, zeta 0.1: half a damped period is 12.563 ms; at FTM_FS = 1 kHz Marlin puts the
    // ZV's second impulse at 13 samples, and the MZV's at 9 and 18 (0.375 periods = 9.42).
    let zv = Shaper::new(ShaperType::marlin(MarlinShaper::Zv), 40.0, 0.1).expect("zv");
    assert_eq!(zv.times_s(), &[0.0, 0.013]);
    let mzv = Shaper::new(ShaperType::marlin(MarlinShaper::Mzv), 40.0, 0.1).expect("mzv");
    assert_eq!(mzv.times_s(), &[0.0, 0.009, 0.018]);
    // Rounding costs cancellation: Klipper's ZV leaves nothing at its frequency, Marlin's
    // 13 ms ZV leaves 5%.
    let klipper = Shaper::new(ShaperType::Zv, 40.0, 0.1).expect("zv");
    assert!(klipper.remaining_vibration(40.0, 0.1) < 1e-12);
    let left = zv.remaining_vibration(40.0, 0.1);
    assert!(left > 0.03 && left < 0.08, "{left}");
    // Marlin's MZV decays by ZV's factor K = exp(-zeta pi / df) over 0.375 periods, so
    // unlike Klipper's MZV it does not cancel its own mode even at FTM_FS = 1 MHz: it
    // leaves |1 + sqrt2 K e^{...} + K^2 e^{...}| / (1 + sqrt2 K + K^2) = 2.511% (this
    // closed form evaluated separately in double precision).
    let fine = ShaperType::Marlin {
        shaper: MarlinShaper::Mzv,
        v_tol: 0.05,
        ftm_fs_hz: 1_000_000,
    };
    let m = Shaper::new(fine, 40.0, 0.1).expect("mzv");
    let left = m.remaining_vibration(40.0, 0.1);
    assert!((left - 0.025109565184347895).abs() < 1e-5, "{left}");
    assert!(
        Shaper::new(ShaperType::MZV, 40.0, 0.1)
            .expect("k")
            .remaining_vibration(40.0, 0.1)
            < 1e-12
    );
    // M493's ranges: A up to FTM_FS/2, I from 0.01.
    let zvk = ShaperType::marlin(MarlinShaper::Zv);
    assert!(Shaper::new(zvk, 500.0, 0.1).is_ok());
    assert!(matches!(
        Shaper::new(zvk, 501.0, 0.1),
        Err(PlanError::InvalidShaper { .. })
    ));
    assert!(matches!(
        Shaper::new(zvk, 40.0, 0.0),
        Err(PlanError::InvalidShaper { .. })
    ));
}

#[test]
fn rrf_shapers_follow_axis_shaper_cpp() {
    let clock = 750_000.0f64;
    for (f, z) in [(40.0f64, 0.05f64), (57.1, 0.1), (33.3, 0.0)] {
        let s_: f64 = (1.0 - z * z).sqrt();
        // Damped period in step clocks, rounded (lrintf), and the integer divisions of it.
        let p = (clock / (f * s_)).round() as i64;
        let k: f64 = (-z * PI / s_).exp();
        let km: f64 = (-z * 0.75 * PI / s_).exp();
        let ticks = |d: &[i64]| d.iter().map(|&d| d as f64 / clock).collect::<Vec<f64>>();
        let cubic = |c: [f64; 4]| c[0] + c[1] * z + c[2] * z * z + c[3] * z * z * z;
        let last_is_rest = |mut a: Vec<f64>| {
            a.push(1.0 - a.iter().sum::<f64>());
            a
        };
        for shaper in RrfShaper::ALL {
            let (a, d): (Vec<f64>, Vec<i64>) = match shaper {
                RrfShaper::Zvd => (normalised(&[1.0, 2.0 * k, k * k]), vec![0, p / 2, p]),
                RrfShaper::Zvdd => (
                    normalised(&[1.0, 3.0 * k, 3.0 * k * k, k.powi(3)]),
                    vec![0, p / 2, p, 3 * p / 2],
                ),
                RrfShaper::Zvddd => (
                    normalised(&[1.0, 4.0 * k, 6.0 * k * k, 4.0 * k.powi(3), k.powi(4)]),
                    vec![0, p / 2, p, 3 * p / 2, 2 * p],
                ),
                RrfShaper::Mzv => {
                    let a1 = 1.0 - SQRT_2 / 2.0;
                    // Reverse order: a3, a2, a1.
                    (
                        normalised(&[a1 * km * km, (SQRT_2 - 1.0) * km, a1]),
                        vec![0, 3 * p / 8, 2 * (3 * p / 8)],
                    )
                }
                RrfShaper::Ei2 => (
                    last_is_rest(vec![
                        cubic([0.16054, 0.76699, 2.26560, -1.22750]),
                        cubic([0.33911, 0.45081, -2.58080, 1.73650]),
                        cubic([0.34089, -0.61533, -0.68765, 0.42261]),
                    ]),
                    [
                        [0.0; 4],
                        [0.49890, 0.16270, -0.54262, 6.16180],
                        [0.99748, 0.18382, -1.58270, 8.17120],
                        [1.49920, -0.09297, -0.28338, 1.85710],
                    ]
                    .map(|c| (cubic(c) * p as f64).round() as i64)
                    .to_vec(),
                ),
                RrfShaper::Ei3 => (
                    last_is_rest(vec![
                        cubic([0.11275, 0.76632, 3.29160, -1.44380]),
                        cubic([0.23698, 0.61164, -2.57850, 4.85220]),
                        cubic([0.30008, -0.19062, -2.14560, 0.13744]),
                        cubic([0.23775, -0.73297, 0.46885, -2.08650]),
                    ]),
                    [
                        [0.0; 4],
                        [0.49974, 0.23834, 0.44559, 12.4720],
                        [0.99849, 0.29808, -2.36460, 23.3990],
                        [1.49870, 0.10306, -2.01390, 17.0320],
                        [1.99960, -0.28231, 0.61536, 5.40450],
                    ]
                    .map(|c| (cubic(c) * p as f64).round() as i64)
                    .to_vec(),
                ),
            };
            let kind = ShaperType::rrf(shaper);
            let s = Shaper::new(kind, f, z).expect("rrf shaper");
            assert_train(&s, &a, &ticks(&d), &format!("{kind} {f} Hz zeta {z}"));
        }
    }
}

#[test]
fn rrf_hand_computed_zvd_and_mzv_order() {
    // 40 Hz, zeta 0.05 (RepRapFirmware 3.6's default damping): the damped period is
    // 750000 / (40 sqrt(1 - 0.0025)) = 18773.48 step clocks -> 18773; ZVD delays 0, 9386,
    // 18773 ticks of 1/750 kHz.
    let s = Shaper::new(ShaperType::rrf(RrfShaper::Zvd), 40.0, 0.05).expect("zvd");
    assert_eq!(s.times_s(), &[0.0, 9386.0 / 750_000.0, 18773.0 / 750_000.0]);
    // RepRapFirmware's MZV applies Klipper's amplitudes last-first: undamped it is
    // Klipper's MZV (up to tick rounding), damped it leaves several percent at the very
    // mode it is tuned to.
    let rrf = Shaper::new(ShaperType::rrf(RrfShaper::Mzv), 40.0, 0.1).expect("mzv");
    let klipper = Shaper::new(ShaperType::MZV, 40.0, 0.1).expect("mzv");
    let w: Vec<f64> = rrf.weights().collect();
    let wk: Vec<f64> = klipper.weights().collect();
    for i in 0..3 {
        assert!((w[i] - wk[2 - i]).abs() < 1e-6, "{w:?} vs {wk:?}");
    }
    assert!(klipper.remaining_vibration(40.0, 0.1) < 1e-12);
    assert!(rrf.remaining_vibration(40.0, 0.1) > 0.1);
    let undamped = Shaper::new(ShaperType::rrf(RrfShaper::Mzv), 40.0, 0.0).expect("mzv");
    assert!(undamped.remaining_vibration(40.0, 0.0) < 1e-3);
    // M593 ranges: F 5.72..=1000 Hz on a 750 kHz step clock, S 0..=0.99.
    let k = ShaperType::rrf(RrfShaper::Zvd);
    assert!(Shaper::new(k, 5.7, 0.1).is_err() && Shaper::new(k, 5.73, 0.1).is_ok());
    assert!(Shaper::new(k, 1000.0, 0.1).is_ok() && Shaper::new(k, 1000.5, 0.1).is_err());
    assert!(Shaper::new(k, 40.0, 0.99).is_ok() && Shaper::new(k, 40.0, 0.995).is_err());
}

#[test]
fn rrf_ei_past_the_fit_run_as_the_firmware_sums_them() {
    // RepRapFirmware src/Movement/AxisShaper.cpp at 8875b7ec447dd29399433711d6b686d4ad587318
    // (3.6-dev), `AxisShaper::Configure`, worked by hand at 40 Hz on the 750 kHz step
    // clock: damped period P = lrintf(750000 / (40 sqrt(1 - S^2))) (19137 ticks at S0.2,
    // 21651 at S0.5, 43015 at S0.9, 132915 at S0.99), amplitudes the damping cubics (the
    // last 1 - the others), delays lrintf(cubic * P). M593 takes S up to 0.99; from about
    // S0.41 (ei3) and S0.47 (ei2) the delays come out of order. At S0.5 the firmware's
    // `ei3` is amplitudes 1.1383350, 0.5047000, -0.3144500, -0.2723350, -0.0562499 at
    // delays 0, 49566, 75373, 68758, 58195 ticks (e.g. the second: 0.49974 + 0.23834/2 +
    // 0.44559/4 + 12.4720/8 = 2.28932 periods, 49566 ticks), and its `ei2` 0.9569975,
    // 0.1363775, -0.0858613, -0.0075138 at 0, 26302, 37134, 34945. The firmware adds
    // each impulse's copy of a move at its own delay into one time-ordered list
    // (`Move::AddLinearSegments` and `Move::AddSegment`, src/Movement/Move.cpp), so the
    // motion is the same train in time order, written here sorted by delay. S0.2 is in
    // the fit's range and already in order.
    let clock = 750_000.0f64;
    let cases: [(RrfShaper, f64, &[f64], &[i64]); 8] = [
        (
            RrfShaper::Ei2,
            0.2,
            &[0.3947420, 0.3399320, 0.1936989, 0.0716271],
            &[0, 10698, 19832, 28402],
        ),
        (
            RrfShaper::Ei2,
            0.5,
            &[0.9569975, 0.1363775, -0.0075138, -0.0858613],
            &[0, 26302, 34945, 37134],
        ),
        (
            RrfShaper::Ei2,
            0.9,
            &[1.7911195, -0.2495983, -0.0797005, -0.4618208],
            &[0, 109250, 202074, 251110],
        ),
        (
            RrfShaper::Ei2,
            0.99,
            &[1.9493326, -0.3580322, -0.0591059, -0.5321944],
            &[0, 389622, 811704, 1004407],
        ),
        (
            RrfShaper::Ei3,
            0.2,
            &[0.3861276, 0.2949856, 0.1772315, 0.0932180, 0.0484372],
            &[0, 12726, 22021, 30141, 38484],
        ),
        (
            RrfShaper::Ei3,
            0.5,
            &[1.1383350, 0.5047000, -0.0562499, -0.2723350, -0.3144500],
            &[0, 49566, 58195, 68758, 75373],
        ),
        (
            RrfShaper::Ei3,
            0.9,
            &[2.4161036, -0.5797954, 2.2361245, -1.5632129, -1.5092201],
            &[0, 265998, 437345, 532376, 705846],
        ),
        (
            RrfShaper::Ei3,
            0.99,
            &[2.6965864, -0.8089089, 3.0234008, -2.0528994, -1.8581785],
            &[0, 1005796, 1764312, 2146981, 2881607],
        ),
    ];
    for (shaper, z, a, d) in cases {
        let kind = ShaperType::rrf(shaper);
        let s = Shaper::new(kind, 40.0, z).unwrap_or_else(|e| panic!("{kind} S{z}: {e}"));
        let t: Vec<f64> = d.iter().map(|&d| d as f64 / clock).collect();
        assert_train(&s, a, &t, &format!("{kind} 40 Hz S{z}"));
    }
    // What these trains leave of the 40 Hz mode of their own damping (Klipper's estimate
    // `|sum A_i e^(-zeta w (T_N - T_i)) e^(i w_d T_i)| / sum A_i` over the impulses above,
    // worked apart in double precision): 11.3% for ei2 at S0.5, 29.2% for ei3 at S0.5 and
    // 150.9% for ei3 at S0.9, more than no shaping leaves.
    for (shaper, z, left) in [
        (RrfShaper::Ei2, 0.5, 0.11278),
        (RrfShaper::Ei3, 0.5, 0.29203),
        (RrfShaper::Ei3, 0.9, 1.50922),
    ] {
        let s = Shaper::new(ShaperType::rrf(shaper), 40.0, z).expect("rrf shaper");
        let got = s.remaining_vibration(40.0, z);
        assert!(
            (got - left).abs() < 1e-4,
            "{shaper:?} S{z}: {got} vs {left}"
        );
    }
    // Two delays on the same tick are one impulse: `ei3` at 100 Hz, S0.5629 (P 9074) has
    // amplitudes 1.3295622, 0.6296889, -0.4625535, -0.3984257, -0.0982720 at delays 0,
    // 27218, 41654, 35900, 27218: the second and the last add up to 0.5314169.
    let s = Shaper::new(ShaperType::rrf(RrfShaper::Ei3), 100.0, 0.5629).expect("ei3");
    let t: Vec<f64> = [0, 27218, 35900, 41654].map(|d| d as f64 / clock).to_vec();
    assert_train(
        &s,
        &[1.3295622, 0.5314169, -0.3984257, -0.4625535],
        &t,
        "ei3 100 Hz S0.5629",
    );
}
