//! Corner paths through the whole harness: a small corner sweep on the printer
//! preset (modal backend: the exact discretisation of the linear model), checked against
//! facts derived here independently of the planner: Klipper's and GRBL's junction speeds
//! by hand, the jerk-limited blend's deviation from its closed form, trapezoid move times in closed
//! form, and geometric inequalities every contour metric must satisfy.

use std::path::Path;

use settle::Metrics;
use settle::RunSpec;
use settle::measure::path_metrics::PathMetrics;
use settle::spec::backend::Backend;
use settle::studies::corner::{Corner, Strategy};
use settle_planner::ProfileKind;

const VMAX: f64 = 200.0; // mm/s
const AMAX: f64 = 3000.0; // mm/s^2
const JMAX: f64 = 100_000.0; // mm/s^3
const LEG: f64 = 50.0; // mm
const SCV: f64 = 5.0; // mm/s
const JD: f64 = 0.01; // mm
const BLEND: f64 = 0.05; // mm

fn scenario() -> String {
    format!(
        r#"name = "corner_test"
[machine]
preset = "printer_xy"
driver_model = "linear"
[corner]
angle_deg = 90.0
leg_in_mm = {LEG}
leg_out_mm = {LEG}
junction_deviation_mm = {JD}
square_corner_velocity_mm_s = {SCV}
blend_deviation_mm = {BLEND}
[limits]
vmax_mm_s = {VMAX}
amax_mm_s2 = {AMAX}
jmax_mm_s3 = {JMAX}
[observe]
window_s = 0.1
sample_rate_hz = 10000
bands_um = [10.0]
[sweep]
"corner.angle_deg" = [0, 60, 90, 180]
"corner.strategy" = ["exact_stop", "junction_deviation", "square_corner_velocity", "blend"]
profile = ["trapezoid", "scurve"]
"#
    )
}

fn run_sweep() -> Vec<(RunSpec, Metrics)> {
    let (sc, src) =
        settle::expand::parse(&scenario(), Path::new("corner_test.toml")).expect("parses");
    let mut runs = settle::expand::expand(&sc, &src).expect("expands");
    assert_eq!(runs.len(), 32);
    settle::execute::set_backend(Path::new("corner_test.toml"), &mut runs, Backend::Modal)
        .expect("modal runs the linear driver");
    let results =
        settle::execute::pool::run_all(&runs, None, &settle::execute::pool::quiet).expect("pool");
    runs.into_iter()
        .zip(results)
        .map(|(r, m)| (r, m.expect("run succeeds")))
        .collect()
}

fn path(m: &Metrics) -> &PathMetrics {
    m.path.as_ref().expect("a corner run has path metrics")
}

fn find(all: &[(RunSpec, Metrics)], angle: f64, strategy: Strategy, kind: ProfileKind) -> &Metrics {
    &all.iter()
        .find(|(r, _)| {
            let c = r.state::<Corner>().expect("corner");
            c.angle_deg == angle && c.strategy == strategy && r.profile == kind
        })
        .expect("run in the sweep")
        .1
}

/// The deviation of a jerk-limited blend from the sharp corner (mm), in closed form (the
/// velocity change `2 s cos(theta/2)` at the jerk and acceleration limits): speed `s`
/// (mm/s), interior angle `theta` (rad).
fn blend_deviation(s: f64, theta: f64, a: f64, j: f64) -> f64 {
    let dv = 2.0 * s * (theta / 2.0).cos();
    if dv * j <= a * a {
        // Triangle: T = 2 sqrt(dv/j), deviation dv T / 12.
        let t = 2.0 * (dv / j).sqrt();
        dv * t / 12.0
    } else {
        // Trapezoid: T = dv/a + a/j; ramps of tr = a/j, half-plateau h = T/2 - tr.
        let t = dv / a + a / j;
        let tr = a / j;
        let h = t / 2.0 - tr;
        j * tr.powi(3) / 6.0 + a * tr * h / 2.0 + a * h * h / 2.0
    }
}

