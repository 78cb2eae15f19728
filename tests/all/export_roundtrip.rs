//! Each firmware's export from a real configuration of that firmware in the repository:
//! `settle import` -> `settle tune` (one move length, three frequency scales) -> the
//! exported file read back by settle's own reader of that firmware gives the values of
//! the winners' rows of `candidates.csv` (shaper, frequency, damping ratio, acceleration),
//! the table the tune wrote, not the export's own text.

use std::path::Path;

use settle::spec::backend::Backend;
use settle::workflows::import::{ImportOptions, import};
use settle::workflows::tune::{Options, Tuned, tune_with};
use settle_gcode::config::{KlipperConfig, RrfConfig};
use settle_gcode::{Dialect, EventKind, LimitChange, Reader, ReaderOptions};
use settle_planner::firmware::Firmware;

use crate::support::root;

/// A winner's row of `candidates.csv`.
#[derive(Debug)]
struct Row {
    shaper: String,
    frequency_hz: Option<f64>,
    damping_ratio: Option<f64>,
    accel_mm_s2: f64,
}

/// The row of candidate `index` of `axis` in `candidates.csv` (its columns `axis`,
/// `candidate`, ..., `shaper_type`, `shaper_frequency_hz`, `shaper_damping_ratio`,
/// `accel_mm_s2`, the first ten).
fn row(csv: &str, axis: &str, index: usize) -> Row {
    let want = index.to_string();
    let line = csv
        .lines()
        .skip(1)
        .find(|l| {
            let mut c = l.split(',');
            c.next() == Some(axis) && c.next() == Some(want.as_str())
        })
        .unwrap_or_else(|| panic!("{axis} {index} in candidates.csv"));
    let c: Vec<&str> = line.split(',').collect();
    let num = |s: &str| (!s.is_empty()).then(|| s.parse::<f64>().expect("a number"));
    Row {
        shaper: c[6].to_string(),
        frequency_hz: num(c[7]),
        damping_ratio: num(c[8]),
        accel_mm_s2: num(c[9]).expect("an acceleration"),
    }
}

/// Per tuned axis, the winner's row, and the lowest current acceleration (candidate 0's).
fn from_csv(t: &Tuned) -> (Vec<(String, Row)>, f64, f64) {
    let csv = std::fs::read_to_string(t.out.join("candidates.csv")).expect("candidates.csv");
    let winners: Vec<(String, Row)> = t
        .axes
        .iter()
        .map(|(a, o)| (a.clone(), row(&csv, a, o.winner)))
        .collect();
    let rec = winners
        .iter()
        .map(|(_, r)| r.accel_mm_s2)
        .fold(f64::INFINITY, f64::min);
    let cur = t
        .axes
        .iter()
        .map(|(a, _)| row(&csv, a, 0).accel_mm_s2)
        .fold(f64::INFINITY, f64::min);
    (winners, rec, cur)
}

/// `settle import FIRMWARE CONFIG` into `dir`, the search cut down, then `settle tune`.
fn import_and_tune(firmware: Firmware, config: &str, dir: &Path) -> Tuned {
    let scenario = dir.join("printer.toml");
    import(&ImportOptions {
        firmware,
        config: root().join(config),
        machine: None,
        out: Some(scenario.clone()),
        force: false,
    })
    .expect("imports");
    let text = std::fs::read_to_string(&scenario).expect("reads");
    let text: String = text
        .lines()
        .map(|l| {
            if l.starts_with("distances_mm = ") {
                "distances_mm = [20.0]".to_string()
            } else if l.starts_with("frequency_scales = ") {
                "frequency_scales = [0.9, 1.0, 1.1]".to_string()
            } else {
                l.to_string()
            }
        })
        .map(|l| l + "\n")
        .collect();
    std::fs::write(&scenario, text).expect("writes");
    let opts = Options {
        jobs: Some(2),
        ..Options::new(Backend::Modal)
    };
    let t = tune_with(
        &scenario,
        Some(dir.join("tuned")),
        &opts,
        &settle::execute::pool::quiet,
    )
    .expect("tunes");
    assert_eq!(t.axes.len(), 2, "X and Y tuned");
    t
}

