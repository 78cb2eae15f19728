//! Simulation faults are failed runs (the sweep goes on; a result: exit code 0, or 1 with
//! `--fail-on-failed-runs`), and interrupted sweeps keep their finished runs and resume to
//! the same output.

use crate::support::{run_case_1, settle, write};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Two modes through rapier with a forced 1 ms step (`max_step_s = 2 ms` does not cut the
/// 1 kHz sample interval; 1 kHz is above the 960 Hz Nyquist rate of the 480 Hz mode, the
/// least a scenario may ask for): symplectic Euler is stable for `w h < 2`, so the 40 Hz
/// mode (`w h = 0.25`) runs and the 480 Hz one (`w h = 3.0`) grows by a factor of about 7
/// per step until it is caught.
const BLOW_UP: &str = include_str!("../faults/blowup.toml");

#[test]
fn a_blow_up_is_a_failed_run_with_its_reason_and_the_sweep_goes_on() {
    let dir = tempfile::tempdir().expect("tempdir");
    let scenario = write(dir.path(), "blowup.toml", BLOW_UP);
    let out = settle()
        .arg("sweep")
        .arg(&scenario)
        .args(["--backend", "rapier", "--out"])
        .arg(dir.path())
        .output()
        .expect("runs");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(
        out.status.code(),
        Some(0),
        "a failed run is a result: {stderr}"
    );
    assert!(
        stderr.contains("1 of 2 runs failed"),
        "a summary of failures: {stderr}"
    );
    let csv = std::fs::read_to_string(dir.path().join("runs.csv")).expect("runs.csv written");
    let header: Vec<&str> = csv.lines().next().expect("header").split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).expect(name);
    let rows: Vec<Vec<&str>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    assert_eq!(rows.len(), 2);
    assert_eq!(rows[0][col("status")], "ok");
    assert_eq!(rows[0][col("reason")], "");
    let peak: f64 = rows[0][col("residual_peak_um")].parse().expect("a number");
    assert!(peak.is_finite() && peak < 1000.0, "the stable run: {peak}");
    assert_eq!(rows[1][col("status")], "fault");
    let reason = rows[1][col("reason")];
    assert!(
        reason.contains("blow-up") || reason.contains("became"),
        "{reason}"
    );
    assert_eq!(
        rows[1][col("residual_peak_um")],
        "",
        "no numbers for a failed run"
    );
    // Caught as it happens: well before the end of the 0.3 s window (t in the reason).
    let t: f64 = reason
        .split("t = ")
        .nth(1)
        .and_then(|s| s.split(' ').next())
        .and_then(|s| s.parse().ok())
        .expect("the time of the fault");
    assert!(t < 0.1, "{reason}");
    let summary = std::fs::read_to_string(dir.path().join("summary.md")).expect("summary");
    assert!(summary.contains("1 run(s) failed"), "{summary}");
    assert!(summary.contains("- run 1: blow-up") || summary.contains("- run 1: "));
    assert!(!dir.path().join("journal.csv").exists(), "journal removed");
    // Asked to, the same sweep ends with exit 1, every output written all the same.
    let strict = dir.path().join("strict");
    let out = settle()
        .arg("sweep")
        .arg(&scenario)
        .args(["--backend", "rapier", "--fail-on-failed-runs", "--out"])
        .arg(&strict)
        .output()
        .expect("runs");
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(
        std::fs::read(strict.join("runs.csv")).expect("written"),
        csv.as_bytes()
    );
}

