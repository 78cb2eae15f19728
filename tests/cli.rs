//! End to end through the `settle` binary.

use std::path::Path;
use std::process::Command;

fn settle() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_settle"));
    c.current_dir(env!("CARGO_MANIFEST_DIR"));
    c
}

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
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/quickstart.toml"),
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
