//! Prusa-Firmware-Buddy: its `M593` shapers against the formulas of
//! lib/Marlin/Marlin/src/feature/input_shaper/input_shaper.cpp (`input_shaper::get`),
//! written out here in double precision, and its precise stepping's trapezoid
//! (lib/Marlin/Marlin/src/feature/precise_stepping/precise_stepping.cpp,
//! `append_move_segments_to_queue`) against the same trapezoid computed by hand.

use std::f64::consts::{PI, SQRT_2};

use settle_planner::firmware::marlin::{MarlinConfig, MarlinPlanner, MarlinStepper};
use settle_planner::shaper::{MarlinShaper, PrusaShaper, Shaper, ShaperType};

use super::firmware_common::{MM, assert_rel, plan_with, xy};

fn normalised(a: &[f64]) -> Vec<f64> {
    let s: f64 = a.iter().sum();
    a.iter().map(|x| x / s).collect()
}

/// Weights agree to single precision (Buddy computes in `float`), and times too (1e-7 s,
/// a relative 1e-6 of a shaper's 10 to 40 ms).
fn assert_train(s: &Shaper, a: &[f64], t: &[f64], what: &str) {
    let w: Vec<f64> = s.weights().collect();
    assert_eq!(w.len(), a.len(), "{what}");
    for (got, want) in w.iter().zip(normalised(a)) {
        assert!((got - want).abs() <= 1e-6, "{what}: A {got} vs {want}");
    }
    for (got, want) in s.times_s().iter().zip(t) {
        assert!((got - want).abs() <= 1e-7, "{what}: T {got} vs {want}");
    }
}

#[test]
fn m593_t2_is_buddys_mzv() {
    // `M593 Y T2 F40.6` (the MK4's Y default) and T2 at 50 Hz, damping 0.1 (`D` default):
    // Buddy's MZV, K = exp(-0.75 zeta pi / df), [1 - 1/sqrt2, (sqrt2 - 1) K, a1 K^2] at
    // [0, 0.375, 0.75] t_d. settle runs Klipper's `mzv` for T2.
    let z: f64 = 0.1;
    for f in [40.6, 50.0] {
        let df = (1.0 - z * z).sqrt();
        let k = (-0.75 * z * PI / df).exp();
        let t_d = 1.0 / (f * df);
        let a1 = 1.0 - 1.0 / SQRT_2;
        let a = [a1, (SQRT_2 - 1.0) * k, a1 * k * k];
        let t = [0.0, 0.375 * t_d, 0.75 * t_d];
        let s = Shaper::new(ShaperType::MZV, f, z).expect("mzv");
        assert_train(&s, &a, &t, &format!("T2 at {f} Hz"));
    }
    // The worked value: MZV at 50 Hz, zeta 0.1 -> .3651, .4075, .2274 at 0, 7.538, 15.076 ms.
    let s = Shaper::new(ShaperType::MZV, 50.0, 0.1).expect("mzv");
    let w: Vec<f64> = s.weights().collect();
    for (got, want) in w.iter().zip([0.3651, 0.4075, 0.2274]) {
        assert!((got - want).abs() < 5e-5, "{got} vs {want}");
    }
    for (got, want) in s.times_s().iter().zip([0.0, 7.538e-3, 15.076e-3]) {
        assert!((got - want).abs() < 5e-7, "{got} vs {want}");
    }
}

#[test]
fn m593_t0_t1_are_klippers_zv_and_zvd() {
    let (f, z): (f64, f64) = (47.0, 0.07);
    let df = (1.0 - z * z).sqrt();
    let k = (-z * PI / df).exp();
    let t_d = 1.0 / (f * df);
    let zv = Shaper::new(ShaperType::Zv, f, z).expect("zv");
    assert_train(&zv, &[1.0, k], &[0.0, 0.5 * t_d], "T0");
    let zvd = Shaper::new(ShaperType::Zvd, f, z).expect("zvd");
    assert_train(&zvd, &[1.0, 2.0 * k, k * k], &[0.0, 0.5 * t_d, t_d], "T1");
}

