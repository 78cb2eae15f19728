//! Every workflow in-process (the library functions `settle` calls): sweep, run, check,
//! merge, validate, tune and plan, with their typed results and what they print. The CLI
//! tests (`cli`, `faults`, `outputs_*`, `plan_cli`) prove the binary's wiring.

use std::path::Path;

use settle::execute::pool::quiet;
use settle::spec::backend::Backend;
use settle::workflows::check::{CheckOptions, CheckOutcome, check};
use settle::workflows::run::{RunOptions, run};
use settle::workflows::shard::Shard;
use settle::workflows::sweep::{SweepOptions, sweep};
use settle::workflows::{Exit, merge, plan, tune, validate};

use crate::support::{root, write};

fn quickstart() -> std::path::PathBuf {
    root().join("scenarios/ci_quickstart.toml")
}

#[test]
fn sweep_writes_the_outputs_and_reports_them() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("qs");
    let notes = std::sync::Mutex::new(Vec::new());
    let done = std::sync::atomic::AtomicUsize::new(0);
    let opts = SweepOptions {
        out: Some(out.clone()),
        jobs: Some(2),
        ..SweepOptions::new(quickstart(), Backend::Modal)
    };
    let o = sweep(
        &opts,
        &|l| notes.lock().expect("lock").push(l.to_string()),
        &|d, total| {
            assert_eq!(total, 6);
            done.fetch_max(d, std::sync::atomic::Ordering::Relaxed);
        },
    )
    .expect("sweeps");
    assert_eq!(done.into_inner(), 6, "progress reported every run");
    assert_eq!((o.runs, o.failed.len(), o.interrupted), (6, 0, None));
    let notes = notes.into_inner().expect("lock");
    assert!(notes[0].ends_with(&format!("6 runs on modal -> {}", out.display())));
    let r = o.report();
    assert_eq!(r.exit, Exit::Ok);
    assert!(
        r.stderr
            .starts_with(&format!("wrote {}", out.join("runs.csv").display()))
    );
    for f in ["runs.csv", "summary.md"] {
        assert!(out.join(f).is_file(), "{f}");
    }
    assert!(!out.join("journal.csv").exists(), "journal removed");
}

#[test]
fn a_sweep_with_lost_steps_reports_the_failed_run() {
    let dir = tempfile::tempdir().expect("tempdir");
    let scenario = write(
        dir.path(),
        "stage.toml",
        "name = \"stage\"\n[machine]\npreset = \"leadscrew_stage\"\n[move]\ndistance_mm = 20.0\n\
[limits]\nvmax_mm_s = 300.0\namax_mm_s2 = 2000.0\njmax_mm_s3 = 200000.0\n[observe]\nwindow_s = 0.1\n\
[sweep]\n\"limits.amax_mm_s2\" = [2000, 20000]\n",
    );
    let opts = SweepOptions {
        out: Some(dir.path().join("out")),
        ..SweepOptions::new(&scenario, Backend::Rapier)
    };
    let o = sweep(&opts, &|_| {}, &quiet).expect("sweeps");
    assert_eq!(o.failed.len(), 1);
    assert_eq!(
        (o.failed[0].id, o.failed[0].status.as_str()),
        (1, "lost_steps")
    );
    let r = o.report();
    assert_eq!(r.exit, Exit::RunsFailed);
    assert!(r.stderr.contains("1 of 2 runs failed"), "{}", r.stderr);
}

#[test]
fn run_writes_the_trace_and_prints_the_metrics() {
    let dir = tempfile::tempdir().expect("tempdir");
    let trace = dir.path().join("t/run-1.csv");
    let opts = RunOptions {
        out: Some(trace.clone()),
        ..RunOptions::new(quickstart(), 1, Backend::Modal)
    };
    let o = run(&opts).expect("runs");
    let csv = std::fs::read_to_string(&trace).expect("trace");
    assert_eq!(
        csv.lines().count(),
        o.samples + 1,
        "header + one line per sample"
    );
    assert_eq!(o.written, std::slice::from_ref(&trace));
    let r = o.report();
    assert!(r.stdout.starts_with("run 1: "), "{}", r.stdout);
    assert!(r.stdout.contains(&format!(
        "  move_time_s            {:.6}",
        o.metrics.move_time_s
    )));
    let e = run(&RunOptions::new(quickstart(), 99, Backend::Modal)).expect_err("no case 99");
    assert!(
        e.is_input_error() && e.to_string().contains("runs 0..=5"),
        "{e}"
    );
}

#[test]
fn check_creates_passes_and_catches_a_changed_baseline() {
    let dir = tempfile::tempdir().expect("tempdir");
    let baseline = dir.path().join("b/base.csv");
    let opts = CheckOptions {
        backend: Some(Backend::Modal),
        update: true,
        ..CheckOptions::new(quickstart(), &baseline)
    };
    let created = check(&opts, &quiet).expect("creates");
    assert!(matches!(
        created.outcome,
        CheckOutcome::Updated {
            runs: 6,
            comparison: None
        }
    ));
    assert!(created.report().stdout.starts_with("created "));
    let same = check(
        &CheckOptions {
            backend: None,
            ..CheckOptions::new(quickstart(), &baseline)
        },
        &quiet,
    )
    .expect("checks");
    assert!(same.passed(), "{:?}", same.outcome);
    assert!(same.report().stdout.contains(": ok: "));
    // One residual 10 % larger in the baseline: the run now is 9 % better, a failure.
    let text = std::fs::read_to_string(&baseline).expect("baseline");
    let header: Vec<&str> = text.lines().next().expect("header").split(',').collect();
    let col = header
        .iter()
        .position(|h| *h == "residual_peak_um")
        .expect("column");
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let mut cells: Vec<String> = lines[1].split(',').map(str::to_string).collect();
    let x: f64 = cells[col].parse().expect("number");
    cells[col] = (x * 1.1).to_string();
    lines[1] = cells.join(",");
    std::fs::write(&baseline, lines.join("\n") + "\n").expect("writes");
    let changed = check(&CheckOptions::new(quickstart(), &baseline), &quiet).expect("checks");
    let CheckOutcome::Compared(c) = &changed.outcome else {
        panic!("{:?}", changed.outcome)
    };
    assert_eq!(c.changes.len(), 1);
    assert_eq!(c.changes[0].column, "residual_peak_um");
    assert!(!changed.passed());
    let r = changed.report();
    assert_eq!(r.exit, Exit::Failed);
    assert!(r.stderr.contains("FAILED: 1 of"), "{}", r.stderr);
}

