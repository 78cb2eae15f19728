//! `settle tune`: a small search on the printer preset tuned on the modal
//! backend, its winner re-checked on rapier (a second, independent engine: rigid bodies,
//! position-dependent belt stiffness) where it must still beat the untuned default; the
//! Pareto front's defining property; the exports; bad `[tune]` input.

use std::path::PathBuf;

use settle::spec::backend::Backend;
use settle::workflows::tune::rank::pareto;
use settle::workflows::tune::search::Score;

fn scenario(tune: &str) -> String {
    format!(
        r#"name = "tune_test"
[machine]
preset = "printer_xy"
driver_model = "linear"
[move]
axis = "y"
distance_mm = 20.0
profile = "scurve"
[limits]
vmax_mm_s = 300.0
amax_mm_s2 = 3000.0
jmax_mm_s3 = 100000.0
[observe]
window_s = 0.4
sample_rate_hz = 5000
bands_um = [10.0]
[tune]
{tune}
"#
    )
}

const SMALL: &str = r#"distances_mm = [5.0, 20.0]
kinds = ["trapezoid", "scurve"]
shapers = ["none", "zv", "mzv"]
frequency_scales = [0.95, 1.0, 1.05]
jerk_steps = 2
jerk_span = 4.0
usteps_per_mm = 80.0
"#;

fn write(dir: &tempfile::TempDir, text: &str) -> PathBuf {
    let p = dir.path().join("tune_test.toml");
    std::fs::write(&p, text).expect("writes");
    p
}

#[test]
fn tuned_on_modal_still_beats_the_default_on_rapier() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = write(&dir, &scenario(SMALL));
    let o = settle::workflows::tune::tune(
        &path,
        Backend::Modal,
        Some(Backend::Rapier),
        Some(2),
        &settle::execute::pool::quiet,
    )
    .expect("tunes");
    // Grid: default + trapezoid (1 jerk) x 7 shapers + scurve x 2 jerks x 7 shapers; two
    // modes x three scales x two types = 12 shaped + 1 unshaped per (kind, jerk).
    assert_eq!(o.scores.len(), 1 + 13 + 2 * 13);
    let (d, w) = (&o.scores[0], &o.scores[o.winner]);
    assert!(
        w.move_and_settle_s < d.move_and_settle_s,
        "winner {w:?} vs default {d:?}"
    );
    let (b, rd, rw) = o.check.as_ref().expect("checked");
    assert_eq!(*b, Backend::Rapier);
    // Same commands on the other engine: identical move times.
    assert!((rd.move_time_s - d.move_time_s).abs() < 1e-9);
    assert!((rw.move_time_s - w.move_time_s).abs() < 1e-9);
    assert!(
        rw.move_and_settle_s < rd.move_and_settle_s,
        "on rapier the winner {rw:?} does not beat the default {rd:?}"
    );
    // rapier agrees with the modal residuals to its validated accuracy (validate: 2-3%;
    // the belt stiffness varies along the move on rapier, hence the looser 15% here).
    for (m, r) in [(d, rd), (w, rw)] {
        assert!(
            (m.residual_peak_um - r.residual_peak_um).abs() < 0.15 * m.residual_peak_um,
            "modal {} um vs rapier {} um",
            m.residual_peak_um,
            r.residual_peak_um
        );
    }
    // The winner is shaped near the measured 39 Hz mode of the preset's Y axis.
    let f0 = o.plan.modes[0].0;
    assert!((f0 - 39.3).abs() < 0.5, "first mode {f0} Hz");

    // Pareto front: nobody dominates a front point; every other point is dominated.
    let front = &o.front;
    let dominates = |a: &Score, b: &Score| {
        a.move_time_s <= b.move_time_s
            && a.residual_peak_um <= b.residual_peak_um
            && (a.move_time_s < b.move_time_s || a.residual_peak_um < b.residual_peak_um)
    };
    for (i, s) in o.scores.iter().enumerate() {
        let dominated = o.scores.iter().any(|t| dominates(t, s));
        let on_front = front.iter().any(|&k| {
            o.scores[k].move_time_s == s.move_time_s
                && o.scores[k].residual_peak_um == s.residual_peak_um
        });
        assert_eq!(on_front, !dominated, "candidate {i}");
    }
    assert_eq!(pareto(&o.scores), *front);

    // Klipper's export needs both X and Y: only Y was tuned and X's current shaper is not
    // known, so it says what is missing rather than switching X's shaper off.
    let axes = vec![("y".to_string(), o.clone())];
    let k = settle::workflows::tune::export::klipper(&axes, "a test");
    assert!(
        k.contains("# no Klipper configuration: axis x was not tuned"),
        "{k}"
    );
    // With X's current settings known, Y's recommendation is written next to them.
    let mut with_x = o.clone();
    with_x.plan.spec.axis = Some(
        [(
            "x".to_string(),
            settle::input::tune_spec::AxisCurrent {
                shaper: Some("mzv".into()),
                frequency_hz: Some(52.0),
                ..Default::default()
            },
        )]
        .into(),
    );
    let k = settle::workflows::tune::export::klipper(&[("y".to_string(), with_x)], "a test");
    assert!(k.contains("shaper_type_x: mzv\nshaper_freq_x: 52\n"), "{k}");
    assert!(!k.contains("max_accel"), "acceleration unchanged: {k}");
    match w.candidate.shaper.and_then(|s| s.shaper_type) {
        Some(kind) => {
            assert!(
                k.contains(&format!("shaper_type_y: {}", kind.name())),
                "{k}"
            );
            assert!(k.contains("shaper_freq_y: "), "{k}");
        }
        None => assert!(k.contains("shaper_freq_y: 0"), "{k}"),
    }
}