#[test]
fn corner_sweep_matches_independent_facts() {
    let all = run_sweep();
    use ProfileKind::{SCurve, Trapezoid};
    use Strategy::*;

    // Klipper: a square corner is passed at exactly the square corner velocity.
    for kind in [Trapezoid, SCurve] {
        let v = path(find(&all, 90.0, SquareCornerVelocity, kind)).corner_speed_mm_s;
        assert!(
            (v - SCV).abs() < 1e-9,
            "{kind}: 90 deg at {v} mm/s, scv {SCV}"
        );
    }
    // GRBL: v^2 = a d sin(t/2)/(1 - sin(t/2)); at 60 deg sin 30 = 1/2, so v^2 = a d.
    let v = path(find(&all, 60.0, JunctionDeviation, SCurve)).corner_speed_mm_s;
    assert!(
        (v - (AMAX * JD).sqrt()).abs() < 1e-9,
        "60 deg: {v} mm/s, expected sqrt(a d) = {}",
        (AMAX * JD).sqrt()
    );
    // And at 90 deg: v^2 = a d (1 + sqrt 2).
    let v = path(find(&all, 90.0, JunctionDeviation, SCurve)).corner_speed_mm_s;
    let want = (AMAX * JD * (1.0 + 2f64.sqrt())).sqrt();
    assert!((v - want).abs() < 1e-9, "90 deg: {v} vs {want}");
    // A reversal stops every junction strategy.
    for s in [ExactStop, JunctionDeviation, SquareCornerVelocity] {
        assert_eq!(
            path(find(&all, 0.0, s, SCurve)).corner_speed_mm_s,
            0.0,
            "{s:?}"
        );
    }

    // The blend runs at the fastest speed within the tolerance, so its rounding
    // is the tolerance, and the closed-form deviation at the planned speed gives it back.
    for angle in [0.0f64, 60.0, 90.0] {
        for kind in [Trapezoid, SCurve] {
            let p = path(find(&all, angle, Blend, kind));
            assert!(
                (p.corner_rounding_um - BLEND * 1e3).abs() < 1e-6,
                "{angle} deg {kind}: rounding {} um, tolerance {} um",
                p.corner_rounding_um,
                BLEND * 1e3
            );
            let d = blend_deviation(p.corner_speed_mm_s, angle.to_radians(), AMAX, JMAX);
            assert!(
                (d * 1e3 - p.corner_rounding_um).abs() < 1e-6 * p.corner_rounding_um,
                "{angle} deg {kind}: the closed form gives {} um at {} mm/s, plan {} um",
                d * 1e3,
                p.corner_speed_mm_s,
                p.corner_rounding_um
            );
        }
    }

    // Exact stop: two rest-to-rest trapezoids of 50 mm (vmax reached after 13.3 mm):
    // T = 2 (L/v + v/a). A straight line with a junction strategy is one 100 mm
    // trapezoid: T = 2L/v + v/a.
    for angle in [0.0, 60.0, 90.0, 180.0] {
        let t = find(&all, angle, ExactStop, Trapezoid).move_time_s;
        let want = 2.0 * (LEG / VMAX + VMAX / AMAX);
        assert!(
            (t - want).abs() < 1e-9,
            "{angle} deg exact stop: T {t}, want {want}"
        );
    }
    for s in [JunctionDeviation, SquareCornerVelocity] {
        let m = find(&all, 180.0, s, Trapezoid);
        let want = 2.0 * LEG / VMAX + VMAX / AMAX;
        assert!(
            (m.move_time_s - want).abs() < 1e-9,
            "{s:?} straight: {}",
            m.move_time_s
        );
        assert!((path(m).corner_speed_mm_s - VMAX).abs() < 1e-9);
    }

    for (r, m) in &all {
        let c = r.state::<Corner>().expect("corner");
        let p = path(m);
        // The commanded point is on the commanded path: the distance to the path is at
        // most the distance to the commanded point (the following error).
        assert!(
            p.max_contour_error_um <= m.max_following_error_um + 1e-9,
            "run {}: contour {} > following {}",
            r.id,
            p.max_contour_error_um,
            m.max_following_error_um
        );
        // The sharp path is within the commanded rounding of the commanded path.
        assert!(p.max_sharp_error_um <= p.max_contour_error_um + p.corner_rounding_um + 1e-6);
        match c.strategy {
            // Exact stop commands the sharp path itself.
            ExactStop => {
                assert_eq!(p.corner_rounding_um, 0.0);
                assert_eq!(p.corner_speed_mm_s, 0.0);
                assert!((p.max_sharp_error_um - p.max_contour_error_um).abs() < 1e-9);
            }
            // Sharp corners are cut only by the 1 us velocity jump: |dv| T / 8 < 0.03 um.
            JunctionDeviation | SquareCornerVelocity => {
                assert!(p.corner_rounding_um < 0.03, "{}", p.corner_rounding_um);
            }
            Blend => {}
        }
        // Straight on (along x), the y axis never moves: a lag along the path is no contour
        // error, however large the following error; what is left is the toolhead running
        // past the end point (it leads the command while decelerating), which the
        // overshoot along the direction of motion bounds.
        if c.angle_deg == 180.0 {
            assert_eq!(m.axes[1].max_following_error_um, 0.0, "run {}", r.id);
            assert!(
                m.max_following_error_um > 10.0,
                "run {}: following {} um",
                r.id,
                m.max_following_error_um
            );
            assert!(
                p.max_contour_error_um <= m.overshoot_um + 1e-9,
                "run {}: straight-line contour error {} um > overshoot {} um",
                r.id,
                p.max_contour_error_um,
                m.overshoot_um
            );
            assert!(p.max_contour_error_um < m.max_following_error_um);
        }
    }
}

