//! Raster scan kinematics: the fly axis scans at constant speed inside the region and
//! turns around outside it with continuous acceleration, the step axis steps inside the
//! window and is at its target at re-entry, the overhead is the shortest window, every
//! step kind works, and the fly-overhead formulas with a slow-down before the edge.

use settle_planner::pvt::{PvtLimits, check};
use settle_planner::raster::{RasterSpec, StepPlacement, plan, slowdown_fly_overhead_s};
use settle_planner::{Limits, ProfileKind, ProfileParams};

fn spec(kind: ProfileKind, step: f64) -> RasterSpec {
    RasterSpec {
        lines: 5,
        width: 0.01,
        step,
        v_scan: 0.5,
        fly_amax: 500.0,
        fly_jmax: None,
        step_kind: kind,
        step_limits: Limits::new(0.05, 2.0, Some(200.0)).expect("limits"),
        step_params: ProfileParams::default(),
        placement: StepPlacement::AtExit,
        settle_margin_s: 0.0,
    }
}

#[test]
fn lines_turnarounds_and_steps() {
    for kind in ProfileKind::ALL {
        for step in [10e-6, 0.002, -0.0005] {
            for placement in [StepPlacement::AtExit, StepPlacement::Centered] {
                let mut s = spec(kind, step);
                s.placement = placement;
                s.settle_margin_s = 0.001;
                let r = plan(&s).unwrap_or_else(|e| panic!("{kind} {step}: {e}"));
                let ctx = format!("{kind} step={step} {placement:?}");
                // The fly axis: continuous acceleration, within its limits.
                let lim = PvtLimits {
                    vmax: s.v_scan,
                    amax: s.fly_amax,
                    jmax: None,
                    accel_jump_tol: 0.0,
                };
                assert!(
                    check(&r.fly, &lim).is_ok(),
                    "{ctx}: {:?}",
                    check(&r.fly, &lim)
                );
                let ov = r.overhead;
                assert!(ov.per_line_s >= 2.0 * ov.t_out_min_s * (1.0 - 1e-12));
                assert!(ov.per_line_s >= ov.step_s + s.settle_margin_s - 1e-15);
                assert!(
                    (ov.per_line_s - (2.0 * ov.t_out_min_s).max(ov.step_s + 0.001)).abs() < 1e-15
                );
                assert_eq!(r.turnarounds.len(), s.lines - 1);
                let x = &r.trajectory.axes()[0];
                let y = &r.trajectory.axes()[1];
                let mut prev_reentry = 2.0 * s.v_scan / (s.fly_amax / 2f64.sqrt());
                for tr in &r.turnarounds {
                    // Constant speed across the line before the exit.
                    for k in 1..10 {
                        let t = prev_reentry + (tr.exit_s - prev_reentry) * k as f64 / 10.0;
                        let st = x.state_at(t);
                        assert!(
                            (st.v.abs() - s.v_scan).abs() < 1e-9 && st.a.abs() < 1e-6,
                            "{ctx}: {st:?}"
                        );
                        assert!(st.p >= -1e-12 && st.p <= s.width + 1e-12);
                    }
                    // Outside the region between exit and re-entry.
                    for k in 1..20 {
                        let t = tr.exit_s + (tr.reentry_s - tr.exit_s) * k as f64 / 20.0;
                        let p = x.state_at(t).p;
                        assert!(
                            p < -1e-12 || p > s.width + 1e-12,
                            "{ctx}: x={p} inside at {t}"
                        );
                    }
                    let re = x.state_at(tr.reentry_s);
                    assert!(
                        (re.p - tr.x_edge).abs() < 1e-12 && (re.v.abs() - s.v_scan).abs() < 1e-9
                    );
                    // The step inside the window, ending the margin before re-entry at the
                    // latest, at rest on its target at re-entry.
                    assert!(tr.step_start_s >= tr.exit_s - 1e-15);
                    assert!(tr.step_end_s <= tr.reentry_s - 0.001 + 1e-12, "{ctx}");
                    let ys = y.state_at(tr.reentry_s);
                    assert!(
                        (ys.p - tr.y_to).abs() <= 1e-12 * step.abs().max(1e-3),
                        "{ctx}: {ys:?} vs {}",
                        tr.y_to
                    );
                    assert!(ys.v.abs() < 1e-9, "{ctx}: {ys:?}");
                    let at_exit = y.state_at(tr.exit_s).p;
                    assert!(
                        (at_exit - tr.y_from).abs() <= 1e-12 * (1.0 + tr.y_from.abs()),
                        "{ctx}"
                    );
                    prev_reentry = tr.reentry_s;
                }
                let end = r.trajectory.duration_s();
                let (xe, ye) = (x.state_at(end), y.state_at(end));
                assert!(xe.v.abs() < 1e-9 && xe.a.abs() < 1e-6, "{ctx}");
                assert!(
                    (ye.p - step * 4.0).abs() < 1e-12 * (1.0 + step.abs()),
                    "{ctx}"
                );
            }
        }
    }
}