#[test]
fn tmc_export_of_an_scurve_reads_back_to_its_jerk() {
    use settle_planner::tmc::registers::{RegisterSet, TmcUnits, import};
    let dir = tempfile::tempdir().expect("tempdir");
    let only_scurve = "distances_mm = [20.0]\nkinds = [\"scurve\"]\nshapers = [\"none\"]\njerk_steps = 1\nusteps_per_mm = 80.0\n";
    let path = write(&dir, &scenario(only_scurve));
    let o = settle::workflows::tune::tune(
        &path,
        Backend::Modal,
        None,
        Some(1),
        &settle::execute::pool::quiet,
    )
    .expect("tunes");
    let w = &o.scores[o.winner];
    assert!(w.candidate.shaper.is_none_or(|s| s.shaper_type.is_none()));
    let text = settle::workflows::tune::export::tmc4361a(&[("y".to_string(), o.clone())]);
    // `NAME 0xAA = value ; note`
    let reg = |name: &str| -> u32 {
        text.lines()
            .find(|l| l.split_whitespace().next() == Some(name))
            .and_then(|l| l.split('=').nth(1))
            .and_then(|v| v.split(';').next())
            .and_then(|v| v.trim().parse().ok())
            .unwrap_or_else(|| panic!("{name} in {text}"))
    };
    let r = RegisterSet {
        xtarget: reg("XTARGET") as i32,
        vmax: reg("VMAX") as i32,
        vstart: reg("VSTART"),
        vstop: reg("VSTOP"),
        amax: reg("AMAX"),
        dmax: reg("DMAX"),
        bow: [reg("BOW1"), reg("BOW2"), reg("BOW3"), reg("BOW4")],
        clk_freq: reg("CLK_FREQ"),
    };
    let u = TmcUnits {
        f_clk_hz: settle::workflows::tune::export::DEFAULT_TMC_CLOCK_HZ,
        usteps_per_unit: 80.0,
        direct_acc: false,
        direct_bow: false,
    };
    let (target, p) = import(&r, &u).expect("imports");
    // 20 mm at 80 usteps/mm; jerk 1e5 mm/s^3 = 8e6 pps^3 (1 pps^3 per LSB).
    assert_eq!(r.xtarget, 1600);
    assert_eq!(r.bow, [8_000_000; 4]);
    assert!((target - 20.0).abs() < 1e-12);
    assert!((p.bow[0] - 1e5).abs() < 1e-6 && (p.amax - 3000.0).abs() < 0.01);
}

fn tune_err(tune: &str) -> String {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = write(&dir, &scenario(tune));
    match settle::workflows::tune::tune(
        &path,
        Backend::Modal,
        None,
        Some(1),
        &settle::execute::pool::quiet,
    ) {
        Ok(_) => panic!("expected an error"),
        Err(e) => {
            assert!(e.is_input_error(), "{e}");
            e.to_string()
        }
    }
}

