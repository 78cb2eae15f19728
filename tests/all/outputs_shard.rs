//! Sharded sweeps: shards merged in any order equal the unsharded sweep byte for byte
//! (runs.csv, summary.md, report.html, every plot, every recording); bad merges are clear errors.

use std::path::{Path, PathBuf};
use std::process::Output;

fn settle(args: &[&str]) -> Output {
    crate::support::settle()
        .args(args)
        .output()
        .expect("settle runs")
}

fn ok(args: &[&str]) {
    let o = settle(args);
    assert!(
        o.status.success(),
        "settle {args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
}

fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8")
}

/// Every file under `dir`, relative, sorted.
fn files(dir: &Path) -> Vec<PathBuf> {
    crate::support::files_under(dir)
}

#[test]
fn merged_shards_equal_the_unsharded_sweep_byte_for_byte() {
    let dir = tempfile::tempdir().expect("tempdir");
    let whole = dir.path().join("whole");
    ok(&[
        "sweep",
        "scenarios/quickstart.toml",
        "--mcap",
        "--out",
        s(&whole),
    ]);
    let n = 3;
    let mut shard_dirs = Vec::new();
    for k in 1..=n {
        let d = dir.path().join(format!("shard{k}"));
        ok(&[
            "sweep",
            "scenarios/quickstart.toml",
            "--mcap",
            "--jobs",
            "1",
            "--shard",
            &format!("{k}/{n}"),
            "--out",
            s(&d),
        ]);
        let csv = std::fs::read_to_string(d.join("runs.csv")).expect("shard runs.csv");
        let ids: Vec<usize> = csv
            .lines()
            .skip(1)
            .map(|l| l.split(',').next().expect("run").parse().expect("id"))
            .collect();
        let expect: Vec<usize> = (0..16).filter(|i| i % n == k - 1).collect();
        assert_eq!(ids, expect, "shard {k}/{n} runs");
        assert!(d.join("shard.toml").exists());
        assert!(
            !d.join("summary.md").exists(),
            "a shard writes no partial summary"
        );
        shard_dirs.push(d);
    }
    let merged = dir.path().join("merged");
    // Any order.
    ok(&[
        "merge",
        s(&shard_dirs[2]),
        s(&shard_dirs[0]),
        s(&shard_dirs[1]),
        "--out",
        s(&merged),
    ]);
    let want = files(&whole);
    assert!(want.iter().any(|p| p.ends_with("runs.csv")));
    assert!(want.iter().any(|p| p.ends_with("summary.md")));
    assert!(want.iter().any(|p| p.ends_with("report.html")));
    assert!(
        want.iter()
            .any(|p| p.extension().is_some_and(|e| e == "png"))
    );
    assert_eq!(
        want.iter()
            .filter(|p| p.extension().is_some_and(|e| e == "mcap"))
            .count(),
        16
    );
    assert_eq!(files(&merged), want, "same files");
    for f in &want {
        let a = std::fs::read(whole.join(f)).expect("read");
        let b = std::fs::read(merged.join(f)).expect("read");
        assert!(
            a == b,
            "{} differs between merged and unsharded",
            f.display()
        );
    }
}

fn merge_err(dirs: &[&Path], expect: &str) {
    let mut args = vec!["merge"];
    args.extend(dirs.iter().map(|d| s(d)));
    let out = tempfile::tempdir().expect("tempdir");
    args.extend(["--out", s(out.path())]);
    let o = settle(&args);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains(expect), "expected `{expect}` in: {err}");
    assert!(!out.path().join("runs.csv").exists(), "nothing written");
}

