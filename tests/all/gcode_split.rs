//! `settle gcode` tells the contour error's two parts apart, each against a closed form:
//! the shaper's smoothing (the commanded point's distance to the G-code path) and the
//! machine's vibration (the toolhead's distance to the command's own path).

use std::f64::consts::{PI, TAU};
use std::path::{Path, PathBuf};

use settle::studies::gcode::stats::Split;
use settle::workflows::gcode::{GcodeOptions, measure, parse_shapers};
use settle_planner::firmware::Firmware;

use crate::support::{root, write};

/// A machine of one mode per axis, X and Y alike, at `hz` and damping 0.1.
fn rigid(dir: &Path, hz: f64) -> String {
    let mode = format!("modes = [{{ frequency_hz = {hz}, damping_ratio = 0.1, weight = 1.0 }}]");
    let text = format!("name = \"rigid\"\n[axis.x]\n{mode}\n[axis.y]\n{mode}\n");
    let path = write(dir, &format!("rigid{hz}.toml"), &text);
    path.to_str().expect("utf-8").to_owned()
}

/// The job's split (the largest of each part) and each layer's, sampled at `rate_hz`
/// (the default when `None`).
fn split(file: PathBuf, machine: &str, shaper: &str, rate_hz: Option<f64>) -> (Split, Vec<Split>) {
    let mut opts = GcodeOptions::new(file, machine, Firmware::Klipper)
        .expect("options")
        .with_shapers(parse_shapers(shaper).expect("a shaper"));
    if let Some(r) = rate_hz {
        opts.sample_rate_hz = r;
    }
    let o = measure(&opts).expect("runs");
    assert!(o.streamed.fault.is_none());
    let layers = o
        .layers
        .iter()
        .filter_map(|l| l.stats.as_ref().map(|s| s.split_worst))
        .collect();
    (o.streamed.split_worst, layers)
}

/// The largest toolhead error `|e|` of a mode (`e'' + 2 zeta w e' + w^2 e = -a`, from
/// rest) under a command whose acceleration never exceeds `a_max` in magnitude: `|e| <=
/// ||g||_1 a_max`, with `g` the mode's impulse response, whose L1 norm is
/// `coth(pi zeta / (2 sqrt(1 - zeta^2))) / w^2`. The vibration is at most `|e|` (the
/// commanded point is on the command's path).
fn vibration_bound_um(hz: f64, zeta: f64, a_max_m_s2: f64) -> f64 {
    let w = TAU * hz;
    let x = PI * zeta / (2.0 * (1.0 - zeta * zeta).sqrt());
    a_max_m_s2 / x.tanh() / (w * w) * 1e6
}

/// An L-shaped print with a stop at its corner and after the travel to it (200 ms dwells): Klipper's trapezoids at
/// its default 3,000 mm/s^2 and no speed jump anywhere, so the unshaped command is exactly
/// on the path (smoothing 0 to rounding) and, with MZV at 48 Hz (16 ms, shorter than the
/// dwell), the shaped command too: a shaper's command is a weighted mean of the command's
/// delayed copies, all on the same leg. Its acceleration is a weighted mean too (positive
/// weights summing to 1), so never above 3,000 mm/s^2, and on a machine of 1 kHz or 2 kHz
/// modes the vibration is within the closed form above: 0.65 um or 0.16 um, falling as
/// `1 / f^2` towards a rigid machine's 0.
#[test]
fn a_stopped_corner_has_no_smoothing_and_a_stiff_machine_the_closed_form_vibration() {
    let dir = tempfile::tempdir().expect("tempdir");
    let file = write(
        dir.path(),
        "corner.gcode",
        "G90\nM83\nG0 X90 Y90 F6000\nG4 P200\nG1 X110 E1 F6000\nG4 P200\nG1 Y110 E1 F6000\n",
    );
    for hz in [1000.0, 2000.0] {
        let machine = rigid(dir.path(), hz);
        let bound = vibration_bound_um(hz, 0.1, 3.0);
        for shaper in ["none", "mzv@48"] {
            // Ten samples per period of the mode: the bound holds at every instant.
            let (s, _) = split(file.clone(), &machine, shaper, Some(10.0 * hz));
            assert!(s.smoothing_um <= 1e-6, "{hz} Hz {shaper}: {s:?}");
            assert!(
                s.vibration_um > 0.0 && s.vibration_um <= bound,
                "{hz} Hz {shaper}: {s:?} against {bound} um"
            );
        }
    }
}

