//! `settle import` -> `settle tune` -> export -> `settle import`: the configuration
//! written for the recommendation, pasted at the end of the user's file as the export's
//! comment says, reads back as the recommended settings, bit for bit.
//!
//! The imported search is cut down (one move length, three frequency scales, three
//! shapers) to keep the test fast; everything else is as `settle import` wrote it,
//! including the 5 % frequency tolerance and the three accelerations.

use std::path::{Path, PathBuf};

use settle::spec::backend::Backend;
use settle::workflows::import::{ImportOptions, import};
use settle::workflows::tune::{Options, tune_with};
use settle_planner::firmware::Firmware;

use crate::support::root;

/// A small Klipper configuration: cartesian, its current shapers on X and Y.
const PRINTER_CFG: &str = "[printer]
kinematics: cartesian
max_velocity: 300
max_accel: 3000

[stepper_x]
rotation_distance: 40
microsteps: 16

[stepper_y]
rotation_distance: 40
microsteps: 16

[input_shaper]
shaper_type_x: zv
shaper_freq_x: 45.0
shaper_type_y: zv
shaper_freq_y: 35.0

[some_plugin]
whatever: 1
";

/// Cut the imported search down (see the module documentation).
fn smaller(scenario: &Path, shapers: &str) {
    let text = std::fs::read_to_string(scenario).expect("reads");
    let text = text
        .replace("distances_mm = [5.0, 20.0]", "distances_mm = [20.0]")
        .replace(
            "frequency_scales = [0.9, 0.95, 1.0, 1.05, 1.1]",
            &format!("frequency_scales = [0.95, 1.0, 1.05]\nshapers = {shapers}"),
        );
    std::fs::write(scenario, text).expect("writes");
}

fn import_to(firmware: Firmware, config: &Path, out: &Path) -> settle::workflows::import::Imported {
    import(&ImportOptions {
        firmware,
        config: config.to_path_buf(),
        machine: None,
        out: Some(out.to_path_buf()),
        force: false,
    })
    .expect("imports")
}

fn tune(scenario: &Path, out: PathBuf) -> settle::workflows::tune::Tuned {
    let opts = Options {
        jobs: Some(2),
        ..Options::new(Backend::Modal)
    };
    tune_with(scenario, Some(out), &opts, &settle::execute::pool::quiet).expect("tunes")
}

/// The recommended `(shaper, frequency, damping)` of an axis, `None` when unshaped.
fn recommended(t: &settle::workflows::tune::Tuned, axis: &str) -> Option<(String, f64, f64)> {
    let o = &t
        .axes
        .iter()
        .find(|(a, _)| a == axis)
        .expect("axis tuned")
        .1;
    let sh = o.scores[o.winner].candidate.shaper?;
    sh.shaper_type
        .map(|k| (k.name(), sh.frequency_hz, sh.damping_ratio))
}

#[test]
fn klipper_import_tune_export_import_gives_the_recommendation() {
    let dir = tempfile::tempdir().expect("tempdir");
    let cfg = dir.path().join("printer.cfg");
    std::fs::write(&cfg, PRINTER_CFG).expect("writes");
    let scenario = dir.path().join("printer.toml");
    import_to(Firmware::Klipper, &cfg, &scenario);
    smaller(&scenario, "[\"none\", \"zv\", \"mzv\", \"ei\"]");
    let t = tune(&scenario, dir.path().join("tuned"));
    assert_eq!(t.axes.len(), 2);
    // Per axis its own shaper, scored against the current ZV settings.
    let md = &t.markdown;
    assert!(
        md.contains("## Your current settings -> recommended"),
        "{md}"
    );
    for (axis, o) in &t.axes {
        let c = &o.scores[0];
        let cur = c.candidate.shaper.expect("current shaper");
        assert_eq!(
            cur.shaper_type.map(|k| k.name()).as_deref(),
            Some("zv"),
            "{axis}"
        );
        assert_eq!(cur.frequency_hz, if axis == "x" { 45.0 } else { 35.0 });
        assert_eq!(c.accel_mm_s2, 3000.0);
        let w = &o.scores[o.winner];
        assert!(
            w.move_and_settle_s <= c.move_and_settle_s,
            "{axis}: {w:?} vs {c:?}"
        );
        // Every candidate is a Klipper trapezoid, within the smoothing limit if scored.
        for s in &o.scores {
            assert_eq!(s.candidate.kind, settle_planner::ProfileKind::Trapezoid);
            if s.move_and_settle_s.is_finite() {
                assert!(s.smoothing_mm <= 0.12, "{s:?}");
            }
        }
    }
    let k = std::fs::read_to_string(t.out.join("klipper.cfg")).expect("klipper.cfg");
    assert_eq!(k.matches("[input_shaper]").count(), 1, "{k}");
    assert!(k.matches("[printer]").count() <= 1, "{k}");
    // Paste it at the end of printer.cfg and import again.
    let pasted = dir.path().join("pasted.cfg");
    std::fs::write(&pasted, format!("{PRINTER_CFG}\n{k}")).expect("writes");
    let again = import_to(Firmware::Klipper, &pasted, &dir.path().join("again.toml"));
    for (i, axis) in ["x", "y"].into_iter().enumerate() {
        assert_eq!(
            again.current.axes[i].shaper,
            recommended(&t, axis),
            "{axis}\n{k}"
        );
    }
    let accel = t
        .axes
        .iter()
        .map(|(_, o)| o.scores[o.winner].accel_mm_s2)
        .fold(f64::INFINITY, f64::min);
    assert_eq!(again.current.amax_mm_s2, accel, "{k}");
    assert_eq!(k.contains("max_accel:"), accel != 3000.0, "{k}");
}