#[test]
fn merged_shards_equal_the_unsharded_sweep() {
    let dir = tempfile::tempdir().expect("tempdir");
    let full = dir.path().join("full");
    let opts = |out: &Path, shard| SweepOptions {
        out: Some(out.to_path_buf()),
        shard,
        ..SweepOptions::new(quickstart(), Backend::Modal)
    };
    sweep(&opts(&full, None), &|_| {}, &quiet).expect("sweeps");
    let mut dirs = Vec::new();
    for k in [2, 1] {
        let d = dir.path().join(format!("s{k}"));
        let o = sweep(&opts(&d, Some(Shard { k, n: 2 })), &|_| {}, &quiet).expect("shard");
        assert!(o.report().stderr.starts_with(&format!("wrote shard {k}/2")));
        dirs.push(d);
    }
    let merged = dir.path().join("merged");
    let m = merge::merge(&dirs, Some(merged.clone()), false).expect("merges");
    assert_eq!((m.shards, m.runs, m.recordings), (2, 6, 0));
    for f in ["runs.csv", "summary.md"] {
        let a = std::fs::read(full.join(f)).expect("full");
        let b = std::fs::read(merged.join(f)).expect("merged");
        assert!(a == b, "{f} differs");
    }
    let e = merge::merge(&dirs[..1], None, false).expect_err("a shard missing");
    assert!(
        e.is_input_error() && e.to_string().contains("missing shard(s) 1/2"),
        "{e}"
    );
}

#[test]
fn validate_writes_its_markdown_and_passes_on_modal() {
    let dir = tempfile::tempdir().expect("tempdir");
    let md = dir.path().join("validate.md");
    let v = validate::validate(Some(Backend::Modal), Some(&md)).expect("validates");
    assert!(v.validation.pass());
    assert_eq!(std::fs::read_to_string(&md).expect("written"), v.markdown);
    let r = v.report();
    assert_eq!((r.exit, r.stdout.as_str()), (Exit::Ok, v.markdown.as_str()));
    assert!(r.stderr.contains(" rows, 0 failed ("), "{}", r.stderr);
}

#[test]
fn tune_writes_its_outputs_and_prints_the_report() {
    let dir = tempfile::tempdir().expect("tempdir");
    let scenario = write(
        dir.path(),
        "t.toml",
        "name = \"t\"\n[machine]\nmodes = [{ frequency_hz = 40.0, damping_ratio = 0.05 }]\n\
[move]\ndistance_mm = 5.0\n[limits]\nvmax_mm_s = 300.0\namax_mm_s2 = 3000.0\njmax_mm_s3 = 100000.0\n\
[observe]\nwindow_s = 0.3\n[tune]\nkinds = [\"scurve\"]\nshapers = [\"none\", \"zv\"]\n\
frequency_scales = [1.0]\njerk_steps = 2\n",
    );
    let out = dir.path().join("out");
    let t = tune::tune_to(
        &scenario,
        Some(out.clone()),
        Backend::Modal,
        None,
        Some(2),
        &quiet,
    )
    .expect("tunes");
    // The default, then 2 jerks x (unshaped, ZV at 40 Hz).
    assert_eq!(t.outcome.scores.len(), 5);
    for f in [
        "tune.md",
        "candidates.csv",
        "klipper.cfg",
        "tmc4361a.txt",
        "pareto.svg",
    ] {
        assert!(out.join(f).is_file(), "{f}");
    }
    assert_eq!(
        std::fs::read_to_string(out.join("tune.md")).expect("md"),
        t.report().stdout
    );
    let csv = std::fs::read_to_string(out.join("candidates.csv")).expect("csv");
    assert_eq!(csv.lines().count(), 6, "{csv}");
}

#[test]
fn plan_answers_every_line_in_order() {
    let input = "{\"p0\":[0],\"pf\":[1],\"vmax\":[1],\"amax\":[2],\"jmax\":[10],\"sync\":\"time\"}\n\
not json\n\
{\"p0\":[0],\"pf\":[2],\"vmax\":[1],\"amax\":[2],\"jmax\":[10],\"sync\":\"time\"}\n";
    let mut out = Vec::new();
    plan::plan_stream(input.as_bytes(), &mut out, Some(2), plan::BATCH).expect("answers");
    let out = String::from_utf8(out).expect("utf-8");
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines.len(), 3);
    assert_eq!(lines[0], plan::answer(input.lines().next().expect("line")));
    assert!(lines[1].starts_with("{\"error\":"), "{}", lines[1]);
    assert!(lines[2].contains("\"duration\""), "{}", lines[2]);
}
