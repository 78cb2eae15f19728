//! Real firmware configurations, as their owners published them (`tests/data/real/`, with
//! where each file comes from in `tests/data/real/MANIFEST.md`), read with the values the
//! firmware would use. Every expected value is taken from the file by hand (its line is
//! named) and was checked with Python's `configparser` set up as `klippy/configfile.py`
//! sets it up (Klipper) or worked out as RepRapFirmware applies the commands
//! (`config_rrf.rs` says how). The input shapers are the owners' published results of
//! `identify/tests/corpus/MANIFEST.md` ("Published results") at the same commits.

use settle_gcode::config::{KlipperConfig, RrfConfig, ShaperSetting};

use crate::data_path;

fn klipper(machine: &str) -> KlipperConfig {
    let path = data_path(&format!("real/{machine}/printer.cfg"));
    KlipperConfig::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn shaper(name: &str, f: f64, z: f64) -> ShaperSetting {
    ShaperSetting {
        name: name.to_string(),
        frequency_hz: f,
        damping_ratio: z,
    }
}

/// The file names (relative to the machine's folder) of what was read, in order.
fn files_read(c: &KlipperConfig, machine: &str) -> Vec<String> {
    let root = data_path(&format!("real/{machine}"));
    c.files
        .iter()
        .map(|f| {
            f.strip_prefix(&root)
                .unwrap_or(f)
                .to_string_lossy()
                .into_owned()
        })
        .collect()
}

fn notes(c: &[settle_gcode::config::ConfigNote]) -> Vec<String> {
    c.iter().map(ToString::to_string).collect()
}

#[test]
fn voronpi_reads_with_its_wildcard_includes() {
    let c = klipper("voronpi");
    let p = &c.printer;
    // printer.cfg lines 37-44.
    assert_eq!(p.kinematics, "corexy");
    assert_eq!(p.max_velocity_mm_s, 500.0); // `max_velocity: 500  ` (trailing spaces)
    assert_eq!(p.max_accel_mm_s2, 6500.0); // `max_accel: 6500   # Max 4000`
    // `max_accel_to_decel: 6500` (line 41) = max_accel: no cruise ratio.
    assert_eq!(p.minimum_cruise_ratio, 0.0);
    assert_eq!(p.square_corner_velocity_mm_s, 5.0);
    assert_eq!((p.max_z_velocity_mm_s, p.max_z_accel_mm_s2), (25.0, 350.0));
    // [input_shaper], lines 47-51: the owner's mzv 58.6 / zv 41.8 of commit 6918f135c581.
    let s = c.input_shaper.as_ref().expect("[input_shaper]");
    assert_eq!(s.x, shaper("mzv", 58.6, 0.1));
    assert_eq!(s.y, shaper("zv", 41.8, 0.1));
    // printer_xy_steppers.cfg (from `[include printer_*.cfg]`): rotation_distance 40,
    // microsteps 32, full_steps_per_rotation 200; [tmc2209 stepper_x] interpolate False,
    // run_current 1.1.
    for a in [&c.steppers.x, &c.steppers.y] {
        let a = a.as_ref().expect("stepper");
        assert_eq!(a.drive.microsteps_per_mm, 160.0);
        assert_eq!(a.drive.interpolate, Some(false));
        assert_eq!(a.drive.run_current_a_rms, Some(1.1));
        assert_eq!(a.driver.as_deref(), Some("tmc2209"));
        assert_eq!(a.drive.position_max_mm, Some(250.0));
    }
    // Every include is in the repository: 8 lines, 31 files, each wildcard's matches in
    // name order, in place.
    let files = files_read(&c, "voronpi");
    assert_eq!(files.len(), 31, "{files:?}");
    assert_eq!(
        &files[..4],
        [
            "printer.cfg",
            "config.d/lcd_tweaks.cfg",
            "config.d/mainsail.cfg",
            "config.d/menu_tweaks.cfg"
        ]
    );
    let i = files
        .iter()
        .position(|f| f == "printer_bed_heater.cfg")
        .expect("printer_*.cfg read");
    assert_eq!(
        files[i..i + 6],
        [
            "printer_bed_heater.cfg",
            "printer_extruder.cfg",
            "printer_fans.cfg",
            "printer_xy_steppers.cfg",
            "printer_z_steppers.cfg",
            "raspberry_pi_mcu.cfg"
        ]
    );
    let n = notes(&c.notes);
    assert_eq!(n.len(), 1, "{n:?}");
    assert!(n[0].contains("printer.cfg:41: max_accel_to_decel"), "{n:?}");
}

#[test]
fn zippy_reads_as_a_cartesian_with_its_macros() {
    let c = klipper("zippy");
    let p = &c.printer;
    // printer.cfg lines 101-107.
    assert_eq!(p.kinematics, "cartesian");
    assert_eq!((p.max_velocity_mm_s, p.max_accel_mm_s2), (300.0, 5000.0));
    assert_eq!(p.minimum_cruise_ratio, 0.5); // not set: Klipper's default
    assert_eq!(p.square_corner_velocity_mm_s, 20.0);
    assert_eq!((p.max_z_velocity_mm_s, p.max_z_accel_mm_s2), (5.0, 100.0));
    // [input_shaper], lines 117-121: the owner's 2hump_ei 75.4 / mzv 41.4 (51b70416e5ae).
    let s = c.input_shaper.as_ref().expect("[input_shaper]");
    assert_eq!(s.x, shaper("2hump_ei", 75.4, 0.1));
    assert_eq!(s.y, shaper("mzv", 41.4, 0.1));
    // [stepper_x] lines 14-23: 200 * 16 / 40; position_min -4, position_max 260.
    let x = c.steppers.x.as_ref().expect("stepper_x");
    assert_eq!(x.drive.microsteps_per_mm, 80.0);
    assert_eq!(
        (x.drive.position_min_mm, x.drive.position_max_mm),
        (-4.0, Some(260.0))
    );
    assert_eq!(x.driver, None);
    let y = c.steppers.y.as_ref().expect("stepper_y");
    assert_eq!(
        (y.drive.position_min_mm, y.drive.position_max_mm),
        (-8.0, Some(223.0))
    );
    assert_eq!(files_read(&c, "zippy").len(), 41);
    assert!(c.notes.is_empty(), "{:?}", notes(&c.notes));
}

#[test]
fn metis_reads_through_crlf_includes_and_0_9_degree_motors() {
    let c = klipper("metis");
    let p = &c.printer;
    // printer.cfg lines 27-33.
    assert_eq!(p.kinematics, "corexy");
    assert_eq!((p.max_velocity_mm_s, p.max_accel_mm_s2), (500.0, 10000.0));
    assert_eq!((p.max_z_velocity_mm_s, p.max_z_accel_mm_s2), (15.0, 350.0));
    // [input_shaper], lines 40-44: the owner's mzv 64.2 / mzv 44 (b776e7070d3e).
    let s = c.input_shaper.as_ref().expect("[input_shaper]");
    assert_eq!(s.x, shaper("mzv", 64.2, 0.1));
    assert_eq!(s.y, shaper("mzv", 44.0, 0.1));
    // metis_config/stepper.cfg lines 12-14: `full_steps_per_rotation:400  #400 for 0.9`,
    // microsteps 32, rotation_distance 40: 400 * 32 / 40.
    let x = c.steppers.x.as_ref().expect("stepper_x");
    assert_eq!(
        (x.full_steps_per_rotation, x.drive.microsteps_per_mm),
        (400, 320.0)
    );
    assert_eq!(x.drive.run_current_a_rms, Some(1.0));
    assert_eq!(
        c.steppers.y.as_ref().map(|y| y.drive.position_max_mm),
        Some(Some(305.0))
    );
    // macros/klicky-macros.cfg and klicky-quad-gantry-level.cfg end their lines with
    // CRLF; metis_config/leds.cfg is empty.
    let files = files_read(&c, "metis");
    assert_eq!(files.len(), 24);
    for f in ["macros/klicky-macros.cfg", "metis_config/leds.cfg"] {
        assert!(files.iter().any(|r| r == f), "{f}: {files:?}");
    }
    let crlf = std::fs::read(data_path("real/metis/macros/klicky-macros.cfg")).expect("read");
    assert!(crlf.windows(2).any(|w| w == b"\r\n"));
    assert!(c.notes.is_empty(), "{:?}", notes(&c.notes));
}

#[test]
fn vt627_reads_without_the_files_that_were_links_out_of_its_folder() {
    // printer.cfg includes mainsail.cfg (line 4) and mmu/optional/client_macros.cfg (line
    // 2), KAMP_Settings.cfg includes three ./KAMP/ files (lines 3, 4, 6): links out of the
    // configuration folder in the owner's repository, so not in it. Each is a note; the
    // rest reads.
    let c = klipper("vt627");
    let n = notes(&c.notes);
    assert_eq!(n.len(), 5, "{n:?}");
    for (i, (file, line, what)) in [
        ("printer.cfg", 2, "[include mmu/optional/client_macros.cfg]"),
        ("printer.cfg", 4, "[include mainsail.cfg]"),
        (
            "KAMP_Settings.cfg",
            3,
            "[include ./KAMP/Adaptive_Meshing.cfg]",
        ),
        ("KAMP_Settings.cfg", 4, "[include ./KAMP/Line_Purge.cfg]"),
        ("KAMP_Settings.cfg", 6, "[include ./KAMP/Smart_Park.cfg]"),
    ]
    .into_iter()
    .enumerate()
    {
        let at = c.notes[i].at.as_ref().expect("a place");
        assert!(at.source_name.ends_with(file), "{}", n[i]);
        assert_eq!(at.line, line, "{}", n[i]);
        assert!(n[i].contains(&format!("{what} skipped")), "{}", n[i]);
        assert!(n[i].contains("is not there"), "{}", n[i]);
    }
    let p = &c.printer;
    // printer.cfg lines 20-26.
    assert_eq!(p.kinematics, "corexy");
    assert_eq!((p.max_velocity_mm_s, p.max_accel_mm_s2), (500.0, 10000.0));
    assert_eq!(p.square_corner_velocity_mm_s, 5.0);
    // [input_shaper], lines 28-34: the owner's copy of Shake&Tune's numbers, mzv 69.6 at
    // zeta 0.039 / ei 71.4 at zeta 0.023 (bae3d0d7574b).
    let s = c.input_shaper.as_ref().expect("[input_shaper]");
    assert_eq!(s.x, shaper("mzv", 69.6, 0.039));
    assert_eq!(s.y, shaper("ei", 71.4, 0.023));
    // [stepper_x] lines 116-127, [tmc2209 stepper_x] 131-134: 200 * 64 / 40; the
    // [autotune_tmc stepper_x] section of a plugin (line 87) is not a driver section.
    let x = c.steppers.x.as_ref().expect("stepper_x");
    assert_eq!((x.drive.microsteps_per_mm, x.drive.microsteps), (320.0, 64));
    assert_eq!(x.drive.run_current_a_rms, Some(1.2));
    assert_eq!(x.driver.as_deref(), Some("tmc2209"));
    assert_eq!(
        c.steppers.y.as_ref().map(|y| y.drive.position_max_mm),
        Some(Some(310.0))
    );
}

#[test]
fn railcore_config_g_reads_as_the_firmware_applies_it() {
    let path = data_path("real/railcore/sys/config.g");
    let c = RrfConfig::read(&path).expect("valid config");
    assert_eq!(c.kinematics, "corexy"); // M669 K1, line 43
    let (x, y, z) = (&c.axes.x, &c.axes.y, &c.axes.z);
    // M92 X160 Y160 Z1600 (line 56, at the default x16), then M350 X64 Y64 Z16 I1
    // (line 63): 160 * 64 / 16.
    assert_eq!((x.drive.microsteps_per_mm, x.drive.microsteps), (640.0, 64));
    assert_eq!(y.drive.microsteps_per_mm, 640.0);
    assert_eq!(
        (z.drive.microsteps_per_mm, z.drive.microsteps),
        (1600.0, 16)
    );
    // M208 X280 Y300 Z325 (line 45), M208 X-37 Y0 Z0 S1 (line 46).
    assert_eq!(
        (x.drive.position_min_mm, x.drive.position_max_mm),
        (-37.0, Some(280.0))
    );
    assert_eq!(
        (y.drive.position_min_mm, y.drive.position_max_mm),
        (0.0, Some(300.0))
    );
    // M203 X15000 Y15000 Z600 mm/min (line 78).
    assert_eq!(
        (x.max_speed_mm_s, y.max_speed_mm_s, z.max_speed_mm_s),
        (250.0, 250.0, 10.0)
    );
    // M201 X2500 Y2500 Z100 (line 82); no M204: the firmware's default.
    assert_eq!(
        (x.max_accel_mm_s2, y.max_accel_mm_s2, z.max_accel_mm_s2),
        (2500.0, 2500.0, 100.0)
    );
    assert_eq!(
        (c.print_accel_mm_s2, c.travel_accel_mm_s2),
        (50_000.0, 50_000.0)
    );
    // M566 X800 Y800 Z100 mm/min (line 87).
    assert_eq!(
        (x.max_jerk_mm_s, z.max_jerk_mm_s),
        (800.0 / 60.0, 100.0 / 60.0)
    );
    // M906 X{2800 * 0.65} Y{2800 * 0.65} Z{1680 * 0.65} I30 (line 70): the firmware works
    // the expressions out; then M906 E1200 I10 (line 73) sets the idle factor to 10 %.
    assert_eq!(
        (x.motor_current_ma, y.motor_current_ma, z.motor_current_ma),
        (1820.0, 1820.0, 1092.0)
    );
    assert_eq!(
        x.drive.run_current_a_rms,
        Some(1.82 / std::f64::consts::SQRT_2)
    );
    assert_eq!(c.idle_current_percent, 10.0);
    // `;M593 P"mzv" F42` (line 187) is a comment: no shaper, as the owner left it (the
    // owner's published mzv 42 of the corpus is this commented line).
    assert_eq!(c.input_shaper.name, "none");
    // No M501: config-override.g is not run. The two `global` lines are listed.
    assert_eq!(c.files.len(), 1);
    let n = notes(&c.notes);
    assert_eq!(n.len(), 2, "{n:?}");
    assert!(
        n[0].contains("config.g:201: `global hotend_timer_started"),
        "{n:?}"
    );
    assert!(
        n[1].contains("config.g:202: `global hotend_timer = 0`"),
        "{n:?}"
    );
}

#[test]
fn railcore_config_override_g_runs_with_m501() {
    // The owner's config.g has no M501; with one, config-override.g (M307, G31, G10 L2:
    // nothing settle reads) runs and changes none of the values above.
    let path = data_path("real/railcore/sys/config.g");
    let text = std::fs::read_to_string(&path).expect("read") + "M501\n";
    let c = RrfConfig::parse(&text, &path).expect("valid config");
    let plain = RrfConfig::read(&path).expect("valid config");
    assert_eq!(c.files.len(), 2);
    assert!(c.files[1].ends_with("sys/config-override.g"));
    assert_eq!(
        (c.axes.clone(), c.input_shaper.clone()),
        (plain.axes, plain.input_shaper)
    );
    assert_eq!(c.notes, plain.notes);
}
