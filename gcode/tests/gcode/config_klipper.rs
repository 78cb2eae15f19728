//! Klipper configurations read as Klipper reads them.
//!
//! The expected values of the committed Voron configuration (`tests/data/klipper/voron/`)
//! were obtained by running Klipper's own code on it, outside this repository:
//! `klippy/configfile.py` `PrinterConfig.read_main_config` (includes, SAVE_CONFIG), the
//! `getfloat` calls of `klippy/toolhead.py` and `klippy/kinematics/corexy.py`,
//! `klippy/extras/input_shaper.py` `InputShaperParams`, `klippy/stepper.py`
//! `parse_step_distance`, and the tmc drivers' `run_current`/`interpolate` reads, at
//! Klipper commit 84104bbbd762 (2026-08).

use std::path::{Path, PathBuf};

use settle_gcode::config::{KlipperConfig, ShaperSetting};
use settle_gcode::{Dialect, GcodeError};

use crate::data_path;

/// Writes `files` (relative path, text) into a new temporary folder.
pub fn tree(files: &[(&str, &str)]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("temp dir");
    for (name, text) in files {
        let p = dir.path().join(name);
        std::fs::create_dir_all(p.parent().expect("has a parent")).expect("mkdir");
        std::fs::write(p, text).expect("write");
    }
    dir
}

const PRINTER: &str = "[printer]\nkinematics: cartesian\nmax_velocity: 200\nmax_accel: 3000\n";

fn read_err(dir: &Path, main: &str) -> GcodeError {
    KlipperConfig::read(dir.join(main)).expect_err("an error")
}

fn shaper(name: &str, f: f64, z: f64) -> ShaperSetting {
    ShaperSetting {
        name: name.to_string(),
        frequency_hz: f,
        damping_ratio: z,
    }
}

#[test]
fn voron_config_reads_as_klipper_does() {
    let dir = data_path("klipper/voron");
    let c = KlipperConfig::read(dir.join("printer.cfg")).expect("valid config");
    let p = &c.printer;
    assert_eq!(p.kinematics, "corexy");
    assert_eq!(p.max_velocity_mm_s, 300.0);
    // user_overrides.cfg, included after [printer], wins; macros/.old_printer.cfg is hidden.
    assert_eq!(p.max_accel_mm_s2, 4000.0);
    assert_eq!(p.minimum_cruise_ratio, 0.4);
    assert_eq!(p.square_corner_velocity_mm_s, 5.0);
    assert_eq!((p.max_z_velocity_mm_s, p.max_z_accel_mm_s2), (15.0, 350.0));
    // SAVE_CONFIG's per-axis types win over the file's `shaper_type: mzv`.
    let s = c.input_shaper.as_ref().expect("[input_shaper]");
    assert_eq!(s.x, shaper("mzv", 54.2, 0.08));
    assert_eq!(s.y, shaper("ei", 41.4, 0.1));
    assert_eq!(s.z, shaper("mzv", 0.0, 0.1));
    assert_eq!(s.y.type_name(Dialect::Klipper).as_deref(), Some("ei"));
    assert_eq!(s.z.type_name(Dialect::Klipper), None);
    let x = c.steppers.x.as_ref().expect("stepper_x");
    assert_eq!(x.drive.microsteps_per_mm, 160.0);
    assert_eq!(x.drive.microsteps, 32);
    assert_eq!(x.drive.interpolate, Some(false));
    assert_eq!(x.drive.run_current_a_rms, Some(1.2));
    assert_eq!(
        (x.drive.position_min_mm, x.drive.position_max_mm),
        (0.0, Some(300.0))
    );
    assert_eq!(x.driver.as_deref(), Some("tmc5160"));
    assert_eq!(
        (x.rotation_distance_mm, x.full_steps_per_rotation),
        (40.0, 200)
    );
    let y = c.steppers.y.as_ref().expect("stepper_y");
    assert_eq!(y.drive.microsteps_per_mm, 160.0);
    assert_eq!(y.drive.interpolate, Some(true));
    assert_eq!(y.drive.position_max_mm, Some(305.0));
    let z = c.steppers.z.as_ref().expect("stepper_z");
    assert_eq!(z.gear_ratio, 5.0);
    assert_eq!(z.drive.microsteps_per_mm, 800.0);
    assert_eq!(z.drive.run_current_a_rms, Some(0.8));
    assert_eq!(z.driver.as_deref(), Some("tmc2209"));
    assert_eq!(
        (z.drive.position_min_mm, z.drive.position_max_mm),
        (-5.0, Some(270.0))
    );
    let files: Vec<PathBuf> = c
        .files
        .iter()
        .map(|f| {
            f.strip_prefix(&dir)
                .expect("under the folder")
                .to_path_buf()
        })
        .collect();
    assert_eq!(
        files,
        [
            "printer.cfg",
            "mainsail.cfg",
            "hardware/steppers_y.cfg",
            "hardware/z.cfg",
            "macros/homing.cfg",
            "user_overrides.cfg"
        ]
        .map(PathBuf::from)
    );
    assert!(c.notes.is_empty(), "{:?}", c.notes);
}

