//! The modal plant's partial-step transition (scaled Taylor series and squaring) against
//! the matrix exponential of the same augmented system (nalgebra's Pade `expm`, the path
//! every step took before): equal to rounding over random step lengths, start positions
//! and the shipped machines' axes.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use settle_planner::State;
use settle_sim::machine::{AxisMachine, Screw, Transmission};
use settle_sim::{AxisModel, DriverMode, ModalPlant, Mode, Plant};

use crate::common::{printer_preset, stage_x};

/// The `leadscrew_stage` preset (scenarios/machines/leadscrew_stage.toml): the stage of
/// the fixtures with its driver at 1.2 A rms and 48 V.
fn leadscrew_preset() -> AxisMachine {
    let mut a = stage_x();
    a.driver.run_current_a_rms = 1.2;
    a.driver.supply_v = 48.0;
    assert!(matches!(
        a.transmission,
        Transmission::Screw(Screw { lead_mm: 5.0, .. })
    ));
    a
}

/// The axes to check, by name: the two presets' axes (linear driver) and the single
/// 40 Hz mode of the mode-described scenarios (scenarios/quickstart.toml), two modes of
/// different damping and five modes (every state size the step handles apart, and one
/// beyond).
fn axes() -> Vec<(String, AxisModel)> {
    let mut out = Vec::new();
    for (name, m) in [
        ("printer_xy x", printer_preset(false)),
        ("printer_xy y", printer_preset(true)),
        ("leadscrew_stage x", leadscrew_preset()),
    ] {
        out.push((
            name.to_string(),
            m.compile(DriverMode::Linear).expect("compile"),
        ));
    }
    let one = [Mode::new(40.0, 0.05, 1.0).expect("mode")];
    let two = [
        Mode::new(39.0, 0.05, 0.7).expect("mode"),
        Mode::new(145.0, 0.1, 0.3).expect("mode"),
    ];
    // More bodies than the fixed-size paths take.
    let five: Vec<Mode> = (0..5)
        .map(|i| Mode::new(30.0 + 70.0 * i as f64, 0.03 + 0.02 * i as f64, 0.2).expect("mode"))
        .collect();
    for (name, modes) in [
        ("40 Hz mode", &one[..]),
        ("39 + 145 Hz modes", &two[..]),
        ("five modes", &five[..]),
    ] {
        out.push((
            name.to_string(),
            AxisModel::from_modes("x", modes).expect("axis"),
        ));
    }
    out
}

/// `max |fast - expm| / max |expm|` over the entries of the transitions (first `rows`
/// rows, by column of `rows` rounded up to 4 entries) in the balanced coordinates of
/// `scale` (entry `(i, j)` times `scale_i / scale_j`): the normwise relative error by
/// which a matrix exponential's accuracy is judged (a tiny entry, a coupling over a short
/// step, is only as exact as the matrix's size allows, in either path).
fn normwise_relative(fast: &[f64], expm: &[f64], scale: &[f64], rows: usize) -> f64 {
    assert_eq!(fast.len(), expm.len());
    let stride = rows.div_ceil(4) * 4;
    assert_eq!(expm.len(), stride * scale.len());
    let (mut diff, mut size) = (0.0f64, 0.0f64);
    for (j, sj) in scale.iter().enumerate() {
        for (i, si) in scale.iter().enumerate().take(rows) {
            let (f, e) = (fast[j * stride + i], expm[j * stride + i]);
            diff = diff.max((f - e).abs() * si / sj);
            size = size.max(e.abs() * si / sj);
        }
    }
    diff / size
}

#[test]
fn partial_step_transition_equals_the_matrix_exponential() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut report = Vec::new();
    for (name, axis) in axes() {
        let n = axis.lumped.dof();
        let plant = ModalPlant::new(vec![axis], 1e-4).expect("plant");
        let mut worst = 0.0f64;
        for _ in 0..20 {
            // Linearised somewhere on the travel (+-0.15 m).
            let start = State {
                p: rng.random_range(-0.15..0.15),
                ..State::default()
            };
            let state = plant.initial_state(&[start]).expect("state");
            for _ in 0..25 {
                // Log-uniform from 1 us to 20 ms: within one 10 kHz sample (Taylor alone)
                // and beyond the 2 kHz sample of `settle gcode` (halved and squared).
                let dt = 10f64.powf(rng.random_range(-6.0..-1.7));
                let [fast, expm, scale] = ModalPlant::partial_transition(&state, 0, dt);
                let rel = normwise_relative(&fast, &expm, &scale, 2 * n);
                assert!(
                    rel <= 1e-13,
                    "{name}: dt {dt:.3e} s: relative error {rel:.2e}"
                );
                worst = worst.max(rel);
            }
        }
        report.push(format!("{name}: {worst:.1e}"));
    }
    eprintln!("worst normwise relative difference: {report:?}");
}

/// A plant linearised at a given position ([`ModalPlant::linearised_at`]) and started
/// elsewhere steps the deflection exactly as a plant started at rest at that position: the
/// same discretisation, and the command's position never enters the deflection's
/// equations (only its velocity, acceleration and jerk do), so bit for bit over a move of
/// X on `printer_xy` (3 m/s^2 up, then down, 20 ms). Linearised at its own start instead
/// (the origin, the middle of the belt's travel, where it is 3.6 % softer than at
/// 110 mm), the same move deflects the machine differently.
#[test]
fn a_plant_linearised_at_a_point_rings_as_one_started_there() {
    let axes = vec![
        printer_preset(false)
            .compile(DriverMode::Linear)
            .expect("compile"),
    ];
    let dt = 1e-4;
    let at = 0.11;
    let plant = |lin: Option<f64>| {
        let p = ModalPlant::new(axes.clone(), dt).expect("plant");
        match lin {
            Some(x) => p.linearised_at(vec![x]).expect("point"),
            None => p,
        }
    };
    let run = |plant: &ModalPlant, start: f64| {
        let mut st = plant
            .initial_state(&[State {
                p: start,
                ..State::default()
            }])
            .expect("state");
        let (mut p, mut v) = (start, 0.0);
        for i in 0..200 {
            let a = if i < 100 { 3.0 } else { -3.0 };
            let cmd = settle_planner::Sample { p, v, a, j: 0.0 };
            plant.step(&mut st, &[cmd], dt).expect("steps");
            p += v * dt + a * dt * dt / 2.0;
            v += a * dt;
        }
        st.axes[0].r().to_vec()
    };
    let there = run(&plant(None), at);
    let here = run(&plant(Some(at)), 0.0);
    assert!(there.iter().any(|r| r.abs() > 1e-7), "{there:?}");
    assert_eq!(
        here.iter().map(|r| r.to_bits()).collect::<Vec<_>>(),
        there.iter().map(|r| r.to_bits()).collect::<Vec<_>>()
    );
    let own = run(&plant(None), 0.0);
    let diff = own
        .iter()
        .zip(&there)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(
        diff > 1e-3 * there.iter().fold(0.0f64, |m, r| m.max(r.abs())),
        "{diff}"
    );
    assert!(
        ModalPlant::new(axes.clone(), dt)
            .expect("plant")
            .linearised_at(vec![])
            .is_err()
    );
    assert!(
        ModalPlant::new(axes, dt)
            .expect("plant")
            .linearised_at(vec![f64::NAN])
            .is_err()
    );
}