#[test]
fn recorded_command_passes_the_corner_at_the_planned_distance() {
    // The commanded positions written to the series come closest to the corner point at
    // the blend's planned deviation (sampled at 10 kHz: the closest sample is within
    // v dt = 1.5 um of the closest point along a curve of radius > 50 um, so within ~0.03 um
    // of it in distance), and the toolhead's closest approach is what the metric reports.
    let text = scenario().replace(
        "\"corner.angle_deg\" = [0, 60, 90, 180]\n\"corner.strategy\" = [\"exact_stop\", \"junction_deviation\", \"square_corner_velocity\", \"blend\"]\nprofile = [\"trapezoid\", \"scurve\"]",
        "\"corner.strategy\" = [\"blend\"]",
    );
    let (sc, src) = settle::expand::parse(&text, Path::new("t.toml")).expect("parses");
    let mut runs = settle::expand::expand(&sc, &src).expect("expands");
    assert_eq!(runs.len(), 1);
    settle::execute::set_backend(Path::new("t.toml"), &mut runs, Backend::Modal).expect("modal");
    let mut series = settle::measure::series::Series::default();
    let m = settle::execute::execute(&runs[0], Some(&mut series)).expect("runs");
    let p = path(&m);
    let ch = |name: &str| {
        &series
            .channel(name)
            .unwrap_or_else(|| panic!("channel {name}"))
            .data
    };
    let (cx, cy, tx, ty, ce) = (
        ch("cmd_p_x"),
        ch("cmd_p_y"),
        ch("toolhead_x"),
        ch("toolhead_y"),
        ch("contour_error"),
    );
    let t_end = m.move_time_s;
    let (mut cmd_min, mut head_min, mut contour_max) = (f64::INFINITY, f64::INFINITY, 0.0f64);
    for (i, &t) in series.t_s.iter().enumerate() {
        if t > t_end {
            continue;
        }
        // The corner is at the origin (the preset's mid-travel).
        cmd_min = cmd_min.min(cx[i].hypot(cy[i]));
        head_min = head_min.min(tx[i].hypot(ty[i]));
        contour_max = contour_max.max(ce[i]);
    }
    assert!(
        (cmd_min * 1e6 - p.corner_rounding_um).abs() < 0.05,
        "commanded closest approach {} um, planned {} um",
        cmd_min * 1e6,
        p.corner_rounding_um
    );
    assert!((head_min * 1e6 - p.toolhead_corner_rounding_um).abs() < 1e-9);
    assert!((contour_max * 1e6 - p.max_contour_error_um).abs() < 1e-9);
}

