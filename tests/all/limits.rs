//! What a scenario may ask for: runs whose simulated time, bands, sweep or sampling would
//! make a run hang, exhaust memory or measure nonsense are refused before any work, with
//! the key and the limit; and a run in progress stops within a second of Ctrl-C.

use std::path::Path;
use std::process::Stdio;
use std::time::{Duration, Instant};

use crate::support::{settle, write};

/// The error of expanding `text` (it must be an input error).
pub fn expand_err(text: &str) -> String {
    let r = settle::expand::parse_runs(text, Path::new("s.toml"));
    match r {
        Ok((_, runs)) => panic!("expected an error, got {} runs", runs.len()),
        Err(e) => {
            assert!(e.is_input_error(), "{e}");
            e.to_string()
        }
    }
}

/// `scenarios/quickstart.toml` with `from` replaced by `to` (which must occur).
pub fn quickstart_with(from: &str, to: &str) -> String {
    let text = std::fs::read_to_string(crate::support::root().join("scenarios/quickstart.toml"))
        .expect("quickstart");
    assert!(text.contains(from), "{from}");
    text.replacen(from, to, 1)
}

#[test]
fn a_move_that_would_never_end_is_refused_with_its_key() {
    // The key blamed is the swept one of distance and limits, else the distance; the
    // message gives all three. The limits are the slowest their ranges take (1e-3): a
    // 100 mm move at 1e-3 mm/s lasts 1e5 s; at 1e-3 mm/s^2 it takes a 1e5 mm move
    // (2e4 s) to go over.
    for (from, to, key) in [
        (
            "distance_mm = 10.0",
            "distance_mm = 1e9",
            "move.distance_mm",
        ),
        (
            "distance_mm = 10.0",
            "distance_mm = 1e308",
            "move.distance_mm",
        ),
        (
            "vmax_mm_s = 300.0",
            "vmax_mm_s = 1e-3",
            "sweep.move.distance_mm",
        ),
        (
            "amax_mm_s2 = 3000.0",
            "amax_mm_s2 = 1e-3",
            "sweep.move.distance_mm",
        ),
    ] {
        let mut text = quickstart_with(from, to);
        if to.contains("amax") {
            text = text.replacen("50, 100]", "50, 1e5]", 1);
        }
        if to.contains("distance") {
            text = text.replace(
                "\"move.distance_mm\" = [0.5, 1, 2, 5, 10, 20, 50, 100]\n",
                "",
            );
        }
        let e = expand_err(&text);
        assert!(e.contains(&format!("key `{key}`")), "{to}: {e}");
        assert!(e.contains("over the limit of 1e8"), "{to}: {e}");
    }
    // Swept: the sweep axis is blamed.
    let e = expand_err(&quickstart_with("[0.5, 1, 2, 5,", "[1e9, 1, 2, 5,"));
    assert!(e.contains("key `sweep.move.distance_mm`"), "{e}");
}

/// One rapier run of a 40 Hz mode observed for 5,000 s at 10 kHz (5e7 samples, a minute
/// or more of work): Ctrl-C must end it within seconds, not after the run.
pub const LONG_RUN: &str = r#"name = "long"
[machine]
modes = [{ frequency_hz = 40.0, damping_ratio = 0.05 }]
[move]
distance_mm = 10.0
profile = "trapezoid"
[limits]
vmax_mm_s = 300.0
amax_mm_s2 = 3000.0
[observe]
window_s = 5000.0
sample_rate_hz = 10000
bands_um = [10.0]
"#;