fn events(text: &str, dialect: Dialect) -> Vec<LimitChange> {
    Reader::new(text.as_bytes(), ReaderOptions::new(dialect))
        .collect::<Result<Vec<_>, _>>()
        .expect("settle reads its own export")
        .into_iter()
        .filter_map(|e| match e.kind {
            EventKind::Limits(l) => Some(l),
            _ => None,
        })
        .collect()
}

/// `M201 X Y` and `M204 P T` as read back: `M204` only when the acceleration changes, both
/// at the recommended acceleration; an `M201` only at it.
fn check_accels(read: &[LimitChange], rec: f64, cur: f64, text: &str) {
    let m204: Vec<_> = read
        .iter()
        .filter_map(|l| match l {
            LimitChange::Accel {
                print_mm_s2,
                travel_mm_s2,
                ..
            } => Some((*print_mm_s2, *travel_mm_s2)),
            _ => None,
        })
        .collect();
    if rec == cur {
        assert!(m204.is_empty(), "{text}");
    } else {
        assert_eq!(m204, [(Some(rec), Some(rec))], "{text}");
    }
    for l in read {
        if let LimitChange::MaxAccel { per_axis_mm_s2, .. } = l {
            for v in [per_axis_mm_s2.x, per_axis_mm_s2.y].into_iter().flatten() {
                assert_eq!(v, rec, "{text}");
            }
        }
    }
}

/// examples/klipper/printer.cfg: `klipper.cfg` read by settle's printer.cfg reader (after
/// a `[printer]` section, as pasted at the end of the file) gives each axis's winning
/// shaper (an unshaped winner: frequency 0, Klipper's off) and the acceleration.
#[test]
fn klipper_export_reads_back_as_candidates_csv() {
    let dir = tempfile::tempdir().expect("tempdir");
    let t = import_and_tune(
        Firmware::Klipper,
        "examples/klipper/printer.cfg",
        dir.path(),
    );
    let (winners, rec, cur) = from_csv(&t);
    let k = std::fs::read_to_string(t.out.join("klipper.cfg")).expect("klipper.cfg");
    let head = "[printer]\nkinematics: cartesian\nmax_velocity: 300\nmax_accel: 1\n";
    let c = KlipperConfig::parse(&format!("{head}{k}"), "printer.cfg").expect("reads back");
    let s = c.input_shaper.expect("[input_shaper]");
    for (axis, r) in &winners {
        let got = if axis == "x" { &s.x } else { &s.y };
        match (r.frequency_hz, r.damping_ratio) {
            (Some(f), Some(z)) => {
                assert_eq!(
                    (got.name.as_str(), got.frequency_hz, got.damping_ratio),
                    (r.shaper.as_str(), f, z),
                    "{axis}\n{k}"
                );
            }
            _ => assert_eq!(got.frequency_hz, 0.0, "{axis} unshaped\n{k}"),
        }
    }
    let want = if rec == cur { 1.0 } else { rec };
    assert_eq!(c.printer.max_accel_mm_s2, want, "{k}");
}

/// gcode/tests/data/rrf/mini5plus/sys/config.g: `rrf.g` read by settle's config.g reader
/// gives the one shaper, the lowest-frequency tuned axis's winner, and the acceleration.
#[test]
fn rrf_export_reads_back_as_candidates_csv() {
    let dir = tempfile::tempdir().expect("tempdir");
    let t = import_and_tune(
        Firmware::Rrf,
        "gcode/tests/data/rrf/mini5plus/sys/config.g",
        dir.path(),
    );
    let (winners, rec, cur) = from_csv(&t);
    let g = std::fs::read_to_string(t.out.join("rrf.g")).expect("rrf.g");
    let c = RrfConfig::parse(&g, "rrf.g").expect("reads back");
    let lowest = winners
        .iter()
        .filter_map(|(_, r)| r.frequency_hz.map(|f| (f, r)))
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, r)| r);
    match lowest {
        Some(r) => assert_eq!(
            (
                c.input_shaper.name.as_str(),
                Some(c.input_shaper.frequency_hz),
                Some(c.input_shaper.damping_ratio)
            ),
            (
                r.shaper.strip_prefix("rrf:").unwrap_or(&r.shaper),
                r.frequency_hz,
                r.damping_ratio
            ),
            "{g}"
        ),
        None => assert_eq!(c.input_shaper.name, "none", "{g}"),
    }
    check_accels(&events(&g, Dialect::Rrf), rec, cur, &g);
}

