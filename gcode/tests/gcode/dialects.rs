//! Each firmware's conventions: modes, units, limit commands, ignored commands.

use settle_gcode::{
    AxisFlags, AxisValues, Dialect, EventKind, FtShaper, GcodeError, LimitChange, MoveKind, Note,
};

use crate::{error, events, ignored, limits, moves};

#[test]
fn g91_and_e_per_dialect() {
    // After M83, G90 makes E absolute again in Marlin only; G91 makes E relative in Marlin
    // and Klipper but not in RepRapFirmware.
    let text = "G92 E10\nM83\nG90\nG1 X1 E2\nM82\nG91\nG1 X1 E2\n";
    let e_ends = |d| {
        moves(text, d)
            .iter()
            .map(|m| m.end.e_mm)
            .collect::<Vec<_>>()
    };
    // G92 E10 makes file E 10 machine E 0, so an absolute E2 is machine -8.
    assert_eq!(e_ends(Dialect::Marlin), [-8.0, -6.0]); // G90 cancelled M83; G91 made E relative
    assert_eq!(e_ends(Dialect::Klipper), [2.0, 4.0]); // M83 held through G90; G91 made E relative
    assert_eq!(e_ends(Dialect::Rrf), [2.0, -8.0]); // M83 held through G90; G91 left E absolute
    let m = moves(text, Dialect::Rrf);
    assert_eq!((m[1].start.x_mm, m[1].end.x_mm), (1.0, 2.0)); // G91 X1: relative
}

#[test]
fn g92_keeps_the_machine_frame_continuous() {
    let m = moves(
        "G1 X10 Y10 E5\nG92 X0 E0\nG1 X5 E1\nG92\nG1 Y1",
        Dialect::Marlin,
    );
    assert_eq!(
        (m[1].start.x_mm, m[1].end.x_mm, m[1].end.e_mm),
        (10.0, 15.0, 6.0)
    );
    assert_eq!(m[2].end.y_mm, 1.0); // Marlin: G92 without axes does nothing
    let m = moves("G1 X10 Y10 E5\nG92\nG1 Y1", Dialect::Klipper);
    assert_eq!(m[1].end.y_mm, 11.0); // Klipper: G92 without axes zeroes X Y Z E
}

#[test]
fn initial_feed_and_units() {
    assert_eq!(moves("G1 X1", Dialect::Klipper)[0].feed_mm_s, 25.0);
    assert_eq!(moves("G1 X1", Dialect::Marlin)[0].feed_mm_s, 25.0);
    assert_eq!(moves("G1 X1", Dialect::Rrf)[0].feed_mm_s, 50.0);
    let m = moves("G1 X1 F6000\nG0 X2\nG1 X2 Y1 F1200", Dialect::Marlin);
    assert_eq!(
        (m[0].feed_mm_s, m[1].feed_mm_s, m[2].feed_mm_s),
        (100.0, 100.0, 20.0)
    );
    assert!(m[1].rapid && !m[0].rapid);
}

#[test]
fn move_kinds_and_dropped_no_ops() {
    let m = moves(
        "G1 X1 E1\nG1 X2\nG1 E-0.5\nG1 X2 F100\nG1 X3 E0.2\nG1 X4 E0.1",
        Dialect::Marlin,
    );
    let kinds: Vec<_> = m.iter().map(|m| m.kind).collect();
    assert_eq!(
        kinds,
        [
            MoveKind::Print,
            MoveKind::Travel,
            MoveKind::Extruder,
            MoveKind::Print,
            MoveKind::Travel
        ]
    );
}