fn corner_err(text: &str) -> String {
    let r = settle::expand::parse(text, Path::new("bad.toml"))
        .and_then(|(sc, src)| settle::expand::expand(&sc, &src));
    match r {
        Ok(runs) => panic!("expected an error, got {} runs", runs.len()),
        Err(e) => {
            assert!(e.is_input_error(), "{e}");
            e.to_string()
        }
    }
}

/// The 1-based line of `text` that starts with `key`.
fn line_of(text: &str, key: &str) -> usize {
    1 + text
        .lines()
        .position(|l| l.starts_with(key))
        .expect("key in text")
}

#[test]
fn bad_corner_input_names_file_line_and_key() {
    let good = scenario();
    // Unknown key in [corner]: its line, and the allowed keys.
    let text = good.replace("leg_out_mm =", "leg_ot_mm = 1\nleg_out_mm =");
    let msg = corner_err(&text);
    let line = line_of(&text, "leg_ot_mm");
    assert!(msg.starts_with(&format!("bad.toml:{line}:")), "{msg}");
    assert!(
        msg.contains("leg_ot_mm") && msg.contains("blend_deviation_mm"),
        "{msg}"
    );
    // Unknown strategy in the sweep: the sweep key's line and the allowed names.
    let text = good.replace("\"exact_stop\", \"junction", "\"exact\", \"junction");
    let msg = corner_err(&text);
    let line = line_of(&text, "\"corner.strategy\"");
    assert!(msg.starts_with(&format!("bad.toml:{line}:")), "{msg}");
    assert!(msg.contains("sweep.corner.strategy"), "{msg}");
    assert!(
        msg.contains("exact_stop, junction_deviation, square_corner_velocity, blend"),
        "{msg}"
    );
    // An angle outside 0-180 (swept): blames the sweep key.
    let msg = corner_err(&good.replace("[0, 60, 90, 180]", "[0, 200]"));
    assert!(
        msg.contains("sweep.corner.angle_deg") && msg.contains("200"),
        "{msg}"
    );
    // An unknown base strategy: blames corner.strategy.
    let text = good.replace("angle_deg = 90.0", "angle_deg = 90.0\nstrategy = \"round\"");
    let msg = corner_err(&text);
    assert!(
        msg.starts_with(&format!("bad.toml:{}:", line_of(&text, "strategy ="))),
        "{msg}"
    );
    // A leg leaving the belt travel (+-165 mm on the preset).
    let msg = corner_err(&good.replace(&format!("leg_in_mm = {LEG}"), "leg_in_mm = 400"));
    assert!(
        msg.contains("corner.leg_in_mm") && msg.contains("belt travel"),
        "{msg}"
    );
    // A swept parameter [corner] does not have.
    let msg = corner_err(&good.replace("profile = [", "\"corner.radius_mm\" = [1]\nprofile = ["));
    assert!(
        msg.contains("corner.radius_mm") && msg.contains("corner.angle_deg"),
        "{msg}"
    );
    // Both a move and a corner, and neither.
    let msg = corner_err(&good.replace("[limits]", "[move]\ndistance_mm = 5\n[limits]"));
    assert!(msg.contains("not both"), "{msg}");
    let start = good.find("[corner]").expect("corner");
    let end = good.find("[limits]").expect("limits");
    let none = format!("{}{}", &good[..start], &good[end..]).replace("\"corner.", "\"x.");
    let msg = corner_err(&none);
    assert!(msg.contains("[move]") && msg.contains("[corner]"), "{msg}");
    // A corner on a machine given by its modes (one axis).
    let text = good.replace(
        "preset = \"printer_xy\"\ndriver_model = \"linear\"",
        "modes = [{ frequency_hz = 40.0, damping_ratio = 0.05 }]",
    );
    let msg = corner_err(&text);
    assert!(msg.contains("2 or 3 axes"), "{msg}");
    // PVT kinds are point-to-point steps, not path speed laws.
    let msg = corner_err(&good.replace(
        "profile = [\"trapezoid\", \"scurve\"]",
        "profile = [\"pvt_sym\"]",
    ));
    assert!(
        msg.contains("sweep.profile") && msg.contains("fourjerk"),
        "{msg}"
    );
    // Axes the machine does not have.
    let msg = corner_err(&good.replace(
        "angle_deg = 90.0",
        "angle_deg = 90.0\naxes = [\"x\", \"z\"]",
    ));
    assert!(
        msg.contains("corner.axes") && msg.contains("no axis `z`"),
        "{msg}"
    );
}

