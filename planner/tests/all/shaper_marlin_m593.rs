//! Marlin's stepper ZV of `M593 F D` (`marlin:m593`) against hand computation from
//! Marlin/src/module/stepper.cpp: `Stepper::set_shaping_damping_ratio` gives the echo
//! `factor2 = FLOOR(64.44056192 - 99.02008832 z - 7.58095488 z^2 + 43.073216 z^3)` of 128
//! (64 at z <= 0, 0 at z >= 1) and the step `factor1 = 128 - factor2`;
//! `Stepper::set_shaping_frequency` delays the echo by `STEPPER_TIMER_RATE / 2 / F` ticks,
//! half the undamped period.

use settle_planner::PlanError;
use settle_planner::shaper::{Shaper, ShaperType};

fn train(f: f64, z: f64) -> (Vec<f64>, Vec<f64>) {
    let s = Shaper::new(ShaperType::MarlinM593, f, z).expect("marlin:m593");
    (s.amplitudes().to_vec(), s.times_s().to_vec())
}

#[test]
fn damping_0_splits_the_step_in_halves_half_a_period_apart() {
    // z = 0: factor2 = 64, factor1 = 128 - 64 = 64: 64/128 = 0.5 each (Klipper's K = 1),
    // the echo at 1 / (2 * 40) = 0.0125 s.
    assert_eq!(train(40.0, 0.0), (vec![0.5, 0.5], vec![0.0, 0.0125]));
}

#[test]
fn damping_0_1_floors_the_cubic_to_54_of_128() {
    // z = 0.1: 64.44056192 - 9.902008832 - 7.58095488 * 0.01 + 43.073216 * 0.001
    //        = 64.44056192 - 9.902008832 - 0.0758095488 + 0.043073216 = 54.5058168...
    // floor 54: the echo 54/128 = 0.421875, the step 74/128 = 0.578125 (Klipper's
    // K / (1 + K) is 0.4217). The delay 1 / (2 * 50) = 0.01 s, where Klipper's zv waits
    // 0.01 / sqrt(1 - 0.01) = 0.0100504 s, 0.5 % longer.
    assert_eq!(
        train(50.0, 0.1),
        (vec![0.578125, 0.421875], vec![0.0, 0.01])
    );
    let klipper = Shaper::new(ShaperType::Zv, 50.0, 0.1).expect("zv");
    assert!((klipper.duration_s() / 0.01 - 1.0 / (1.0f64 - 0.01).sqrt()).abs() < 1e-12);
}

#[test]
fn damping_0_5_keeps_the_undamped_half_period() {
    // z = 0.5: 64.44056192 - 49.51004416 - 7.58095488 * 0.25 + 43.073216 * 0.125
    //        = 64.44056192 - 49.51004416 - 1.89523872 + 5.384152 = 18.41943104,
    // floor 18: [110, 18] / 128 = [0.859375, 0.140625]; the echo at 1 / (2 * 40) =
    // 0.0125 s, where Klipper's zv waits 0.0125 / sqrt(0.75) = 0.0144338 s (15.5 % later).
    assert_eq!(
        train(40.0, 0.5),
        (vec![0.859375, 0.140625], vec![0.0, 0.0125])
    );
    let klipper = Shaper::new(ShaperType::Zv, 40.0, 0.5).expect("zv");
    assert!((klipper.duration_s() - 0.0125 / 0.75f64.sqrt()).abs() < 1e-12);
}

#[test]
fn from_damping_0_8646_the_echo_floors_to_nothing() {
    // z = 0.95: 64.44056192 - 94.069083904 - 7.58095488 * 0.9025 + 43.073216 * 0.857375
    //         = 64.44056192 - 94.069083904 - 6.841811779 + 36.929898 = 0.45956...,
    // floor 0: factor1 = 128, the move runs unshaped.
    assert_eq!(train(40.0, 0.95), (vec![1.0], vec![0.0]));
    // The cubic crosses 1 between 0.864 (64.44056192 - 85.5533563 - 5.6591525 +
    // 27.7810417 = 1.00909...) and 0.865 (0.99354...); at 1 it is 0 by definition.
    assert_eq!(
        train(40.0, 0.864),
        (vec![127.0 / 128.0, 1.0 / 128.0], vec![0.0, 0.0125])
    );
    assert_eq!(train(40.0, 0.865), (vec![1.0], vec![0.0]));
    assert_eq!(train(40.0, 1.0), (vec![1.0], vec![0.0]));
    // M593 refuses D outside 0..=1 ("Zeta (D) value out of range").
    assert!(matches!(
        Shaper::new(ShaperType::MarlinM593, 40.0, 1.01),
        Err(PlanError::InvalidShaper { .. })
    ));
}

#[test]
fn the_name_is_marlin_m593() {
    let k = ShaperType::parse("marlin:m593").expect("parse");
    assert_eq!(k, ShaperType::MarlinM593);
    assert_eq!(k.to_string(), "marlin:m593");
    assert_ne!(ShaperType::parse("marlin:zv").expect("parse"), k);
    assert!(ShaperType::parse("marlin:m593(ftm_fs=1000)").is_err());
}