#[test]
fn ctrl_c_stops_a_run_in_progress_within_a_second() {
    let dir = tempfile::tempdir().expect("tempdir");
    let scenario = write(dir.path(), "long.toml", LONG_RUN);
    let out = dir.path().join("out");
    let mut child = settle()
        .arg("sweep")
        .arg(&scenario)
        .args(["--backend", "rapier", "--jobs", "1", "--out"])
        .arg(&out)
        .stderr(Stdio::null())
        .spawn()
        .expect("starts");
    // The journal exists once the run has started.
    let t0 = Instant::now();
    while !out.join("journal.csv").exists() {
        assert!(t0.elapsed() < Duration::from_secs(60), "never started");
        std::thread::sleep(Duration::from_millis(20));
    }
    std::thread::sleep(Duration::from_millis(300));
    let ok = std::process::Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .expect("kill runs");
    assert!(ok.success());
    let signalled = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().expect("wait") {
            break s;
        }
        if signalled.elapsed() > Duration::from_secs(5) {
            child.kill().expect("kill");
            panic!("still running 5 s after Ctrl-C");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    assert_eq!(status.code(), Some(130));
    let journal = std::fs::read_to_string(out.join("journal.csv")).expect("journal kept");
    assert_eq!(
        journal.lines().count(),
        2,
        "the stopped run is not a row: {journal}"
    );
}

#[test]
fn many_bands_or_sweep_axes_are_refused_with_the_limit() {
    let bands: Vec<String> = (1..=10_000).map(|b| format!("{b}.0")).collect();
    let e = expand_err(&quickstart_with(
        "bands_um = [10.0, 50.0]",
        &format!("bands_um = [{}]", bands.join(", ")),
    ));
    assert!(e.contains("key `observe.bands_um`"), "{e}");
    assert!(e.contains("10000 bands; at most 16"), "{e}");
    let axes: String = (0..9)
        .map(|i| format!("\"machine.modes.{i}.frequency_hz\" = [40.0]\n"))
        .collect();
    let modes = ["{ frequency_hz = 40.0, damping_ratio = 0.05 }"; 9].join(", ");
    let text = quickstart_with(
        "modes = [{ frequency_hz = 40.0, damping_ratio = 0.05 }]",
        &format!("modes = [{modes}]"),
    )
    .replace("profile = [\"trapezoid\", \"scurve\"]\n", &axes);
    let e = expand_err(&text);
    assert!(e.contains("key `sweep`"), "{e}");
    assert!(e.contains("10 sweep axes; at most 8"), "{e}");
}

#[test]
fn a_window_or_sample_rate_that_cannot_see_the_modes_is_refused() {
    // 40 Hz: half a period is 12.5 ms; Nyquist is 80 Hz.
    let e = expand_err(&quickstart_with("window_s = 0.5", "window_s = 1e-9"));
    assert!(e.contains("key `observe.window_s`"), "{e}");
    assert!(
        e.contains("half a period of the slowest mode (40.0000 Hz"),
        "{e}"
    );
    let e = expand_err(&quickstart_with(
        "sample_rate_hz = 10000",
        "sample_rate_hz = 1",
    ));
    assert!(e.contains("key `observe.sample_rate_hz`"), "{e}");
    assert!(e.contains("at least 80.0000 Hz"), "{e}");
    // At the limits the scenario is accepted.
    let ok = quickstart_with("window_s = 0.5", "window_s = 0.0125")
        .replace("sample_rate_hz = 10000", "sample_rate_hz = 80");
    settle::expand::parse_runs(&ok, Path::new("s.toml")).expect("at the limits");
    // A physical machine: its linearised modes (the preset's first mode is well below
    // 1 kHz, its fastest well above 2 Hz).
    let e = expand_err(
        &std::fs::read_to_string(crate::support::root().join("scenarios/printer_xy.toml"))
            .expect("printer_xy")
            .replace("sample_rate_hz = 10000", "sample_rate_hz = 2"),
    );
    assert!(e.contains("the machine's linearised modes"), "{e}");
}

#[test]
fn a_band_given_twice_is_refused() {
    let e = expand_err(&quickstart_with(
        "bands_um = [10.0, 50.0]",
        "bands_um = [10.0, 50.0, 10]",
    ));
    assert!(e.contains("key `observe.bands_um`"), "{e}");
    assert!(e.contains("band 10 um is given twice"), "{e}");
}

#[test]
fn a_bad_name_writes_nothing_and_names_the_key() {
    let dir = tempfile::tempdir().expect("tempdir");
    let name = "n".repeat(300);
    let scenario = write(
        dir.path(),
        "s.toml",
        &quickstart_with("name = \"quickstart\"", &format!("name = \"{name}\"")),
    );
    let out = settle()
        .arg("sweep")
        .arg(&scenario)
        .current_dir(dir.path())
        .output()
        .expect("runs");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("s.toml:6:"), "{stderr}");
    assert!(stderr.contains("key `name`"), "{stderr}");
    assert!(stderr.contains("1 to 64 letters"), "{stderr}");
    assert!(stderr.len() < 400, "the name is not echoed whole: {stderr}");
    let left: Vec<_> = std::fs::read_dir(dir.path())
        .expect("dir")
        .map(|e| e.expect("entry").file_name())
        .collect();
    assert_eq!(
        left,
        vec![std::ffi::OsString::from("s.toml")],
        "nothing created"
    );
}
