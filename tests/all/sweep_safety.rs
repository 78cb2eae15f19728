//! A sweep's output folder stays consistent whatever happens around it: a second sweep on
//! the same folder is refused while the first runs; a damaged journal is not trusted; an
//! edited input file is noticed; the resume hint resumes; temporary files do not survive.

use std::path::Path;
use std::process::{Child, Stdio};
use std::time::{Duration, Instant};

use crate::support::{settle, write};

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
    let scenario = write(dir.path(), "long.toml", crate::limits::LONG_RUN);
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

/// The quickstart's 16 runs, small: fast on the modal backend.
fn small_quickstart(dir: &Path) -> std::path::PathBuf {
    let text = std::fs::read_to_string(crate::support::root().join("scenarios/quickstart.toml"))
        .expect("quickstart")
        .replace("window_s = 0.5", "window_s = 0.2")
        .replace("sample_rate_hz = 10000", "sample_rate_hz = 2000");
    write(dir, "q.toml", &text)
}

fn sweep(scenario: &Path, out: &Path, extra: &[&str]) -> std::process::Output {
    settle()
        .arg("sweep")
        .arg(scenario)
        .args(["--backend", "modal", "--out"])
        .arg(out)
        .args(extra)
        .args(if extra.contains(&"--jobs") {
            &[][..]
        } else {
            &["--jobs", "2"][..]
        })
        .output()
        .expect("runs")
}

/// A journal line as the sweep writes it: the row's checksum, a space, the row.
pub fn journal_line(row: &str) -> String {
    format!(
        "{:016x} {row}",
        settle::input::file::digest(&[row.as_bytes()])
    )
}

/// The journal a sweep of `scenario` on modal would write, holding `rows` (with newlines).
pub fn journal_of(scenario: &Path, header: &str, rows: &[String]) -> String {
    let (sc, src) = settle::expand::load(scenario).expect("loads");
    let inputs = settle::expand::machine::inputs_identity(&sc, &src).expect("inputs");
    let key = settle::workflows::journal::key_line(src.text(), &inputs, &sc.name, "modal", "");
    format!("{key}\n{header}{}", rows.concat())
}