/// Scan speed 0.5 and fly acceleration limit 500 give `t_out = 2 v/a = 0.002` s; a step
/// that needs longer stretches the window to the step's duration (`t_edge` is the excess).
#[test]
fn overhead_of_a_worked_case() {
    let s = spec(ProfileKind::PvtSym, 0.002);
    let r = plan(&s).expect("raster");
    assert!((r.overhead.t_out_min_s - 0.002).abs() < 1e-15);
    let t_step = ProfileKind::PvtSym
        .rest_to_rest(0.0, 0.002, &s.step_limits)
        .expect("step")
        .duration_s();
    assert!(t_step > 0.004);
    assert!((r.overhead.per_line_s - t_step).abs() < 1e-15);
    assert!((r.overhead.t_edge_s - (t_step - 0.004)).abs() < 1e-15);
    assert!((r.turn.t_out_s - t_step / 2.0).abs() < 1e-15);
    // A tiny step fits in the fastest turnaround: the overhead is the fly axis's 4 v/a.
    let r = plan(&spec(ProfileKind::Trapezoid, 1e-7)).expect("raster");
    assert_eq!(r.overhead.t_edge_s, 0.0);
    assert!((r.overhead.per_line_s - 0.004).abs() < 1e-15);
    assert!((r.turn.d_out - 0.5 * 0.004 / 3.0).abs() < 1e-15);
}

/// The fly-overhead formulas with a slow-down before the edge: without slow-down the out
/// time is the 2-segment turnaround's `2 v/a`. The overhead grows with the slow-down
/// `v_diff` where the step axis sets the overhead (`t_add` grows, nothing else depends on
/// it) but not where the fly axis does: there slowing down before the edge shortens
/// `t_out` by more than `t_add` costs (at the price of scanning slower near the edge),
/// which is why the raster planner keeps `v_diff = 0` and scans at `v_scan`.
#[test]
fn slowdown_fly_overhead_formulas() {
    for t_ln in [0.001, 0.002, 0.01] {
        let (t_out, t_add, total) = slowdown_fly_overhead_s(0.5, 500.0, t_ln, 0.0);
        assert!((t_out - 0.002).abs() < 1e-15 && t_add == 0.0 && total == t_out);
    }
    let (_, _, at0) = slowdown_fly_overhead_s(0.5, 500.0, 0.002, 0.0);
    let (t_out, t_add, at1) = slowdown_fly_overhead_s(0.5, 500.0, 0.002, 0.1);
    assert!((t_out - 2.0 * 0.002 * 0.4 / 1.2).abs() < 1e-15);
    assert!((t_add - 0.002 * 0.1 / 1.5).abs() < 1e-15);
    assert!(
        at1 < at0,
        "fly-limited: slowing down shortens the overhead ({at1} < {at0})"
    );
}

#[test]
fn bad_specs_are_errors() {
    let mut s = spec(ProfileKind::SCurve, 0.001);
    s.lines = 0;
    assert!(plan(&s).is_err());
    let mut s = spec(ProfileKind::SCurve, 0.0);
    assert!(plan(&s).is_err());
    s.step = 0.001;
    s.v_scan = -1.0;
    assert!(plan(&s).is_err());
    let mut s = spec(ProfileKind::SCurve, 0.001);
    s.step_limits = Limits::new(0.05, 2.0, None).expect("limits");
    assert!(plan(&s).is_err(), "scurve steps need a jerk limit");
}