#[test]
fn bad_tune_input_names_file_line_and_key() {
    let msg = tune_err("kinds = [\"scurv\"]\n");
    assert!(
        msg.contains("tune_test.toml:18")
            && msg.contains("key `tune.kinds`")
            && msg.contains("trapezoid"),
        "{msg}"
    );
    let msg = tune_err("shapers = [\"mvz\"]\n");
    assert!(
        msg.contains("key `tune.shapers`") && msg.contains("2hump_ei"),
        "{msg}"
    );
    let msg = tune_err("band_um = 50.0\n");
    assert!(
        msg.contains("key `tune.band_um`") && msg.contains("bands_um"),
        "{msg}"
    );
    let msg = tune_err("distances_mm = []\n");
    assert!(msg.contains("key `tune.distances_mm`"), "{msg}");
    let msg = tune_err("refine_rounds = 50\n");
    assert!(msg.contains("key `tune.refine_rounds`"), "{msg}");
    let msg = tune_err("margin = 0.0\n");
    assert!(msg.contains("key `tune.margin`"), "{msg}");
    let msg = tune_err("jerk_stepz = 3\n");
    assert!(
        msg.contains("jerk_stepz") && msg.contains("jerk_steps"),
        "{msg}"
    );
    // The modal backend needs the linear driver: the search says so.
    let dir = tempfile::tempdir().expect("tempdir");
    let path = write(
        &dir,
        &scenario("").replace("driver_model = \"linear\"", "driver_model = \"full\""),
    );
    let e = settle::workflows::tune::tune(
        &path,
        Backend::Modal,
        None,
        Some(1),
        &settle::execute::pool::quiet,
    )
    .expect_err("modal refuses the full driver");
    assert!(e.to_string().contains("--backend rapier"), "{e}");
}

#[test]
fn corner_family_respects_the_contour_limit_and_holds_on_rapier() {
    let dir = tempfile::tempdir().expect("tempdir");
    let text = r#"name = "tune_corner_test"
[machine]
preset = "printer_xy"
driver_model = "linear"
[corner]
angle_deg = 90.0
leg_in_mm = 30.0
leg_out_mm = 30.0
strategy = "square_corner_velocity"
profile = "scurve"
[limits]
vmax_mm_s = 200.0
amax_mm_s2 = 3000.0
jmax_mm_s3 = 100000.0
[observe]
window_s = 0.5
sample_rate_hz = 5000
bands_um = [10.0]
[tune]
angles_deg = [60.0, 120.0]
kinds = ["trapezoid", "scurve"]
shapers = ["none", "zv", "mzv"]
frequency_scales = [0.9, 1.0, 1.1]
jerk_steps = 2
max_contour_error_um = 25.0
"#;
    let path = write(&dir, text);
    let o = settle::workflows::tune::tune(
        &path,
        Backend::Modal,
        Some(Backend::Rapier),
        Some(2),
        &settle::execute::pool::quiet,
    )
    .expect("tunes");
    // Both path axes' modes: the preset's X (~48 Hz) and Y (~39 Hz) first modes.
    assert_eq!(o.plan.modes.len(), 2);
    let w = &o.scores[o.winner];
    assert!(w.max_contour_error_um <= 25.0, "{w:?}");
    // Every candidate over the limit is infeasible; every candidate within it is scored.
    for s in &o.scores {
        // Shaped paths keep their geometry: every scored candidate has a contour error.
        assert!(
            s.move_and_settle_s.is_infinite() || s.max_contour_error_um.is_finite(),
            "{s:?}"
        );
        if s.max_contour_error_um > 25.0 {
            assert!(s.move_and_settle_s.is_infinite(), "{s:?}");
        }
    }
    let (_, rd, rw) = o.check.as_ref().expect("checked");
    let d = &o.scores[0];
    assert!(w.move_and_settle_s <= d.move_and_settle_s || d.move_and_settle_s.is_infinite());
    assert!(
        rw.move_and_settle_s < rd.move_and_settle_s || rd.move_and_settle_s.is_infinite(),
        "rapier: winner {rw:?} default {rd:?}"
    );
    let k = settle::workflows::tune::export::klipper(
        &[(o.plan.base.axis.clone(), o.clone())],
        "a test",
    );
    assert!(
        k.contains("shaper_freq_x:") && k.contains("shaper_freq_y:"),
        "{k}"
    );
    assert!(k.contains("square_corner_velocity: 5"), "{k}");
}