#[test]
fn save_config_values_lose_to_the_same_option_outside_the_block() {
    // As klippy/configfile.py `_strip_duplicates` does on loading (Klipper's own code,
    // run on this text, gives shaper_freq_y 40.0 and shaper_freq_x 54.2).
    let text = format!(
        "{PRINTER}[input_shaper]\nshaper_freq_y: 40\n\n\
         #*# <---------------------- SAVE_CONFIG ---------------------->\n\
         #*# DO NOT EDIT THIS BLOCK OR BELOW. The contents are auto-generated.\n#*#\n\
         #*# [input_shaper]\n#*# shaper_type_x = zv\n#*# shaper_freq_x = 54.2\n#*# shaper_freq_y = 41.4\n"
    );
    let c = KlipperConfig::parse(&text, "printer.cfg").expect("valid");
    let s = c.input_shaper.expect("[input_shaper]");
    assert_eq!(s.x, shaper("zv", 54.2, 0.1));
    assert_eq!(s.y, shaper("mzv", 40.0, 0.1));
    assert_eq!(c.notes.len(), 1, "{:?}", c.notes);
    let note = c.notes[0].to_string();
    assert!(note.starts_with("printer.cfg:14: "), "{note}");
    assert!(note.contains("printer.cfg:6"), "{note}");
}

#[test]
fn a_save_config_block_with_foreign_lines_is_ignored_whole() {
    let text = format!(
        "{PRINTER}\n#*# <---------------------- SAVE_CONFIG ---------------------->\n\
         #*# DO NOT EDIT THIS BLOCK OR BELOW. The contents are auto-generated.\n#*#\n\
         #*# [input_shaper]\n#*# shaper_freq_x = 54.2\nmax_z_velocity: 30\n"
    );
    let c = KlipperConfig::parse(&text, "printer.cfg").expect("valid");
    assert_eq!(c.input_shaper, None);
    // The foreign line is read where it stands: in [printer], the `#*#` lines comments.
    assert_eq!(c.printer.max_z_velocity_mm_s, 30.0);
    assert_eq!(c.notes.len(), 1);
    assert!(c.notes[0].to_string().contains("line 11"), "{}", c.notes[0]);
    // So an [input_shaper] option there is one [printer] does not take, which Klipper
    // refuses ("Option 'shaper_freq_y' is not valid in section 'printer'").
    let e = KlipperConfig::parse(
        &text.replace("max_z_velocity", "shaper_freq_y"),
        "printer.cfg",
    )
    .expect_err("not an option of [printer]");
    assert!(
        e.to_string()
            .starts_with("printer.cfg:11: key `printer.shaper_freq_y`: Klipper does not know"),
        "{e}"
    );
}

#[test]
fn max_accel_to_decel_maps_to_minimum_cruise_ratio() {
    let c = KlipperConfig::parse(&format!("{PRINTER}max_accel_to_decel: 1000\n"), "p.cfg")
        .expect("valid");
    assert_eq!(c.printer.minimum_cruise_ratio, 1.0 - 1000.0 / 3000.0);
    assert_eq!(c.notes.len(), 1);
    // minimum_cruise_ratio wins when both are given; an accel_to_decel above max_accel
    // gives 0.
    let both = format!("{PRINTER}max_accel_to_decel: 1000\nminimum_cruise_ratio: 0.2\n");
    let c = KlipperConfig::parse(&both, "p.cfg").expect("valid");
    assert_eq!((c.printer.minimum_cruise_ratio, c.notes.len()), (0.2, 0));
    let c = KlipperConfig::parse(&format!("{PRINTER}max_accel_to_decel: 5000\n"), "p.cfg")
        .expect("valid");
    assert_eq!(c.printer.minimum_cruise_ratio, 0.0);
}

