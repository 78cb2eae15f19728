//! Klipper's own example configurations (`tests/data/klipper-examples/`, from Klipper's
//! `config/` folder at commit 84104bbbd762, listed in `tests/data/klipper-examples/MANIFEST.md`),
//! read as Klipper reads them. Each expected value is the file's own line (named) or
//! Klipper's default, as the module that reads the option takes it: `klippy/toolhead.py`
//! (`max_velocity`, `max_accel`, `minimum_cruise_ratio` default 0.5,
//! `square_corner_velocity` default 5), `klippy/kinematics/<kinematics>.py`
//! (`max_z_velocity`, `max_z_accel`, default `max_velocity` and `max_accel`),
//! `klippy/stepper.py` (`position_min` default 0; microsteps per mm
//! `full_steps_per_rotation * microsteps * gear_ratio / rotation_distance`, default 200 full
//! steps) and the tmc drivers (`run_current`, `interpolate` default true).

use settle_gcode::GcodeError;
use settle_gcode::config::{KlipperConfig, KlipperStepper};
use settle_gcode::job::JobConfig;

use crate::data_path;

fn read(name: &str) -> Result<KlipperConfig, GcodeError> {
    KlipperConfig::read(data_path(&format!("klipper-examples/{name}")))
}

fn config(name: &str) -> KlipperConfig {
    read(name).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// `[printer]` as read: kinematics, max_velocity, max_accel, minimum_cruise_ratio,
/// square_corner_velocity, max_z_velocity, max_z_accel.
type Printer = (&'static str, f64, f64, f64, f64, f64, f64);

fn printer(c: &KlipperConfig) -> (String, f64, f64, f64, f64, f64, f64) {
    let p = &c.printer;
    (
        p.kinematics.clone(),
        p.max_velocity_mm_s,
        p.max_accel_mm_s2,
        p.minimum_cruise_ratio,
        p.square_corner_velocity_mm_s,
        p.max_z_velocity_mm_s,
        p.max_z_accel_mm_s2,
    )
}

/// A stepper as read: microsteps per mm, microsteps, position_min, position_max, driver,
/// run_current, interpolate.
type Stepper = (
    f64,
    u32,
    f64,
    Option<f64>,
    Option<&'static str>,
    Option<f64>,
    Option<bool>,
);

type Read = (
    f64,
    u32,
    f64,
    Option<f64>,
    Option<String>,
    Option<f64>,
    Option<bool>,
);

fn stepper(s: &Option<KlipperStepper>) -> Read {
    let s = s.as_ref().expect("the stepper section");
    (
        s.drive.microsteps_per_mm,
        s.drive.microsteps,
        s.drive.position_min_mm,
        s.drive.position_max_mm,
        s.driver.clone(),
        s.drive.run_current_a_rms,
        s.drive.interpolate,
    )
}

fn expected(s: Stepper) -> Read {
    (s.0, s.1, s.2, s.3, s.4.map(String::from), s.5, s.6)
}

/// The files settle reads and plans: `[printer]`, the X, Y and Z steppers.
#[test]
fn planned_examples_read_with_klippers_values() {
    // 200 full steps x 16 microsteps / 40 mm = 80 per mm; / 8 mm = 400 per mm.
    let belt = |max: f64| (80.0, 16, 0.0, Some(max), None, None, None);
    let cases: [(&str, Printer, [Stepper; 3]); 8] = [
        (
            // Lines 58-63; no minimum_cruise_ratio, square_corner_velocity: the defaults.
            "example-cartesian.cfg",
            ("cartesian", 500.0, 3000.0, 0.5, 5.0, 25.0, 30.0),
            [
                belt(200.0),
                belt(200.0),
                (400.0, 16, 0.0, Some(200.0), None, None, None),
            ],
        ),
        (
            "example-corexy.cfg",
            ("corexy", 300.0, 3000.0, 0.5, 5.0, 25.0, 30.0),
            [
                belt(200.0),
                belt(200.0),
                (400.0, 16, 0.0, Some(200.0), None, None, None),
            ],
        ),
        (
            // A Voron 2.4: position_min 0 written out, Z from -2 ("room for squaring
            // gantry with quad_gantry_level").
            "kit-voron2-250mm.cfg",
            ("corexy", 350.0, 3000.0, 0.5, 5.0, 50.0, 350.0),
            [
                belt(250.0),
                belt(250.0),
                (400.0, 16, -2.0, Some(250.0), None, None, None),
            ],
        ),
        (
            // `square_corner_velocity: 5.0` written out; max_z_accel after it.
            "printer-creality-ender3-v2-neo-2022.cfg",
            ("cartesian", 300.0, 5000.0, 0.5, 5.0, 5.0, 100.0),
            [
                belt(235.0),
                belt(235.0),
                (400.0, 16, 0.0, Some(250.0), None, None, None),
            ],
        ),
        (
            // `minimum_cruise_ratio: 0.0`: no cruise share.
            "printer-sovol-sv05-2022.cfg",
            ("cartesian", 300.0, 1000.0, 0.0, 5.0, 5.0, 100.0),
            [
                (80.0, 16, -4.0, Some(220.0), None, None, None),
                (80.0, 16, -4.0, Some(220.0), None, None, None),
                (400.0, 16, -3.0, Some(300.0), None, None, None),
            ],
        ),
        (
            // max_velocity 3000 above max_accel 450; square_corner_velocity 15.
            "printer-wanhao-duplicator-9-2018.cfg",
            ("cartesian", 3000.0, 450.0, 0.5, 15.0, 225.0, 30.0),
            [
                belt(295.0),
                belt(290.0),
                (400.0, 16, -0.99, Some(370.0), None, None, None),
            ],
        ),
        (
            // 0.9 degree motors (`full_steps_per_rotation: 400`): 400 x 16 / 40 = 160 and
            // 400 x 16 / 8 = 800 per mm; tmc2209 at 0.8 and 1.0 A, interpolating (default).
            "printer-biqu-bx-2021.cfg",
            ("cartesian", 200.0, 1000.0, 0.5, 5.0, 10.0, 1000.0),
            [
                (
                    160.0,
                    16,
                    -13.0,
                    Some(250.0),
                    Some("tmc2209"),
                    Some(0.8),
                    Some(true),
                ),
                (
                    160.0,
                    16,
                    -7.0,
                    Some(250.0),
                    Some("tmc2209"),
                    Some(0.8),
                    Some(true),
                ),
                (
                    800.0,
                    16,
                    -2.0,
                    Some(250.0),
                    Some("tmc2209"),
                    Some(1.0),
                    Some(true),
                ),
            ],
        ),
        (
            // 64 microsteps: 200 x 64 / 40 = 320 and 200 x 64 / 4 = 3200 per mm; tmc2209
            // with `interpolate: false`.
            "printer-ratrig-v-minion-2021.cfg",
            ("cartesian", 500.0, 20000.0, 0.5, 5.0, 15.0, 2000.0),
            [
                (
                    320.0,
                    64,
                    0.0,
                    Some(180.0),
                    Some("tmc2209"),
                    Some(0.8),
                    Some(false),
                ),
                (
                    320.0,
                    64,
                    0.0,
                    Some(180.0),
                    Some("tmc2209"),
                    Some(0.8),
                    Some(false),
                ),
                (
                    3200.0,
                    64,
                    -5.0,
                    Some(180.0),
                    Some("tmc2209"),
                    Some(0.8),
                    Some(false),
                ),
            ],
        ),
    ];
    for (name, want, [x, y, z]) in cases {
        let c = config(name);
        let (k, v, a, r, scv, vz, az) = want;
        assert_eq!(printer(&c), (k.to_string(), v, a, r, scv, vz, az), "{name}");
        assert_eq!(stepper(&c.steppers.x), expected(x), "{name} stepper_x");
        assert_eq!(stepper(&c.steppers.y), expected(y), "{name} stepper_y");
        assert_eq!(stepper(&c.steppers.z), expected(z), "{name} stepper_z");
        // None of Klipper's examples enables [input_shaper] (it is commented out where
        // it appears): no shaping.
        assert_eq!(c.input_shaper, None, "{name}");
        assert!(c.notes.is_empty(), "{name}: {:?}", c.notes);
        let job = JobConfig::from_klipper(&c).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(job.shapers.iter().all(Option::is_none), "{name}");
    }
}

/// Kinematics Klipper has and settle reads, but whose motion settle's planners do not
/// model: the configuration reads, the job refuses it at the `kinematics` line.
#[test]
fn examples_of_other_kinematics_are_refused_at_their_kinematics_line() {
    for (name, line, kinematics, want) in [
        (
            "example-corexz.cfg",
            74,
            "corexz",
            ("corexz", 300.0, 3000.0, 0.5, 5.0, 50.0, 30.0),
        ),
        // delta.py: max_z_velocity 150, no max_z_accel (default max_accel); delta_radius
        // is delta.py's.
        (
            "example-delta.cfg",
            66,
            "delta",
            ("delta", 300.0, 3000.0, 0.5, 5.0, 150.0, 3000.0),
        ),
        // polar.py reads max_angular_velocity.
        (
            "example-polar.cfg",
            70,
            "polar",
            ("polar", 300.0, 3000.0, 0.5, 5.0, 25.0, 30.0),
        ),
        // rotary_delta.py reads shoulder_radius and shoulder_height (and no max_z_accel).
        (
            "example-rotary-delta.cfg",
            67,
            "rotary_delta",
            ("rotary_delta", 300.0, 3000.0, 0.5, 5.0, 50.0, 3000.0),
        ),
        // winch.py reads nothing more of [printer].
        (
            "example-winch.cfg",
            83,
            "winch",
            ("winch", 300.0, 3000.0, 0.5, 5.0, 300.0, 3000.0),
        ),
    ] {
        let c = config(name);
        let (k, v, a, r, scv, vz, az) = want;
        assert_eq!(printer(&c), (k.to_string(), v, a, r, scv, vz, az), "{name}");
        let e = JobConfig::from_klipper(&c).expect_err("not planned");
        let path = data_path(&format!("klipper-examples/{name}"));
        assert_eq!(
            e.to_string(),
            format!(
                "{}:{line}: key `printer.kinematics`: `{kinematics}`: settle's firmware planners model cartesian and corexy kinematics",
                path.display()
            ),
            "{name}"
        );
    }
}

/// Files of Klipper's `config/` that hold no `[printer]` (a tool-changer's carriage and
/// extruder, a macro collection): fragments, refused as such, naming the file once.
#[test]
fn fragments_are_refused_as_fragments() {
    for name in ["sample-idex.cfg", "sample-macros.cfg"] {
        let e = read(name).expect_err("a fragment");
        let path = data_path(&format!("klipper-examples/{name}"));
        assert!(
            matches!(&e, GcodeError::ConfigNoSection { section, .. } if section == "printer"),
            "{name}: {e:?}"
        );
        assert_eq!(
            e.to_string(),
            format!(
                "{}: no [printer] section: the file is a fragment of a configuration, not a whole printer.cfg (Klipper requires [printer] with kinematics, max_velocity and max_accel: klippy/toolhead.py); give the printer.cfg that includes it",
                path.display()
            ),
        );
    }
}

fn example_with(name: &str, extra: &str) -> (String, Result<KlipperConfig, GcodeError>) {
    let path = data_path(&format!("klipper-examples/{name}"));
    let text = std::fs::read_to_string(&path).expect("reads the example") + extra;
    let lines = text.lines().count();
    (
        format!("{}:{lines}", path.display()),
        KlipperConfig::parse(&text, &path),
    )
}

/// An option Klipper does not read in `[printer]` or `[input_shaper]` stops Klipper
/// (`ConfigValidate.check_unused`: "Option 'x' is not valid in section 'y'"); settle
/// refuses it at its line, with the options Klipper reads there. Which options are read
/// depends on the kinematics: `max_z_accel` is corexy.py's but not winch.py's.
#[test]
fn unknown_options_are_refused_with_the_allowed_ones() {
    let (at, r) = example_with(
        "example-corexy.cfg",
        "\n[input_shaper]\nshaper_freq_x: 48\nshaper_frequency_y: 40\n",
    );
    assert_eq!(
        r.expect_err("unknown option").to_string(),
        format!(
            "{at}: key `input_shaper.shaper_frequency_y`: Klipper does not know this option of [input_shaper] and refuses to start (\"Option 'shaper_frequency_y' is not valid in section 'input_shaper'\", klippy/configfile.py); allowed: shaper_type, shaper_type_x, shaper_type_y, shaper_type_z, damping_ratio_x, damping_ratio_y, damping_ratio_z, shaper_freq_x, shaper_freq_y, shaper_freq_z"
        )
    );
    // A second [printer] continues the first (configparser, strict off).
    let (at, r) = example_with("example-corexy.cfg", "\n[printer]\nmax_jerk: 8\n");
    assert_eq!(
        r.expect_err("unknown option").to_string(),
        format!(
            "{at}: key `printer.max_jerk`: Klipper does not know this option of [printer] with kinematics corexy and refuses to start (\"Option 'max_jerk' is not valid in section 'printer'\", klippy/configfile.py); allowed: kinematics, max_velocity, max_accel, minimum_cruise_ratio, square_corner_velocity, max_z_velocity, max_z_accel"
        )
    );
    let (at, r) = example_with("example-winch.cfg", "\n[printer]\nmax_z_accel: 100\n");
    assert_eq!(
        r.expect_err("not winch.py's").to_string(),
        format!(
            "{at}: key `printer.max_z_accel`: Klipper does not know this option of [printer] with kinematics winch and refuses to start (\"Option 'max_z_accel' is not valid in section 'printer'\", klippy/configfile.py); allowed: kinematics, max_velocity, max_accel, minimum_cruise_ratio, square_corner_velocity"
        )
    );
    // delta.py's own options are allowed with delta.
    let (_, r) = example_with(
        "example-delta.cfg",
        "\n[printer]\nprint_radius: 150\nminimum_z_position: -5\n",
    );
    r.expect("delta.py reads print_radius and minimum_z_position");
}

/// Options Klipper removed from `[printer]` (`docs/Config_Changes.md`) that older
/// configurations still carry: Klipper now refuses them; settle notes them and reads on,
/// since none sets a speed, an acceleration or a shaper. What the SAVE_CONFIG block sets
/// Klipper never refuses.
#[test]
fn removed_printer_options_are_noted_and_save_config_is_exempt() {
    let (at, r) = example_with(
        "example-cartesian.cfg",
        "\n[printer]\nmove_flush_time: 0.05\n",
    );
    let c = r.expect("a removed option is a note");
    let notes: Vec<String> = c.notes.iter().map(ToString::to_string).collect();
    assert_eq!(
        notes,
        [format!(
            "{at}: move_flush_time is not read: Klipper removed it on 2023-12-07 and now refuses it (docs/Config_Changes.md); it sets no speed, acceleration or shaper"
        )]
    );
    let (at, r) = example_with(
        "example-cartesian.cfg",
        "\n[printer]\nmax_stepper_error: 0.000025\n",
    );
    let notes: Vec<String> = r
        .expect("noted")
        .notes
        .iter()
        .map(ToString::to_string)
        .collect();
    assert_eq!(
        notes,
        [format!(
            "{at}: max_stepper_error is not read: Klipper removed it on 2025-10-03 and now refuses it (docs/Config_Changes.md); it sets no speed, acceleration or shaper"
        )]
    );
    // `delta_radius` is not corexy.py's, but set in the SAVE_CONFIG block Klipper
    // accepts it (check_unused adds the block's options to those read).
    let (_, r) = example_with(
        "example-corexy.cfg",
        "\n#*# <---------------------- SAVE_CONFIG ---------------------->\n#*# DO NOT EDIT THIS BLOCK OR BELOW. The contents are auto-generated.\n#*#\n#*# [printer]\n#*# delta_radius = 140\n",
    );
    let c = r.expect("SAVE_CONFIG's options are not refused");
    assert_eq!(c.printer.max_velocity_mm_s, 300.0);
}
