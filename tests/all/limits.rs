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

/// A point move whose time the jerk limit sets: 1e5 mm at 1e-3 mm/s^3 with limits it
/// never reaches (1e6 mm/s, 1e9 mm/s^2), on one 40 Hz mode, observed 0.02 s at `rate` Hz.
fn jerk_bound_move(rate: u64) -> String {
    format!(
        r#"name = "jerk_bound"
[machine]
modes = [{{ frequency_hz = 40.0, damping_ratio = 0.05 }}]
[move]
distance_mm = 1e5
profile = "scurve"
[limits]
vmax_mm_s = 1e6
amax_mm_s2 = 1e9
jmax_mm_s3 = 1e-3
[observe]
window_s = 0.02
sample_rate_hz = {rate}
bands_um = [10.0]
"#
    )
}

#[test]
fn a_move_stretched_by_its_jerk_limit_is_refused_on_its_planned_time() {
    // The S-curve that reaches neither limit has three jerk phases of tau, 2 tau and tau
    // and covers 2 j tau^3: tau = cbrt(d / (2 j)), the move lasts 4 tau = 1473.6 s, not
    // the 0.101 s of its trapezoid (d / v + v / a). Its samples with the window:
    // (4 tau + 0.02) rate. The last rate within 1e8 samples is taken, the next refused
    // before any run, blaming the jerk limit with the planned time.
    let (d, j, w) = (1e5_f64, 1e-3_f64, 0.02);
    let move_s = 4.0 * (d / (2.0 * j)).cbrt();
    assert!((move_s - 1473.6).abs() < 0.1, "{move_s}");
    let ok = (1e8 / (move_s + w)).floor() as u64;
    // Far from an integer: rounding cannot move the boundary.
    assert!(1e8 - ok as f64 * (move_s + w) > 100.0);
    assert!((ok + 1) as f64 * (move_s + w) > 1e8 + 100.0);
    settle::expand::parse_runs(&jerk_bound_move(ok), Path::new("s.toml"))
        .unwrap_or_else(|e| panic!("{ok} Hz: {e}"));
    let e = expand_err(&jerk_bound_move(ok + 1));
    assert!(e.starts_with("s.toml:10:"), "{e}");
    assert!(e.contains("key `limits.jmax_mm_s3`"), "{e}");
    assert!(
        e.contains(&format!("the planned move takes {move_s:.3e} s"))
            && e.contains("over the limit of 1e8 per run"),
        "{e}"
    );
}

/// `scenarios/ci_scan.toml` with `lines` extra lines appended to its `[sweep]` and its
/// sample rate `rate`.
fn ci_scan_with(sweep: &str, rate: f64) -> String {
    let text = std::fs::read_to_string(crate::support::root().join("scenarios/ci_scan.toml"))
        .expect("ci_scan");
    let text = text.replace(
        "sample_rate_hz = 10000\n",
        &format!("sample_rate_hz = {rate}\n"),
    );
    format!("{text}{sweep}")
}

#[test]
fn a_scan_sweep_too_long_for_memory_is_refused_before_any_run() {
    // One swept scan speed of 1e-2 mm/s: each of the 2 lines of 10 mm takes 1000 s, 2000 s
    // of raster that ci_scan keeps whole (1 axis simulated: 6 channels, the path error and
    // the time stamp, 8 values a sample) at 10 kHz: 1.6e8 values, over 1.6e7. The sweep is
    // refused before any of its 12 runs starts, blaming the swept key.
    let e = expand_err(&ci_scan_with("\"scan.v_scan_mm_s\" = [100, 1e-2]\n", 1e4));
    assert!(e.contains("key `sweep.scan.v_scan_mm_s`"), "{e}");
    assert!(
        e.contains("run 1:") && e.contains("the 2.000e3 s move") && e.contains("of 8 values each"),
        "{e}"
    );
    assert!(e.contains("over the limit of 1.6e7"), "{e}");
    // The boundary on the planned raster at 1 mm/s: its duration is the planner's (at
    // least the 20 s the fly axis takes over the lines, and the turnaround and run-out add
    // well under a second), the last rate within 1.6e7 values taken, the next refused.
    let text = ci_scan_with("\"scan.v_scan_mm_s\" = [1]\n", 1e4);
    let (_, runs) = settle::expand::parse_runs(&text, Path::new("s.toml")).expect("runs");
    let names = runs[0].axis_names();
    let raster_s = runs
        .iter()
        .map(|r| {
            settle::studies::plan(r, &names)
                .expect("plans")
                .motion
                .duration_s()
        })
        .fold(0.0, f64::max);
    assert!((20.0..21.0).contains(&raster_s), "{raster_s}");
    let ok = (1.6e7 / (8.0 * (raster_s + 0.02))).floor();
    settle::expand::parse_runs(
        &ci_scan_with("\"scan.v_scan_mm_s\" = [1]\n", ok),
        Path::new("s.toml"),
    )
    .unwrap_or_else(|e| panic!("{ok} Hz: {e}"));
    let e = expand_err(&ci_scan_with("\"scan.v_scan_mm_s\" = [1]\n", ok + 1.0));
    assert!(
        e.contains("key `sweep.scan.v_scan_mm_s`") && e.contains("its trace is kept in memory"),
        "{e}"
    );
}

