//! A real Cura 5.4 file for a Prusa MINI (gcode/prints/cura5/PROVENANCE.md) against what
//! Cura wrote in its header (`;LAYER_COUNT:`, the box `;MINX:` .. `;MAXZ:` and
//! `;Filament used:` of the extruding moves, `;TIME:`) and what its text counts.
//!
//! The counts were taken from the file's text by a script outside settle: a `G0`/`G1`
//! that changes X, Y or Z and raises E (absolute, `M82`, with its `G92 E0` resets) is an
//! extruding move, counted under the last `;TYPE:` and the last `;LAYER:`.

use std::collections::BTreeMap;

use settle_gcode::job::{JobConfig, JobSummary};
use settle_gcode::{Bounds, Dialect, EventKind, LimitChange, Reader, ReaderOptions};
use settle_planner::firmware::Firmware;

use crate::cura::{assert_cura_box, header};
use crate::print_path;

const FILE: &str = "cura5/prusa_mini_cura5.gcode";

fn text() -> String {
    std::fs::read_to_string(print_path(FILE)).expect("print")
}

#[test]
fn a_cura5_files_layers_features_box_filament_and_limits_are_the_files() {
    let text = text();
    // What the file says of itself.
    assert!(text.starts_with(";FLAVOR:Marlin\n"));
    assert!(text.contains("\n;Generated with Cura_SteamEngine 5.4.0\n"));
    assert!(text.contains("definition = Original_Prusa_MINI"));

    let mut r = Reader::open(print_path(FILE), ReaderOptions::new(Dialect::Marlin)).expect("opens");
    let (mut layers, mut per_layer, mut per_feature) = (Vec::new(), BTreeMap::new(), Vec::new());
    let (mut bounds, mut extruded_mm, mut limits) = (Bounds::empty(), 0.0, Vec::new());
    for e in r.by_ref() {
        let e = e.expect("every line reads under Marlin");
        match e.kind {
            EventKind::Layer(c) => layers.push(c.z_mm),
            EventKind::Move(m) if m.is_working() => {
                *per_layer.entry(e.layer).or_insert(0u32) += 1;
                per_feature.push(m.feature);
                // Cura's header counts the print, not the start G-code's intro line
                // before `;LAYER:0`.
                if e.layer >= 1 {
                    bounds.union(&m.bounds());
                    extruded_mm += m.extrusion_mm();
                }
            }
            EventKind::Limits(c) => limits.push((e.line, c)),
            _ => {}
        }
    }
    // `;LAYER_COUNT:10`, `;LAYER:0` .. `;LAYER:9`, 0.2 mm apart from Z 0.2.
    assert_eq!(layers.len() as f64, header(&text, "LAYER_COUNT"));
    assert_eq!(layers.len(), 10);
    // Extruding moves per layer: the intro line's two before the first marker.
    assert_eq!(
        per_layer,
        BTreeMap::from([
            (0, 2),
            (1, 453),
            (2, 363),
            (3, 363),
            (4, 270),
            (5, 139),
            (6, 139),
            (7, 270),
            (8, 270),
            (9, 270),
            (10, 259),
        ])
    );
    // Per feature type, under Cura's names (the intro line has none).
    let names = r.features();
    let counted = crate::count_by_feature(names, &per_feature);
    assert_eq!(
        counted,
        BTreeMap::from([
            ("", 2),
            ("FILL", 38),
            ("SKIN", 1195),
            ("SKIRT", 372),
            ("WALL-INNER", 595),
            ("WALL-OUTER", 596),
        ])
    );
    // The box Cura wrote, to its three decimals: the file's own coordinates.
    assert_cura_box(&text, &bounds);
    // `;Filament used: 0.343517m`: the extrusion of the printing moves (each retraction
    // is pushed back before the next one), 343.51656 mm, to Cura's six digits.
    let used_m = header(&text, "Filament used");
    assert!(
        (extruded_mm / 1e3 - used_m).abs() <= 5e-7,
        "{extruded_mm} mm vs {used_m} m"
    );
    // The start G-code's limits (lines 13-15), read as Marlin reads them.
    assert_eq!(limits.len(), 3);
    let (
        line,
        LimitChange::MaxAccel {
            per_axis_mm_s2: a, ..
        },
    ) = &limits[0]
    else {
        panic!("{:?}", limits[0]);
    };
    assert_eq!(*line, 13);
    assert_eq!(
        [a.x, a.y, a.z, a.e],
        [Some(1250.0), Some(1250.0), Some(400.0), Some(5000.0)]
    );
    let (
        line,
        LimitChange::MaxFeedrate {
            per_axis_mm_s: v, ..
        },
    ) = &limits[1]
    else {
        panic!("{:?}", limits[1]);
    };
    assert_eq!(*line, 14);
    assert_eq!(
        [v.x, v.y, v.z, v.e],
        [Some(180.0), Some(180.0), Some(12.0), Some(80.0)]
    );
    let (line, LimitChange::MarlinAdvanced { jerk_mm_s: j, .. }) = &limits[2] else {
        panic!("{:?}", limits[2]);
    };
    assert_eq!(*line, 15);
    assert_eq!(
        [j.x, j.y, j.z, j.e],
        [Some(8.0), Some(8.0), Some(2.0), Some(10.0)]
    );
}

