//! End to end through the `settle` binary (its wiring: arguments, outputs, exit codes), and
//! sweeps whose outputs are compared, in-process (`settle::workflows::sweep`).

use std::path::Path;

use settle::execute::pool::quiet;
use settle::spec::backend::Backend;
use settle::workflows::sweep::{SweepOptions, sweep};

use crate::support::{root, run_case_1, settle};

#[test]
fn quickstart_sweep_writes_one_row_per_run() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = settle()
        .args(["sweep", "scenarios/quickstart.toml", "--jobs", "2", "--out"])
        .arg(dir.path())
        .output()
        .expect("runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let csv = std::fs::read_to_string(dir.path().join("runs.csv")).expect("runs.csv");
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 16, "8 distances x 2 kinds");
    let first_metric = header
        .iter()
        .position(|h| *h == "move_time_s")
        .expect("metrics");
    for row in &rows {
        assert_eq!(row.len(), header.len());
        for (h, v) in header.iter().zip(row).skip(first_metric) {
            let x: f64 = v
                .parse()
                .unwrap_or_else(|_| panic!("{h} = {v} is not a number"));
            assert!(
                x.is_finite() || (x == f64::INFINITY && h.contains("settle")),
                "{h} = {v}"
            );
        }
    }
    let summary = std::fs::read_to_string(dir.path().join("summary.md")).expect("summary.md");
    assert!(summary.contains("| move.distance_mm |"), "{summary}");
    assert!(summary.contains("**"), "best marked");
}

#[test]
fn same_scenario_gives_identical_output() {
    let a = tempfile::tempdir().expect("tempdir");
    let b = tempfile::tempdir().expect("tempdir");
    for (dir, jobs) in [(&a, "1"), (&b, "2")] {
        let st = settle()
            .args([
                "sweep",
                "scenarios/quickstart.toml",
                "--jobs",
                jobs,
                "--out",
            ])
            .arg(dir.path())
            .status()
            .expect("runs");
        assert!(st.success());
    }
    for f in ["runs.csv", "summary.md"] {
        let x = std::fs::read(a.path().join(f)).expect("read");
        let y = std::fs::read(b.path().join(f)).expect("read");
        assert!(x == y, "{f} differs between --jobs 1 and --jobs 2");
    }
}

/// `--jobs` takes at most `MAX_JOBS` threads, and a pool never starts more threads than it
/// has work: `--jobs 65535` on a sweep of 16 runs started 65,535 threads, which kept it
/// busy for minutes. The largest `--jobs` answers as `--jobs 2` does.
#[test]
fn jobs_are_bounded_by_the_limit_and_the_work() {
    use settle::execute::pool::{MAX_JOBS, thread_pool};
    let n = |jobs, work| {
        thread_pool(Some(jobs), work)
            .expect("pool")
            .current_num_threads()
    };
    assert_eq!(n(65_535, 16), 16);
    assert_eq!(n(3, 16), 3);
    assert_eq!(n(4, 0), 1);
    assert_eq!(MAX_JOBS, 1024);
    let out = settle()
        .args([
            "sweep",
            "scenarios/quickstart.toml",
            "--jobs",
            "1025",
            "--out",
        ])
        .arg(tempfile::tempdir().expect("tempdir").path())
        .output()
        .expect("runs");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("1025 is not in 1..=1024"), "{err}");
    let (a, b) = (
        tempfile::tempdir().expect("tempdir"),
        tempfile::tempdir().expect("tempdir"),
    );
    for (dir, jobs) in [(&a, "1024"), (&b, "2")] {
        let st = settle()
            .args(["sweep", "scenarios/quickstart.toml", "--backend", "modal"])
            .args(["--jobs", jobs, "--out"])
            .arg(dir.path())
            .status()
            .expect("runs");
        assert!(st.success());
    }
    let runs = |d: &tempfile::TempDir| std::fs::read(d.path().join("runs.csv")).expect("runs.csv");
    assert!(
        runs(&a) == runs(&b),
        "runs.csv differs between --jobs 1024 and --jobs 2"
    );
}

