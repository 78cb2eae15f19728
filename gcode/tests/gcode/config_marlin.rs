//! A real `M503` reply (`tests/data/real/marlin/`, with where it comes from in
//! `tests/data/real/marlin/PROVENANCE.md`), read with the values the file states: each
//! expected value below is the file's, its line named.

use settle_gcode::config::MarlinSettings;
use settle_planner::firmware::marlin::MarlinJerk;

use crate::data_path;

/// The Ender-3 V2 Neo's reply as OctoPrint's terminal shows it: the planner's values,
/// classic jerk (its `M205` has jerks and no `J`), no shaper, and every other command
/// listed once as read and not used.
#[test]
fn a_real_octoprint_copy_of_m503_reads_its_values() {
    let path = data_path("real/marlin/ender3v2neo/m503_20241028.gcode");
    let s = MarlinSettings::read(&path).unwrap_or_else(|e| panic!("{e}"));
    let mm = |v: [f64; 4]| v.map(|x| x * 1e-3);
    let p = &s.planner;
    // Line 9: `M92 X80.29 Y80.29 Z399.21 E425.35`.
    assert_eq!(s.steps_per_mm, [80.29, 80.29, 399.21, 425.35].map(Some));
    assert_eq!(
        p.steps_per_m,
        [80.29, 80.29, 399.21, 425.35].map(|v| v * 1e3)
    );
    // Line 11: `M203 X500.00 Y500.00 Z10.00 E50.00`.
    assert_eq!(p.max_feedrate_m_s, mm([500.0, 500.0, 10.0, 50.0]));
    // Line 13: `M201 X500.00 Y500.00 Z100.00 E5000.00`.
    assert_eq!(p.max_accel_m_s2, mm([500.0, 500.0, 100.0, 5000.0]));
    // Line 15: `M204 P500.00 R5000.00 T500.00`.
    assert_eq!(
        [
            p.print_accel_m_s2,
            p.retract_accel_m_s2,
            p.travel_accel_m_s2,
            0.0
        ],
        mm([500.0, 5000.0, 500.0, 0.0])
    );
    // Line 17: `M205 B20000.00 S0.00 T0.00 X10.00 Y10.00 Z0.40 E5.00`.
    assert!(s.classic_jerk);
    assert_eq!(p.min_segment_time_s, 20000.0 * 1e-6);
    assert_eq!((p.min_feedrate_m_s, p.min_travel_feedrate_m_s), (0.0, 0.0));
    let MarlinJerk::Classic { max_jerk_m_s, .. } = p.jerk else {
        panic!("classic jerk expected: {:?}", p.jerk)
    };
    assert_eq!(max_jerk_m_s, mm([10.0, 10.0, 0.4, 5.0]));
    assert_eq!(s.shapers, [None; 3]);
    let followed: Vec<(u64, &str)> = s.followed.clone();
    assert_eq!(
        followed,
        [(11, "M203"), (13, "M201"), (15, "M204"), (17, "M205")]
    );
    // Lines 3 to 65: G21, M149, M200, M420, M145 (four lines, one note), M304, M256,
    // M413, M207, M208, M851, M603, M412, M306 and the firmware's own C100 ... C851.
    let noted: Vec<String> = s
        .notes
        .iter()
        .map(|n| {
            let t = n.to_string();
            let after = t.split_once(".gcode:").expect("a located note").1;
            after.split(' ').next().expect("a word").to_string()
        })
        .collect();
    assert_eq!(
        noted,
        [
            "3:", "5:", "7:", "19:", "26:", "31:", "33:", "35:", "37:", "39:", "41:", "43:", "45:",
            "47:", "49:", "51:", "53:", "55:", "57:", "59:", "61:", "63:", "65:"
        ],
        "{:?}",
        s.notes
    );
    assert!(
        s.notes[4]
            .text
            .starts_with("M145 (material preheat presets)")
    );
    assert!(s.notes[14].text.starts_with("C100: not a command"));
}

/// A RepRapFirmware config.g is not an `M503` reply: its `M203` is in mm/min where Marlin's
/// is in mm/s (the mini 5+'s `M203 X18000.00` would be 18000 mm/s). Marlin's and Prusa's
/// readers refuse it at its first command that Marlin does not have: the RailCore's
/// `M584 X0.0 Y0.1 ...` at line 44, the mini 5+'s `M550 P"mini5plus"` at line 9.
#[test]
fn a_real_config_g_is_refused_at_its_first_reprapfirmware_command() {
    for (file, line, command, prusa) in [
        (
            "real/railcore/sys/config.g",
            44,
            "M584 (drive mapping)",
            false,
        ),
        (
            "rrf/mini5plus/sys/config.g",
            9,
            "M550 (machine name)",
            false,
        ),
        ("rrf/mini5plus/sys/config.g", 9, "M550 (machine name)", true),
    ] {
        let path = data_path(file);
        let read = if prusa {
            MarlinSettings::read_prusa(&path)
        } else {
            MarlinSettings::read(&path)
        };
        let e = read.expect_err("a config.g").to_string();
        let at = format!("config.g:{line}: {command} is a RepRapFirmware command");
        assert!(e.contains(&at), "{file}: {e}");
        assert!(e.contains("settle import rrf"), "{e}");
    }
}

/// The commands only RepRapFirmware has are not Marlin's: the reply of a Marlin with TMC
/// drivers and Ethernet, copied without its `echo:` prefixes (as some hosts show it), with
/// the `M906`, `M569` and `M552` lines Marlin's settings.cpp prints for them, reads the
/// same planner values as the Ender-3 V2 Neo's own reply, and notes the three as read.
#[test]
fn marlin_commands_that_a_config_g_also_has_are_read_as_marlin() {
    let path = data_path("real/marlin/ender3v2neo/m503_20241028.gcode");
    let text = std::fs::read_to_string(&path).expect("reads");
    let mut bare: String = text
        .lines()
        .filter(|l| !l.starts_with("Send:"))
        .map(|l| {
            let l = l.strip_prefix("Recv: ").unwrap_or(l);
            format!("{}\n", l.strip_prefix("echo:").unwrap_or(l).trim())
        })
        .collect();
    assert!(!bare.contains("echo:"));
    bare.push_str("; Stepper driver current:\nM906 X580 Y580 Z580\nM906 T0 E650\n");
    bare.push_str("; Driver stepping mode:\nM569 S1 X Y Z\nM552 P192.168.0.7\n");
    let own = MarlinSettings::read(&path).unwrap_or_else(|e| panic!("{e}"));
    let s = MarlinSettings::parse(&bare, "bare.txt").unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.planner, own.planner);
    assert_eq!(s.steps_per_mm, own.steps_per_mm);
    for c in [
        "M906 (stepper currents)",
        "M569 (driver chopper mode)",
        "M552 (network)",
    ] {
        assert!(
            s.notes.iter().any(|n| n.text.starts_with(c)),
            "{c}: {:?}",
            s.notes
        );
    }
}