#[test]
fn m593_t3_to_t5_are_buddys_closed_forms() {
    // EI at 50 Hz, damping 0.1, R 20 (v = 0.05): [(1+v)/4, (1-v)K/2, (1+v)K^2/4] at
    // [0, 1/2, 1] t_d = .35071, .46279, .18651 at 0, 10.050, 20.101 ms.
    let (f, z, v): (f64, f64, f64) = (50.0, 0.1, 0.05);
    let df = (1.0 - z * z).sqrt();
    let k = (-z * PI / df).exp();
    let t_d = 1.0 / (f * df);
    let ei = Shaper::new(ShaperType::prusa(PrusaShaper::Ei), f, z).expect("ei");
    let a1 = 0.25 * (1.0 + v);
    assert_train(
        &ei,
        &[a1, 0.5 * (1.0 - v) * k, a1 * k * k],
        &[0.0, 0.5 * t_d, t_d],
        "T3",
    );
    let w: Vec<f64> = ei.weights().collect();
    for (got, want) in w.iter().zip([0.35071, 0.46279, 0.18651]) {
        assert!((got - want).abs() < 5e-6, "{got} vs {want}");
    }
    // Klipper's current `ei` (damping polynomials) is another shaper.
    let klipper = Shaper::new(ShaperType::EI, f, z).expect("ei");
    assert!((klipper.times_s()[1] - ei.times_s()[1]).abs() > 1e-5);

    let v2 = v * v;
    let x = (v2 * ((1.0 - v2).sqrt() + 1.0)).powf(1.0 / 3.0);
    let b1 = (3.0 * x * x + 2.0 * x + 3.0 * v2) / (16.0 * x);
    let b2 = (0.5 - b1) * k;
    let two = Shaper::new(ShaperType::prusa(PrusaShaper::TwoHumpEi), f, z).expect("2hump");
    assert_train(
        &two,
        &[b1, b2, b2 * k, b1 * k * k * k],
        &[0.0, 0.5 * t_d, t_d, 1.5 * t_d],
        "T4",
    );
    let c1 = 0.0625 * (1.0 + 3.0 * v + 2.0 * (2.0 * (v + 1.0) * v).sqrt());
    let c2 = 0.25 * (1.0 - v) * k;
    let three = Shaper::new(ShaperType::prusa(PrusaShaper::ThreeHumpEi), f, z).expect("3hump");
    assert_train(
        &three,
        &[
            c1,
            c2,
            (0.5 * (1.0 + v) - 2.0 * c1) * k * k,
            c2 * k * k,
            c1 * k.powi(4),
        ],
        &[0.0, 0.5 * t_d, t_d, 1.5 * t_d, 2.0 * t_d],
        "T5",
    );
    // Marlin FT_MOTION's EI family has the same amplitudes, at times rounded to its 1 kHz.
    for (p, m) in [
        (PrusaShaper::Ei, MarlinShaper::Ei),
        (PrusaShaper::TwoHumpEi, MarlinShaper::TwoHei),
        (PrusaShaper::ThreeHumpEi, MarlinShaper::ThreeHei),
    ] {
        let a = Shaper::new(ShaperType::prusa(p), f, z).expect("prusa");
        let b = Shaper::new(ShaperType::marlin(m), f, z).expect("marlin");
        for (x, y) in a.weights().zip(b.weights()) {
            assert!((x - y).abs() < 1e-6, "{p:?}: {x} vs {y}");
        }
    }
    // `R` 10: tolerance 0.1.
    let r10 = ShaperType::Prusa {
        shaper: PrusaShaper::Ei,
        v_tol: 0.1,
    };
    let s = Shaper::new(r10, f, z).expect("ei");
    assert!((s.amplitudes()[0] - 0.275).abs() < 1e-7);
}

#[test]
fn prusa_names_parse_back() {
    for p in PrusaShaper::ALL {
        let kind = ShaperType::prusa(p);
        assert_eq!(ShaperType::parse(&kind.name()).expect("parse"), kind);
        assert_eq!(kind.firmware().name(), "prusa");
    }
    let k = ShaperType::parse("prusa:3hump_ei(v_tol=0.1)").expect("parse");
    assert_eq!(k.name(), "prusa:3hump_ei(v_tol=0.1)");
    assert!(ShaperType::parse("prusa:mzv").is_err());
    assert!(ShaperType::parse("prusa:ei(v_tol=0)").is_err());
    assert!(Shaper::new(ShaperType::prusa(PrusaShaper::Ei), 40.0, 1.0).is_err());
}