#[test]
fn tune_command_writes_report_table_plot_and_exports() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = write(&dir, &scenario(SMALL));
    let out = dir.path().join("out");
    let status = crate::support::settle()
        .arg("tune")
        .arg(&path)
        .arg("--out")
        .arg(&out)
        .args(["--jobs", "1"])
        .output()
        .expect("runs");
    assert!(status.status.success(), "{status:?}");
    let stdout = String::from_utf8_lossy(&status.stdout);
    assert!(
        stdout.contains("**recommended**") && stdout.contains("Gain of the recommendation"),
        "{stdout}"
    );
    let csv = std::fs::read_to_string(out.join("candidates.csv")).expect("csv");
    assert_eq!(csv.lines().count(), 1 + 40); // header + the 40 candidates of SMALL
    for f in [
        "tune.md",
        "klipper.cfg",
        "rrf.g",
        "tmc4361a.txt",
        "pareto.svg",
    ] {
        assert!(out.join(f).is_file(), "{f}");
    }
    let png = image::open(out.join("pareto.png")).expect("decodes");
    assert!(png.width() >= 800);
    // Bad input: exit code 2 with file, line and key.
    let bad = write(&dir, &scenario("kinds = [\"scurv\"]\n"));
    let r = crate::support::settle()
        .arg("tune")
        .arg(&bad)
        .output()
        .expect("runs");
    assert_eq!(r.status.code(), Some(2));
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(
        err.contains("tune_test.toml:18") && err.contains("tune.kinds"),
        "{err}"
    );
}

#[test]
fn refinement_never_loses_to_the_grid_and_stays_within_the_limits() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = write(&dir, &scenario(&format!("{SMALL}refine_rounds = 4\n")));
    let o = settle::workflows::tune::tune(
        &path,
        Backend::Modal,
        Some(Backend::Rapier),
        Some(2),
        &settle::execute::pool::quiet,
    )
    .expect("tunes");
    let grid = o.plan.candidates.len();
    assert_eq!(grid, 40);
    // At most 8 neighbours per round, none evaluated twice.
    assert!(o.scores.len() > grid && o.scores.len() <= grid + 4 * 8);
    let (g, w) = (&o.scores[o.grid_winner], &o.scores[o.winner]);
    assert!(o.grid_winner < grid);
    assert!(w.move_and_settle_s <= g.move_and_settle_s, "{w:?} vs {g:?}");
    let (gc, wc) = (g.candidate, w.candidate);
    assert_eq!((gc.kind, gc.params), (wc.kind, wc.params));
    // Refinement moves the frequency by at most 2 x (2.5 + 1.25 + 0.625 + 0.3125)% in
    // total, and never raises the jerk above the scenario's limit.
    if let (Some(a), Some(b)) = (gc.shaper, wc.shaper) {
        assert_eq!(a.shaper_type, b.shaper_type);
        let r = b.frequency_hz / a.frequency_hz;
        assert!((1.0 - 0.1..=1.0 + 0.1).contains(&r), "{r}");
    }
    for s in &o.scores[grid..] {
        assert!(
            s.candidate.jmax_mm_s3.is_none_or(|j| j <= 100000.0),
            "{s:?}"
        );
    }
    // The refined winner is what the second backend re-checks, and it still wins there.
    let (_, rd, rw) = o.check.as_ref().expect("checked");
    assert_eq!(rw.candidate, wc);
    assert!(
        rw.move_and_settle_s < rd.move_and_settle_s,
        "{rw:?} vs {rd:?}"
    );
}

#[test]
fn neighbours_step_the_frequency_and_cap_the_jerk() {
    use settle::studies::shaping::ShaperSetting;
    use settle::workflows::tune::rank::neighbours;
    use settle::workflows::tune::search::Candidate;
    use settle_planner::shaper::ShaperType;
    use settle_planner::{ProfileKind, ProfileParams};
    let c = Candidate {
        kind: ProfileKind::SCurve,
        jmax_mm_s3: Some(1e5),
        params: ProfileParams::default(),
        shaper: Some(ShaperSetting {
            shaper_type: Some(ShaperType::MZV),
            frequency_hz: 40.0,
            damping_ratio: 0.1,
        }),
        amax_mm_s2: None,
    };
    let n = neighbours(&c, 0.025, 2.0, 1e5);
    let f: Vec<f64> = n
        .iter()
        .filter(|x| x.jmax_mm_s3 == Some(1e5))
        .filter_map(|x| x.shaper.map(|s| s.frequency_hz))
        .collect();
    assert_eq!(f, vec![38.0, 39.0, 41.0, 42.0]);
    // At the jerk limit only lower jerks: 1e5 / 4 and 1e5 / 2.
    let j: Vec<f64> = n
        .iter()
        .filter(|x| x.shaper == c.shaper)
        .filter_map(|x| x.jmax_mm_s3)
        .collect();
    assert_eq!(j, vec![25000.0, 50000.0]);
}