fn assert_input_error(args: &[&str], scenario_text: Option<&str>, expect: &str) {
    let dir = tempfile::tempdir().expect("tempdir");
    let out_dir = dir.path().join("out");
    let mut cmd = settle();
    cmd.args(args);
    if let Some(text) = scenario_text {
        let p = dir.path().join("s.toml");
        std::fs::write(&p, text).expect("write");
        cmd.arg(&p);
    }
    cmd.arg("--out").arg(&out_dir);
    let out = cmd.output().expect("runs");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains(expect), "expected `{expect}` in: {stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(!out_dir.join("runs.csv").exists(), "no output on bad input");
}

#[test]
fn bad_input_exits_2_with_a_clear_error_and_no_output() {
    let good = std::fs::read_to_string(
        Path::new(crate::support::manifest_dir()).join("scenarios/quickstart.toml"),
    )
    .expect("quickstart");
    assert_input_error(
        &["sweep"],
        Some(&good.replace("vmax_mm_s = 300.0", "vmax_mm_s = 0.0")),
        "key `limits.vmax_mm_s`",
    );
    assert_input_error(
        &["sweep"],
        Some(&good.replace("\"scurve\"]", "\"bezier\"]")),
        "unknown profile kind `bezier`",
    );
    assert_input_error(
        &["sweep"],
        Some(&good.replace("profile = [\"trapezoid\", \"scurve\"]", "profile = []")),
        "empty sweep axis",
    );
    assert_input_error(
        &["sweep", "/nonexistent/scenario.toml"],
        None,
        "cannot read /nonexistent/scenario.toml",
    );
    assert_input_error(&["sweep"], Some("name = \"x\"\n[machine\n"), "s.toml:2");
}

#[test]
fn help_carries_examples() {
    for args in [vec!["--help"], vec!["sweep", "--help"]] {
        let out = settle().args(&args).output().expect("runs");
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(out.status.success());
        assert!(
            text.contains("Example") && text.contains("settle sweep scenarios/quickstart.toml"),
            "{text}"
        );
    }
}

#[test]
fn backend_flag_errors_are_input_errors() {
    // The modal backend cannot run the full stepper driver.
    assert_input_error(
        &["sweep", "scenarios/printer_xy.toml", "--backend", "modal"],
        None,
        "driver_model = \"linear\"",
    );
    if !settle::spec::backend::Backend::Mujoco.available() {
        assert_input_error(
            &["sweep", "scenarios/quickstart.toml", "--backend", "mujoco"],
            None,
            "not built with MuJoCo; run scripts/setup-mujoco.sh and build with --features mujoco",
        );
        let out = settle()
            .args(["validate", "--backend", "mujoco"])
            .output()
            .expect("runs");
        assert_eq!(out.status.code(), Some(2));
        assert!(String::from_utf8_lossy(&out.stderr).contains("setup-mujoco.sh"));
    }
    let out = settle()
        .args(["sweep", "scenarios/quickstart.toml", "--backend", "bullet"])
        .output()
        .expect("runs");
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("modal, rapier, mujoco"));
}

#[test]
fn modal_and_rapier_agree_on_the_quickstart() {
    let dirs: Vec<_> = (0..2)
        .map(|_| tempfile::tempdir().expect("tempdir"))
        .collect();
    for (dir, backend) in dirs.iter().zip([Backend::Modal, Backend::Rapier]) {
        sweep_into(
            &root().join("scenarios/quickstart.toml"),
            dir.path(),
            backend,
            None,
        );
    }
    let read =
        |d: &tempfile::TempDir| std::fs::read_to_string(d.path().join("runs.csv")).expect("csv");
    let (modal, rapier) = (read(&dirs[0]), read(&dirs[1]));
    let col = |csv: &str, name: &str| -> Vec<f64> {
        let mut lines = csv.lines();
        let header: Vec<&str> = lines.next().expect("header").split(',').collect();
        let i = header.iter().position(|h| *h == name).expect("column");
        lines
            .map(|l| l.split(',').nth(i).expect("cell").parse().expect("number"))
            .collect()
    };
    for (m, r) in col(&modal, "residual_peak_um")
        .iter()
        .zip(col(&rapier, "residual_peak_um"))
    {
        assert!((m - r).abs() <= 0.02 * m, "{m} vs {r}");
    }
    assert!(rapier.contains(",rapier,ok,0,") && modal.contains(",modal,ok,0,"));
}

