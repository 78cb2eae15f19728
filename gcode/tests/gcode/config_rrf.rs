//! RepRapFirmware configurations read as the firmware applies them.
//!
//! Expected values follow the firmware's documented algorithm (RepRapFirmware 3.6
//! source), worked by hand: `M350` rescales steps per mm by new/old microstepping
//! (`GCodes::ChangeMicrostepping`), `M92 S<m>` converts by in-force/m
//! (`Move::SetDriveStepsPerMm`), `M203`/`M566` values are mm/min (/ 60), `M906` mA are
//! peak (RMS = mA / 1000 / sqrt 2), `M593` with `F` or `S` but no type selects `zvd`
//! (`AxisShaper::Configure`).

use settle_gcode::config::{RrfConfig, ShaperSetting};
use settle_gcode::{Dialect, GcodeError};

use crate::config_klipper::tree;
use crate::{data_path, ignored};

fn parse(text: &str) -> RrfConfig {
    RrfConfig::parse(text, "sys/config.g").expect("valid config")
}

fn parse_err(text: &str) -> GcodeError {
    RrfConfig::parse(text, "sys/config.g").expect_err("an error")
}

#[test]
fn mini5plus_config_reads_as_the_firmware_applies_it() {
    let root = data_path("rrf/mini5plus");
    let c = RrfConfig::read(root.join("sys/config.g")).expect("valid config");
    assert_eq!(c.kinematics, "cartesian");
    let (x, y, z) = (&c.axes.x, &c.axes.y, &c.axes.z);
    // M350 X16, M92 X80, then M350 X32: 160 steps/mm at x32.
    assert_eq!((x.drive.microsteps_per_mm, x.drive.microsteps), (160.0, 32));
    assert_eq!((y.drive.microsteps_per_mm, y.drive.microsteps), (160.0, 32));
    // M92 Z400, then M92 Z1600 S64 with x16 in force: 1600 * 16 / 64.
    assert_eq!((z.drive.microsteps_per_mm, z.drive.microsteps), (400.0, 16));
    assert!([x, y, z].iter().all(|a| a.drive.interpolate == Some(true)));
    // M566 X900 in config.g, then M566 X600 in tuning.g; M205 X5 does not move the limit.
    assert_eq!(
        (x.max_jerk_mm_s, y.max_jerk_mm_s, z.max_jerk_mm_s),
        (10.0, 10.0, 1.0)
    );
    assert_eq!((x.max_speed_mm_s, z.max_speed_mm_s), (300.0, 10.0));
    assert_eq!(
        (x.max_accel_mm_s2, y.max_accel_mm_s2, z.max_accel_mm_s2),
        (3000.0, 3000.0, 100.0)
    );
    assert_eq!((x.motor_current_ma, z.motor_current_ma), (1200.0, 800.0));
    assert_eq!(
        x.drive.run_current_a_rms,
        Some(1.2 / std::f64::consts::SQRT_2)
    );
    assert_eq!(
        z.drive.run_current_a_rms,
        Some(0.8 / std::f64::consts::SQRT_2)
    );
    assert_eq!(c.idle_current_percent, 30.0);
    assert_eq!(
        (x.drive.position_min_mm, x.drive.position_max_mm),
        (0.0, Some(235.0))
    );
    // Z from /macros/z_limits.g (M98 P"0:/macros/z_limits.g").
    assert_eq!(
        (z.drive.position_min_mm, z.drive.position_max_mm),
        (-0.5, Some(245.0))
    );
    assert_eq!(
        (c.print_accel_mm_s2, c.travel_accel_mm_s2),
        (2000.0, 4000.0)
    );
    assert_eq!(
        c.input_shaper,
        ShaperSetting {
            name: "mzv".into(),
            frequency_hz: 42.5,
            damping_ratio: 0.1
        }
    );
    assert_eq!(
        c.input_shaper.type_name(Dialect::Rrf).as_deref(),
        Some("rrf:mzv")
    );
    let files: Vec<String> = c
        .files
        .iter()
        .map(|f| {
            f.strip_prefix(&root)
                .expect("under the card")
                .display()
                .to_string()
        })
        .collect();
    assert_eq!(
        files,
        [
            "sys/config.g",
            "sys/tuning.g",
            "macros/z_limits.g",
            "sys/config-override.g"
        ]
    );
    let notes: Vec<String> = c.notes.iter().map(ToString::to_string).collect();
    assert_eq!(notes.len(), 3, "{notes:#?}");
    assert!(
        notes[0].contains("config.g:76: `if boards[1]") && notes[0].contains("lines 76-78"),
        "{}",
        notes[0]
    );
    assert!(
        notes[1].contains("config.g:79: `global maxPrintAccel"),
        "{}",
        notes[1]
    );
    assert!(
        notes[2].contains("config.g:83: macro") && notes[2].contains("absent.g"),
        "{}",
        notes[2]
    );
}