#[test]
fn precise_stepping_runs_the_blocks_trapezoid_in_mm() {
    // One 10 mm move at 100 mm/s on the MK4's settings (1250 mm/s^2, 400 mini-steps per
    // mm): from and to MINIMUM_PLANNER_SPEED (0.05 mm/s) at 1250 mm/s^2, 3.999999 mm
    // each way, 2.000002 mm at 100 mm/s.
    let cfg = MarlinConfig::prusa_mk4();
    let (a, v, v0) = (1250.0, 100.0, 0.05);
    let ramp_mm = (v * v - v0 * v0) / (2.0 * a);
    let want = 2.0 * (v - v0) / a + (10.0 - 2.0 * ramp_mm) / v;
    let (planned, t) = plan_with(
        &mut MarlinPlanner::new(cfg).expect("config"),
        &[xy([0.0, 0.0], [10.0, 0.0], v)],
    );
    assert_eq!(planned.len(), 1);
    let p = &planned[0];
    assert_rel("print time", t, want, 1e-12);
    assert_rel("start speed", p.start_speed_m_s, v0 * MM, 1e-12);
    assert_rel("end speed", p.end_speed_m_s, v0 * MM, 1e-12);
    assert_rel("acceleration", p.accel_m_s2, a * MM, 1e-12);
    assert_rel("cruise", p.cruise_t_s, (10.0 - 2.0 * ramp_mm) / v, 1e-12);
    // Marlin's stepper on the same settings starts at MINIMAL_STEP_RATE, 120 steps/s
    // (0.3 mm/s at 400 per mm), and ends its ramps at step counts.
    let marlin = MarlinConfig {
        stepper: MarlinStepper::Stepper,
        ..cfg
    };
    let (planned, _) = plan_with(
        &mut MarlinPlanner::new(marlin).expect("config"),
        &[xy([0.0, 0.0], [10.0, 0.0], v)],
    );
    assert_rel("stepper start", planned[0].start_speed_m_s, 0.3 * MM, 1e-9);

    // Too short to reach the nominal speed: the ramps meet at
    // v^2 = v0^2 + a L (equal entry and exit), 0.5 mm at 100 mm/s.
    let (planned, t) = plan_with(
        &mut MarlinPlanner::new(cfg).expect("config"),
        &[xy([0.0, 0.0], [0.5, 0.0], v)],
    );
    let peak = (v0 * v0 + a * 0.5f64).sqrt();
    assert_rel("peak", planned[0].cruise_speed_m_s, peak * MM, 1e-9);
    assert_rel("short time", t, 2.0 * (peak - v0) / a, 1e-9);
}

