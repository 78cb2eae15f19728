//! A swept value a run does not use leaves it the same run: a jerk limit for a trapezoid,
//! a frequency for no shaper, a corner strategy's parameter under another strategy. The
//! summary ranks such runs once, shows the unused value as `-` and says which runs repeat
//! which (runs.csv keeps every run, the same numbers). `[current]` takes settings only: a
//! workload value (the move length) is refused with the reason. Swept through the binary
//! on the modal backend; every number asserted is read from the same sweep's runs.csv.

use std::path::Path;

use settle::input::runs_table::RunsTable;

use crate::support::{root, run_ok, settle, write};

/// Sweep `scenario` on the modal backend into `dir/out`; `(runs.csv, summary.md)`.
fn sweep(scenario: &Path, dir: &Path) -> (RunsTable, String) {
    let out = dir.join("out");
    run_ok(
        settle()
            .arg("sweep")
            .arg(scenario)
            .args(["--backend", "modal", "--jobs", "2", "--out"])
            .arg(&out),
    );
    let read = |f: &str| std::fs::read_to_string(out.join(f)).expect(f);
    (
        RunsTable::parse(&read("runs.csv")).expect("runs.csv"),
        read("summary.md"),
    )
}

/// The data rows of the first Markdown table after `heading`, cells trimmed.
fn rows(md: &str, heading: &str) -> Vec<Vec<String>> {
    md[md.find(heading).unwrap_or_else(|| panic!("{heading}"))..]
        .lines()
        .skip_while(|l| !l.starts_with('|'))
        .take_while(|l| l.starts_with('|'))
        .skip(2)
        .map(|l| {
            l.trim_matches('|')
                .split('|')
                .map(|c| c.trim().to_string())
                .collect()
        })
        .collect()
}

const TRAPEZOID_JERK: &str = r#"name = "trapezoid_jerk"
[machine]
modes = [{ frequency_hz = 40.0, damping_ratio = 0.05 }]
[move]
distance_mm = 10.0
[limits]
vmax_mm_s = 200.0
amax_mm_s2 = 3000.0
jmax_mm_s3 = 200000.0
[observe]
bands_um = [10.0]
[sweep]
profile = ["trapezoid", "scurve"]
"limits.jmax_mm_s3" = [1e5, 1e6]
[current]
profile = "trapezoid"
"limits.jmax_mm_s3" = 1e6
"#;

#[test]
fn a_trapezoid_swept_over_jerk_is_ranked_once_and_can_be_current() {
    let dir = tempfile::tempdir().expect("tempdir");
    let sc = write(dir.path(), "tj.toml", TRAPEZOID_JERK);
    let (runs, summary) = sweep(&sc, dir.path());
    // Runs 0 and 1 are the trapezoid at 1e5 and 1e6 mm/s^3: one move, every number equal.
    assert_eq!(runs.rows.len(), 4);
    let (a, b) = (&runs.rows[0], &runs.rows[1]);
    let jmax = runs.column("jmax_mm_s3").expect("jmax");
    for (c, name) in runs.header.iter().enumerate() {
        if !matches!(name.as_str(), "run" | "jmax_mm_s3") {
            assert_eq!(a[c], b[c], "{name}");
        }
    }
    assert_ne!(a[jmax], b[jmax]);
    assert!(
        summary.contains(
            "Ranked once: 1 run(s) repeat another run of their point in every setting that changes them (`limits.jmax_mm_s3`: a trapezoid has no jerk limit)"
        ) && summary.contains("(run 1 repeats run 0)"),
        "{summary}"
    );
    let t = rows(&summary, "## Ranking: move and settle to within 10 um");
    assert_eq!(
        t.len(),
        3,
        "trapezoid once, the S-curve at both jerks: {t:?}"
    );
    let trap: Vec<&Vec<String>> = t.iter().filter(|r| r[1] == "trapezoid").collect();
    assert_eq!(trap.len(), 1);
    // [current] names the trapezoid at 1e6, which is run 0's move: it is the reference.
    assert!(trap[0][0].ends_with("(current)"), "{:?}", trap[0]);
    assert_eq!(trap[0][2], "-", "its jerk is shown as unused");
    assert_eq!(trap[0][7], "+0.0 %");
    let total = |i: usize| runs.num(i, "move_and_settle_s_10um").expect("total");
    for r in t.iter().filter(|r| r[1] == "scurve") {
        let i: usize = r[8].parse().expect("run");
        let g = 100.0 * (total(0) / total(i) - 1.0);
        let shown = if g.abs() < 10.0 {
            format!("{g:+.1} %")
        } else {
            format!("{g:+.0} %")
        };
        assert_eq!(r[7], shown, "{r:?}");
    }
    assert!(
        summary.contains(&format!("vs current (trapezoid, {:.1} ms)", total(0) * 1e3)),
        "{summary}"
    );
    assert!(!summary.contains("trapezoid, jmax_mm_s3="), "{summary}");
}