#[test]
fn microstepping_and_steps_per_mm_in_either_order() {
    let a = parse("M92 X80\nM350 X32 I1\n");
    assert_eq!(a.axes.x.drive.microsteps_per_mm, 160.0);
    let b = parse("M350 X32 I1\nM92 X80\n");
    assert_eq!(b.axes.x.drive.microsteps_per_mm, 80.0);
    // Given at x32 while x16 is in force.
    let c = parse("M92 X160 S32\n");
    assert_eq!(c.axes.x.drive.microsteps_per_mm, 80.0);
    // No I: interpolation off.
    let d = parse("M350 X64\n");
    assert_eq!(
        (d.axes.x.drive.microsteps, d.axes.x.drive.interpolate),
        (64, Some(false))
    );
    assert_eq!(d.axes.x.drive.microsteps_per_mm, 320.0);
}

#[test]
fn defaults_are_the_firmwares() {
    let c = parse("; nothing\n");
    assert_eq!(c.kinematics, "cartesian");
    assert_eq!(
        (
            c.axes.x.drive.microsteps_per_mm,
            c.axes.z.drive.microsteps_per_mm
        ),
        (80.0, 800.0)
    );
    assert_eq!(
        (c.axes.x.max_speed_mm_s, c.axes.z.max_speed_mm_s),
        (100.0, 20.0)
    );
    assert_eq!(
        (c.axes.x.max_accel_mm_s2, c.axes.z.max_accel_mm_s2),
        (1000.0, 200.0)
    );
    assert_eq!(
        (c.axes.y.max_jerk_mm_s, c.axes.z.max_jerk_mm_s),
        (15.0, 10.0)
    );
    assert_eq!(c.axes.x.drive.run_current_a_rms, None);
    assert_eq!(
        (c.print_accel_mm_s2, c.travel_accel_mm_s2),
        (50_000.0, 50_000.0)
    );
    assert_eq!(c.input_shaper.name, "none");
    assert!(!c.input_shaper.is_enabled(Dialect::Rrf));
    assert_eq!(c.input_shaper.type_name(Dialect::Rrf), None);
    assert_eq!(parse("M669 K1\n").kinematics, "corexy");
    assert_eq!(parse("M665 L360 R180 H400\n").kinematics, "delta");
}

#[test]
fn a_jerk_under_the_minimum_is_raised_to_it_as_the_firmware_does() {
    // M566 is in mm/min: X0 is raised to RepRapFirmware's 0.1 mm/s (`MinimumJerk`), Y30
    // (0.5 mm/s) is kept; the job then plans (a zero jerk used to be refused).
    let c = parse("M566 X0 Y30\n");
    assert_eq!((c.axes.x.max_jerk_mm_s, c.axes.y.max_jerk_mm_s), (0.1, 0.5));
    let job = settle_gcode::job::JobConfig::from_rrf(&c).expect("plans");
    let settle_gcode::job::PlannerConfig::Rrf(r) = job.planner else {
        panic!("an RRF planner")
    };
    assert_eq!(&r.instant_dv_m_s[..2], &[0.1 * 1e-3, 0.5 * 1e-3]);
}