#[test]
fn a_damaged_journal_is_not_trusted_and_resume_ends_identical() {
    let dir = tempfile::tempdir().expect("tempdir");
    let scenario = small_quickstart(dir.path());
    let (full, cut) = (dir.path().join("full"), dir.path().join("cut"));
    assert!(sweep(&scenario, &full, &[]).status.success());
    let csv = std::fs::read_to_string(full.join("runs.csv")).expect("runs.csv");
    let mut lines: Vec<String> = csv.split_inclusive('\n').map(str::to_string).collect();
    let header = lines.remove(0);
    let mut journal: Vec<String> = lines[..10].iter().map(|r| journal_line(r)).collect();
    // Run 1: a metric edited (the checksum no longer matches).
    journal[1] = journal[1].replacen(",ok,0,,", ",ok,0,,9", 1);
    // Run 2: a NaN metric with a checksum that matches.
    let cells: Vec<&str> = lines[2].trim_end().split(',').collect();
    let status = header
        .split(',')
        .position(|h| h == "status")
        .expect("status");
    let mut nan = cells.clone();
    nan[status + 4] = "NaN";
    journal[2] = journal_line(&format!("{}\n", nan.join(",")));
    // Run 3: its distance changed, checksum recomputed (not this sweep's parameters).
    let mut moved = cells.clone();
    moved[0] = "3";
    moved[3] = "123";
    journal[3] = journal_line(&format!("{}\n", moved.join(",")));
    // Run 4: a second row that says otherwise; then a half-written line in the middle.
    journal.push(journal_line(&lines[4].replacen(",ok,", ",fault,", 1)));
    journal.insert(6, "0123456789abcdef 6,scurve,0.".to_string() + "\n");
    std::fs::create_dir_all(&cut).expect("mkdir");
    std::fs::write(
        cut.join("journal.csv"),
        journal_of(&scenario, &header, &journal),
    )
    .expect("journal");
    let out = sweep(&scenario, &cut, &["--resume"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    for run in [1, 2, 3, 4] {
        assert!(
            stderr.contains(&format!("run {run} runs again")),
            "{run}: {stderr}"
        );
    }
    assert!(
        stderr.contains("line 9: its checksum does not match"),
        "{stderr}"
    );
    assert_eq!(
        std::fs::read_to_string(cut.join("runs.csv")).expect("runs.csv"),
        csv,
        "the same runs.csv as an uninterrupted sweep"
    );
}

#[test]
fn an_edited_machine_file_is_noticed_by_resume_and_merge() {
    let dir = tempfile::tempdir().expect("tempdir");
    let machine =
        std::fs::read_to_string(crate::support::root().join("scenarios/machines/printer_xy.toml"))
            .expect("machine");
    let m = write(dir.path(), "m.toml", &machine);
    let text = std::fs::read_to_string(crate::support::root().join("scenarios/printer_xy.toml"))
        .expect("scenario")
        .replace("preset = \"printer_xy\"", "preset = \"m.toml\"")
        .replace("driver_model = \"full\"", "driver_model = \"linear\"")
        .replace("window_s = 0.5", "window_s = 0.1");
    let scenario = write(dir.path(), "s.toml", &text);
    let out = dir.path().join("out");
    std::fs::create_dir_all(&out).expect("mkdir");
    std::fs::write(out.join("journal.csv"), journal_of(&scenario, "run\n", &[])).expect("journal");
    let (s1, s2) = (dir.path().join("s1"), dir.path().join("s2"));
    assert!(sweep(&scenario, &s1, &["--shard", "1/2"]).status.success());
    // The same edit between the interruption and the resume, and between two shards.
    std::fs::write(
        &m,
        machine.replacen("toolhead_kg = 0.6", "toolhead_kg = 0.7", 1),
    )
    .expect("edit");
    let resumed = sweep(&scenario, &out, &["--resume"]);
    let stderr = String::from_utf8_lossy(&resumed.stderr);
    assert_eq!(resumed.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("written by another sweep"), "{stderr}");
    assert!(stderr.contains("a file it reads"), "{stderr}");
    assert!(sweep(&scenario, &s2, &["--shard", "2/2"]).status.success());
    let merged = settle()
        .arg("merge")
        .arg(&s1)
        .arg(&s2)
        .arg("--out")
        .arg(dir.path().join("merged"))
        .output()
        .expect("runs");
    let stderr = String::from_utf8_lossy(&merged.stderr);
    assert_eq!(merged.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("the content of the files the scenario reads"),
        "{stderr}"
    );
}

#[test]
fn an_edited_shard_or_a_missing_recording_is_not_merged() {
    let dir = tempfile::tempdir().expect("tempdir");
    let scenario = small_quickstart(dir.path());
    let (s1, s2) = (dir.path().join("s1"), dir.path().join("s2"));
    assert!(
        sweep(&scenario, &s1, &["--shard", "1/2", "--mcap"])
            .status
            .success()
    );
    assert!(sweep(&scenario, &s2, &["--shard", "2/2"]).status.success());
    let merge = || {
        settle()
            .arg("merge")
            .arg(&s1)
            .arg(&s2)
            .arg("--out")
            .arg(dir.path().join("merged"))
            .output()
            .expect("runs")
    };
    assert!(merge().status.success());
    std::fs::remove_file(s1.join("recordings/run-2.mcap")).expect("remove");
    let out = merge();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("run-2.mcap: a recording shard.toml lists is missing"),
        "{stderr}"
    );
    let csv = std::fs::read_to_string(s2.join("runs.csv")).expect("runs.csv");
    std::fs::write(s2.join("runs.csv"), csv.replacen(",ok,", ",fault,", 1)).expect("edit");
    let out = settle()
        .arg("merge")
        .arg(&s2)
        .arg(&s1)
        .arg("--out")
        .arg(dir.path().join("merged"))
        .output()
        .expect("runs");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("edited or damaged since"), "{stderr}");
}

