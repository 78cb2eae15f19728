//! The regression gate: an unchanged run passes, a worsened metric fails with the table,
//! `--update` rewrites the baseline, bad baselines are clear errors. The binary's exit codes
//! are checked end to end; the comparisons in-process (`settle::workflows::check`).

use std::path::Path;
use std::process::Output;

use settle::execute::pool::quiet;
use settle::input::runs_table::RunsTable;
use settle::workflows::check::{CheckOptions, check};
use settle::workflows::{Exit, Report};

const SCENARIO: &str = "scenarios/ci_quickstart.toml";
const BASELINE: &str = "results/baselines/ci_quickstart.rapier.csv";

fn settle(args: &[&str]) -> Output {
    crate::support::settle()
        .args(args)
        .output()
        .expect("settle runs")
}

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// `settle check SCENARIO --baseline baseline` in-process, with `edit` applied to the
/// options: its report (stdout then stderr as `text`), or the error.
fn check_with(
    scenario: &Path,
    baseline: &Path,
    edit: impl FnOnce(&mut CheckOptions),
) -> Result<(Report, String), settle::Error> {
    let mut opts = CheckOptions::new(scenario, baseline);
    edit(&mut opts);
    let r = check(&opts, &quiet)?.report();
    let text = format!("{}{}", r.stdout, r.stderr);
    Ok((r, text))
}

fn scenario() -> std::path::PathBuf {
    Path::new(crate::support::manifest_dir()).join(SCENARIO)
}

fn baseline() -> RunsTable {
    let p = Path::new(crate::support::manifest_dir()).join(BASELINE);
    RunsTable::parse(&std::fs::read_to_string(p).expect("committed baseline")).expect("parses")
}

#[test]
fn unchanged_runs_pass_on_every_backend_with_a_baseline() {
    let dir = Path::new(crate::support::manifest_dir()).join("results/baselines");
    let mut checked = Vec::new();
    for e in std::fs::read_dir(&dir).expect("results/baselines") {
        let name = e.expect("entry").file_name().to_string_lossy().into_owned();
        let Some(backend) = name
            .strip_prefix("ci_quickstart.")
            .and_then(|r| r.strip_suffix(".csv"))
        else {
            continue;
        };
        if backend == "mujoco" && !cfg!(feature = "mujoco") {
            continue;
        }
        let base = format!("results/baselines/{name}");
        // The backend comes from the baseline's own `backend` column.
        let o = settle(&["check", SCENARIO, "--baseline", &base, "--jobs", "2"]);
        assert_eq!(o.status.code(), Some(0), "{base}: {}", text(&o));
        assert!(text(&o).contains("ok: "), "{}", text(&o));
        checked.push(backend.to_string());
    }
    checked.sort();
    assert!(
        checked.contains(&"modal".to_string()) && checked.contains(&"rapier".to_string()),
        "{checked:?}"
    );
}

#[test]
fn a_baseline_of_another_backend_is_refused() {
    let base = Path::new(crate::support::manifest_dir()).join(BASELINE);
    let e = check_with(&scenario(), &base, |o| {
        o.backend = Some(settle::spec::backend::Backend::Modal)
    })
    .expect_err("refused");
    assert!(e.is_input_error(), "{e}");
    assert!(e.to_string().contains("made on backend `rapier`"), "{e}");
}

