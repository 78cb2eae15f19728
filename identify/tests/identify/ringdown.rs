//! Free decays after a move (RepRapFirmware M956, Klipper's ACCELEROMETER_MEASURE).

use settle_identify::read::{klipper_raw, rrf};
use settle_identify::{Method, Options, WeightBasis, identify_recording};

use crate::common::check_modes;
use crate::synth::{self, Truth};

/// A trapezoid move along printer Y (5,000 mm/s^2 for 35 ms, 20 ms cruise) starting
/// 0.1 s into a capture of `seconds`, sensor rotated.
fn ringdown_axes(truth: &[Truth], fs: f64, seconds: f64, seed: u64) -> [Vec<f64>; 3] {
    let move_ = synth::trapezoid(5_000.0, 0.035, 0.02);
    let n = (seconds * fs) as usize;
    let accel = synth::toolhead_accel(truth, &move_, 0.1, fs, n);
    let rot = synth::rotation(-70.0, 5.0, 15.0);
    synth::adxl345(&accel, [0.0, 1.0, 0.0], &rot, fs, seed)
}

#[test]
fn rrf_m956_ring_down_one_mode() {
    let truth = [(47.0, 0.04, 1.0)];
    let axes = ringdown_axes(&truth, 1344.0, 0.7, 11);
    let rec =
        rrf::parse("0:/sys/accelerometer/1.csv", &synth::rrf_csv(&axes, 1344)).expect("parse");
    let id = identify_recording(&rec, &Options::default()).expect("identify");
    assert_eq!(id.method, Method::RingDownFit);
    check_modes(&id, &truth, false);
    assert_eq!(id.modes[0].weight_basis, WeightBasis::AssumedSingleMode);
}

#[test]
fn rrf_m956_ring_down_two_modes() {
    let truth = [(41.0, 0.03, 0.6), (97.0, 0.025, 0.4)];
    let axes = ringdown_axes(&truth, 1344.0, 0.9, 12);
    let rec =
        rrf::parse("0:/sys/accelerometer/2.csv", &synth::rrf_csv(&axes, 1344)).expect("parse");
    let id = identify_recording(&rec, &Options::default()).expect("identify");
    check_modes(&id, &truth, false);
    assert!(
        id.modes
            .iter()
            .all(|m| m.weight_basis == WeightBasis::NotIdentified)
    );
}

#[test]
fn klipper_raw_ring_down_heavily_damped() {
    let truth = [(55.0, 0.15, 1.0)];
    let fs = 3200.0;
    let axes = ringdown_axes(&truth, fs, 0.6, 13);
    let rec = klipper_raw::parse(
        "adxl345-move.csv",
        &synth::klipper_raw_csv(&axes, 300.0, fs),
    )
    .expect("parse");
    let id = identify_recording(&rec, &Options::default()).expect("identify");
    assert_eq!(id.method, Method::RingDownFit);
    check_modes(&id, &truth, false);
}
