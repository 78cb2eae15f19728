//! `settle machine FILE`: a preset's linearised modes (against the undamped eigenvalues of
//! its linearised axes, computed by settle-sim's `natural_frequencies_hz`), a machine file
//! in the modes form printed as written, a scenario's machine, and bad input.

use std::path::Path;

use settle::workflows::machine::machine_modes;
use settle_sim::DriverMode;

use crate::support::{settle, write};

#[test]
fn a_presets_modes_are_its_linearised_axes_modes() {
    let got = machine_modes("printer_xy").expect("preset");
    assert!(got.linearised);
    let (_, path, text) = settle::input::machine_file::PRESETS[0];
    let (m, _) = settle::input::machine_file::parse(text, Path::new(path)).expect("preset");
    let axes = m.compile(DriverMode::Linear).expect("compiles");
    assert_eq!(got.axes.len(), axes.len());
    for ((name, rows), axis) in got.axes.iter().zip(&axes) {
        assert_eq!(name, &axis.name);
        let q = axis.lumped.equilibrium(0.0, None).expect("equilibrium");
        let f = axis.lumped.natural_frequencies_hz(&q);
        // Every undamped natural frequency above 0.5 Hz appears, within the shift
        // non-proportional damping gives |lambda| against the undamped eigenvalue (second
        // order in the damping ratio).
        let want: Vec<f64> = f.iter().copied().filter(|f| *f >= 0.5).collect();
        assert_eq!(rows.len(), want.len(), "{name}: {rows:?} vs {want:?}");
        for (r, w) in rows.iter().zip(&want) {
            let tol = r.damping_ratio.powi(2) + 1e-3;
            assert!(
                (r.frequency_hz - w).abs() < tol * w,
                "{name}: {rows:?} vs {want:?}"
            );
            assert!((0.0..0.5).contains(&r.damping_ratio), "{rows:?}");
        }
        // The toolhead sits behind springs: at high frequency it stands still, so its
        // error follows -a_cmd / s^2 and the weights (the modes form's high-frequency
        // limit is -sum w / s^2) sum to 1, up to the imaginary parts of the residues that
        // non-proportional damping leaves out of the real weights.
        let sum: f64 = rows.iter().map(|r| r.weight).sum();
        assert!(
            (sum - 1.0).abs() < 0.01,
            "{name}: weights sum to {sum}: {rows:?}"
        );
        // The preset's comment: first modes about 48 Hz (X) and 39 Hz (Y).
        let first = rows[0].frequency_hz;
        let expect = if name == "x" { 48.0 } else { 39.0 };
        assert!((first - expect).abs() < 2.0, "{name}: {first}");
        // The belt mode carries most of the toolhead's motion.
        let strongest = rows
            .iter()
            .max_by(|a, b| a.weight.abs().total_cmp(&b.weight.abs()))
            .expect("modes");
        assert_eq!(strongest.frequency_hz, first, "{rows:?}");
    }
}

#[test]
fn settle_machine_prints_a_modes_file_as_written_and_a_scenarios_machine() {
    let dir = tempfile::tempdir().expect("tempdir");
    let file = write(
        dir.path(),
        "machine.toml",
        "name = \"mine\"\n[axis.x]\nmodes = [{ frequency_hz = 52.5, damping_ratio = 0.07, weight = 0.9 }, { frequency_hz = 110.0, damping_ratio = 0.1, weight = 0.1 }]\n[axis.y]\nmodes = [{ frequency_hz = 38.25, damping_ratio = 0.05 }]\n",
    );
    let out = settle()
        .args(["machine", file.to_str().expect("utf-8")])
        .output()
        .expect("runs");
    assert!(out.status.success(), "{out:?}");
    let text = String::from_utf8(out.stdout).expect("utf-8");
    let rows: Vec<Vec<&str>> = text
        .lines()
        .skip(2)
        .map(|l| l.split_whitespace().collect())
        .collect();
    assert_eq!(
        rows,
        [
            ["x", "0", "52.500", "0.0700", "0.9000"],
            ["x", "1", "110.000", "0.1000", "0.1000"],
            ["y", "0", "38.250", "0.0500", "1.0000"],
        ],
        "{text}"
    );
    // A scenario naming that file gives the same machine.
    let scenario = write(
        dir.path(),
        "s.toml",
        "name = \"s\"\n[machine]\npreset = \"machine.toml\"\n[move]\ndistance_mm = 5.0\naxis = \"y\"\n[limits]\nvmax_mm_s = 100.0\namax_mm_s2 = 1000.0\njmax_mm_s3 = 1e5\n",
    );
    let from_scenario = machine_modes(scenario.to_str().expect("utf-8")).expect("scenario");
    let from_file = machine_modes(file.to_str().expect("utf-8")).expect("file");
    assert_eq!(from_scenario.axes, from_file.axes);
    assert_eq!(from_scenario.name, "mine");
    // Bad input: exit 2, the file, line and key.
    let bad = write(
        dir.path(),
        "bad.toml",
        "name = \"bad\"\n[axis.x]\nmodes = [{ frequency_hz = -5.0, damping_ratio = 0.05 }]\n",
    );
    let out = settle()
        .args(["machine", bad.to_str().expect("utf-8")])
        .output()
        .expect("runs");
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8(out.stderr).expect("utf-8");
    assert!(
        err.contains("bad.toml:3:1: key `axis.x.modes`") && err.contains("frequency_hz"),
        "{err}"
    );
}

