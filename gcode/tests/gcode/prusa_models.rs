//! `--firmware prusa` plans a file with the settings of the printer its `M862.3 P` names
//! (planner/src/firmware/marlin/prusa.rs; Prusa-Firmware-Buddy's
//! include/marlin/Configuration_<printer>.h), refuses a printer settle has no settings
//! for, and takes the MK4's when the file names none.

use settle_gcode::job::{JobConfig, PlannerConfig, PrusaPrinter, prusa_printer};
use settle_gcode::{Dialect, GcodeError, Reader, ReaderOptions};
use settle_planner::firmware::marlin::PrusaModel;

use crate::job_util::{assert_rel, leg, run};

fn printer(text: &str) -> Result<PrusaPrinter, GcodeError> {
    prusa_printer(Reader::new(
        text.as_bytes(),
        ReaderOptions::new(Dialect::Prusa),
    ))
}

/// A square corner from X to Y at 250 mm/s (F15000), 100 mm each way.
const CORNER: &str = "G1 X100 F15000\nG1 Y100\n";

#[test]
fn a_mini_file_plans_with_the_minis_speed_limit_and_jerk() {
    // PrusaSlicer's MINI start G-code names the printer before any move.
    let text = format!("M862.3 P \"MINI\" ; printer model check\nG28\n{CORNER}");
    let p = printer(&text).expect("a printer settle knows");
    assert_eq!(p.model, PrusaModel::Mini);
    assert_eq!(p.named_at, Some((1, "MINI".to_string())));
    assert_eq!(
        p.to_string(),
        "Prusa MINI settings (from line 1: M862.3 P \"MINI\")"
    );
    let cfg = JobConfig::prusa(p).expect("config");
    // The MINI's shapers as Buddy ships them (input_shaper_config.hpp).
    let shapers = cfg
        .shapers
        .map(|s| s.map(|s| (s.shaper_type.name(), s.frequency_hz)));
    assert_eq!(
        shapers,
        [
            Some(("mzv".to_string(), 118.2)),
            Some(("mzv".to_string(), 32.8)),
            None
        ]
    );
    let (_, summary) = run(&text, cfg);
    // Configuration_MINI.h: X and Y at most 180 mm/s (DEFAULT_MAX_FEEDRATE), travel at
    // 1250 mm/s^2, classic jerk 8 mm/s: the square corner is taken at 8 mm/s; the file
    // starts and ends at MINIMUM_PLANNER_SPEED, 0.05 mm/s.
    let (v, a, j, v0) = (180.0, 1250.0, 8.0, 0.05);
    let want = leg(100.0, v, a, v0, j) + leg(100.0, v, a, j, v0);
    assert_rel("MINI corner", summary.print_time_s, want, 1e-9);

    // The same moves on the MK4 (no M862.3): 250 mm/s, under its 300.
    let mk4 = JobConfig::defaults(settle_planner::firmware::Firmware::Prusa).expect("defaults");
    assert_eq!(mk4.prusa, Some(PrusaPrinter::unnamed()));
    let (_, summary) = run(CORNER, mk4);
    let want = leg(100.0, 250.0, a, v0, j) + leg(100.0, 250.0, a, j, v0);
    assert_rel("MK4 corner", summary.print_time_s, want, 1e-9);
}