#[test]
fn an_acceleration_under_the_minimum_is_raised_to_it_as_the_firmware_does() {
    // `Platform::SetAcceleration` and `GCodes::ConfigureAccelerations` keep 0.1 mm/s^2 at
    // least (`MinimumAcceleration`), as a job does; the config's notes say so.
    let c = parse("M201 X0.01 Y500\nM204 P0.05 T3000\n");
    assert_eq!(
        (c.axes.x.max_accel_mm_s2, c.axes.y.max_accel_mm_s2),
        (0.1, 500.0)
    );
    assert_eq!((c.print_accel_mm_s2, c.travel_accel_mm_s2), (0.1, 3000.0));
    let notes: Vec<_> = c.notes.iter().map(ToString::to_string).collect();
    assert_eq!(notes.len(), 2, "{notes:?}");
    assert!(
        notes[0].contains("config.g:1") && notes[0].contains("M201"),
        "{notes:?}"
    );
    assert!(
        notes[1].contains("config.g:2") && notes[1].contains("M204"),
        "{notes:?}"
    );
}

#[test]
fn m593_without_a_type_selects_zvd_and_types_are_reduced() {
    let c = parse("M593 F48.5\n");
    assert_eq!(
        (c.input_shaper.name.as_str(), c.input_shaper.frequency_hz),
        ("zvd", 48.5)
    );
    assert_eq!(c.input_shaper.damping_ratio, 0.05);
    let c = parse("M593 P\"ZV-DD\" F40\nM593 S0.15\n");
    assert_eq!(
        (c.input_shaper.name.as_str(), c.input_shaper.damping_ratio),
        ("zvdd", 0.15)
    );
    let c = parse("M593 P\"none\"\nM593 S0.1\n");
    assert_eq!(c.input_shaper.name, "zvd");
}

#[test]
fn bad_values_name_file_line_and_parameter() {
    let text = "M92 X80\n\nM593 P\"zvx\" F40\n";
    match parse_err(text) {
        GcodeError::ConfigValue {
            at,
            section,
            key,
            allowed,
            ..
        } => {
            assert_eq!(
                (at.to_string().as_str(), section.as_str(), key.as_str()),
                ("sys/config.g:3", "M593", "P")
            );
            assert!(allowed.contains("zvddd"), "{allowed}");
        }
        e => panic!("{e:?}"),
    }
    for (text, line, param) in [
        ("M593 F2000\n", 1, "F"),
        ("G90\nM593 F3\n", 2, "F"),
        ("M593 P\"none\" F3\n", 1, "F"),
        ("M208 S1 X300\n", 1, "X"),
    ] {
        match parse_err(text) {
            GcodeError::ConfigValue { at, key, .. } => {
                assert_eq!((at.line, key.as_str()), (line, param), "{text}");
            }
            e => panic!("{text}: {e:?}"),
        }
    }
    for (text, line, param) in [
        ("M92 X-80\n", 1, "X"),
        ("M350 X12\n", 1, "X"),
        ("\nM208 X10:5\n", 2, "X"),
        ("M906 X800 Y-1\n", 1, "Y"),
        ("M669 K20\n", 1, "K"),
    ] {
        match parse_err(text) {
            GcodeError::OutOfRange { at, param: p, .. } => {
                assert_eq!(at.source_name.as_ref(), "sys/config.g");
                assert_eq!((at.line, p.as_str()), (line, param), "{text}");
            }
            e => panic!("{text}: {e:?}"),
        }
    }
    assert!(matches!(
        parse_err("M92 X1.2.3\n"),
        GcodeError::NotANumber { .. }
    ));
    assert!(matches!(
        parse_err("M92 X\n"),
        GcodeError::MissingValue { .. }
    ));
}