#[test]
fn defaults_are_klippers() {
    let c = KlipperConfig::parse(&format!("{PRINTER}[input_shaper]\n"), "p.cfg").expect("valid");
    let p = &c.printer;
    assert_eq!(
        (p.minimum_cruise_ratio, p.square_corner_velocity_mm_s),
        (0.5, 5.0)
    );
    assert_eq!(
        (p.max_z_velocity_mm_s, p.max_z_accel_mm_s2),
        (200.0, 3000.0)
    );
    assert_eq!(c.input_shaper.expect("section").x, shaper("mzv", 0.0, 0.1));
    let c = KlipperConfig::parse(PRINTER, "p.cfg").expect("valid");
    assert_eq!(c.input_shaper, None);
    assert_eq!(c.steppers.x, None);
    let stepper = "[stepper_x]\nrotation_distance: 32\nmicrosteps: 12\n";
    let c = KlipperConfig::parse(&format!("{PRINTER}{stepper}"), "p.cfg").expect("valid");
    let x = c.steppers.x.expect("stepper_x");
    // No TMC section: any microstep count, no current, no interpolation flag.
    assert_eq!(x.drive.microsteps_per_mm, 200.0 * 12.0 / 32.0);
    assert_eq!(
        (x.drive.run_current_a_rms, x.drive.interpolate),
        (None, None)
    );
    assert_eq!(
        (x.drive.position_min_mm, x.drive.position_max_mm),
        (0.0, None)
    );
}

/// The error reading `extra` after a valid `[printer]`, as `file:line`, key and message.
fn value_error(extra: &str) -> (String, String, String) {
    let text = format!("{PRINTER}{extra}");
    match KlipperConfig::parse(&text, "printer.cfg") {
        Err(e @ GcodeError::ConfigValue { .. }) => {
            let GcodeError::ConfigValue { at, key, .. } = &e else {
                unreachable!()
            };
            (at.to_string(), key.clone(), e.to_string())
        }
        other => panic!("{extra}: {other:?}"),
    }
}

#[test]
fn malformed_values_name_file_line_and_key() {
    for (extra, line, key, allowed) in [
        (
            "max_velocity: fast\n",
            5,
            "max_velocity",
            "a finite number > 0",
        ),
        (
            "minimum_cruise_ratio: 1\n",
            5,
            "minimum_cruise_ratio",
            "< 1",
        ),
        ("max_z_velocity: 250\n", 5, "max_z_velocity", "<= 200"),
        (
            "square_corner_velocity: nan\n",
            5,
            "square_corner_velocity",
            ">= 0",
        ),
        (
            "[input_shaper]\nshaper_type: zvdd\n",
            6,
            "shaper_type",
            "not a Klipper shaper",
        ),
        (
            "[input_shaper]\nshaper_type_y: MZV\n",
            6,
            "shaper_type_y",
            "lower case",
        ),
        (
            "[input_shaper]\nshaper_type_x: ei\ndamping_ratio_x: 0.5\n",
            7,
            "damping_ratio_x",
            "<= 0.4",
        ),
        (
            "[input_shaper]\nshaper_type: mzv(n=2)\n",
            6,
            "shaper_type",
            "too small",
        ),
        (
            "[stepper_x]\nrotation_distance: 40\nmicrosteps: 12\n[tmc2209 stepper_x]\nrun_current: 0.8\n",
            7,
            "microsteps",
            "with a tmc2209 driver",
        ),
        (
            "[stepper_x]\nrotation_distance: 40\nmicrosteps: 16\n[tmc2209 stepper_x]\nrun_current: 2.5\n",
            9,
            "run_current",
            "<= 2",
        ),
        (
            "[stepper_x]\nrotation_distance: 40\nmicrosteps: 16\n[tmc2209 stepper_x]\nrun_current: 1\ninterpolate: maybe\n",
            10,
            "interpolate",
            "true/false",
        ),
        (
            "[stepper_z]\nrotation_distance: 40\nmicrosteps: 16\ngear_ratio: 80/16\n",
            8,
            "gear_ratio",
            "80:16",
        ),
        (
            "[stepper_z]\nrotation_distance: 40\nmicrosteps: 16\nfull_steps_per_rotation: 202\n",
            8,
            "full_steps_per_rotation",
            "divisible by 4",
        ),
        // 200 x 16 / 1e-12 mm = 3.2e15 and 200 x 1 / 5000 mm = 0.04 microsteps per mm,
        // outside 1 to 1e9 (settle_gcode::config::MICROSTEPS_PER_MM).
        (
            "[stepper_z]\nrotation_distance: 1e-12\nmicrosteps: 16\n",
            6,
            "rotation_distance",
            "gives 1 to 1e9 microsteps per mm (200 full steps x 16 microsteps x gear ratio 1 / 1e-12 mm is 3.2e15)",
        ),
        (
            "[stepper_z]\nrotation_distance: 5000\nmicrosteps: 1\n",
            6,
            "rotation_distance",
            "(200 full steps x 1 microsteps x gear ratio 1 / 5000 mm is 4e-2)",
        ),
        (
            "[stepper_z]\nrotation_distance: 40\nmicrosteps: 16.5\n",
            7,
            "microsteps",
            "a whole number",
        ),
        (
            "[stepper_z]\nrotation_distance: 40\nmicrosteps: 16\nposition_min: 10\nposition_max: 5\n",
            9,
            "position_max",
            "> 10",
        ),
    ] {
        let (at, k, message) = value_error(extra);
        assert_eq!(at, format!("printer.cfg:{line}"), "{extra}: {message}");
        assert_eq!(k, key, "{extra}");
        assert!(message.contains(allowed), "{extra}: {message}");
    }
    let e = KlipperConfig::parse("[printer]\nkinematics: coreyx\n", "p.cfg").expect_err("bad");
    assert!(e.to_string().contains("one of cartesian, corexy"), "{e}");
    let e = KlipperConfig::parse("[printer]\nkinematics: corexy\nmax_accel: 1\n", "p.cfg")
        .expect_err("missing");
    assert!(
        matches!(&e, GcodeError::ConfigMissing { key, .. } if key == "max_velocity"),
        "{e}"
    );
    let e = KlipperConfig::parse("[mcu]\nserial: x\n", "p.cfg").expect_err("no printer");
    assert!(matches!(&e, GcodeError::ConfigNoSection { section, .. } if section == "printer"));
    let e = KlipperConfig::parse(
        &format!("{PRINTER}[tmc2209 stepper_x]\nuart_pin: PA1\n[stepper_x]\nrotation_distance: 40\nmicrosteps: 16\n"),
        "p.cfg",
    )
    .expect_err("no run_current");
    assert!(
        matches!(&e, GcodeError::ConfigMissing { key, .. } if key == "run_current"),
        "{e}"
    );
}