#[test]
fn a_worsened_metric_fails_with_the_table() {
    // Make run 2's residual peak look 10% smaller in the baseline: the rerun is then 11.1%
    // worse, far beyond the 0.1% tolerance.
    let mut b = baseline();
    let col = b.column("residual_peak_um").expect("column");
    let old: f64 = b.rows[2][col].parse().expect("number");
    let new = old * 0.9;
    b.rows[2][col] = new.to_string();
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("base.csv");
    std::fs::write(&path, b.to_csv()).expect("write");
    let (r, t) = check_with(&scenario(), &path, |_| {}).expect("checks");
    assert_eq!(r.exit, Exit::Failed, "{t}");
    let header = r.stdout.lines().next().expect("table header");
    for h in ["run", "metric", "baseline", "now", "delta%"] {
        assert!(header.contains(h), "{header}");
    }
    let rows: Vec<&str> = r
        .stdout
        .lines()
        .skip(2)
        .filter(|l| !l.trim().is_empty())
        .collect();
    assert_eq!(rows.len(), 1, "exactly the edited cell: {}", r.stdout);
    let cells: Vec<&str> = rows[0].split_whitespace().collect();
    let pct = (old / new - 1.0) * 100.0;
    assert_eq!(
        cells,
        vec![
            "2",
            "residual_peak_um",
            &new.to_string(),
            &old.to_string(),
            &format!("{pct:+.3}%"),
            "worse"
        ]
    );
    assert!(t.contains("--update"), "tells how to accept it: {t}");
    // --allow-improvements does not let a regression through.
    let (r, t) = check_with(&scenario(), &path, |o| o.allow_improvements = true).expect("checks");
    assert_eq!(r.exit, Exit::Failed, "{t}");
}

#[test]
fn a_worse_machine_fails_on_settling_metrics() {
    // Less damping: the same moves ring longer. Checked against the committed baseline.
    let dir = tempfile::tempdir().expect("tempdir");
    let src = std::fs::read_to_string(scenario()).expect("scenario");
    let worse = src.replace("damping_ratio = 0.05", "damping_ratio = 0.03");
    assert_ne!(worse, src);
    let p = dir.path().join("ci_quickstart.toml");
    std::fs::write(&p, worse).expect("write");
    let base = Path::new(crate::support::manifest_dir()).join(BASELINE);
    let (r, t) = check_with(&p, &base, |_| {}).expect("checks");
    assert_eq!(r.exit, Exit::Failed, "{t}");
    // The damping column changed, and settle times got worse.
    assert!(
        t.contains("mode0_damping_ratio") && t.contains("changed"),
        "{t}"
    );
    let worse_settle = t
        .lines()
        .filter(|l| l.contains("settle_time_s_") && l.trim_end().ends_with("worse"))
        .count();
    assert!(worse_settle >= 3, "{t}");
}

