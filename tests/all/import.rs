//! `settle import`: a Klipper printer.cfg and a RepRapFirmware config.g become a scenario
//! whose own point is the user's current settings, marked in `[current]` among a sweep
//! around them. The configurations are settle-gcode's test files, whose values were
//! checked against the firmwares' own code (gcode/tests/gcode/config_klipper.rs,
//! config_rrf.rs); malformed keys are errors naming file, line and key.

use std::path::{Path, PathBuf};

use settle::error::Error;
use settle::workflows::import::{ImportOptions, import};
use settle_planner::firmware::Firmware;

use crate::support::root;

fn voron() -> PathBuf {
    root().join("gcode/tests/data/klipper/voron/printer.cfg")
}

fn mini5plus() -> PathBuf {
    root().join("gcode/tests/data/rrf/mini5plus/sys/config.g")
}

fn opts(firmware: Firmware, config: PathBuf, out: &Path) -> ImportOptions {
    ImportOptions {
        firmware,
        config,
        machine: None,
        out: Some(out.to_path_buf()),
        force: false,
    }
}

fn current(sc: &settle::input::scenario::Scenario, key: &str) -> toml::Value {
    sc.current
        .get(key)
        .cloned()
        .unwrap_or_else(|| panic!("[current] {key}"))
}

fn swept(sc: &settle::input::scenario::Scenario, key: &str) -> Vec<toml::Value> {
    sc.sweep
        .get(key)
        .and_then(|v| v.as_array())
        .cloned()
        .unwrap_or_else(|| panic!("[sweep] {key}"))
}

#[test]
fn klipper_config_becomes_a_scenario_of_the_current_settings() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("voron.toml");
    let i = import(&opts(Firmware::Klipper, voron(), &out)).expect("imports");
    // The Voron's values as Klipper reads them (user_overrides.cfg's max_accel,
    // SAVE_CONFIG's per-axis shapers, 200 x 32 / 40 mm microsteps per mm).
    let c = &i.current;
    assert_eq!((c.vmax_mm_s, c.amax_mm_s2), (300.0, 4000.0));
    assert_eq!(c.axes[0].shaper, Some(("mzv".into(), 54.2, 0.08)));
    assert_eq!(c.axes[1].shaper, Some(("ei".into(), 41.4, 0.1)));
    assert_eq!(c.axes[0].usteps_per_mm, Some(160.0));
    assert_eq!(i.axes, ["x", "y"]);
    assert!(
        i.notes
            .iter()
            .any(|n| n.contains("no --machine") && n.contains("printer_xy")),
        "{:?}",
        i.notes
    );
    // The written scenario loads; its own point is the current X settings...
    let (sc, runs) = settle::load_runs(&out).expect("loads");
    assert_eq!(std::fs::read_to_string(&out).expect("written"), i.scenario);
    assert_eq!(current(&sc, "shaper.type").as_str(), Some("mzv"));
    assert_eq!(current(&sc, "shaper.frequency_hz").as_float(), Some(54.2));
    assert_eq!(current(&sc, "limits.amax_mm_s2").as_float(), Some(4000.0));
    // ...every [current] value is among the swept ones...
    for key in ["shaper.type", "shaper.frequency_hz", "limits.amax_mm_s2"] {
        assert!(swept(&sc, key).contains(&current(&sc, key)), "{key}");
    }
    // ...with Klipper's six shapers and no shaping, 5 frequencies, 3 accelerations.
    assert_eq!(swept(&sc, "shaper.type").len(), 7);
    assert_eq!(runs.len(), 7 * 5 * 3);
    let t = sc.tune.as_ref().expect("[tune]");
    assert_eq!(t.firmware.as_deref(), Some("klipper"));
    let y = &t.axis.as_ref().expect("[tune.axis]")["y"];
    assert_eq!(
        (
            y.shaper.as_deref(),
            y.frequency_hz,
            y.damping_ratio,
            y.usteps_per_mm
        ),
        (Some("ei"), Some(41.4), Some(0.1), Some(160.0))
    );
    // The report names the next command.
    let r = i.report();
    assert!(r.stdout.contains("next: settle tune"), "{}", r.stdout);
}