/// gcode/tests/data/real/marlin/ender3v2neo/m503_20241028.gcode (no input shaper in the
/// reply: Marlin's built-in ZV, `M593`): `marlin.gcode` read by settle's Marlin reader
/// gives each axis's `F` and `D` (`F0` unshaped) and the acceleration.
#[test]
fn marlin_export_reads_back_as_candidates_csv() {
    let dir = tempfile::tempdir().expect("tempdir");
    let t = import_and_tune(
        Firmware::Marlin,
        "gcode/tests/data/real/marlin/ender3v2neo/m503_20241028.gcode",
        dir.path(),
    );
    let (winners, rec, cur) = from_csv(&t);
    let g = std::fs::read_to_string(t.out.join("marlin.gcode")).expect("marlin.gcode");
    let read = events(&g, Dialect::Marlin);
    let m593: Vec<_> = read
        .iter()
        .filter_map(|l| match l {
            LimitChange::MarlinInputShaping {
                axes,
                frequency_hz,
                damping_ratio,
            } => Some((axes.x, axes.y, *frequency_hz, *damping_ratio)),
            _ => None,
        })
        .collect();
    assert_eq!(m593.len(), 2, "{g}");
    for ((axis, r), got) in winners.iter().zip(&m593) {
        assert_eq!((got.0, got.1), (axis == "x", axis == "y"), "{g}");
        if r.frequency_hz.is_some() {
            assert_eq!(r.shaper, "marlin:m593", "{g}");
            assert_eq!((got.2, got.3), (r.frequency_hz, r.damping_ratio), "{g}");
        } else {
            assert_eq!(got.2, Some(0.0), "{axis} unshaped\n{g}");
        }
    }
    check_accels(&read, rec, cur, &g);
}

/// gcode/tests/data/prusa/mk4s_m115_m503_m593.txt: `prusa.gcode` read by settle's reader
/// of Prusa-Firmware-Buddy gives each axis's `T` (Buddy's M593.cpp: 0 zv, 1 zvd, 2 mzv,
/// 3 to 5 its EI family), `F`, `D` and the acceleration.
#[test]
fn prusa_export_reads_back_as_candidates_csv() {
    let dir = tempfile::tempdir().expect("tempdir");
    let t = import_and_tune(
        Firmware::Prusa,
        "gcode/tests/data/prusa/mk4s_m115_m503_m593.txt",
        dir.path(),
    );
    let (winners, rec, cur) = from_csv(&t);
    let g = std::fs::read_to_string(t.out.join("prusa.gcode")).expect("prusa.gcode");
    let read = events(&g, Dialect::Prusa);
    let m593: Vec<_> = read
        .iter()
        .filter_map(|l| match l {
            LimitChange::PrusaInputShaping {
                axes,
                shaper_type,
                frequency_hz,
                damping_ratio,
                save: false,
                ..
            } => Some((axes.x, axes.y, *shaper_type, *frequency_hz, *damping_ratio)),
            _ => None,
        })
        .collect();
    assert_eq!(m593.len(), 2, "{g}");
    let codes = [
        "zv",
        "zvd",
        "mzv",
        "prusa:ei",
        "prusa:2hump_ei",
        "prusa:3hump_ei",
    ];
    for ((axis, r), got) in winners.iter().zip(&m593) {
        assert_eq!((got.0, got.1), (axis == "x", axis == "y"), "{g}");
        if r.frequency_hz.is_some() {
            let code = codes.iter().position(|c| *c == r.shaper).expect("Buddy's");
            assert_eq!(
                (got.2, got.3, got.4),
                (Some(code as u32), r.frequency_hz, r.damping_ratio),
                "{axis}\n{g}"
            );
        } else {
            assert_eq!((got.2, got.3), (None, Some(0.0)), "{axis} unshaped\n{g}");
        }
    }
    check_accels(&read, rec, cur, &g);
}
