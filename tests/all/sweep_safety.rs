//! A sweep's output folder stays consistent whatever happens around it: a second sweep on
//! the same folder is refused while the first runs; a damaged journal is not trusted; an
//! edited input file is noticed; the resume hint resumes; temporary files do not survive.

use std::path::Path;
use std::process::{Child, Stdio};
use std::time::{Duration, Instant};

use crate::support::{settle, write};

/// One long rapier run (see `limits::LONG_RUN`'s twin): a sweep that is still running
/// when the test looks at it.
const LONG_RUN: &str = r#"name = "long"
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

/// Start a sweep of `scenario` into `out`; returns once its journal exists.
fn start_long(scenario: &Path, out: &Path) -> Child {
    let child = settle()
        .arg("sweep")
        .arg(scenario)
        .args(["--backend", "rapier", "--jobs", "1", "--out"])
        .arg(out)
        .stderr(Stdio::null())
        .spawn()
        .expect("starts");
    let t0 = Instant::now();
    while !out.join("journal.csv").exists() {
        assert!(t0.elapsed() < Duration::from_secs(60), "never started");
        std::thread::sleep(Duration::from_millis(20));
    }
    child
}

#[test]
fn a_second_sweep_on_a_busy_folder_is_refused_and_names_the_holder() {
    let dir = tempfile::tempdir().expect("tempdir");
    let scenario = write(dir.path(), "long.toml", LONG_RUN);
    let out = dir.path().join("out");
    let mut first = start_long(&scenario, &out);
    let journal = std::fs::read(out.join("journal.csv")).expect("journal");
    for resume in [true, false] {
        let mut cmd = settle();
        cmd.arg("sweep")
            .arg(&scenario)
            .args(["--backend", "rapier", "--out"])
            .arg(&out);
        if resume {
            cmd.arg("--resume");
        }
        let second = cmd.output().expect("runs");
        let stderr = String::from_utf8_lossy(&second.stderr);
        assert_eq!(second.status.code(), Some(2), "{stderr}");
        assert!(stderr.contains("another sweep is writing"), "{stderr}");
        assert!(stderr.contains(&format!("pid {}", first.id())), "{stderr}");
        assert!(stderr.contains("command "), "{stderr}");
    }
    first.kill().expect("kill");
    first.wait().expect("ends");
    assert_eq!(
        std::fs::read(out.join("journal.csv")).expect("journal"),
        journal,
        "the second sweep did not touch the journal"
    );
}