/// The ringing tower (`gcode/prints/ringing_tower.gcode`, 90-degree corners at 150 mm/s
/// and 4,000 mm/s^2) unshaped on printer_xy: Klipper takes each corner at its square
/// corner velocity (5 mm/s: at 90 degrees the junction speed is exactly it), a speed jump
/// of 5 mm/s on each axis that a profile spreads over its 100 us window, off the exact
/// position by at most `|dv| w / 8 + |da| w^2 / 8` per axis
/// (`settle_planner::firmware::profiles`): the command is within `sqrt(2)` times that of
/// the path, 0.095 um, in every layer, and above 0 in the job (the bridge is there). With MZV at
/// 48 Hz the command cuts the corners by tens of um.
#[test]
fn an_unshaped_tower_smooths_only_within_the_corner_bridge_bound() {
    let tower = root().join("gcode/prints/ringing_tower.gcode");
    let (dv, da, w) = (5e-3, 4.0, 100e-6);
    let bound_um = 2f64.sqrt() * (dv * w / 8.0 + da * w * w / 8.0) * 1e6;
    let (job, layers) = split(tower.clone(), "printer_xy", "none", None);
    assert!(layers.len() >= 5 && job.smoothing_um > 0.0, "{job:?}");
    for s in layers.iter().chain([&job]) {
        assert!(s.smoothing_um <= bound_um, "{s:?} against {bound_um} um");
    }
    let (shaped, _) = split(tower, "printer_xy", "mzv@48", None);
    assert!(shaped.smoothing_um > 10.0, "{shaped:?}");
}

/// What a user reads first shows the split: the terminal's line gives the job's largest
/// smoothing and vibration, the largest of layers.csv's columns, and `--versus`'s table
/// (printed and in compare.md) gives each setting's, the second one's equal to that
/// setting measured on its own.
#[test]
fn the_terminal_and_the_versus_table_show_smoothing_and_vibration() {
    use crate::support::{run_ok, settle};
    let dir = tempfile::tempdir().expect("temporary folder");
    let out = dir.path().join("out");
    let file = root().join("gcode/prints/ringing_tower.gcode");
    let run = run_ok(
        settle()
            .arg("gcode")
            .arg(&file)
            .args(["--machine", "printer_xy", "--firmware", "klipper"])
            .args(["--shaper", "mzv@48", "--versus", "klipper", "--out"])
            .arg(&out),
    );
    let stdout = String::from_utf8_lossy(&run.stdout).into_owned();
    let csv = std::fs::read_to_string(out.join("layers.csv")).expect("layers.csv");
    let rows = settle::input::runs_table::RunsTable::parse(&csv).expect("layers.csv");
    let largest = |col: &str| {
        (0..rows.rows.len())
            .filter_map(|k| rows.num(k, col))
            .fold(0.0_f64, f64::max)
    };
    let (smooth, vib) = (largest("smoothing_worst_um"), largest("vibration_worst_um"));
    assert!(smooth > 1.0 && vib > 1.0, "a shaped tower: {smooth}, {vib}");
    let words = format!("(smoothing worst {smooth:.2} um, vibration worst {vib:.2} um)");
    assert!(
        stdout.lines().next().expect("a line").ends_with(&words),
        "{words} in {stdout}"
    );
    let (unshaped, _) = split(file, "printer_xy", "none", None);
    let compare = std::fs::read_to_string(out.join("compare.md")).expect("compare.md");
    let row = |setting: &str| {
        compare
            .lines()
            .find(|l| l.starts_with(&format!("| {setting} |")))
            .unwrap_or_else(|| panic!("{setting} in {compare}"))
            .split('|')
            .map(str::trim)
            .map(str::to_owned)
            .collect::<Vec<_>>()
    };
    let (shaped_row, unshaped_row) = (row("klipper + mzv@48 Hz"), row("klipper"));
    assert_eq!(
        shaped_row[5..7],
        [format!("{smooth:.2}"), format!("{vib:.2}")]
    );
    assert_eq!(
        unshaped_row[5..7],
        [
            format!("{:.2}", unshaped.smoothing_um),
            format!("{:.2}", unshaped.vibration_um)
        ]
    );
    assert!(stdout.contains(&compare[compare.find("| setting").expect("a table")..]));
}