/// `settle run` on the run that blows up: its status and reason, no metric that could be
/// read as a settling result (the run stopped at 7 ms with a residual it never measured),
/// the trace up to the fault; exit 0 as in a sweep, 1 with `--fail-on-failed-runs`.
#[test]
fn settle_run_reports_a_fault_as_a_failed_run_not_as_numbers() {
    let dir = tempfile::tempdir().expect("tempdir");
    let scenario = write(dir.path(), "blowup.toml", BLOW_UP);
    let trace = dir.path().join("run-1.csv");
    let run = |extra: &[&str]| {
        run_case_1(
            &scenario,
            &trace,
            &[&["--backend", "rapier"], extra].concat(),
        )
    };
    let out = run(&[]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{stdout}");
    assert!(stdout.contains("FAILED (fault): blow-up"), "{stdout}");
    for metric in [
        "residual_peak_um",
        "settle_time_s",
        "move_and_settle_s",
        "overshoot_um",
    ] {
        assert!(
            !stdout.contains(metric),
            "{metric} printed for a fault: {stdout}"
        );
    }
    let text = std::fs::read_to_string(&trace).expect("trace");
    assert!(text.lines().count() > 2, "the trace up to the fault");
    assert_eq!(run(&["--fail-on-failed-runs"]).status.code(), Some(1));
}

#[test]
fn sim_step_must_be_positive() {
    let dir = tempfile::tempdir().expect("tempdir");
    let scenario = write(
        dir.path(),
        "bad.toml",
        &BLOW_UP.replace("max_step_s = 0.002", "max_step_s = -0.002"),
    );
    let out = settle()
        .arg("sweep")
        .arg(&scenario)
        .arg("--out")
        .arg(dir.path())
        .output()
        .expect("runs");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("bad.toml:16"), "{stderr}");
    assert!(stderr.contains("sim.max_step_s"), "{stderr}");
    assert!(stderr.contains("> 0"), "{stderr}");
}

/// Enough rapier runs on one thread to be interrupted mid-way (each ~10-30 ms).
const MANY: &str = r#"name = "many"
[machine]
modes = [{ frequency_hz = 40.0, damping_ratio = 0.05 }]
[move]
distance_mm = 5.0
profile = "scurve"
[limits]
vmax_mm_s = 300.0
amax_mm_s2 = 3000.0
jmax_mm_s3 = 100000.0
[observe]
window_s = 0.5
[sweep]
"move.distance_mm" = { from = 0.5, to = 100.0, steps = 150, scale = "log" }
profile = ["trapezoid", "scurve"]
"#;

fn journal_rows(out: &Path) -> usize {
    std::fs::read_to_string(out.join("journal.csv"))
        .map(|t| t.lines().count().saturating_sub(2))
        .unwrap_or(0)
}

/// Start a sweep into `out` on one thread and stop it with `signal` once it has finished
/// at least 5 runs; returns its exit status.
fn interrupt(scenario: &Path, out: &Path, signal: &str) -> std::process::ExitStatus {
    let mut child = settle()
        .arg("sweep")
        .arg(scenario)
        .args(["--jobs", "1", "--out"])
        .arg(out)
        .stderr(Stdio::null())
        .spawn()
        .expect("starts");
    let t0 = Instant::now();
    while journal_rows(out) < 5 {
        assert!(t0.elapsed() < Duration::from_secs(120), "no progress");
        assert!(child.try_wait().expect("wait").is_none(), "ended too soon");
        std::thread::sleep(Duration::from_millis(20));
    }
    if signal == "KILL" {
        child.kill().expect("kill");
    } else {
        let ok = Command::new("kill")
            .arg(format!("-{signal}"))
            .arg(child.id().to_string())
            .status()
            .expect("kill runs");
        assert!(ok.success());
    }
    child.wait().expect("exits")
}

fn resume(scenario: &Path, out: &Path) {
    let status = settle()
        .arg("sweep")
        .arg(scenario)
        .args(["--jobs", "2", "--resume", "--out"])
        .arg(out)
        .status()
        .expect("runs");
    assert!(status.success());
}

