//! `settle run` on a raster scan: the re-entry figures printed, and the figure's scan view
//! (line exits and re-entries, the fly axis, the error zoomed on the re-entry with the
//! bands). The printed numbers are checked against runs.csv of a sweep of the same
//! scenario.

use settle::input::runs_table::RunsTable;

use crate::support::{run_ok, settle};

#[test]
fn a_scan_run_prints_its_reentry_and_marks_the_lines_in_its_figure() {
    let dir = tempfile::tempdir().expect("tempdir");
    run_ok(
        settle()
            .args([
                "sweep",
                "scenarios/ci_scan.toml",
                "--backend",
                "modal",
                "--out",
            ])
            .arg(dir.path().join("sweep")),
    );
    let csv = std::fs::read_to_string(dir.path().join("sweep/runs.csv")).expect("runs.csv");
    let runs = RunsTable::parse(&csv).expect("runs.csv");
    let trace = dir.path().join("run-1.csv");
    let out = run_ok(
        settle()
            .args([
                "run",
                "scenarios/ci_scan.toml",
                "--case",
                "1",
                "--backend",
                "modal",
            ])
            .args(["--plot", "--out"])
            .arg(&trace),
    );
    let text = String::from_utf8_lossy(&out.stdout);
    let reentry = runs
        .num(1, "scan_reentry_error_um")
        .expect("re-entry error");
    assert!(
        text.contains(&format!(
            "scan: |error| of the step axis when the next line starts (re-entry) {reentry:.4} um"
        )),
        "{text}"
    );
    let window_ms = (runs.num(1, "scan_window_s").expect("window")
        - runs.num(1, "scan_step_s").expect("step"))
        * 1e3;
    for band in [1.0, 10.0] {
        let t = runs
            .num(1, &format!("scan_step_settle_time_s_{band}um"))
            .expect("settle time");
        let when = if t.is_finite() {
            format!("{:.1} ms", t * 1e3)
        } else {
            "never (not before the next exit)".to_string()
        };
        assert!(
            text.contains(&format!(
                "scan: inside {band} um for good {when} after the step's end, re-entry {window_ms:.1} ms after it"
            )),
            "{text}"
        );
    }
    let svg = std::fs::read_to_string(dir.path().join("run-1.svg")).expect("figure");
    for label in [
        "line 1 exit (laser off)",
        "line 2 re-entry (laser on)",
        "fly axis y (commanded, from the raster plan)",
        "re-entry (laser on)",
        "+10 um",
        "-1 um",
        &format!("|error| at re-entry {reentry:.2} um"),
    ] {
        assert!(svg.contains(label), "no `{label}` in the figure");
    }
    assert!(
        !svg.contains("after the move (residual vibration)"),
        "the run-out zoom is replaced by the re-entry zoom"
    );
}