#[test]
fn the_resume_hint_resumes_and_stale_temporary_files_are_removed() {
    let dir = tempfile::tempdir().expect("tempdir");
    let scenario = small_quickstart(dir.path());
    let out = dir.path().join("out");
    let outcome = settle::workflows::sweep::SweepOutcome {
        scenario: scenario.clone(),
        out: out.clone(),
        runs: 16,
        shard: None,
        failed: Vec::new(),
        interrupted: Some(3),
        recordings: None,
        elapsed_s: 0.0,
        options: settle::workflows::sweep::SweepOptions {
            jobs: Some(2),
            out: Some(out.clone()),
            ..settle::workflows::sweep::SweepOptions::new(
                &scenario,
                settle::spec::backend::Backend::Modal,
            )
        },
    };
    let hint = outcome.report().stderr;
    let command = hint.lines().nth(1).expect("the command").trim();
    assert!(command.contains("--backend modal"), "{command}");
    // A journal of this sweep on modal, and a temporary figure a kill left behind.
    std::fs::create_dir_all(out.join("plots")).expect("mkdir");
    let full = dir.path().join("full");
    assert!(sweep(&scenario, &full, &[]).status.success());
    let csv = std::fs::read_to_string(full.join("runs.csv")).expect("runs.csv");
    let mut lines: Vec<String> = csv.split_inclusive('\n').map(str::to_string).collect();
    let header = lines.remove(0);
    let rows: Vec<String> = lines[..3].iter().map(|r| journal_line(r)).collect();
    std::fs::write(
        out.join("journal.csv"),
        journal_of(&scenario, &header, &rows),
    )
    .expect("journal");
    std::fs::write(out.join("plots/.vs_distance.tmp4242.png"), b"half").expect("tmp");
    let words: Vec<&str> = command.split(' ').collect();
    assert_eq!(words[..2], ["settle", "sweep"], "{command}");
    let resumed = settle().args(&words[1..]).output().expect("runs");
    let stderr = String::from_utf8_lossy(&resumed.stderr);
    assert!(resumed.status.success(), "{command}: {stderr}");
    assert!(stderr.contains("resuming: 3 of 16"), "{stderr}");
    assert_eq!(
        std::fs::read_to_string(out.join("runs.csv")).expect("runs.csv"),
        csv
    );
    let left: Vec<String> = std::fs::read_dir(out.join("plots"))
        .expect("plots")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with('.'))
        .collect();
    assert!(left.is_empty(), "{left:?}");
}

#[test]
fn an_output_that_cannot_be_written_stops_the_sweep_and_resume_completes_it() {
    let dir = tempfile::tempdir().expect("tempdir");
    let scenario = small_quickstart(dir.path());
    let (full, out) = (dir.path().join("full"), dir.path().join("out"));
    assert!(sweep(&scenario, &full, &["--mcap"]).status.success());
    // A folder where run 5's recording goes: its write fails with a real OS error (as a
    // full disk does, "no space left on device"), whoever runs the test.
    std::fs::create_dir_all(out.join("recordings/run-5.mcap/x")).expect("mkdir");
    let first = sweep(&scenario, &out, &["--mcap", "--jobs", "1"]);
    let stderr = String::from_utf8_lossy(&first.stderr);
    assert_eq!(first.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("cannot write"), "{stderr}");
    assert!(stderr.contains("run-5.mcap"), "{stderr}");
    assert!(out.join("journal.csv").exists(), "the journal is kept");
    assert!(!out.join("runs.csv").exists());
    let journal = std::fs::read_to_string(out.join("journal.csv")).expect("journal");
    assert!(
        !journal.contains("fault"),
        "no run became a fault: {journal}"
    );
    std::fs::remove_dir_all(out.join("recordings/run-5.mcap")).expect("free");
    let resumed = sweep(&scenario, &out, &["--mcap", "--resume"]);
    assert!(
        resumed.status.success(),
        "{}",
        String::from_utf8_lossy(&resumed.stderr)
    );
    assert_eq!(
        std::fs::read(out.join("runs.csv")).expect("runs.csv"),
        std::fs::read(full.join("runs.csv")).expect("runs.csv")
    );
    for id in 0..16 {
        assert!(
            out.join(format!("recordings/run-{id}.mcap")).is_file(),
            "{id}"
        );
    }
}

#[test]
fn device_files_and_folders_are_not_read_as_inputs() {
    let dir = tempfile::tempdir().expect("tempdir");
    for (preset, what) in [
        ("/dev/zero", "not a regular file"),
        ("/dev/urandom", "not a regular file"),
    ] {
        let text =
            std::fs::read_to_string(crate::support::root().join("scenarios/printer_xy.toml"))
                .expect("scenario")
                .replace("preset = \"printer_xy\"", &format!("preset = \"{preset}\""));
        let scenario = write(dir.path(), "s.toml", &text);
        let t0 = Instant::now();
        let out = sweep(&scenario, &dir.path().join("out"), &[]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{stderr}");
        assert!(stderr.contains(what), "{stderr}");
        assert!(t0.elapsed() < Duration::from_secs(20));
    }
    for path in ["/dev/zero", "/dev/urandom"] {
        let out = settle().args(["sweep", path]).output().expect("runs");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{stderr}");
        assert!(stderr.contains("not a regular file"), "{stderr}");
    }
}