#[test]
fn rrf_config_has_one_shaper_for_every_axis() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("mini.toml");
    let i = import(&opts(Firmware::Rrf, mini5plus(), &out)).expect("imports");
    let c = &i.current;
    // M203 X300 (mm/min / 60 applied by the reader); printing moves at the lower of
    // M204 P2000 and M201 X3000/Y3000.
    assert_eq!((c.vmax_mm_s, c.amax_mm_s2), (300.0, 2000.0));
    for a in &c.axes {
        assert_eq!(a.shaper, Some(("rrf:mzv".into(), 42.5, 0.1)));
        assert_eq!(a.usteps_per_mm, Some(160.0));
    }
    let (sc, _) = settle::load_runs(&out).expect("loads");
    assert_eq!(current(&sc, "shaper.type").as_str(), Some("rrf:mzv"));
    // RepRapFirmware's shapers are the ones swept.
    let types = swept(&sc, "shaper.type");
    assert!(
        types.iter().any(|t| t.as_str() == Some("rrf:ei2")),
        "{types:?}"
    );
    assert!(!types.iter().any(|t| t.as_str() == Some("zv")), "{types:?}");
}

#[test]
fn malformed_key_names_file_line_and_key_unknown_sections_are_ignored() {
    let dir = tempfile::tempdir().expect("tempdir");
    let cfg = dir.path().join("printer.cfg");
    std::fs::write(
        &cfg,
        "[some_plugin]\nanything: goes\n[printer]\nkinematics: cartesian\nmax_velocity: 300\nmax_accel: fast\n",
    )
    .expect("writes");
    let e = import(&opts(
        Firmware::Klipper,
        cfg.clone(),
        &dir.path().join("o.toml"),
    ))
    .expect_err("malformed max_accel");
    assert!(e.is_input_error());
    let Error::Input { at, message } = &e else {
        panic!("{e}")
    };
    assert_eq!(at.file, cfg);
    assert_eq!(at.line, Some(6));
    assert_eq!(at.key.as_deref(), Some("printer.max_accel"));
    assert!(message.contains("fast"), "{message}");
    // The unknown section alone is no error.
    std::fs::write(
        &cfg,
        "[some_plugin]\nanything: goes\n[printer]\nkinematics: cartesian\nmax_velocity: 300\nmax_accel: 3000\n",
    )
    .expect("writes");
    let i = import(&opts(Firmware::Klipper, cfg, &dir.path().join("o.toml"))).expect("imports");
    assert_eq!(i.current.amax_mm_s2, 3000.0);
    // No [input_shaper]: not shaped, and the sweep centres on the machine's mode.
    assert_eq!(i.current.axes[0].shaper, None);
    let (sc, _) = settle::load_runs(&dir.path().join("o.toml")).expect("loads");
    assert_eq!(current(&sc, "shaper.type").as_str(), Some("none"));
}

#[test]
fn import_command_exit_codes() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("v.toml");
    let r = crate::support::settle()
        .args(["import", "klipper"])
        .arg(voron())
        .arg("--out")
        .arg(&out)
        .output()
        .expect("runs");
    assert!(r.status.success(), "{r:?}");
    assert!(out.is_file());
    let r = crate::support::settle()
        .args(["import", "klipper"])
        .arg(dir.path().join("missing.cfg"))
        .output()
        .expect("runs");
    assert_eq!(r.status.code(), Some(2), "{r:?}");
    // A configuration folder as Mainsail downloads it is a zip archive: named as one.
    let zip = dir.path().join("config.zip");
    std::fs::write(&zip, b"PK\x03\x04\x14\x00\x00\x00\x08\x00\xe3\x9c").expect("writes");
    let r = crate::support::settle()
        .args(["import", "klipper"])
        .arg(&zip)
        .output()
        .expect("runs");
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(2), "{err}");
    assert!(
        err.contains(
            "config.zip:1:11: not UTF-8 text (a zip archive: unpack it and name the file inside)"
        ),
        "{err}"
    );
}

