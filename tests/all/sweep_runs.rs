//! A sweep's runs made on demand from their ids (`settle::expand::sweep_runs`) are the runs
//! of the cartesian product of its axes, last axis fastest, every value not swept at its
//! base: checked against a list built here, loop by loop, for every run of a four-axis
//! sweep and of each of its shards.

use std::path::Path;

use settle::spec::runs::RunList;
use settle::spec::value::Value;
use settle_planner::ProfileKind;

const SCENARIO: &str = r#"
name = "runs_on_demand"
[machine]
modes = [{ frequency_hz = 40.0, damping_ratio = 0.05 }]
[move]
distance_mm = 10.0
profile = "scurve"
[limits]
vmax_mm_s = 200.0
amax_mm_s2 = 3000.0
jmax_mm_s3 = 100000.0
[observe]
window_s = 0.5
bands_um = [10.0, 50.0]
[sweep]
profile = ["trapezoid", "scurve", "fourjerk"]
"move.distance_mm" = [1.0, 5.0]
"limits.vmax_mm_s" = { from = 100.0, to = 300.0, steps = 3 }
"machine.modes.0.frequency_hz" = [30.0, 50.0]
"#;

/// One expected run: (id, profile, distance, vmax, frequency).
type Expected = (usize, ProfileKind, f64, f64, f64);

fn expected() -> Vec<Expected> {
    let mut out = Vec::new();
    for kind in [
        ProfileKind::Trapezoid,
        ProfileKind::SCurve,
        ProfileKind::FourJerk,
    ] {
        for d in [1.0, 5.0] {
            for v in [100.0, 200.0, 300.0] {
                for f in [30.0, 50.0] {
                    out.push((out.len(), kind, d, v, f));
                }
            }
        }
    }
    out
}

fn check(r: &settle::spec::run_spec::RunSpec, &(id, kind, d, v, f): &Expected) {
    assert_eq!(r.id, id);
    assert_eq!(r.profile, kind, "run {id}");
    assert_eq!(r.distance_mm, d, "run {id}");
    assert_eq!(r.vmax_mm_s, v, "run {id}");
    // Not swept: the base values.
    assert_eq!(r.start_mm, 0.0, "run {id}");
    assert_eq!(r.amax_mm_s2, 3000.0, "run {id}");
    assert_eq!(r.jmax_mm_s3, Some(100000.0), "run {id}");
    assert_eq!(r.bands_um, vec![10.0, 50.0], "run {id}");
    let modes = r.machine.modes();
    assert_eq!(modes.len(), 1, "run {id}");
    assert_eq!(modes[0].modes[0].frequency_hz, f, "run {id}");
    assert_eq!(modes[0].modes[0].damping_ratio, 0.05, "run {id}");
    assert_eq!(
        r.swept,
        vec![
            ("profile".to_string(), Value::Study(kind)),
            ("move.distance_mm".to_string(), Value::Number(d)),
            ("limits.vmax_mm_s".to_string(), Value::Number(v)),
            ("machine.modes.0.frequency_hz".to_string(), Value::Number(f)),
        ],
        "run {id}"
    );
}

#[test]
fn runs_made_on_demand_are_the_product_of_the_axes() {
    let expected = expected();
    assert_eq!(expected.len(), 36);
    let (sc, src) =
        settle::expand::parse(SCENARIO, Path::new("runs_on_demand.toml")).expect("parses");
    let runs = settle::expand::sweep_runs(&sc, &src).expect("expands");
    let list: &dyn RunList = &runs;
    assert_eq!(list.len(), expected.len());
    for (i, e) in expected.iter().enumerate() {
        check(&list.at(i), e);
        assert_eq!(list.id(i), Some(i));
    }
    assert!(list.get(expected.len()).is_none());
    // The list `expand` returns is the same runs.
    let listed = settle::expand::expand(&sc, &src).expect("expands");
    assert_eq!(listed.len(), expected.len());
    for (r, e) in listed.iter().zip(&expected) {
        check(r, e);
    }
    // Each shard K of N holds the runs with id % N == K - 1, in order.
    for n in [1, 5, 36, 37] {
        for k in 1..=n {
            let shard = settle::expand::sweep_runs(&sc, &src)
                .expect("expands")
                .every(k - 1, n);
            let mine: Vec<&Expected> = expected.iter().filter(|e| e.0 % n == k - 1).collect();
            let list: &dyn RunList = &shard;
            assert_eq!(list.len(), mine.len(), "shard {k}/{n}");
            for (i, e) in mine.iter().enumerate() {
                check(&list.at(i), e);
                assert_eq!(shard.position(e.0), Some(i));
            }
        }
    }
}