#[test]
fn an_error_in_an_included_file_names_that_file() {
    let dir = tree(&[
        (
            "printer.cfg",
            "[include conf/limits.cfg]\n[mcu]\nserial: x\n",
        ),
        (
            "conf/limits.cfg",
            "# limits\n\n[printer]\nkinematics: corexy\nmax_velocity: 300\nmax_accel: -5\n",
        ),
    ]);
    let e = read_err(dir.path(), "printer.cfg");
    let at = e.location().expect("a line error").to_string();
    assert!(at.ends_with("conf/limits.cfg:6"), "{e}");
    assert!(e.to_string().contains("[printer] max_accel = `-5`"), "{e}");
}

#[test]
fn includes_missing_cyclic_and_misplaced() {
    let dir = tree(&[
        (
            "printer.cfg",
            &format!("{PRINTER}[include extras/*.cfg]\n[include nope.cfg]\n"),
        ),
        ("a.cfg", "[include b.cfg]\n"),
        ("b.cfg", "[include sub/../a.cfg]\n"),
        ("loop.cfg", &format!("{PRINTER}\n[include a.cfg]\n")),
        ("after.cfg", "[include a2.cfg]\nmax_accel: 5\n"),
        ("a2.cfg", PRINTER),
        (
            "indented.cfg",
            &format!("{PRINTER}[mcu]\n [include a2.cfg]\n"),
        ),
        ("sub/keep", ""),
    ]);
    // A wildcard that matches nothing is fine; a plain name that is not there (Klipper
    // refuses it) is skipped with a note naming the include's file and line.
    let c = KlipperConfig::read(dir.path().join("printer.cfg")).expect("read on");
    assert_eq!(c.notes.len(), 1, "{:?}", c.notes);
    let at = c.notes[0].at.as_ref().expect("a place");
    assert!(
        at.source_name.ends_with("printer.cfg") && at.line == 6,
        "{at}"
    );
    assert!(
        c.notes[0].text.starts_with("[include nope.cfg] skipped: `")
            && c.notes[0].text.contains("nope.cfg` is not there"),
        "{}",
        c.notes[0].text
    );
    // Where a skipped file may have set what Klipper requires, the error says so.
    std::fs::write(
        dir.path().join("split.cfg"),
        "[include hardware.cfg]\n[mcu]\nserial: /dev/null\n",
    )
    .expect("write");
    let e = read_err(dir.path(), "split.cfg");
    assert!(
        matches!(&e, GcodeError::ConfigNoSection { section, .. } if section == "printer"),
        "{e:?}"
    );
    assert!(!e.to_string().contains("fragment"), "{e}");
    let text = e.to_string();
    assert!(
        text.contains("1 [include]s of files that are not there were skipped, the first [include hardware.cfg] at ")
            && text.contains("split.cfg:1"),
        "{text}"
    );
    // A link to nothing, by name or matched by a wildcard, is skipped the same way.
    #[cfg(unix)]
    {
        std::fs::write(
            dir.path().join("links.cfg"),
            format!("{PRINTER}[include gone.cfg]\n[include g*.cfg]\n"),
        )
        .expect("write");
        std::os::unix::fs::symlink(dir.path().join("nowhere.cfg"), dir.path().join("gone.cfg"))
            .expect("link");
        let c = KlipperConfig::read(dir.path().join("links.cfg")).expect("read on");
        let notes: Vec<String> = c.notes.iter().map(ToString::to_string).collect();
        assert_eq!(notes.len(), 2, "{notes:?}");
        assert!(
            notes[0].contains("links.cfg:5: [include gone.cfg] skipped"),
            "{notes:?}"
        );
        assert!(
            notes[1].contains("links.cfg:6: [include g*.cfg] skipped"),
            "{notes:?}"
        );
        assert!(
            notes.iter().all(|n| n.contains("is a link to nothing")),
            "{notes:?}"
        );
    }
    match read_err(dir.path(), "loop.cfg") {
        GcodeError::IncludeCycle { at, chain, .. } => {
            assert!(at.source_name.ends_with("b.cfg") && at.line == 1, "{at}");
            assert_eq!(chain.matches(" -> ").count(), 3, "{chain}");
        }
        e => panic!("{e:?}"),
    }
    // After an include, reading starts outside any section again.
    match read_err(dir.path(), "after.cfg") {
        GcodeError::ConfigSyntax { at, what } => {
            assert_eq!(at.line, 2);
            assert!(what.contains("before any [section]"), "{what}");
        }
        e => panic!("{e:?}"),
    }
    match read_err(dir.path(), "indented.cfg") {
        GcodeError::ConfigSyntax { at, what } => {
            assert_eq!(at.line, 6);
            assert!(what.contains("start of its line"), "{what}");
        }
        e => panic!("{e:?}"),
    }
}