/// One list of firmware names: `settle gcode` plans grbl (and grblHAL), `settle import`
/// refuses it with the reason (exit 2), and names what it reads.
#[test]
fn import_refuses_grbl_with_its_reason() {
    let r = crate::support::settle()
        .args(["import", "grblHAL"])
        .arg(voron())
        .output()
        .expect("runs");
    assert_eq!(r.status.code(), Some(2), "{r:?}");
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(
        err.contains("grbl is not a firmware whose configuration settle import reads: GRBL has no input shaper"),
        "{err}"
    );
    assert!(
        err.contains("allowed: klipper, marlin, prusa, rrf"),
        "{err}"
    );
    assert_eq!(
        settle::workflows::import::parse_firmware("duet"),
        Ok(Firmware::Rrf)
    );
}

/// A scenario already at `--out` (an earlier import, or one edited since) is kept: the
/// import is refused without `--force`, names it and changes nothing; with `--force` it is
/// replaced.
#[test]
fn import_keeps_an_existing_scenario_without_force() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("v.toml");
    std::fs::write(&out, "# my edits\n").expect("writes");
    let import_cmd = |force: bool| {
        let mut c = crate::support::settle();
        c.args(["import", "klipper"])
            .arg(voron())
            .arg("--out")
            .arg(&out);
        if force {
            c.arg("--force");
        }
        c.output().expect("runs")
    };
    let r = import_cmd(false);
    assert_eq!(r.status.code(), Some(2), "{r:?}");
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(err.contains("--force") && err.contains("v.toml"), "{err}");
    assert_eq!(std::fs::read_to_string(&out).expect("kept"), "# my edits\n");
    let r = import_cmd(true);
    assert!(r.status.success(), "{r:?}");
    let (sc, _) = settle::load_runs(&out).expect("loads");
    assert_eq!(sc.name, "printer_import");
}

/// The real configurations of settle-gcode's corpus (gcode/tests/data/real/MANIFEST.md)
/// import with their owners' input shapers, the published results of
/// identify/tests/corpus/MANIFEST.md at the same commits.
#[test]
fn real_configurations_import_with_their_owners_shapers() {
    let dir = tempfile::tempdir().expect("tempdir");
    let real = root().join("gcode/tests/data/real");
    type Shaper = Option<(String, f64, f64)>;
    let s = |name: &str, f: f64, z: f64| -> Shaper { Some((name.into(), f, z)) };
    let cases: [(Firmware, &str, Shaper, Shaper, f64, f64); 5] = [
        (
            Firmware::Klipper,
            "voronpi/printer.cfg",
            s("mzv", 58.6, 0.1),
            s("zv", 41.8, 0.1),
            6500.0,
            160.0,
        ),
        (
            Firmware::Klipper,
            "zippy/printer.cfg",
            s("2hump_ei", 75.4, 0.1),
            s("mzv", 41.4, 0.1),
            5000.0,
            80.0,
        ),
        (
            Firmware::Klipper,
            "metis/printer.cfg",
            s("mzv", 64.2, 0.1),
            s("mzv", 44.0, 0.1),
            10000.0,
            320.0,
        ),
        (
            Firmware::Klipper,
            "vt627/printer.cfg",
            s("mzv", 69.6, 0.039),
            s("ei", 71.4, 0.023),
            10000.0,
            320.0,
        ),
        // RepRapFirmware: M201 X2500; no M593 (the owner's `;M593 P"mzv" F42` is a comment).
        (
            Firmware::Rrf,
            "railcore/sys/config.g",
            None,
            None,
            2500.0,
            640.0,
        ),
    ];
    for (firmware, file, x, y, accel, usteps) in cases {
        let out = dir.path().join(file.replace('/', "_") + ".toml");
        let i = import(&opts(firmware, real.join(file), &out)).expect(file);
        let c = &i.current;
        assert_eq!(c.amax_mm_s2, accel, "{file}");
        assert_eq!((&c.axes[0].shaper, &c.axes[1].shaper), (&x, &y), "{file}");
        assert_eq!(c.axes[0].usteps_per_mm, Some(usteps), "{file}");
        settle::load_runs(&out).unwrap_or_else(|e| panic!("{file}: {e}"));
        // What the reader could not follow is among the notes: vt627's five includes of
        // files that are not in its repository; on the RailCore, its two `global` lines
        // (its `M906 X{2800 * 0.65}` is worked out, not noted).
        let skipped = i.notes.iter().filter(|n| n.contains("skipped")).count();
        assert_eq!(
            skipped,
            if file.starts_with("vt627") { 5 } else { 0 },
            "{file}: {:?}",
            i.notes
        );
        assert!(
            !i.notes.iter().any(|n| n.contains("expressions")),
            "{file}: {:?}",
            i.notes
        );
        // The scenario written keeps the reader's notes above the settings read, so a
        // skipped include stays with what it may have set.
        let written = std::fs::read_to_string(&out).expect("written");
        let header: Vec<&str> = written.lines().take_while(|l| l.starts_with('#')).collect();
        for n in &c.notes {
            assert!(
                header.contains(&format!("#   - {n}").as_str()),
                "{file}: {n}"
            );
        }
        assert_eq!(
            header.iter().filter(|l| l.contains("skipped")).count(),
            if file.starts_with("vt627") { 5 } else { 0 },
            "{file}"
        );
    }
}

