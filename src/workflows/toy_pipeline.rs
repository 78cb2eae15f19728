//! The toy study (`crate::studies::toy`, registered for the unit tests by one line in
//! `crate::studies::STUDIES`) through the whole pipeline: its table parsed with errors that
//! name the line and key, its key swept, its runs planned, simulated and measured, its
//! columns in runs.csv and its section in the summary, by the sweep workflow. None of the
//! expander, the runner, runs.csv or the summary knows it: adding a study is one file and
//! one line.

use std::path::Path;

use crate::execute::pool::quiet;
use crate::spec::backend::Backend;
use crate::studies::toy::Shuttle;
use crate::workflows::sweep::{SweepOptions, sweep};

const TOY: &str = r#"name = "toy"
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
window_s = 0.2
[toy]
legs = 1
[sweep]
"toy.legs" = [1, 2, 3]
"#;

#[test]
fn a_toy_study_goes_through_expand_run_csv_and_summary() {
    let (_, mut runs) = crate::expand::parse_runs(TOY, Path::new("toy.toml")).expect("expands");
    assert_eq!(runs.len(), 3);
    let legs: Vec<u32> = runs
        .iter()
        .map(|r| r.state::<Shuttle>().expect("a toy run").legs)
        .collect();
    assert_eq!(legs, [1, 2, 3]);
    crate::execute::set_backend(Path::new("toy.toml"), &mut runs, Backend::Modal)
        .expect("modal runs the modes form");
    // The duration of one leg, from the planner directly.
    let one = runs[0]
        .profile
        .rest_to_rest(0.0, 5e-3, &runs[0].limits_si().expect("limits"))
        .expect("plans")
        .duration_s();
    for r in &runs {
        let m = crate::execute::execute(r, None).expect("runs");
        let legs = f64::from(r.state::<Shuttle>().expect("toy").legs);
        assert!(
            (m.move_time_s - legs * one).abs() < 1e-12,
            "{legs} legs: {} s, one leg {one} s",
            m.move_time_s
        );
        // The probe's figure from the series equals the streaming metric on the same samples.
        let (name, x) = &m.extra[0];
        assert_eq!(name, "toy_max_error_um");
        assert!(
            (x - m.max_following_error_um).abs() <= 1e-9 * m.max_following_error_um,
            "{x} vs {}",
            m.max_following_error_um
        );
    }

    let dir = tempfile::tempdir().expect("tempdir");
    let scenario = dir.path().join("toy.toml");
    std::fs::write(&scenario, TOY).expect("writes");
    let opts = SweepOptions {
        out: Some(dir.path().join("out")),
        jobs: Some(1),
        ..SweepOptions::new(&scenario, Backend::Modal)
    };
    let outcome = sweep(&opts, &|_| {}, &quiet).expect("sweeps");
    assert!(outcome.failed.is_empty());
    let csv = std::fs::read_to_string(dir.path().join("out/runs.csv")).expect("runs.csv");
    let header = csv.lines().next().expect("header");
    assert!(header.ends_with(",toy_legs,toy_max_error_um"), "{header}");
    assert!(csv.lines().nth(3).expect("run 2").contains(",3,"), "{csv}");
    let summary = std::fs::read_to_string(dir.path().join("out/summary.md")).expect("summary");
    assert!(summary.contains("## Toy shuttle"), "{summary}");
    assert!(summary.contains("## Ranking: move and settle"), "{summary}");
    let plot =
        std::fs::read_to_string(dir.path().join("out/plots/vs_toy_legs.svg")).expect("figure");
    assert!(plot.contains("shuttle: largest error during the move"));
}

#[test]
fn a_toy_table_error_names_its_line_and_key() {
    let bad = TOY.replace("legs = 1\n", "legs = 1\nlegz = 2\n");
    let e = crate::expand::parse_runs(&bad, Path::new("toy.toml")).expect_err("unknown key");
    let msg = e.to_string();
    assert!(msg.starts_with("toy.toml:15:1: key `toy.legz`"), "{msg}");
    assert!(msg.contains("legz"), "{msg}");
    let swept = TOY.replace("[1, 2, 3]", "[1, 0]");
    let msg = crate::expand::parse_runs(&swept, Path::new("toy.toml"))
        .expect_err("0 legs")
        .to_string();
    assert!(
        msg.starts_with("toy.toml:16:1: key `sweep.toy.legs`"),
        "{msg}"
    );
}