#[test]
fn the_printer_is_named_as_buddy_reads_it() {
    // Buddy skips spaces and quotes after P and reads letters, digits and dots
    // (src/marlin_stubs/M862_2_3.cpp); MeatPack's no-spaces text writes `M862.3P"MK4S"`.
    for (text, model) in [
        ("M862.3 P \"MK4S\"\n", PrusaModel::Mk4),
        ("M862.3P\"MK4S\"\n", PrusaModel::Mk4),
        ("M862.3 P MK3.9\n", PrusaModel::Mk4),
        ("M862.3 P \"MK3.5\"\n", PrusaModel::Mk3_5),
        ("M862.3 P \"MK3.5SMMU3\"\n", PrusaModel::Mk3_5),
        ("M862.3 P \"XL\"\n", PrusaModel::Xl),
        ("M862.3 P \"COREONE\"\n", PrusaModel::CoreOne),
    ] {
        assert_eq!(printer(text).expect(text).model, model, "{text}");
    }
    // Only the first, and only before the first move.
    let p = printer("M862.3 P \"XL\"\nM862.3 P \"MINI\"\nG1 X1\n").expect("XL");
    assert_eq!(
        (p.model, p.named_at.map(|n| n.0)),
        (PrusaModel::Xl, Some(1))
    );
    let late = printer("G1 X10 F600\nM862.3 P \"MINI\"\n").expect("unnamed");
    assert_eq!(late, PrusaPrinter::unnamed());
    // `M862.3 Q` asks the printer; it names none.
    assert_eq!(
        printer("M862.3 Q\n").expect("unnamed"),
        PrusaPrinter::unnamed()
    );
}

#[test]
fn no_m862_3_is_the_mk4_and_says_so() {
    let p = printer("G28\nG1 X10 F600\n").expect("unnamed");
    assert_eq!(p.model, PrusaModel::Mk4);
    assert!(
        p.to_string()
            .starts_with("Prusa MK4 settings (the file names no printer"),
        "{p}"
    );
    let cfg = JobConfig::prusa(p).expect("config");
    let PlannerConfig::Prusa(c) = cfg.planner else {
        panic!("Prusa's planner")
    };
    assert_eq!(c, PrusaModel::Mk4.config());
}

#[test]
fn a_printer_settle_has_no_settings_for_is_refused_with_its_line() {
    // The MK3S runs Prusa-Firmware (not Buddy); COREONEL is newer than the Buddy settle
    // read; names are exact, as Buddy compares them.
    for name in ["MK3S", "COREONEL", "iX", "mk4s", ""] {
        let text = format!(";start\nM862.3 P \"{name}\"\nG1 X10 F600\n");
        let e = printer(&text).expect_err(name);
        assert!(matches!(e, GcodeError::UnknownPrinter { .. }), "{e:?}");
        assert_eq!(e.line(), Some(2), "{name}");
        let m = e.to_string();
        assert!(
            m.starts_with("<input>:2: `M862.3 P \"") && m.contains(&format!("\"{name}\"")),
            "{m}"
        );
        assert!(m.contains("allowed: MINI, MK3.5, "), "{m}");
        assert!(m.contains("MK4S") && m.contains("COREONE"), "{m}");
    }
}

#[test]
fn libbgcodes_test_files_name_a_mini_and_an_mk4s() {
    // gcode/prints/bgcode/PROVENANCE.md: PrusaSlicer 2.6.0 for a MINI, 2.8.1 for an MK4S;
    // the binary files decode to the text of their `_ref.gcode` (the lines differ in
    // number: the reference has the metadata and thumbnails as comments).
    let prints = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("prints/bgcode");
    let of = |name: &str| {
        let reader =
            Reader::open(prints.join(name), ReaderOptions::new(Dialect::Prusa)).expect("open");
        prusa_printer(reader).expect("a printer settle knows")
    };
    let mini = of("mini_cube_b_ref.gcode");
    assert_eq!(
        (mini.model, mini.named_at.clone()),
        (PrusaModel::Mini, Some((136, "MINI".into())))
    );
    assert_eq!(of("mini_cube_b.bgcode").model, PrusaModel::Mini);
    let mk4s = of("mini_cube_ps2.8.1_ref.gcode");
    assert_eq!(
        (mk4s.model, mk4s.named_at.clone()),
        (PrusaModel::Mk4, Some((240, "MK4S".into())))
    );
    let b = of("mini_cube_ps2.8.1.bgcode");
    assert_eq!(b.model, PrusaModel::Mk4);
    assert_eq!(b.named_at.map(|n| n.1), Some("MK4S".to_string()));
}