#[test]
fn macro_cycles_are_errors() {
    let dir = tree(&[
        ("sys/config.g", "M98 P\"a.g\"\n"),
        ("sys/a.g", "; a\nM98 P\"/sys/b.g\"\n"),
        ("sys/b.g", "M98 P\"a.g\"\n"),
    ]);
    match RrfConfig::read(dir.path().join("sys/config.g")).expect_err("a cycle") {
        GcodeError::IncludeCycle { at, chain, .. } => {
            assert!(at.source_name.ends_with("b.g") && at.line == 1, "{at}");
            assert_eq!(chain.matches(" -> ").count(), 3, "{chain}");
        }
        e => panic!("{e:?}"),
    }
}

#[test]
fn relative_macro_names_are_found_in_sys_whoever_calls_them() {
    let dir = tree(&[
        ("sys/config.g", "M98 P\"0:/macros/m.g\"\n"),
        ("macros/m.g", "M98 P\"b.g\"\n"),
        ("sys/b.g", "M201 X1234\n"),
        ("macros/b.g", "M201 X9\n"),
    ]);
    let c = RrfConfig::read(dir.path().join("sys/config.g")).expect("valid");
    assert_eq!(c.axes.x.max_accel_mm_s2, 1234.0);
    assert_eq!(c.files.last(), Some(&dir.path().join("sys/b.g")));
}

#[test]
fn other_dialects_ignore_configuration_commands() {
    assert_eq!(
        ignored(
            "M92 X80\nM350 X16\nM906 X800\nM98 P\"x.g\"\n",
            Dialect::Marlin
        ),
        ["M350 x1", "M906 x1", "M92 x1", "M98 x1"]
    );
    assert_eq!(
        ignored("M92 X80\nM208 X200\n", Dialect::Klipper),
        ["M208 x1", "M92 x1"]
    );
}

#[test]
fn steps_per_mm_outside_what_tune_takes_are_refused_where_written() {
    // RepRapFirmware takes any positive `M92` and raises a value below 0.01 to 0.01
    // (`MinimumStepsPerMm`, src/Config/Configuration.h); settle tune takes 1 to 1e9
    // microsteps per mm. The axis's final value is checked, at the line that set it:
    // M350 X16, M92 X10, then M350 X1 leaves 10 * 1 / 16 = 0.625; M92 Z1e9 (the most the
    // word takes) at the default x16, then M350 Z256, 1e9 * 256 / 16.
    for (text, line, command, key, leaves) in [
        ("M92 X80 Y0.5\n", 1, "M92", "Y", "leaves 0.5,"),
        ("G90\nM92 X0.001\n", 2, "M92", "X", "leaves 0.01,"),
        (
            "M350 X16\nM92 X10\nM350 X1\n",
            3,
            "M350",
            "X",
            "leaves 0.625,",
        ),
        (
            "M92 Z1e9\nM350 Z256\n",
            2,
            "M350",
            "Z",
            "leaves 16000000000,",
        ),
    ] {
        match parse_err(text) {
            GcodeError::ConfigValue {
                at,
                section,
                key: k,
                allowed,
                ..
            } => {
                assert_eq!(
                    (at.line, section.as_str(), k.as_str()),
                    (line, command, key),
                    "{text}"
                );
                assert!(allowed.contains(leaves), "{text}: {allowed}");
            }
            e => panic!("{text}: {e:?}"),
        }
    }
    // What a later line sets is what the firmware runs with: read, not refused.
    assert_eq!(
        parse("M92 X0.5\nM92 X80\n").axes.x.drive.microsteps_per_mm,
        80.0
    );
    assert_eq!(parse("M92 X1 Y1e9\n").axes.y.drive.microsteps_per_mm, 1e9);
}
