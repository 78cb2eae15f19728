//! Exported settings paste cleanly and read back as the same values.

use settle_gcode::GcodeError;
use settle_gcode::config::{KlipperConfig, KlipperExport, RrfConfig, RrfExport, ShaperSetting};

use crate::data_path;

fn shaper(name: &str, f: f64, z: f64) -> ShaperSetting {
    ShaperSetting {
        name: name.to_string(),
        frequency_hz: f,
        damping_ratio: z,
    }
}

fn klipper_export() -> KlipperExport {
    KlipperExport {
        produced_by: "settle tune scenarios/corner.toml\n(second line)".into(),
        x: shaper("mzv(n=4,t=0.8)", 61.73, 0.071),
        y: shaper("ei", 38.099999999999994, 0.12),
        max_accel_mm_s2: Some(7123.5),
        minimum_cruise_ratio: Some(0.25),
        square_corner_velocity_mm_s: None,
    }
}

#[test]
fn klipper_export_has_one_section_of_each_name_and_reads_back() {
    let e = klipper_export();
    let text = e.to_config().expect("valid values");
    assert_eq!(text.matches("[input_shaper]").count(), 1, "{text}");
    assert_eq!(text.matches("[printer]").count(), 1, "{text}");
    assert!(!text.contains("square_corner_velocity"), "{text}");
    assert!(
        text.lines()
            .all(|l| !l.contains("(second line)") || l.starts_with('#'))
    );
    // Pasted above the SAVE_CONFIG block of the Voron configuration, it wins over the
    // block's SHAPER_CALIBRATE values and over the [printer] values before it. (Klipper's
    // own reading, run on the same pasted file outside this repository, gives these
    // values too: see config_klipper.rs for how.)
    let dir = data_path("klipper/voron");
    let original = std::fs::read_to_string(dir.join("printer.cfg")).expect("test data");
    let header = "#*# <---------------------- SAVE_CONFIG";
    let at = original.find(header).expect("a SAVE_CONFIG block");
    let pasted = format!("{}{text}\n{}", &original[..at], &original[at..]);
    let c = KlipperConfig::parse(&pasted, dir.join("printer.cfg")).expect("valid config");
    let s = c.input_shaper.expect("[input_shaper]");
    assert_eq!((s.x, s.y), (e.x.clone(), e.y.clone()));
    assert_eq!(c.printer.max_accel_mm_s2, 7123.5);
    assert_eq!(c.printer.minimum_cruise_ratio, 0.25);
    assert_eq!(c.printer.square_corner_velocity_mm_s, 5.0);
    // The block's shaper_type_x/y and shaper_freq_x/y are the values set twice.
    assert_eq!(c.notes.len(), 4, "{:?}", c.notes);
    // Alone in a file (after a minimal [printer]) it reads back too.
    let alone =
        format!("[printer]\nkinematics: cartesian\nmax_velocity: 300\nmax_accel: 1\n{text}");
    let c = KlipperConfig::parse(&alone, "p.cfg").expect("valid");
    assert_eq!(c.input_shaper.expect("section").x, e.x);
    assert_eq!(c.printer.max_accel_mm_s2, 7123.5);
}

#[test]
fn klipper_export_without_limits_writes_no_printer_section() {
    let e = KlipperExport {
        max_accel_mm_s2: None,
        minimum_cruise_ratio: None,
        ..klipper_export()
    };
    let text = e.to_config().expect("valid");
    assert!(!text.contains("[printer]"), "{text}");
}

#[test]
fn klipper_export_refuses_what_klipper_refuses() {
    for (change, key) in [
        (
            KlipperExport {
                x: shaper("zvdd", 50.0, 0.1),
                ..klipper_export()
            },
            "shaper_type_x",
        ),
        (
            KlipperExport {
                y: shaper("rrf:zvd", 50.0, 0.1),
                ..klipper_export()
            },
            "shaper_type_y",
        ),
        (
            KlipperExport {
                y: shaper("3hump_ei", 50.0, 0.25),
                ..klipper_export()
            },
            "damping_ratio_y",
        ),
        (
            KlipperExport {
                x: shaper("zv", f64::NAN, 0.1),
                ..klipper_export()
            },
            "shaper_freq_x",
        ),
        (
            KlipperExport {
                x: shaper("zv", 1000.5, 0.1),
                ..klipper_export()
            },
            "shaper_freq_x",
        ),
        (
            KlipperExport {
                minimum_cruise_ratio: Some(1.0),
                ..klipper_export()
            },
            "minimum_cruise_ratio",
        ),
        (
            KlipperExport {
                max_accel_mm_s2: Some(0.0),
                ..klipper_export()
            },
            "max_accel",
        ),
    ] {
        match change.to_config() {
            Err(GcodeError::ExportValue { key: k, .. }) => assert_eq!(k, key),
            other => panic!("{key}: {other:?}"),
        }
    }
}

/// The highest shaper frequency written is the highest settle's printer.cfg reader takes
/// back (`MAX_SHAPER_FREQUENCY_HZ`, 1000 Hz): 1000 Hz reads back as written, 1000.5 Hz is
/// refused by the reader too, so the export does not write it (Klipper itself takes any
/// frequency >= 0: `minval=0.` in klippy/extras/input_shaper.py).
#[test]
fn klipper_export_writes_only_frequencies_settle_reads_back() {
    let at = |f: f64| KlipperExport {
        x: shaper("zv", f, 0.1),
        ..klipper_export()
    };
    let text = at(1000.0).to_config().expect("1000 Hz is written");
    let head = "[printer]\nkinematics: cartesian\nmax_velocity: 300\nmax_accel: 1\n";
    let c = KlipperConfig::parse(&format!("{head}{text}"), "p.cfg").expect("reads back");
    assert_eq!(c.input_shaper.expect("section").x.frequency_hz, 1000.0);
    let too_high = format!("{head}[input_shaper]\nshaper_type_x: zv\nshaper_freq_x: 1000.5\n");
    let refused = KlipperConfig::parse(&too_high, "p.cfg").expect_err("the reader refuses it");
    assert!(refused.to_string().contains("shaper_freq_x"), "{refused}");
    assert!(at(1000.5).to_config().is_err());
}