/// Each printer's settings as Prusa-Firmware-Buddy (commit 818d812f) ships them, typed
/// from its include/marlin/Configuration_<printer>.h: `DEFAULT_AXIS_STEPS_PER_UNIT` (times
/// the planner's 4 mini-steps, lib/Marlin/Marlin/src/module/planner.h),
/// `DEFAULT_MAX_FEEDRATE` capped by `HWLIMIT_NORMAL_MAX_FEEDRATE`,
/// `DEFAULT_MAX_ACCELERATION`, `DEFAULT_ACCELERATION`, `DEFAULT_RETRACT_ACCELERATION`,
/// `DEFAULT_TRAVEL_ACCELERATION`, `DEFAULT_XJERK`..`DEFAULT_EJERK`, `COREXY`.
#[test]
fn each_prusa_printer_has_its_configuration_h() {
    use settle_planner::firmware::Kinematics;
    use settle_planner::firmware::marlin::{MarlinJerk, PrusaModel};
    struct Want {
        model: PrusaModel,
        steps: [f64; 4],
        feed: [f64; 4],
        accel: [f64; 4],
        print_retract_travel: [f64; 3],
        e_jerk: f64,
        corexy: bool,
    }
    let wants = [
        Want {
            // MINI: feed 180/180/12/80 under the caps 400/400/12/80.
            model: PrusaModel::Mini,
            steps: [100.0, 100.0, 400.0, 325.0],
            feed: [180.0, 180.0, 12.0, 80.0],
            accel: [1250.0, 1250.0, 400.0, 4000.0],
            print_retract_travel: [1250.0, 1250.0, 1250.0],
            e_jerk: 10.0,
            corexy: false,
        },
        Want {
            // MK3.5: feed 200/200/40/45 capped by 300/300/12/120 (Z 12); E 266 steps.
            model: PrusaModel::Mk3_5,
            steps: [100.0, 100.0, 400.0, 266.0],
            feed: [200.0, 200.0, 12.0, 45.0],
            accel: [1250.0, 1250.0, 400.0, 4000.0],
            print_retract_travel: [1250.0, 1250.0, 1250.0],
            e_jerk: 5.0,
            corexy: false,
        },
        Want {
            // MK4: feed 400/400/40/50 capped by 300/300/40/100.
            model: PrusaModel::Mk4,
            steps: [100.0, 100.0, 400.0, 380.0],
            feed: [300.0, 300.0, 40.0, 50.0],
            accel: [1250.0, 1250.0, 200.0, 1500.0],
            print_retract_travel: [1250.0, 800.0, 1250.0],
            e_jerk: 5.0,
            corexy: false,
        },
        Want {
            // XL: feed 550/550/12/45 capped by 460/460/20/100.
            model: PrusaModel::Xl,
            steps: [80.0, 80.0, 800.0, 380.0],
            feed: [460.0, 460.0, 12.0, 45.0],
            accel: [5000.0, 5000.0, 200.0, 1500.0],
            print_retract_travel: [1800.0, 1200.0, 5000.0],
            e_jerk: 5.0,
            corexy: true,
        },
        Want {
            // CORE One: feed 350/350/30/50 under the caps 350/350/35/100.
            model: PrusaModel::CoreOne,
            steps: [100.0, 100.0, 400.0, 380.0],
            feed: [350.0, 350.0, 30.0, 50.0],
            accel: [10000.0, 10000.0, 1000.0, 1500.0],
            print_retract_travel: [1250.0, 1250.0, 1500.0],
            e_jerk: 5.0,
            corexy: true,
        },
    ];
    for w in wants {
        let c = w.model.config();
        let what = w.model.name();
        for i in 0..4 {
            assert_rel(what, c.steps_per_m[i], w.steps[i] * 4.0 / MM, 1e-12);
            assert_rel(what, c.max_feedrate_m_s[i], w.feed[i] * MM, 1e-12);
            assert_rel(what, c.max_accel_m_s2[i], w.accel[i] * MM, 1e-12);
        }
        let [p, r, t] = w.print_retract_travel;
        assert_rel(what, c.print_accel_m_s2, p * MM, 1e-12);
        assert_rel(what, c.retract_accel_m_s2, r * MM, 1e-12);
        assert_rel(what, c.travel_accel_m_s2, t * MM, 1e-12);
        let MarlinJerk::Classic { max_jerk_m_s, .. } = c.jerk else {
            panic!("{what}: Buddy plans with classic jerk");
        };
        for (got, want) in max_jerk_m_s.iter().zip([8.0, 8.0, 2.0, w.e_jerk]) {
            assert_rel(what, *got, want * MM, 1e-12);
        }
        let kinematics = if w.corexy {
            Kinematics::CoreXy
        } else {
            Kinematics::Cartesian
        };
        assert_eq!(c.kinematics, kinematics, "{what}");
        assert_eq!(c.block_buffer_size, 32, "{what}");
        assert_eq!(
            c.min_steps_per_segment, 24,
            "{what}: 6 steps of 4 mini-steps"
        );
        assert_eq!(c.stepper, MarlinStepper::PreciseStepping, "{what}");
        assert!(!c.s_curve && !c.slowdown, "{what}");
        assert_rel(what, c.minimum_planner_speed_m_s, 0.05 * MM, 1e-12);
    }
}

#[test]
fn a_long_travel_move_cruises_at_each_printers_limits() {
    // 150 mm in X asked at 500 mm/s, faster than every printer's limit: each runs the
    // trapezoid of its own travel acceleration and X speed limit, from and to
    // MINIMUM_PLANNER_SPEED (0.05 mm/s). On the CoreXY printers (XL, CORE One) a move in X
    // turns both motors by 150 mm, each within X's limits.
    use settle_planner::firmware::marlin::PrusaModel;
    let v0 = 0.05;
    for (model, v, a) in [
        (PrusaModel::Mini, 180.0, 1250.0),
        (PrusaModel::Mk3_5, 200.0, 1250.0),
        (PrusaModel::Mk4, 300.0, 1250.0),
        (PrusaModel::Xl, 460.0, 5000.0),
        (PrusaModel::CoreOne, 350.0, 1500.0),
    ] {
        let ramp_mm = (v * v - v0 * v0) / (2.0 * a);
        let want = 2.0 * (v - v0) / a + (150.0 - 2.0 * ramp_mm) / v;
        let (planned, t) = plan_with(
            &mut MarlinPlanner::new(model.config()).expect("config"),
            &[xy([0.0, 0.0], [150.0, 0.0], 500.0)],
        );
        assert_eq!(planned.len(), 1, "{model}");
        assert_rel(model.name(), planned[0].cruise_speed_m_s, v * MM, 1e-9);
        assert_rel(model.name(), planned[0].accel_m_s2, a * MM, 1e-9);
        assert_rel(model.name(), t, want, 1e-9);
    }
}