/// runs.csv, summary.md and every figure equal byte for byte; no journal left.
fn assert_same_outputs(a: &Path, b: &Path) {
    let mut files = vec![PathBuf::from("runs.csv"), PathBuf::from("summary.md")];
    let mut plots: Vec<PathBuf> = std::fs::read_dir(b.join("plots"))
        .expect("plots")
        .map(|e| Path::new("plots").join(e.expect("entry").file_name()))
        .collect();
    plots.sort();
    assert!(plots.len() >= 2, "{plots:?}");
    files.extend(plots);
    for f in &files {
        let (x, y) = (std::fs::read(a.join(f)), std::fs::read(b.join(f)));
        assert!(x.is_ok(), "{} missing in {}", f.display(), a.display());
        assert!(x.ok() == y.ok(), "{} differs", f.display());
    }
    assert!(!a.join("journal.csv").exists());
}

#[test]
fn sigint_keeps_finished_runs_and_resume_ends_identical() {
    let dir = tempfile::tempdir().expect("tempdir");
    let scenario = write(dir.path(), "many.toml", MANY);
    let (cut, full) = (dir.path().join("cut"), dir.path().join("full"));
    let status = interrupt(&scenario, &cut, "INT");
    assert_eq!(status.code(), Some(130), "interrupted: exit 130");
    let kept = journal_rows(&cut);
    assert!((5..300).contains(&kept), "{kept} runs kept");
    assert!(!cut.join("runs.csv").exists(), "no partial runs.csv");
    // Without --resume the journal is not thrown away.
    let out = settle()
        .arg("sweep")
        .arg(&scenario)
        .arg("--out")
        .arg(&cut)
        .output()
        .expect("runs");
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--resume"));
    assert_eq!(journal_rows(&cut), kept);
    resume(&scenario, &cut);
    let status = settle()
        .arg("sweep")
        .arg(&scenario)
        .args(["--jobs", "2", "--out"])
        .arg(&full)
        .status()
        .expect("runs");
    assert!(status.success());
    assert_same_outputs(&cut, &full);
}

#[test]
fn sigterm_and_sigkill_with_a_cut_row_resume_identical() {
    let dir = tempfile::tempdir().expect("tempdir");
    let scenario = write(dir.path(), "many.toml", MANY);
    let (term, killed, full) = (
        dir.path().join("term"),
        dir.path().join("killed"),
        dir.path().join("full"),
    );
    assert_eq!(interrupt(&scenario, &term, "TERM").code(), Some(130));
    resume(&scenario, &term);
    interrupt(&scenario, &killed, "KILL");
    // A row cut off mid-write, as a kill during the write would leave it.
    let mut j = std::fs::OpenOptions::new()
        .append(true)
        .open(killed.join("journal.csv"))
        .expect("journal");
    std::io::Write::write_all(&mut j, b"299,scurve,0.5,10").expect("append");
    drop(j);
    resume(&scenario, &killed);
    let status = settle()
        .arg("sweep")
        .arg(&scenario)
        .args(["--jobs", "2", "--out"])
        .arg(&full)
        .status()
        .expect("runs");
    assert!(status.success());
    assert_same_outputs(&term, &full);
    assert_same_outputs(&killed, &full);
}

/// The same forced step on MuJoCo: RK4 is stable for `w h` up to about 2.8, so 480 Hz at
/// 1 ms (`w h = 3.0`) diverges and 40 Hz runs.
#[cfg(feature = "mujoco")]
#[test]
fn a_mujoco_blow_up_is_a_fault_too() {
    let dir = tempfile::tempdir().expect("tempdir");
    let scenario = write(dir.path(), "blowup.toml", BLOW_UP);
    let out = settle()
        .arg("sweep")
        .arg(&scenario)
        .args(["--backend", "mujoco", "--out"])
        .arg(dir.path())
        .output()
        .expect("runs");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    let csv = std::fs::read_to_string(dir.path().join("runs.csv")).expect("runs.csv");
    let rows: Vec<&str> = csv.lines().skip(1).collect();
    assert!(rows[0].contains(",ok,0,,"), "{}", rows[0]);
    assert!(rows[1].contains(",fault,0,"), "{}", rows[1]);
}