/// Sweep `scenario` into `out` in-process on `backend` (`jobs` threads); all runs ok.
fn sweep_into(scenario: &Path, out: &Path, backend: Backend, jobs: Option<usize>) {
    let opts = SweepOptions {
        out: Some(out.to_path_buf()),
        jobs,
        ..SweepOptions::new(scenario, backend)
    };
    let o = sweep(&opts, &|_| {}, &quiet).expect("sweeps");
    assert!(o.failed.is_empty() && o.interrupted.is_none(), "{o:?}");
}

#[test]
fn printer_preset_sweep_is_deterministic_and_reports_per_axis() {
    let a = tempfile::tempdir().expect("tempdir");
    let b = tempfile::tempdir().expect("tempdir");
    for (dir, jobs) in [(&a, 1), (&b, 2)] {
        let scenario = root().join("scenarios/printer_xy.toml");
        sweep_into(&scenario, dir.path(), Backend::Rapier, Some(jobs));
    }
    for f in ["runs.csv", "summary.md"] {
        let x = std::fs::read(a.path().join(f)).expect("read");
        let y = std::fs::read(b.path().join(f)).expect("read");
        assert!(x == y, "{f} differs between --jobs 1 and --jobs 2");
    }
    let csv = std::fs::read_to_string(a.path().join("runs.csv")).expect("csv");
    let header = csv.lines().next().expect("header");
    for h in [
        "y_residual_peak_um",
        "x_max_load_angle_deg",
        "status",
        "lost_steps",
    ] {
        assert!(header.split(',').any(|c| c == h), "{h} in {header}");
    }
    assert_eq!(csv.lines().count(), 9, "8 runs");
    assert!(
        csv.lines()
            .skip(1)
            .all(|l| l.contains(",printer_xy,y,full,rapier,ok,0,"))
    );
}