#[test]
fn dwell_per_dialect() {
    let dwell = |text: &str, d| {
        events(text, d)
            .iter()
            .filter_map(|e| match e.kind {
                EventKind::Dwell { duration_s } => Some(duration_s),
                _ => None,
            })
            .collect::<Vec<_>>()
    };
    assert_eq!(
        dwell("G4 P500\nG4 S2 P500\nM400", Dialect::Marlin),
        [0.5, 2.0, 0.0]
    );
    assert_eq!(dwell("G4 P500\nG4 S2 P500", Dialect::Rrf), [0.5, 2.0]);
    assert_eq!(dwell("G4 P500\nG4 S2", Dialect::Klipper), [0.5, 0.0]);
    let ev = events("G4 S2", Dialect::Klipper);
    assert!(
        matches!(&ev[0].kind, EventKind::Note(Note::IgnoredByFirmware { command, .. }) if command == "G4 S2")
    );
    assert!(matches!(
        error("G4 P-1", Dialect::Marlin),
        GcodeError::OutOfRange { .. }
    ));
}

#[test]
fn homing_is_a_note_and_zeroes_the_homed_axes() {
    let ev = events("G1 X5 Y6 Z7\nG92 X0\nG28 X\nG1 Y1", Dialect::Marlin);
    assert!(matches!(
        ev[1].kind,
        EventKind::Note(Note::Homed {
            axes: AxisFlags {
                x: true,
                y: false,
                z: false,
                ..
            }
        })
    ));
    match &ev[2].kind {
        EventKind::Move(m) => assert_eq!((m.start.x_mm, m.start.y_mm, m.end.y_mm), (0.0, 6.0, 1.0)),
        k => panic!("{k:?}"),
    }
}

#[test]
fn klipper_refuses_r_arcs_and_relative_arcs() {
    assert!(matches!(
        error("G2 X2 Y0 R1", Dialect::Klipper),
        GcodeError::Unsupported { .. }
    ));
    assert!(matches!(
        error("G91\nG2 X2 Y0 I1", Dialect::Klipper),
        GcodeError::Unsupported { .. }
    ));
    // Marlin and RepRapFirmware take both; relative arcs end relative to the start.
    let m = moves("G1 X1 Y1\nG91\nG2 X2 Y0 I1 J0", Dialect::Rrf);
    assert_eq!((m[1].end.x_mm, m[1].end.y_mm), (3.0, 1.0));
}

#[test]
fn marlin_limits() {
    let got = limits(
        "M201 X3000 Y2500 E10000\nM203 X300 Y250\nM204 P1500 T3000 R800\nM204 S2000\nM205 J0.02 X8 B20000\n\
         M593 X F40.5 D0.12\nM493 S1 X Y C2 A37 I0.1\nM494 T1 X0.005\nM566 X600",
        Dialect::Marlin,
    );
    let ax = |x, y, z, e| AxisValues { x, y, z, e };
    assert_eq!(
        got,
        [
            LimitChange::MaxAccel {
                per_axis_mm_s2: ax(Some(3000.0), Some(2500.0), None, Some(10000.0)),
                xy_frequency_limit_hz: None,
                xy_frequency_min_speed_pct: None
            },
            LimitChange::MaxFeedrate {
                per_axis_mm_s: ax(Some(300.0), Some(250.0), None, None),
                min_speed_mm_s: None
            },
            LimitChange::Accel {
                print_mm_s2: Some(1500.0),
                travel_mm_s2: Some(3000.0),
                retract_mm_s2: Some(800.0)
            },
            LimitChange::Accel {
                print_mm_s2: Some(2000.0),
                travel_mm_s2: Some(2000.0),
                retract_mm_s2: None
            },
            LimitChange::MarlinAdvanced {
                junction_deviation_mm: Some(0.02),
                jerk_mm_s: ax(Some(8.0), None, None, None),
                min_feedrate_mm_s: None,
                min_travel_feedrate_mm_s: None,
                min_segment_time_s: Some(0.02),
            },
            LimitChange::MarlinInputShaping {
                axes: AxisFlags {
                    x: true,
                    ..AxisFlags::default()
                },
                frequency_hz: Some(40.5),
                damping_ratio: Some(0.12)
            },
            LimitChange::FtMotion {
                enabled: Some(true),
                axis_sync: None,
                axes: AxisFlags {
                    x: true,
                    y: true,
                    ..AxisFlags::default()
                },
                shaper: Some(FtShaper::Zvd),
                dynamic_mode: None,
                frequency_hz: Some(37.0),
                frequency_scaling: None,
                damping_ratio: Some(0.1),
                vibration_tolerance: None,
            },
            LimitChange::FtSmoothing {
                trajectory: Some(1),
                overshoot: None,
                smoothing_s: ax(Some(0.005), None, None, None)
            },
        ]
    );
    // M566 is RepRapFirmware's: ignored by Marlin.
    assert_eq!(
        ignored("M566 X600\nM566 Y600\nM104 S200\n", Dialect::Marlin),
        ["M104 x1", "M566 x2"]
    );
}