#[test]
fn the_modes_ranges_keep_what_settle_resolves_and_identify_writes() {
    use settle::input::modes::{MAX_FREQUENCY_HZ, MIN_FREQUENCY_HZ};
    // No sample rate settle gcode takes resolves a faster mode.
    assert_eq!(
        MAX_FREQUENCY_HZ,
        settle::workflows::gcode::MAX_SAMPLE_RATE_HZ / 2.0
    );
    // settle identify's resonance tests start at 1 Hz at the lowest.
    const { assert!(MIN_FREQUENCY_HZ < settle::workflows::identify::FREQ_MIN_HZ) };
}

/// A physical machine whose parts are in the wrong unit has no modes settle can stand
/// behind: a rotor inertia in kg m^2 (5.4e-6 for 54 g cm^2) puts the rotor's mode near
/// 1 MHz, which was dropped from the list while the others were printed as if sound; a
/// mount stiffness of 1e308 N/m made the eigenvalue iteration run forever. Both are
/// outside their key's plausible range (`settle_sim::machine::PART_RANGES`) and exit 2 at
/// once, naming the file, line and key; parts each plausible whose mode is not (a 0.1 g
/// toolhead on a 1e12 N/m mount, 16 MHz) exit 2 naming the units to check.
#[test]
fn parts_in_the_wrong_unit_are_refused_not_listed() {
    let dir = tempfile::tempdir().expect("tempdir");
    let preset = settle::input::machine_file::PRESETS[0].2;
    for (name, from, to, says) in [
        (
            "kg_m2.toml",
            "rotor_inertia_g_cm2 = 54.0",
            "rotor_inertia_g_cm2 = 5.4e-6",
            ":45:1: key `motor.rotor_inertia_g_cm2`: must be a number from 1e-3 to 1e7 (g cm^2: 54 for a NEMA 17, not kg m^2), got 0.0000054",
        ),
        (
            "stiff.toml",
            "stiffness_n_per_m = 5.0e5",
            "stiffness_n_per_m = 1e308",
            ":69:1: key `axis.x.mount.stiffness_n_per_m`: must be a number from 1 to 1e15 (N/m), got 1e308",
        ),
        (
            "light.toml",
            "stiffness_n_per_m = 5.0e5\ndamping_ratio = 0.05\n\n[axis.y]",
            "stiffness_n_per_m = 1e12\ndamping_ratio = 0.05\n\n[axis.y]",
            "above the 50000 Hz a machine's mode may have: settle cannot resolve its modes; check the units",
        ),
    ] {
        assert!(preset.contains(from), "{from}");
        let mut text = preset.replacen(from, to, 1);
        if name == "light.toml" {
            text = text.replacen("toolhead_kg = 0.6", "toolhead_kg = 1e-4", 1);
        }
        let path = dir.path().join(name);
        std::fs::write(&path, text).expect("write");
        let mut child = settle()
            .arg("machine")
            .arg(&path)
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .expect("settle runs");
        let start = std::time::Instant::now();
        while child.try_wait().expect("waits").is_none() {
            if start.elapsed().as_secs() > 30 {
                let _ = child.kill();
                panic!("{name}: still running after 30 s");
            }
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
        let out = child.wait_with_output().expect("ends");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{name}: {err}");
        assert!(err.contains(name) && err.contains(says), "{name}: {err}");
    }
}

/// Every part of a physical machine is bounded before work starts: `1e308` and `1e-300`
/// for a torque, a belt's `ea_n` or a mass overflowed the model ("invalid lumped model:
/// coupling `belt`: stiffness and damping must be finite", "eigenvector iteration
/// failed"), naming neither key nor line. Each exits 2 at its line and key with the range.
#[test]
fn every_part_is_bounded_at_its_key() {
    let dir = tempfile::tempdir().expect("tempdir");
    let preset = settle::input::machine_file::PRESETS[0].2;
    for (from, key) in [
        ("holding_torque_n_m = 0.40", "motor.holding_torque_n_m"),
        ("ea_n = 15000.0", "axis.x.belt.ea_n"),
        ("carriage_kg = 0.15", "axis.x.carriage_kg"),
        ("toolhead_kg = 0.6", "axis.x.toolhead_kg"),
        ("mass_kg = 5.0", "axis.y.frame.mass_kg"),
        ("span_mm = 350.0", "axis.x.belt.span_mm"),
        ("run_current_a_rms = 0.8", "driver.run_current_a_rms"),
        ("supply_v = 24.0", "driver.supply_v"),
        ("inductance_mh = 2.8", "motor.inductance_mh"),
    ] {
        let line = preset
            .lines()
            .position(|l| l.starts_with(from))
            .expect("the preset has the key")
            + 1;
        let name = from.split(' ').next().expect("key");
        for value in ["1e308", "1e-300", "-1", "nan"] {
            let path = dir.path().join("m.toml");
            let text = preset.replacen(from, &format!("{name} = {value}"), 1);
            std::fs::write(&path, text).expect("write");
            let out = settle().arg("machine").arg(&path).output().expect("runs");
            let err = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(2), "{key} = {value}: {err}");
            assert!(
                err.contains(&format!(
                    "m.toml:{line}:1: key `{key}`: must be a number from "
                )),
                "{key} = {value}: {err}"
            );
        }
    }
}