#[test]
fn lost_steps_fail_the_run_with_their_count() {
    let dir = tempfile::tempdir().expect("tempdir");
    let scenario = dir.path().join("stage.toml");
    std::fs::write(
        &scenario,
        r#"name = "stage"
[machine]
preset = "leadscrew_stage"
[move]
distance_mm = 20.0
[limits]
vmax_mm_s = 300.0
amax_mm_s2 = 2000.0
jmax_mm_s3 = 200000.0
[observe]
window_s = 0.1
[sweep]
"limits.amax_mm_s2" = [2000, 20000]
"#,
    )
    .expect("write");
    let out = settle()
        .arg("sweep")
        .arg(&scenario)
        .arg("--out")
        .arg(dir.path())
        .output()
        .expect("runs");
    // Every output is written, then the failure is listed; a failed run is a result, so
    // the exit code is 0 (1 with --fail-on-failed-runs, tested with a fault in `faults`).
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    assert!(stderr.contains("1 of 2 runs failed"), "{stderr}");
    assert!(stderr.contains("lost_steps: lost "), "{stderr}");
    let csv = std::fs::read_to_string(dir.path().join("runs.csv")).expect("csv");
    let rows: Vec<&str> = csv.lines().skip(1).collect();
    assert!(rows[0].contains(",ok,0,,"), "{}", rows[0]);
    // At 2 g towards 300 mm/s the motor needs more torque than the 48 V supply leaves it
    // at that speed (the back-EMF of a 5 mm lead at 300 mm/s is 63 V): failed, with the
    // count, and no metric values that could be averaged.
    let cells: Vec<&str> = rows[1].split(',').collect();
    let header: Vec<&str> = csv.lines().next().expect("header").split(',').collect();
    let at = |name: &str| cells[header.iter().position(|h| *h == name).expect(name)];
    assert_eq!(at("status"), "lost_steps");
    assert!(at("lost_steps").parse::<u32>().expect("count") >= 4);
    assert!(at("reason").contains("first on axis x"), "{}", at("reason"));
    assert_eq!(at("residual_peak_um"), "");
    assert_eq!(at("settle_time_s_10um"), "");
    let summary = std::fs::read_to_string(dir.path().join("summary.md")).expect("summary");
    assert!(
        summary.contains("1 run(s) failed") && summary.contains("lost "),
        "{summary}"
    );
    // `settle run` agrees: the same status and reason, no metrics, the same exit code.
    let run = |extra: &[&str]| run_case_1(&scenario, &dir.path().join("run-1.csv"), extra);
    let out = run(&[]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{stdout}");
    assert!(
        stdout.contains(&format!("FAILED (lost_steps): {}", at("reason"))),
        "{stdout}"
    );
    assert!(!stdout.contains("residual_peak_um"), "{stdout}");
    assert!(stdout.contains("max load angle"), "{stdout}");
    assert_eq!(run(&["--fail-on-failed-runs"]).status.code(), Some(1));
}

/// Swept presets with different axes (the printer has x and y, the stage only x): one
/// runs.csv whose columns are the union, every row as long as the header, the stage's y
/// cells empty. Rows are written one by one into the sweep journal, so each row must be
/// formed against the whole sweep.
#[test]
fn swept_presets_with_different_axes_share_one_table() {
    let dir = tempfile::tempdir().expect("tempdir");
    let scenario = dir.path().join("presets.toml");
    std::fs::write(
        &scenario,
        r#"name = "presets"
[machine]
preset = "printer_xy"
driver_model = "linear"
[move]
distance_mm = 2.0
[limits]
vmax_mm_s = 100.0
amax_mm_s2 = 2000.0
jmax_mm_s3 = 100000.0
[observe]
window_s = 0.05
[sweep]
"machine.preset" = ["printer_xy", "leadscrew_stage", "printer_xy"]
"#,
    )
    .expect("write");
    sweep_into(&scenario, dir.path(), Backend::Modal, Some(2));
    let csv = std::fs::read_to_string(dir.path().join("runs.csv")).expect("csv");
    let header: Vec<&str> = csv.lines().next().expect("header").split(',').collect();
    let y = header
        .iter()
        .position(|h| *h == "y_residual_peak_um")
        .expect("the printer's y axis has columns");
    let rows: Vec<Vec<&str>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    assert_eq!(rows.len(), 3);
    for r in &rows {
        assert_eq!(r.len(), header.len(), "{r:?}");
    }
    assert!(rows[0][y].parse::<f64>().is_ok(), "printer: {}", rows[0][y]);
    assert_eq!(rows[1][y], "", "the stage has no y axis");
    // The same machine twice: the same numbers (only the run id differs).
    assert_eq!(rows[0][1..], rows[2][1..]);
}

#[cfg(not(feature = "rerun"))]
fn settle_output(args: &[&str]) -> std::process::Output {
    settle().args(args).output().expect("settle runs")
}

#[cfg(not(feature = "rerun"))]
#[test]
fn without_the_feature_rerun_is_a_clear_error() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("x");
    let o = settle_output(&[
        "sweep",
        "scenarios/ci_quickstart.toml",
        "--rerun",
        "--out",
        out.to_str().expect("utf-8"),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("--features rerun"), "{err}");
    assert!(!out.join("runs.csv").exists(), "nothing was run");
}

/// A reader that stops before the output ends (`settle machine printer_xy | head -1`)
/// closes the pipe: the command names the failed write and exits 1, never a panic (101).
#[test]
fn a_closed_standard_output_is_an_io_failure_not_a_panic() {
    // A pipe whose reader is closed before the command starts: every write to it fails.
    // (Closing the reader after the start races the command: its whole output fits in
    // the pipe's buffer when it writes first.)
    let (reader, writer) = std::io::pipe().expect("a pipe");
    drop(reader);
    let out = settle()
        .args(["machine", "printer_xy"])
        .stdout(writer)
        .output()
        .expect("settle runs");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("error: cannot write stdout: Broken pipe"),
        "{err}"
    );
    assert!(!err.contains("panicked"), "{err}");
}