#[test]
fn the_imported_sweep_shows_no_frequency_for_no_shaper() {
    // The Voron's configuration on the stand-in printer: shaper type (with `none`) x five
    // frequencies x three accelerations.
    let dir = tempfile::tempdir().expect("tempdir");
    let sc = dir.path().join("voron.toml");
    run_ok(
        settle()
            .args(["import", "klipper"])
            .arg(root().join("gcode/tests/data/klipper/voron/printer.cfg"))
            .arg("--out")
            .arg(&sc),
    );
    let (runs, summary) = sweep(&sc, dir.path());
    assert_eq!(runs.rows.len(), 7 * 5 * 3);
    assert!(!summary.contains("none, frequency_hz="), "{summary}");
    // `none` at each acceleration once: the four other frequencies repeat it.
    assert!(
        summary.contains("Ranked once: 12 run(s) repeat another run"),
        "{summary}"
    );
    let t = rows(&summary, "## Ranking: move and settle to within 10 um");
    assert_eq!(t.len(), 105 - 12);
    let none: Vec<&Vec<String>> = t.iter().filter(|r| r[1] == "none").collect();
    assert_eq!(none.len(), 3, "one per acceleration");
    let mut accels: Vec<&str> = none.iter().map(|r| r[3].as_str()).collect();
    accels.sort_unstable();
    assert_eq!(accels, ["2000", "3000", "4000"]);
    assert!(none.iter().all(|r| r[2] == "-"), "{none:?}");
}

#[test]
fn a_corner_strategys_parameter_counts_only_under_that_strategy() {
    let dir = tempfile::tempdir().expect("tempdir");
    let text = std::fs::read_to_string(root().join("scenarios/corner_shapers.toml"))
        .expect("scenario")
        .replace(
            "\"shaper.type\" = [\"none\", \"mzv\"]",
            "\"corner.blend_deviation_mm\" = [0.02, 0.05]",
        );
    let sc = write(dir.path(), "corner.toml", &text);
    let (runs, summary) = sweep(&sc, dir.path());
    assert_eq!(runs.rows.len(), 4);
    assert!(
        summary.contains(
            "(`corner.blend_deviation_mm`: only the blend strategy uses it). Those settings show as `-`; runs.csv keeps every run (run 1 repeats run 0)."
        ),
        "{summary}"
    );
    let t = rows(&summary, "## Ranking: move and settle to within 10 um");
    let stops: Vec<&Vec<String>> = t.iter().filter(|r| r[1] == "exact_stop").collect();
    assert_eq!(stops.len(), 1);
    assert_eq!(stops[0][2], "-");
    assert_eq!(t.iter().filter(|r| r[1] == "blend").count(), 2);
}

#[test]
fn current_refuses_a_workload_value_with_the_reason() {
    let dir = tempfile::tempdir().expect("tempdir");
    let text = TRAPEZOID_JERK
        .replace("[sweep]\n", "[sweep]\n\"move.distance_mm\" = [2.0, 10.0]\n")
        .replace("[current]\n", "[current]\n\"move.distance_mm\" = 10.0\n");
    let sc = write(dir.path(), "workload.toml", &text);
    let out = settle()
        .args(["sweep", "--backend", "modal", "--out"])
        .arg(dir.path().join("out"))
        .arg(&sc)
        .output()
        .expect("runs");
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    let line = text
        .lines()
        .position(|l| l == "\"move.distance_mm\" = 10.0")
        .expect("line")
        + 1;
    assert!(
        err.contains(&format!("{}:{line}", sc.display()))
            && err.contains("key `current.move.distance_mm`")
            && err.contains("is part of the workload the settings are compared on")
            && err.contains("[current] takes the swept settings: `profile`, `limits.jmax_mm_s3`"),
        "{err}"
    );
    assert!(!dir.path().join("out").exists(), "nothing written");
}