#[test]
fn rrf_export_is_one_m593_line_and_reads_back() {
    let e = RrfExport {
        produced_by: "settle tune scenarios/corner.toml".into(),
        shaper: shaper("rrf:ei2", 47.300000000000004, 0.07),
        max_accel_xy_mm_s2: [None, Some(3500.0)],
        print_accel_mm_s2: Some(2500.0),
        travel_accel_mm_s2: None,
    };
    let text = e.to_config().expect("valid values");
    assert_eq!(
        text.lines().filter(|l| l.starts_with("M593")).count(),
        1,
        "{text}"
    );
    assert!(
        text.contains("M593 P\"ei2\" F47.300000000000004 S0.07\nM201 Y3500\nM204 P2500\n"),
        "{text}"
    );
    let alone = RrfConfig::parse(&text, "sys/config.g").expect("valid");
    assert_eq!(alone.input_shaper, shaper("ei2", 47.300000000000004, 0.07));
    assert_eq!(alone.print_accel_mm_s2, 2500.0);
    // At the end of the Duet 3 Mini configuration it replaces its M593 and M204 P.
    let root = data_path("rrf/mini5plus/sys");
    let original = std::fs::read_to_string(root.join("config.g")).expect("test data");
    let c = RrfConfig::parse(&format!("{original}{text}"), root.join("config.g")).expect("valid");
    assert_eq!(c.input_shaper, alone.input_shaper);
    assert_eq!(
        (c.print_accel_mm_s2, c.travel_accel_mm_s2),
        (2500.0, 4000.0)
    );
    // Its M201 X3000.00 Y3000.00 (line 30): Y raised to 3500, X left as it is.
    assert_eq!(
        (c.axes.x.max_accel_mm_s2, c.axes.y.max_accel_mm_s2),
        (3000.0, 3500.0)
    );
}

#[test]
fn rrf_export_refuses_what_the_firmware_refuses() {
    let base = RrfExport {
        produced_by: String::new(),
        shaper: shaper("zvd", 40.0, 0.1),
        max_accel_xy_mm_s2: [None; 2],
        print_accel_mm_s2: None,
        travel_accel_mm_s2: None,
    };
    for (change, key) in [
        (
            RrfExport {
                shaper: shaper("mzv(n=4)", 40.0, 0.1),
                ..base.clone()
            },
            "M593 P",
        ),
        (
            RrfExport {
                shaper: shaper("custom", 40.0, 0.1),
                ..base.clone()
            },
            "M593 P",
        ),
        (
            RrfExport {
                shaper: shaper("zvd", 1001.0, 0.1),
                ..base.clone()
            },
            "M593 F",
        ),
        (
            RrfExport {
                shaper: shaper("zvd", 40.0, 1.0),
                ..base.clone()
            },
            "M593 S",
        ),
        (
            RrfExport {
                travel_accel_mm_s2: Some(-1.0),
                ..base.clone()
            },
            "M204 T",
        ),
        (
            RrfExport {
                max_accel_xy_mm_s2: [None, Some(f64::INFINITY)],
                ..base.clone()
            },
            "M201 Y",
        ),
    ] {
        match change.to_config() {
            Err(GcodeError::ExportValue { key: k, .. }) => assert_eq!(k, key),
            other => panic!("{key}: {other:?}"),
        }
    }
    assert!(base.to_config().is_ok());
}

#[test]
fn shaping_off_is_m593_none_alone_and_notes_sit_above_their_values() {
    use settle_gcode::config::Note;
    let off = RrfExport {
        produced_by: "a test".into(),
        shaper: shaper("none", f64::NAN, f64::NAN),
        max_accel_xy_mm_s2: [None; 2],
        print_accel_mm_s2: Some(2500.0),
        travel_accel_mm_s2: None,
    };
    let note = |key: &str, text: &str| Note {
        key: key.into(),
        text: text.into(),
    };
    let text = off
        .to_config_with_notes(&[note("M204 P", "was 3000"), note("", "head\nline")])
        .expect("valid");
    assert!(
        text.ends_with("; head line\nM593 P\"none\"\n; was 3000\nM204 P2500\n"),
        "{text}"
    );
    let c = RrfConfig::parse(&text, "sys/config.g").expect("valid");
    assert_eq!(c.input_shaper.name, "none");
    assert_eq!(c.print_accel_mm_s2, 2500.0);
    let k = klipper_export()
        .to_config_with_notes(&[note("shaper_freq_y", "41.4 -> 38.1"), note("nowhere", "x")])
        .expect("valid");
    assert!(
        k.contains("shaper_type_y: ei\n# 41.4 -> 38.1\nshaper_freq_y: 38.099999999999994\n"),
        "{k}"
    );
    assert!(
        !k.contains("# x\n"),
        "a note whose key is not written is left out: {k}"
    );
    let printer = "[printer]\nkinematics: cartesian\nmax_velocity: 300\nmax_accel: 1\n";
    let read = |t: &str| {
        KlipperConfig::parse(&format!("{printer}{t}"), "p.cfg")
            .expect("valid")
            .input_shaper
    };
    assert_eq!(
        read(&k),
        read(&klipper_export().to_config().expect("valid"))
    );
}