#[test]
fn update_writes_a_baseline_that_then_passes() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("sub/new.csv");
    let p = path.to_str().expect("utf-8");
    let o = settle(&["check", SCENARIO, "--baseline", p]);
    assert_eq!(o.status.code(), Some(2), "missing baseline: {}", text(&o));
    assert!(text(&o).contains("--update"), "{}", text(&o));
    let o = settle(&["check", SCENARIO, "--baseline", p, "--update"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert!(text(&o).contains("created"), "{}", text(&o));
    let o = settle(&["check", SCENARIO, "--baseline", p, "--tolerance", "0"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    // The baseline is the sweep's runs.csv, byte for byte.
    let out = dir.path().join("sweep");
    let o = settle(&["sweep", SCENARIO, "--out", out.to_str().expect("utf-8")]);
    assert!(o.status.success(), "{}", text(&o));
    assert_eq!(
        std::fs::read(out.join("runs.csv")).expect("runs.csv"),
        std::fs::read(&path).expect("baseline")
    );
}

#[test]
fn a_baseline_of_another_shape_is_a_failure_with_the_reason() {
    let mut b = baseline();
    b.rows.pop();
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("short.csv");
    std::fs::write(&path, b.to_csv()).expect("write");
    let (r, t) = check_with(&scenario(), &path, |_| {}).expect("checks");
    assert_eq!(r.exit, Exit::Failed, "{t}");
    assert!(t.contains("the sweep changed"), "{t}");
    // A negative tolerance is bad input, from the binary too.
    let o = settle(&[
        "check",
        SCENARIO,
        "--baseline",
        BASELINE,
        "--tolerance",
        "-1",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
}

/// A baseline settle cannot have written (a run listed twice) is bad input, exit 2, and
/// refused before the scenario runs; `--update` rewrites it.
#[test]
fn a_baseline_with_a_run_twice_is_bad_input() {
    let mut b = baseline();
    b.rows.push(b.rows[0].clone());
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("twice.csv");
    std::fs::write(&path, b.to_csv()).expect("write");
    let p = path.display().to_string();
    let o = settle(&["check", SCENARIO, "--baseline", &p]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    let t = text(&o);
    assert!(t.contains("twice.csv") && t.contains("run 0 twice"), "{t}");
    assert!(!t.contains("runs)"), "no run was simulated: {t}");
    let o = settle(&["check", SCENARIO, "--baseline", &p, "--update"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let o = settle(&["check", SCENARIO, "--baseline", &p]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
}

/// A move a ZV shaper at the mode's own frequency and damping cancels exactly: on the
/// modal backend its residual is 0 um and its overshoot 2.5 nm.
const CANCELLED: &str = r#"name = "zv_exact"
[machine]
modes = [{ frequency_hz = 40.0, damping_ratio = 0.05 }]
[move]
distance_mm = 10.0
profile = "trapezoid"
[limits]
vmax_mm_s = 200.0
amax_mm_s2 = 3000.0
[shaper]
type = "zv"
frequency_hz = 40.0
damping_ratio = 0.05
[observe]
window_s = 0.2
"#;

#[test]
fn changes_under_a_nanometre_are_no_regression_whatever_their_percentage() {
    let dir = tempfile::tempdir().expect("tempdir");
    let sc = crate::support::write(dir.path(), "zv.toml", CANCELLED);
    let base = dir.path().join("base.csv");
    let (sc_s, base_s) = (sc.to_str().expect("UTF-8"), base.to_str().expect("UTF-8"));
    let o = settle(&[
        "check",
        sc_s,
        "--baseline",
        base_s,
        "--backend",
        "modal",
        "--update",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let mut b = RunsTable::parse(&std::fs::read_to_string(&base).expect("baseline")).expect("csv");
    let at = |b: &RunsTable, c: &str| b.column(c).expect(c);
    let (peak, rms) = (at(&b, "residual_peak_um"), at(&b, "residual_rms_um"));
    assert_eq!(
        (b.rows[0][peak].as_str(), b.rows[0][rms].as_str()),
        ("0", "0")
    );
    // Round-off residuals of another build, e.g. 7e-6 and 4.8e-6 um: a "change" of
    // -100 % that is a few picometres.
    b.rows[0][peak] = "7e-6".into();
    b.rows[0][rms] = "4.8e-6".into();
    std::fs::write(&base, b.to_csv()).expect("write");
    let check = |extra: &[&str]| {
        let mut args = vec!["check", sc_s, "--baseline", base_s];
        args.extend_from_slice(extra);
        settle(&args)
    };
    let o = check(&[]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert!(
        text(&o).contains("within 0.1% (or 0.001 um)"),
        "{}",
        text(&o)
    );
    // The floor is the user's to set: at 0 every picometre counts.
    let o = check(&["--floor-um", "0"]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(text(&o).contains("residual_peak_um"), "{}", text(&o));
    // A change of a few nanometres is beyond the floor: the 2.5 nm overshoot halved fails.
    let over = at(&b, "overshoot_um");
    let now: f64 = b.rows[0][over].parse().expect("number");
    assert!((0.002..0.003).contains(&now), "{now}");
    b.rows[0][over] = (now * 2.0).to_string();
    std::fs::write(&base, b.to_csv()).expect("write");
    let o = check(&[]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(text(&o).contains("overshoot_um"), "{}", text(&o));
    assert!(!text(&o).contains("residual_peak_um"), "{}", text(&o));
    // A floor that is not a length is bad input.
    let o = check(&["--floor-um=-1"]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("--floor-um"), "{}", text(&o));
}