/// A configuration whose acceleration is under 100 mm/s^2 (`max_accel: 3`, written in
/// m/s^2) gets a search `settle tune` takes: no acceleration above it rounds down to 0.
#[test]
fn a_tiny_acceleration_searches_no_zero() {
    for current in [3.0, 60.0, 99.0] {
        let v = settle::workflows::import::tune_accels(current, Some(10_800.0));
        assert!(v.iter().all(|a| *a > 0.0), "{current}: {v:?}");
        assert!(v.contains(&current), "{current}: {v:?}");
    }
    let dir = tempfile::tempdir().expect("tempdir");
    let cfg = dir.path().join("printer.cfg");
    std::fs::write(
        &cfg,
        "[printer]\nkinematics: cartesian\nmax_velocity: 0.3\nmax_accel: 3\n",
    )
    .expect("write");
    let out = dir.path().join("p.toml");
    import(&opts(Firmware::Klipper, cfg, &out)).expect("imports");
    let (sc, _) = settle::load_runs(&out).expect("loads");
    let accels = sc
        .tune
        .as_ref()
        .and_then(|t| t.accelerations_mm_s2.clone())
        .expect("[tune] accelerations_mm_s2");
    assert!(accels.iter().all(|a| *a > 0.0), "{accels:?}");
}

/// A value Klipper reads but settle cannot stand behind is refused at its file, line and
/// option: a shaper frequency of 1e308 Hz (it came back as "key `input_shaper`: ... got
/// inf", no line, once the sweep around it overflowed), and an acceleration no run can
/// reach in a sane number of samples (named the option but not its line).
#[test]
fn implausible_values_are_refused_at_their_line() {
    let dir = tempfile::tempdir().expect("tempdir");
    let cfg = dir.path().join("printer.cfg");
    let out = dir.path().join("o.toml");
    let printer = "[printer]\nkinematics: cartesian\nmax_velocity: 300\nmax_accel: 3000\n";
    for (text, line, key, says) in [
        (
            format!("{printer}\n[input_shaper]\nshaper_freq_x: 1e308\nshaper_type_x: mzv\n"),
            7,
            "input_shaper.shaper_freq_x",
            "a finite number >= 0 <= 1000",
        ),
        (
            format!("{printer}\n[input_shaper]\nshaper_freq_y: 40\nshaper_freq_x: 1e9\n"),
            8,
            "input_shaper.shaper_freq_x",
            "a finite number >= 0 <= 1000",
        ),
        (
            printer.replace("max_accel: 3000", "max_accel: 0.0000001"),
            4,
            "printer.max_accel",
            "settle cannot run these settings",
        ),
        // A speed at which the search's 20 mm move outlasts a run: the speed is named,
        // not the acceleration the search sweeps (the old error named max_accel).
        (
            printer.replace("max_velocity: 300", "max_velocity: 0.001"),
            3,
            "printer.max_velocity",
            "a move of 20 mm at vmax_mm_s = 0.001",
        ),
    ] {
        std::fs::write(&cfg, &text).expect("write");
        let e = import(&opts(Firmware::Klipper, cfg.clone(), &out)).expect_err(&text);
        let Error::Input { at, message } = &e else {
            panic!("{text}: {e}")
        };
        assert_eq!(at.file, cfg, "{text}: {e}");
        assert_eq!(at.line, Some(line), "{text}: {e}");
        assert_eq!(at.key.as_deref(), Some(key), "{text}: {e}");
        assert!(message.contains(says), "{text}: {e}");
        assert!(!out.exists(), "{text}");
        let r = crate::support::settle()
            .args(["import", "klipper"])
            .arg(&cfg)
            .arg("--out")
            .arg(&out)
            .output()
            .expect("runs");
        assert_eq!(r.status.code(), Some(2), "{text}: {r:?}");
    }
}