#[test]
fn rrf_limits_convert_mm_per_min() {
    let got = limits(
        "M201 X3000 E1000:2000\nM203 X18000 Y12000 I60\nM203 S1 X300\nM204 P1000 T2000\nM566 X600 Y900 P1\n\
         M205 X10\nM593 P\"zvd\" F42 S0.1\nM593 P\"custom\" H0.4:0.7 T0.01:0.01",
        Dialect::Rrf,
    );
    let ax = |x, y| AxisValues {
        x,
        y,
        z: None,
        e: None,
    };
    assert_eq!(
        got[0],
        LimitChange::MaxAccel {
            per_axis_mm_s2: AxisValues {
                x: Some(3000.0),
                y: None,
                z: None,
                e: Some(1000.0)
            },
            xy_frequency_limit_hz: None,
            xy_frequency_min_speed_pct: None
        }
    );
    assert_eq!(
        got[1],
        LimitChange::MaxFeedrate {
            per_axis_mm_s: ax(Some(18000.0 * (1.0 / 60.0)), Some(12000.0 * (1.0 / 60.0))),
            min_speed_mm_s: Some(1.0)
        }
    );
    let LimitChange::MaxFeedrate { per_axis_mm_s, .. } = &got[1] else {
        panic!()
    };
    assert!(
        (per_axis_mm_s.x.expect("test value") - 300.0).abs() < 1e-12
            && (per_axis_mm_s.y.expect("test value") - 200.0).abs() < 1e-12
    );
    assert_eq!(
        got[2],
        LimitChange::MaxFeedrate {
            per_axis_mm_s: ax(Some(300.0), None),
            min_speed_mm_s: None
        }
    );
    assert_eq!(
        got[3],
        LimitChange::Accel {
            print_mm_s2: Some(1000.0),
            travel_mm_s2: Some(2000.0),
            retract_mm_s2: None
        }
    );
    let LimitChange::RrfJerk {
        per_axis_mm_s,
        policy,
        sets_maximum: true,
    } = &got[4]
    else {
        panic!("{:?}", got[4])
    };
    assert!(
        (per_axis_mm_s.x.expect("test value") - 10.0).abs() < 1e-12
            && (per_axis_mm_s.y.expect("test value") - 15.0).abs() < 1e-12
    );
    assert_eq!(*policy, Some(1));
    assert_eq!(
        got[5],
        LimitChange::RrfJerk {
            per_axis_mm_s: ax(Some(10.0), None),
            policy: None,
            sets_maximum: false
        }
    );
    assert_eq!(
        got[6],
        LimitChange::RrfInputShaping {
            shaper: Some("zvd".into()),
            frequency_hz: Some(42.0),
            damping_ratio: Some(0.1),
            reduction_limit: None,
            amplitudes: vec![],
            durations_s: vec![]
        }
    );
    let LimitChange::RrfInputShaping {
        amplitudes,
        durations_s,
        ..
    } = &got[7]
    else {
        panic!()
    };
    assert_eq!(
        (amplitudes.as_slice(), durations_s.as_slice()),
        ([0.4, 0.7].as_slice(), [0.01, 0.01].as_slice())
    );
}