/// The next f64 above (`up`) or below `x > 0`.
fn next(x: f64, up: bool) -> f64 {
    f64::from_bits(if up { x.to_bits() + 1 } else { x.to_bits() - 1 })
}

#[test]
fn corner_deviations_and_square_corner_velocity_are_bounded_as_written_and_swept() {
    // Each key's range (crate::spec::DEVIATION_RANGE_MM for the deviations: 1 nm to 100 m;
    // SPEED_RANGE_MM_S for the square corner velocity): its ends are taken, the next f64
    // beyond either end is refused with the key, its line, the range and the value; a
    // swept value is checked the same way and blames the sweep key.
    let good = scenario();
    for (key, written, lo, hi, range) in [
        (
            "junction_deviation_mm",
            JD,
            1e-6,
            1e5,
            "from 1e-6 to 1e5 (mm)",
        ),
        (
            "square_corner_velocity_mm_s",
            SCV,
            1e-3,
            1e6,
            "from 1e-3 to 1e6 (mm/s)",
        ),
        (
            "blend_deviation_mm",
            BLEND,
            1e-6,
            1e5,
            "from 1e-6 to 1e5 (mm)",
        ),
    ] {
        let at = |x: f64| good.replace(&format!("{key} = {written}\n"), &format!("{key} = {x}\n"));
        for x in [lo, hi] {
            let text = at(x);
            assert_ne!(text, good);
            settle::expand::parse_runs(&text, Path::new("bad.toml"))
                .unwrap_or_else(|e| panic!("{key} = {x}: {e}"));
        }
        for x in [next(lo, false), next(hi, true), 0.0, f64::INFINITY] {
            let text = at(x);
            let msg = corner_err(&text);
            let line = line_of(&text, key);
            assert!(msg.starts_with(&format!("bad.toml:{line}:")), "{msg}");
            assert!(msg.contains(&format!("key `corner.{key}`")), "{msg}");
            assert!(
                msg.contains(range) && msg.contains(&format!("got {x}")),
                "{msg}"
            );
        }
        // Swept: each value is checked; the bad one blames the sweep key and its line.
        let text = format!("{good}\"corner.{key}\" = [{lo}, {}]\n", next(hi, true));
        let msg = corner_err(&text);
        let line = line_of(&text, &format!("\"corner.{key}\""));
        assert!(msg.starts_with(&format!("bad.toml:{line}:")), "{msg}");
        assert!(msg.contains(&format!("key `sweep.corner.{key}`")), "{msg}");
        assert!(msg.contains(range), "{msg}");
        let text = format!("{good}\"corner.{key}\" = [{lo}, {hi}]\n");
        let runs = settle::expand::parse_runs(&text, Path::new("bad.toml"))
            .unwrap_or_else(|e| panic!("{key} swept over its range: {e}"))
            .1;
        assert_eq!(runs.len(), 64);
    }
}