#[test]
fn unreadable_files_are_errors() {
    let dir = tree(&[
        ("printer.cfg", &format!("{PRINTER}[include bad.cfg]\n")),
        ("bad.cfg", "[mcu]\nserial: \u{fffd}\n"),
        ("dir.cfg", &format!("{PRINTER}[include d1*]\n")),
        ("d1/x", ""),
    ]);
    std::fs::write(dir.path().join("bad.cfg"), b"[mcu]\nserial: /dev/tty\xff\n").expect("write");
    // The include line is named, then the included file's line and column.
    match read_err(dir.path(), "printer.cfg") {
        GcodeError::Include { at, what, source } => {
            assert!(at.source_name.ends_with("printer.cfg"));
            assert_eq!(what, "[include bad.cfg]");
            match *source {
                settle_files::FileError::NotText {
                    path, line, column, ..
                } => {
                    assert!(path.ends_with("bad.cfg"));
                    assert_eq!((line, column), (2, 17));
                }
                e => panic!("{e:?}"),
            }
        }
        e => panic!("{e:?}"),
    }
    // A folder matched by an include: named with the include's line.
    match read_err(dir.path(), "dir.cfg") {
        GcodeError::Include { at, source, .. } => {
            assert!(at.source_name.ends_with("dir.cfg"));
            assert!(matches!(
                *source,
                settle_files::FileError::NotRegular {
                    what: "a folder",
                    ..
                }
            ));
        }
        e => panic!("{e:?}"),
    }
    assert!(matches!(
        read_err(dir.path(), "missing.cfg"),
        GcodeError::File(f) if matches!(*f, settle_files::FileError::Read { .. })
    ));
}

#[test]
fn a_long_malformed_value_is_quoted_by_its_start() {
    // 200,000 characters of a value: the error names file, line and key, and quotes the
    // first 120 characters.
    let value = "x".repeat(200_000);
    let (at, key, msg) = value_error(&format!("max_accel_to_decel: {value}\n"));
    assert_eq!(
        (at.as_str(), key.as_str()),
        ("printer.cfg:5", "max_accel_to_decel")
    );
    assert!(
        msg.contains(&format!("`{}...`", &value[..120])),
        "{}",
        &msg[..200]
    );
    assert!(msg.len() < 400, "{} bytes", msg.len());
}