#[test]
fn rrf_import_tune_export_import_gives_the_recommendation() {
    let dir = tempfile::tempdir().expect("tempdir");
    let cfg = dir.path().join("config.g");
    std::fs::write(
        &cfg,
        "M92 X80 Y80\nM350 X16 Y16\nM203 X18000 Y18000\nM201 X3000 Y3000\nM204 P3000 T3000\nM593 P\"zvd\" F40 S0.1\n",
    )
    .expect("writes");
    let scenario = dir.path().join("rrf.toml");
    import_to(Firmware::Rrf, &cfg, &scenario);
    smaller(
        &scenario,
        "[\"none\", \"rrf:zvd\", \"rrf:mzv\", \"rrf:ei2\"]",
    );
    let t = tune(&scenario, dir.path().join("tuned"));
    let g = std::fs::read_to_string(t.out.join("rrf.g")).expect("rrf.g");
    assert_eq!(
        g.lines().filter(|l| l.starts_with("M593")).count(),
        1,
        "{g}"
    );
    let pasted = dir.path().join("pasted.g");
    std::fs::write(
        &pasted,
        format!("{}\n{g}", std::fs::read_to_string(&cfg).expect("reads")),
    )
    .expect("writes");
    let again = import_to(Firmware::Rrf, &pasted, &dir.path().join("again.toml"));
    // One shaper for all axes: the lowest-frequency axis's recommendation.
    let mut recs: Vec<(String, f64, f64)> = ["x", "y"]
        .iter()
        .filter_map(|a| recommended(&t, a))
        .collect();
    recs.sort_by(|a, b| a.1.total_cmp(&b.1));
    let want = recs.first().map(|(n, f, z)| (n.clone(), *f, *z));
    assert_eq!(again.current.axes[0].shaper, want, "{g}");
    assert_eq!(again.current.axes[1].shaper, want, "{g}");
}

/// The RailCore II's own `config.g` (gcode/tests/data/real/railcore, RepRapFirmware 3):
/// `M201 X2500 Y2500 Z100` (line 82) and no `M204`, so it prints at 2500 mm/s^2.
/// RepRapFirmware caps every move by `M201` as well as by `M204`: when tune recommends
/// more, `rrf.g` raises both, and the configuration with `rrf.g` at its end reads back
/// at the recommended acceleration.
#[test]
fn rrf_export_raises_m201_of_the_real_railcore_to_the_recommendation() {
    let dir = tempfile::tempdir().expect("tempdir");
    let real = root().join("gcode/tests/data/real/railcore/sys/config.g");
    let scenario = dir.path().join("railcore.toml");
    let i = import_to(Firmware::Rrf, &real, &scenario);
    assert_eq!(i.current.amax_mm_s2, 2500.0);
    for a in &i.current.axes {
        assert_eq!(a.max_accel_mm_s2, Some(2500.0), "{}", a.name);
    }
    smaller(
        &scenario,
        "[\"none\", \"rrf:zvd\", \"rrf:mzv\", \"rrf:ei2\"]",
    );
    let t = tune(&scenario, dir.path().join("tuned"));
    let o = &t.axes[0].1;
    let rec = o.scores[o.winner].accel_mm_s2;
    assert!(
        rec > 2500.0,
        "the stand-in's modes take more than 2500 mm/s^2"
    );
    let g = std::fs::read_to_string(t.out.join("rrf.g")).expect("rrf.g");
    let lines: Vec<&str> = g.lines().filter(|l| !l.starts_with(';')).collect();
    let (m201, m204) = (format!("M201 X{rec} Y{rec}"), format!("M204 P{rec} T{rec}"));
    assert_eq!(lines[1..], [m201.as_str(), m204.as_str()], "{g}");
    let pasted = dir.path().join("config.g");
    let original = std::fs::read_to_string(&real).expect("reads");
    std::fs::write(&pasted, format!("{original}\n{g}")).expect("writes");
    let again = import_to(Firmware::Rrf, &pasted, &dir.path().join("again.toml"));
    assert_eq!(again.current.amax_mm_s2, rec, "{g}");
    for a in &again.current.axes {
        assert_eq!(a.max_accel_mm_s2, Some(rec), "{}", a.name);
    }
    // Without the M201 line the RailCore would stay at its 2500.
    let without = g.replace(&format!("M201 X{rec} Y{rec}\n"), "");
    std::fs::write(&pasted, format!("{original}\n{without}")).expect("writes");
    let capped = import_to(Firmware::Rrf, &pasted, &dir.path().join("capped.toml"));
    assert_eq!(capped.current.amax_mm_s2, 2500.0, "{without}");
}