/// Two trapezoid moves of 1 and 300 mm at 1 mm/s and 1000 mm/s^2 on one 40 Hz mode,
/// observed 0.5 s at `rate` Hz.
fn slow_moves(rate: f64) -> String {
    format!(
        r#"name = "slow"
[machine]
modes = [{{ frequency_hz = 40.0, damping_ratio = 0.05 }}]
[move]
distance_mm = 1.0
profile = "trapezoid"
[limits]
vmax_mm_s = 1.0
amax_mm_s2 = 1000.0
[observe]
window_s = 0.5
sample_rate_hz = {rate}
bands_um = [10.0]
[sweep]
"move.distance_mm" = [1, 300]
"#
    )
}

#[test]
fn a_recorded_sweep_checks_every_runs_trace_before_any_run() {
    // The 300 mm move lasts d / v + v / a = 300.001 s; with the 0.5 s window its samples
    // are 300.501 rate, each of 8 values when recorded (one axis: 6 channels, the path
    // error, the time stamp). `--mcap` and `--rerun` keep every run's trace, at most 1.6e7
    // values: the last rate within is taken, the next refused, blaming the swept distance.
    let t: f64 = 300.0 / 1.0 + 1.0 / 1000.0 + 0.5;
    let ok = (1.6e7 / (8.0 * t)).floor();
    assert!(1.6e7 - 8.0 * t * ok > 100.0 && 8.0 * t * (ok + 1.0) > 1.6e7 + 100.0);
    let check = |rate: f64| {
        let text = slow_moves(rate);
        let (sc, src) = settle::expand::parse(&text, Path::new("s.toml")).expect("parses");
        let runs = settle::expand::expand(&sc, &src).expect("not recorded, every run is taken");
        runs.iter()
            .map(|r| settle::expand::validate::validate_recorded(r, &src))
            .collect::<Result<Vec<()>, _>>()
    };
    check(ok).unwrap_or_else(|e| panic!("{ok} Hz: {e}"));
    let e = check(ok + 1.0).expect_err("refused").to_string();
    assert!(
        e.starts_with("s.toml:15:") && e.contains("key `sweep.move.distance_mm`"),
        "{e}"
    );
    assert!(
        e.contains("run 1: its trace is kept in memory") && e.contains("of 8 values each"),
        "{e}"
    );
    // Through the command: exit 2 before any run, nothing written.
    let dir = tempfile::tempdir().expect("tempdir");
    let scenario = write(dir.path(), "s.toml", &slow_moves(ok + 1.0));
    let out = settle()
        .args([
            "sweep",
            "s.toml",
            "--mcap",
            "--backend",
            "modal",
            "--out",
            "o",
        ])
        .current_dir(dir.path())
        .output()
        .expect("runs");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("key `sweep.move.distance_mm`"), "{stderr}");
    assert!(
        scenario.exists() && !dir.path().join("o").exists(),
        "nothing written"
    );
    // `settle run` keeps its one run's trace whole: run 1 at the refused rate is refused
    // before it starts with the sweep's message, exit 2, no folder made; run 0 (the 1 mm
    // move, 1.501 s of samples) is within and runs.
    let run = |case: &str| {
        settle()
            .args(["run", "s.toml", "--case", case, "--backend", "modal"])
            .args(["--out", "o/t.csv"])
            .current_dir(dir.path())
            .output()
            .expect("runs")
    };
    let out = run("1");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains(&format!(
            "s.toml:{}",
            e.strip_prefix("s.toml:").expect("file")
        )),
        "the sweep's message {e}, got {stderr}"
    );
    assert!(!dir.path().join("o").exists(), "nothing written");
    let out = run("0");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(dir.path().join("o/t.csv").is_file());
}