#[test]
fn klipper_limits() {
    let got = limits(
        "SET_VELOCITY_LIMIT VELOCITY=300 ACCEL=5000 SQUARE_CORNER_VELOCITY=5 MINIMUM_CRUISE_RATIO=0.5\n\
         set_velocity_limit accel_to_decel=2500\nM204 S3000\nM204 P2000 T4000\n\
         SET_INPUT_SHAPER SHAPER_FREQ_X=52.4 SHAPER_TYPE_X=mzv DAMPING_RATIO_Y=0.08",
        Dialect::Klipper,
    );
    assert_eq!(
        got[0],
        LimitChange::VelocityLimit {
            velocity_mm_s: Some(300.0),
            accel_mm_s2: Some(5000.0),
            accel_to_decel_mm_s2: None,
            square_corner_velocity_mm_s: Some(5.0),
            minimum_cruise_ratio: Some(0.5)
        }
    );
    assert!(matches!(
        got[1],
        LimitChange::VelocityLimit {
            accel_to_decel_mm_s2: Some(2500.0),
            accel_mm_s2: None,
            ..
        }
    ));
    assert!(matches!(
        got[2],
        LimitChange::VelocityLimit {
            accel_mm_s2: Some(3000.0),
            ..
        }
    ));
    assert!(matches!(
        got[3],
        LimitChange::VelocityLimit {
            accel_mm_s2: Some(2000.0),
            ..
        }
    ));
    assert_eq!(
        got[4],
        LimitChange::InputShaper {
            shaper_type: None,
            shaper_type_xyz: [Some("mzv".into()), None, None],
            frequency_hz_xyz: [Some(52.4), None, None],
            damping_ratio_xyz: [None, Some(0.08), None]
        }
    );
    // Klipper ignores M204 without S unless both P and T are there.
    let ev = events("M204 P2000", Dialect::Klipper);
    assert!(matches!(
        &ev[0].kind,
        EventKind::Note(Note::IgnoredByFirmware { .. })
    ));
    assert!(matches!(
        error(
            "SET_INPUT_SHAPER SHAPER_TYPE=zv SHAPER_TYPE_X=mzv",
            Dialect::Klipper
        ),
        GcodeError::Syntax { .. }
    ));
    assert!(matches!(
        error(
            "SET_VELOCITY_LIMIT MINIMUM_CRUISE_RATIO=1",
            Dialect::Klipper
        ),
        GcodeError::OutOfRange { .. }
    ));
    // Marlin's M201/M203/M205 are not Klipper commands; macros are counted, not run.
    assert_eq!(
        ignored(
            "M201 X1\nM205 X8\nPRINT_START BED=60\nPRINT_START\n",
            Dialect::Klipper
        ),
        ["M201 x1", "M205 x1", "PRINT_START x2"]
    );
}

#[test]
fn an_e_after_a_digit_is_an_exponent_in_reprapfirmware_only() {
    // RepRapFirmware's StringParser::Seen skips an `E` that follows a digit, and the number
    // is read with its exponent; Klipper and Marlin split at every letter.
    let text = "G1 X1.5e1 Y10 F600\n";
    let rrf = moves(text, Dialect::Rrf);
    assert_eq!(
        (rrf[0].end.x_mm, rrf[0].end.y_mm, rrf[0].end.e_mm),
        (15.0, 10.0, 0.0)
    );
    for d in [Dialect::Marlin, Dialect::Klipper] {
        let m = moves(text, d);
        assert_eq!((m[0].end.x_mm, m[0].end.e_mm), (1.5, 1.0), "{d:?}");
    }
    // `E` after a space or a dot is the parameter in every dialect.
    let m = moves("G1 X2. E3 F600\n", Dialect::Rrf);
    assert_eq!((m[0].end.x_mm, m[0].end.e_mm), (2.0, 3.0));
}