fn run(cfg: JobConfig) -> JobSummary {
    crate::plan_print(FILE, cfg)
}

/// The commands listed as not followed, by name (`G29`, `M104`, ...).
fn not_followed(s: &JobSummary) -> BTreeMap<String, u64> {
    let mut by_name = BTreeMap::new();
    for (k, n) in &s.ignored {
        let name = k.split(':').next().expect("a name").to_owned();
        *by_name.entry(name).or_insert(0) += n;
    }
    by_name
}

#[test]
fn a_cura5_file_runs_on_a_prusa_minis_own_m503_reply_and_times_near_cura() {
    let text = text();
    // A Prusa MINI's reply to M503 (gcode/prints/prusaslicer/PROVENANCE.md): Marlin's
    // planner with the MINI's settings, classic jerk. Cura's MINI profile writes the same
    // X and Y limits and jerks at the file's head (lines 13-15), so none of the limits
    // settle lists (`M204 P`/`T`, `M201`/`M203` of X and Y) is raised; its `M201 E5000`
    // lifts the reply's E 4000, which is followed and not listed.
    let m503 = print_path("prusaslicer/M503_prusa_mini.txt");
    let settings = settle_gcode::config::MarlinSettings::read(&m503).expect("reads");
    let mm = |v: [f64; 4]| v.map(|x| x * 1e-3);
    // `M203 X180.00 Y180.00 Z12.00 E80.00`, `M201 X1250.00 Y1250.00 Z400.00 E4000.00`,
    // `M204 P1250.00 R1250.00 T1250.00`, `M205 B20000.00 S0.00 T0.00 X8.00 Y8.00 Z2.00
    // E10.00`, `M92 X100.00 Y100.00 Z400.00 E325.00`.
    let p = &settings.planner;
    assert_eq!(p.max_feedrate_m_s, mm([180.0, 180.0, 12.0, 80.0]));
    assert_eq!(p.max_accel_m_s2, mm([1250.0, 1250.0, 400.0, 4000.0]));
    assert_eq!(
        [
            p.print_accel_m_s2,
            p.retract_accel_m_s2,
            p.travel_accel_m_s2,
            0.0
        ],
        mm([1250.0, 1250.0, 1250.0, 0.0])
    );
    assert!(settings.classic_jerk);
    assert_eq!(
        settings.steps_per_mm,
        [100.0, 100.0, 400.0, 325.0].map(Some)
    );
    let s = run(settings.job_config().expect("a Marlin configuration"));
    assert!(s.complete);
    assert_eq!(
        s.layers.len(),
        11,
        "the start G-code's layer and Cura's ten"
    );
    assert_eq!(s.limit_changes, 3);
    assert!(s.overrides.is_empty(), "{:?}", s.overrides);
    // Every command that moves nothing or is not simulated is listed, with its count
    // from the file's text (`M109 R170` and `M109 S200`; `M107` at `;LAYER:0` and twice
    // in the end G-code).
    let count = |prefix: &str| {
        text.lines()
            .filter(|l| l.split(' ').next() == Some(prefix))
            .count() as u64
    };
    let listed = not_followed(&s);
    for name in [
        "G29", "M104", "M106", "M107", "M109", "M140", "M190", "M84", "M900",
    ] {
        assert_eq!(listed.get(name), Some(&count(name)), "{name}");
    }
    assert_eq!(listed.len(), 9, "{listed:?}");
    // The print time against Cura's `;TIME:407`: both are Marlin-style planners over the
    // MINI's limits (Cura's TimeEstimateCalculator with its MINI profile's machine
    // settings, the same values as this reply). Settle gives 0.9 % less; asserted within
    // 3 %, a bound of two implementations of one model, not a derivation.
    let cura_s = header(&text, "TIME");
    assert!(
        (s.print_time_s / cura_s - 1.0).abs() < 0.03,
        "{} s against Cura's {cura_s} s",
        s.print_time_s
    );

    // A Marlin of default settings is built with junction deviation: it does not read the
    // file's classic jerk `M205 X8.00 Y8.00 Z2.00 E10.00`, and lists it.
    let s = run(JobConfig::defaults(Firmware::Marlin).expect("defaults"));
    assert_eq!(not_followed(&s).get("M205"), Some(&1));
}