/// `scenarios/quickstart.toml` with its `[observe]` values replaced: `window_s`,
/// `sample_rate_hz`, `bands_um` as written here.
fn quickstart_observing(window: &str, rate: &str, bands: &str) -> String {
    quickstart_with("window_s = 0.5", &format!("window_s = {window}"))
        .replace(
            "sample_rate_hz = 10000",
            &format!("sample_rate_hz = {rate}"),
        )
        .replace("bands_um = [10.0, 50.0]", &format!("bands_um = [{bands}]"))
}

/// The line (1-based) of `text` that starts with `key`.
fn line_of(text: &str, key: &str) -> usize {
    1 + text
        .lines()
        .position(|l| l.starts_with(key))
        .expect("the key is written")
}

#[test]
fn the_observe_keys_are_bounded_at_their_limits() {
    // Each limit is taken, the next f64 above it refused with the key's line, the range
    // and the value. Window: at most 1e4 s (at 100 Hz, over the 80 Hz Nyquist of the
    // 40 Hz mode: 1e6 samples, within the 1e8 of a run). Rate: at most 1e6 Hz. Bands:
    // each below 0.1 m, the blow-up limit, 1e5 um; at most 16.
    let above = |x: f64| f64::from_bits(x.to_bits() + 1);
    let below = |x: f64| f64::from_bits(x.to_bits() - 1);
    let accepted = |text: &str| {
        settle::expand::parse_runs(text, Path::new("s.toml")).unwrap_or_else(|e| panic!("{e}"));
    };
    let refused = |text: &str, key: &str, what: &str| {
        let e = expand_err(text);
        let line = line_of(text, key.strip_prefix("observe.").expect("observe"));
        assert!(
            e.starts_with(&format!("s.toml:{line}:1: key `{key}`: {what}")),
            "{e}"
        );
    };
    accepted(&quickstart_observing("1e4", "100", "10.0"));
    let w = above(1e4);
    refused(
        &quickstart_observing(&format!("{w:?}"), "100", "10.0"),
        "observe.window_s",
        &format!("must be a finite number > 0 and at most 1e4 (s), got {w}"),
    );
    assert_eq!(format!("{w}"), "10000.000000000002");
    accepted(&quickstart_observing("0.5", "1e6", "10.0"));
    let r = above(1e6);
    refused(
        &quickstart_observing("0.5", &format!("{r:?}"), "10.0"),
        "observe.sample_rate_hz",
        &format!("must be a finite number > 0 and at most 1e6 (Hz), got {r}"),
    );
    refused(
        &quickstart_observing("0.5", "nan", "10.0"),
        "observe.sample_rate_hz",
        "must be a finite number > 0 and at most 1e6 (Hz), got NaN",
    );
    let b = below(1e5);
    assert_eq!(format!("{b:?}"), "99999.99999999999");
    accepted(&quickstart_observing(
        "0.5",
        "10000",
        &format!("10.0, {b:?}"),
    ));
    refused(
        &quickstart_observing("0.5", "10000", "10.0, 1e5"),
        "observe.bands_um",
        "band 1 must be a finite number > 0 and below 1e5 (um), got 100000: an error past 0.1 m stops the run as a fault",
    );
    let bands = |n: usize| {
        (1..=n)
            .map(|b| format!("{b}.0"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    accepted(&quickstart_observing("0.5", "10000", &bands(16)));
    refused(
        &quickstart_observing("0.5", "10000", &bands(17)),
        "observe.bands_um",
        "17 bands; at most 16",
    );
}