/// A raster scan's step on one 480 Hz mode through rapier: with `[sim] max_step_s = 2 ms`
/// at 1 kHz sampling (a 1 ms step, `w h = 3.0`, past symplectic Euler's limit of 2) the run blows up and is a fault; with
/// rapier's own step it runs. Every study is simulated with the scenario's `[sim]`
/// settings (`settle::execute::sim_options`), the scan step included.
#[test]
fn a_scan_step_honours_the_sim_max_step() {
    const SCAN: &str = r#"name = "scan_blowup"
[machine]
modes = [{ frequency_hz = 480.0, damping_ratio = 0.05 }]
[move]
distance_mm = 0.5
profile = "trapezoid"
[limits]
vmax_mm_s = 300.0
amax_mm_s2 = 3000.0
[scan]
v_scan_mm_s = 100.0
fly_amax_mm_s2 = 10000.0
width_mm = 10.0
[observe]
window_s = 0.05
sample_rate_hz = 1000
[sim]
max_step_s = 0.002
"#;
    let status = |text: &str| {
        let path = Path::new("scan_blowup.toml");
        let (_, mut runs) = settle::expand::parse_runs(text, path).expect("expands");
        settle::execute::set_backend(path, &mut runs, settle::spec::backend::Backend::Rapier)
            .expect("rapier");
        settle::execute::execute(&runs[0], None)
            .expect("runs")
            .status
    };
    let forced = status(SCAN);
    assert_eq!(forced.name(), "fault", "{forced:?}");
    assert!(
        forced.reason().contains("blow-up") || forced.reason().contains("became"),
        "{forced:?}"
    );
    let own = status(&SCAN.replace("[sim]\nmax_step_s = 0.002\n", ""));
    assert_eq!(own.name(), "ok", "{own:?}");
}

/// `settle gcode` on a machine that blows up before the first extruding move (an
/// undamped 0.01 Hz mode of weight 10 per axis: the toolhead drifts 0.1 m off its command
/// within a second of the start G-code's travel): a failed run (exit 0, 1 with
/// `--fail-on-failed-runs`) whose contour error was never measured, and says so on stdout,
/// in summary.md and in report.html instead of a worst error of 0.00 um.
#[test]
fn a_gcode_job_that_faults_before_working_says_nothing_was_measured() {
    let dir = tempfile::tempdir().expect("tempdir");
    let machine = write(
        dir.path(),
        "drift.toml",
        "name = \"drift\"\n\
         [axis.x]\nmodes = [{ frequency_hz = 0.01, damping_ratio = 0.0, weight = 10.0 }]\n\
         [axis.y]\nmodes = [{ frequency_hz = 0.01, damping_ratio = 0.0, weight = 10.0 }]\n",
    );
    let job = |out: &str, extra: &[&str]| {
        settle()
            .args(["gcode", "gcode/prints/ringing_tower.gcode", "--machine"])
            .arg(&machine)
            .arg("--out")
            .arg(dir.path().join(out))
            .args(extra)
            .output()
            .expect("runs")
    };
    let out = job("o", &[]);
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr),
    );
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    assert!(stderr.contains("simulation fault: blow-up"), "{stderr}");
    assert!(
        stdout.contains("contour error not measured") && !stdout.contains("0.00 um"),
        "{stdout}"
    );
    let summary = std::fs::read_to_string(dir.path().join("o/summary.md")).expect("summary");
    assert!(
        summary.contains("| not measured | not measured |"),
        "{summary}"
    );
    let html = std::fs::read_to_string(dir.path().join("o/report.html")).expect("report");
    assert!(html.contains("contour error not measured"), "report.html");
    assert_eq!(job("o2", &["--fail-on-failed-runs"]).status.code(), Some(1));
}