/// A config.g value settle cannot run is named at its line: the old reader recorded no
/// line for config.g (`c.g: key M203: ...`), and named the acceleration for a speed too
/// low to run.
#[test]
fn a_config_g_value_is_refused_at_its_line() {
    let dir = tempfile::tempdir().expect("tempdir");
    let cfg = dir.path().join("config.g");
    let out = dir.path().join("o.toml");
    for (text, line, key, says) in [
        (
            "M92 X80 Y80\nM201 X1000 Y1000\nM203 X0.06 Y0.06\nM204 P1000 T1000\n",
            3,
            "M203",
            "a move of 20 mm at vmax_mm_s = 0.001",
        ),
        (
            "M92 X80 Y80\nM593 P\"ei3\" F2000 S0.1\nM201 X1000 Y1000\n",
            2,
            "M593.F",
            "5.722 to 1000 Hz",
        ),
    ] {
        std::fs::write(&cfg, text).expect("write");
        let e = import(&opts(Firmware::Rrf, cfg.clone(), &out)).expect_err(text);
        let Error::Input { at, message } = &e else {
            panic!("{text}: {e}")
        };
        assert_eq!(
            (&at.file, at.line, at.key.as_deref()),
            (&cfg, Some(line), Some(key)),
            "{text}: {e}"
        );
        assert!(message.contains(says), "{text}: {e}");
        assert!(!out.exists(), "{text}");
    }
}

/// Klipper's own example files through the command (settle-gcode's
/// `tests/data/klipper-examples/`, `MANIFEST.md` there): a fragment without `[printer]` is
/// named once and called a fragment; an option Klipper does not read in `[input_shaper]`
/// is refused at its line with its key, as Klipper refuses to start on it (exit 2).
#[test]
fn klipper_fragments_and_unknown_options_are_refused_through_the_command() {
    let examples = root().join("gcode/tests/data/klipper-examples");
    let fragment = examples.join("sample-idex.cfg");
    let r = crate::support::settle()
        .args(["import", "klipper"])
        .arg(&fragment)
        .output()
        .expect("runs");
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(2), "{err}");
    assert_eq!(
        err.trim_end(),
        format!(
            "error: {}: no [printer] section: the file is a fragment of a configuration, not a whole printer.cfg (Klipper requires [printer] with kinematics, max_velocity and max_accel: klippy/toolhead.py); give the printer.cfg that includes it",
            fragment.display()
        )
    );
    // example-corexy.cfg (79 lines) with an [input_shaper] whose Y frequency is misnamed.
    let dir = tempfile::tempdir().expect("tempdir");
    let cfg = dir.path().join("printer.cfg");
    let text = std::fs::read_to_string(examples.join("example-corexy.cfg")).expect("reads");
    let lines = text.lines().count();
    std::fs::write(
        &cfg,
        format!("{text}[input_shaper]\nshaper_freq_x: 48\nshaper_freq: 40\n"),
    )
    .expect("writes");
    let r = crate::support::settle()
        .args(["import", "klipper"])
        .arg(&cfg)
        .arg("--out")
        .arg(dir.path().join("o.toml"))
        .output()
        .expect("runs");
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(2), "{err}");
    assert!(
        err.contains(&format!(
            "{}:{}: key `input_shaper.shaper_freq`: Klipper does not know this option of [input_shaper] and refuses to start",
            cfg.display(),
            lines + 3
        )),
        "{err}"
    );
    assert!(!dir.path().join("o.toml").exists());
}