#[test]
fn bad_merges_are_clear_errors() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mk = |name: &str, scenario: &str, shard: &str| {
        let d = dir.path().join(name);
        ok(&["sweep", scenario, "--shard", shard, "--out", s(&d)]);
        d
    };
    let a1 = mk("a1", "scenarios/ci_quickstart.toml", "1/3");
    let a2 = mk("a2", "scenarios/ci_quickstart.toml", "2/3");
    let a3 = mk("a3", "scenarios/ci_quickstart.toml", "3/3");
    let q2 = mk("q2", "scenarios/quickstart.toml", "2/3");
    merge_err(&[&a1, &a3], "missing shard(s) 2/3");
    merge_err(
        &[&a1, &a3],
        "run it with `settle sweep scenarios/ci_quickstart.toml --shard 2/3`",
    );
    merge_err(&[&a2], "missing shard(s) 1/3, 3/3");
    merge_err(&[&a1, &a2, &a2, &a3], "given twice");
    merge_err(&[&a1, &q2, &a3], "not from the same sweep");
    merge_err(&[&a1, dir.path()], "not a shard folder");
    // A shard stopped before it finished (a time limit): a journal, no manifest.
    let stopped = dir.path().join("stopped");
    std::fs::create_dir(&stopped).expect("mkdir");
    std::fs::write(
        stopped.join("journal.csv"),
        "settle-journal; key 0; ci_quickstart; backend rapier; shard 2/3; settle 0.1.0\n",
    )
    .expect("write");
    merge_err(&[&a1, &stopped, &a3], "an unfinished shard");
    merge_err(&[&a1, &stopped, &a3], "its journal is of shard 2/3");
    merge_err(
        &[&a1, &stopped, &a3],
        &format!(
            "settle sweep SCENARIO --shard 2/3 --out {} --resume",
            stopped.display()
        ),
    );
    // A shard whose rows were tampered with.
    let csv = std::fs::read_to_string(a2.join("runs.csv")).expect("csv");
    let cut: String = csv.lines().take(2).map(|l| format!("{l}\n")).collect();
    std::fs::write(a2.join("runs.csv"), cut).expect("write");
    merge_err(&[&a1, &a2, &a3], "edited or damaged since");
    // Bad --shard values.
    for bad in ["0/3", "4/3", "x"] {
        let o = settle(&["sweep", "scenarios/ci_quickstart.toml", "--shard", bad]);
        assert_eq!(o.status.code(), Some(2), "{bad}");
        assert!(String::from_utf8_lossy(&o.stderr).contains("K/N"), "{bad}");
    }
    let o = settle(&["sweep", "scenarios/ci_quickstart.toml", "--shard", "1/7"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("at most 6 shards"));
}

/// Shards whose runs lose steps merge like any other (failed runs are results): the merge
/// lists them and exits 0, or 1 with `--fail-on-failed-runs`, and writes the unsharded
/// sweep's files either way.
#[test]
fn shards_with_failed_runs_merge_and_list_them() {
    let dir = tempfile::tempdir().expect("tempdir");
    // 16 runs of a lead-screw stage, 3 of which lose steps (runs 7, 11 and 15).
    let scenario = crate::support::root().join("tests/shards/big_lost_steps.toml");
    let whole = dir.path().join("whole");
    ok(&["sweep", s(&scenario), "--out", s(&whole)]);
    let csv = std::fs::read_to_string(whole.join("runs.csv")).expect("csv");
    assert_eq!(
        csv.lines()
            .skip(1)
            .filter(|l| l.contains(",lost_steps,"))
            .count(),
        3,
        "the scenario loses steps in 3 runs: {csv}"
    );
    let shards: Vec<PathBuf> = (1..=2)
        .map(|k| {
            let d = dir.path().join(format!("shard{k}"));
            ok(&[
                "sweep",
                s(&scenario),
                "--shard",
                &format!("{k}/2"),
                "--out",
                s(&d),
            ]);
            d
        })
        .collect();
    let merged = dir.path().join("merged");
    let o = settle(&["merge", s(&shards[0]), s(&shards[1]), "--out", s(&merged)]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{err}");
    assert!(
        err.contains("runs failed") && err.contains("lost_steps: lost "),
        "{err}"
    );
    for f in files(&whole) {
        assert!(
            std::fs::read(whole.join(&f)).expect("read")
                == std::fs::read(merged.join(&f)).expect("read"),
            "{} differs",
            f.display()
        );
    }
    let strict = dir.path().join("strict");
    let o = settle(&[
        "merge",
        s(&shards[0]),
        s(&shards[1]),
        "--fail-on-failed-runs",
        "--out",
        s(&strict),
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(strict.join("summary.md").exists(), "written all the same");
}
