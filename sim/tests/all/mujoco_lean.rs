//! The MuJoCo lean path ([`Plant::step_samples`]): RK4 steps spanning several 10 kHz
//! samples (`|lambda| h <= MujocoConfig::long_lambda_h`, the full driver's held torque at
//! `w_e h <= MujocoConfig::long_explicit_w_h`) with the samples in between interpolated
//! (cubic Hermite). What the harness reports without a recording comes from here, so this
//! checks it against `settle validate`'s thresholds (frequency 0.5 %, residual 2 %,
//! engines 3 %) and against the per-sample path (one step per sample, `|lambda| h <= 0.2`)
//! and a converged reference (`|lambda| h <= 0.05`).

use crate::common::run;
use crate::lean_support::run_lean;
use settle_planner::{Limits, Profile, ProfileKind};
use settle_sim::mujoco::{MujocoConfig, MujocoPlant};
use settle_sim::{AxisModel, DriverMode, ModalPlant, Mode, Observation, Plant};

/// `settle validate`'s frequency threshold (%).
const FREQUENCY_PCT: f64 = 0.5;
/// `settle validate`'s residual threshold (%).
const RESIDUAL_PCT: f64 = 2.0;
/// `settle validate`'s engines threshold (%).
const ENGINES_PCT: f64 = 3.0;
const DT: f64 = 1e-4;

fn plant(axes: Vec<AxisModel>, config: MujocoConfig) -> MujocoPlant {
    MujocoPlant::new(axes, config).expect("plant")
}

fn with_lambda_h(max_lambda_h: f64) -> MujocoConfig {
    MujocoConfig {
        max_lambda_h,
        ..MujocoConfig::default()
    }
}

/// Toolhead error after the move (m), every sample, of axis `i`.
fn post_move(trace: &[(f64, Vec<Observation>)], t_end: f64, target: f64, i: usize) -> Vec<f64> {
    trace
        .iter()
        .filter(|(t, _)| *t >= t_end - 1e-12)
        .map(|(_, o)| o[i].toolhead_m - target)
        .collect()
}

fn peak(e: &[f64]) -> f64 {
    e.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// Largest |toolhead difference| between two traces on the same sample times, relative to
/// the peak |toolhead - commanded| of `b`.
fn trace_error(a: &[(f64, Vec<Observation>)], b: &[(f64, Vec<Observation>)], i: usize) -> f64 {
    assert_eq!(a.len(), b.len());
    let mut worst = 0.0f64;
    let mut defl = 0.0f64;
    for ((ta, oa), (tb, ob)) in a.iter().zip(b) {
        assert!((ta - tb).abs() < 1e-9);
        worst = worst.max((oa[i].toolhead_m - ob[i].toolhead_m).abs());
        defl = defl.max((ob[i].toolhead_m - ob[i].commanded_m).abs());
    }
    worst / defl
}

/// The dominant post-move ringing (frequency by matrix pencil).
fn ringing(e: &[f64]) -> settle_identify::fit::pencil::MeasuredMode {
    let y: Vec<f64> = e.iter().take(1200).step_by(2).copied().collect();
    let fit = settle_identify::fit::pencil::fit(&y, 2.0 * DT, 8).expect("pencil fit");
    *fit.iter()
        .find(|m| m.frequency_hz > 5.0)
        .expect("an oscillatory mode")
}

fn moves() -> Vec<(ProfileKind, Profile)> {
    let lim = Limits::new(0.3, 3.0, Some(100.0)).expect("limits");
    let mut out = Vec::new();
    for d in [0.001, 0.01, 0.1] {
        for kind in [ProfileKind::Trapezoid, ProfileKind::SCurve] {
            out.push((kind, kind.rest_to_rest(0.0, d, &lim).expect("plan")));
        }
    }
    out
}

/// Lean vs per-sample vs converged on the preset's Y axis for one driver model.
fn compare(driver: DriverMode, lean_config: MujocoConfig) -> (f64, f64, f64, f64) {
    let axis = crate::common::printer_preset(true)
        .compile(driver)
        .expect("y");
    let lean = plant(vec![axis.clone()], lean_config);
    let per_sample = plant(vec![axis.clone()], MujocoConfig::default());
    let fine = plant(vec![axis], with_lambda_h(0.05));
    eprintln!(
        "{driver}: long step {:.1} us (cap {:.1} us), per-sample step {:.1} us, reference {:.1} us",
        lean.model(0).nominal_long_step_s() * 1e6,
        lean.long_cap_s(0) * 1e6,
        per_sample.model(0).nominal_step_s() * 1e6,
        fine.model(0).nominal_step_s() * 1e6
    );
    let (mut w_res, mut w_res_ps, mut w_freq, mut w_trace) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for (kind, p) in moves() {
        let (t_end, target) = (p.duration_s(), p.end().p);
        let one = std::slice::from_ref(&p);
        let a = run_lean(&lean, one, DT, 0.3);
        let b = run(&per_sample, one, DT, 0.3);
        let r = run(&fine, one, DT, 0.3);
        let (ea, eb, er) = (
            post_move(&a, t_end, target, 0),
            post_move(&b, t_end, target, 0),
            post_move(&r, t_end, target, 0),
        );
        let (ma, mr) = (ringing(&ea), ringing(&er));
        let df = (ma.frequency_hz / mr.frequency_hz - 1.0) * 100.0;
        let dr = (peak(&ea) / peak(&er) - 1.0) * 100.0;
        let dr_ps = (peak(&eb) / peak(&er) - 1.0) * 100.0;
        let tr = trace_error(&a, &r, 0);
        let tr_ps = trace_error(&b, &r, 0);
        eprintln!(
            "{driver} {kind} {:5.1} mm: residual lean {:.4} / per-sample {:.4} / reference {:.4} um ({dr:+.3} % / {dr_ps:+.3} %), ringing {:.3} Hz ({df:+.4} %), trace error {tr:.2e} / {tr_ps:.2e} of the peak deflection",
            p.end().p * 1e3,
            peak(&ea) * 1e6,
            peak(&eb) * 1e6,
            peak(&er) * 1e6,
            mr.frequency_hz,
        );
        w_res = w_res.max(dr.abs());
        w_res_ps = w_res_ps.max(dr_ps.abs());
        w_freq = w_freq.max(df.abs());
        w_trace = w_trace.max(tr);
        let last = (&a.last().expect("a").1[0], &b.last().expect("b").1[0]);
        assert_eq!(last.0.lost_steps, 0);
        assert_eq!(last.1.lost_steps, 0);
    }
    eprintln!(
        "{driver}: worst residual {w_res:.3} % (per-sample {w_res_ps:.3} %), frequency {w_freq:.4} %, trace {w_trace:.2e}"
    );
    (w_res, w_res_ps, w_freq, w_trace)
}

/// The linear driver (the path `settle validate`, the sweeps' default machine models and
/// the bench's linear case take): the lean path at its default long step (2.6 samples per
/// MuJoCo step on the preset's Y axis) is within 1e-5 of the peak deflection of the
/// converged reference over the whole trace, the same as the per-sample path for every
/// purpose: residual and ringing frequency agree to 1e-3 %.
#[test]
fn linear_driver_lean_path_matches_the_converged_reference() {
    let (res, res_ps, freq, trace) = compare(DriverMode::Linear, MujocoConfig::default());
    assert!(res <= RESIDUAL_PCT && freq <= FREQUENCY_PCT);
    // Far tighter than validate: RK4 at |lambda| h = 0.5 and the Hermite interpolation
    // move nothing measurable (measured 1.8e-6 and 1e-4 %).
    assert!(trace < 2e-5, "trace error {trace}");
    assert!(res < 1e-3 && res_ps < 1e-3, "residual {res} / {res_ps} %");
    assert!(freq < 1e-3, "frequency {freq} %");
}

/// The full stepper driver: the lean path's residual within `settle validate`'s 2 % of a
/// converged reference (4x smaller steps, one per 26 us) on 1, 10 and 100 mm trapezoids and
/// S-curves, the ringing frequency within 0.5 %; nothing lost. The residuals here are a few
/// microsteps' worth and scatter by about 1-3 % between step sizes (the per-sample path at
/// its default step is off by up to 2.8 % on the 100 mm S-curve, printed for comparison).
#[test]
fn full_driver_lean_path_is_within_the_validate_thresholds() {
    let (res, _, freq, trace) = compare(DriverMode::Full, MujocoConfig::default());
    assert!(res <= RESIDUAL_PCT, "residual {res} %");
    assert!(freq <= FREQUENCY_PCT, "frequency {freq} %");
    assert!(trace <= ENGINES_PCT / 100.0, "trace {trace}");
}

/// `settle validate`'s single-mode cases through the lean path: 40 Hz (zeta 0.05, 0.02) and
/// 120 Hz (zeta 0.02) after 2, 20 and 100 mm trapezoids and S-curves, at the harness's
/// 10 kHz (one MuJoCo step per 10 samples for 40 Hz: the 1 ms cap) and at 1 kHz: the whole
/// toolhead trace against the exact modal plant (engines 3 %), and the post-move residual
/// peak (residual 2 %, relative to the larger of the residual and 1e-3 of the static
/// deflection, as in `mujoco_modes.rs`, for moves whose residual cancels).
#[test]
fn single_modes_on_the_lean_path_match_the_exact_modal_plant() {
    let trap = Limits::new(0.3, 5.0, None).expect("limits");
    let sc = Limits::new(0.3, 5.0, Some(200.0)).expect("limits");
    let mut worst = (0.0f64, 0.0f64);
    for mode in [
        Mode::new(40.0, 0.05, 1.0).expect("mode"),
        Mode::new(40.0, 0.02, 1.0).expect("mode"),
        Mode::new(120.0, 0.02, 1.0).expect("mode"),
    ] {
        let axis = AxisModel::from_modes("x", &[mode]).expect("axis");
        let mj = plant(vec![axis.clone()], MujocoConfig::default());
        for dt in [1e-4, 1e-3] {
            let modal = ModalPlant::new(vec![axis.clone()], dt).expect("modal");
            for d in [0.002, 0.02, 0.1] {
                for p in [
                    settle_planner::trapezoid::rest_to_rest(0.0, d, &trap).expect("plan"),
                    settle_planner::scurve::rest_to_rest(0.0, d, &sc).expect("plan"),
                ] {
                    let one = std::slice::from_ref(&p);
                    let a = run_lean(&mj, one, dt, 0.3);
                    let b = run(&modal, one, dt, 0.3);
                    let tr = trace_error(&a, &b, 0);
                    let (t_end, target) = (p.duration_s(), p.end().p);
                    let (ra, rb) = (
                        peak(&post_move(&a, t_end, target, 0)),
                        peak(&post_move(&b, t_end, target, 0)),
                    );
                    let w = mode.omega();
                    let static_defl = 5.0 / (w * w);
                    let rel = (ra - rb).abs() / rb.max(1e-3 * static_defl);
                    eprintln!(
                        "{:5.0} Hz zeta {:.2} dt {:.0e} {:5.1} mm: residual lean {:.4e} m, modal {:.4e} m ({rel:.1e}); trace {tr:.1e}",
                        mode.frequency_hz(),
                        mode.damping_ratio(),
                        dt,
                        d * 1e3,
                        ra,
                        rb
                    );
                    worst = (worst.0.max(rel), worst.1.max(tr));
                }
            }
        }
    }
    eprintln!("worst: residual {:.1e}, trace {:.1e}", worst.0, worst.1);
    assert!(worst.0 < RESIDUAL_PCT / 100.0 && worst.1 < ENGINES_PCT / 100.0);
    // RK4 at |w h| <= 0.5 (or the 1 ms cap) with the Hermite interpolation is far inside
    // both: a loss of accuracy (a step too long, an interpolation off by a sample) shows.
    assert!(worst.0 < 1e-3, "residual {}", worst.0);
    assert!(worst.1 < 1e-3, "trace {}", worst.1);
}

/// Both printer axes moving at once (the fixture printer, full driver): the lean path
/// steps each axis with its own long step in lockstep over the samples; residuals within
/// 3 % of the per-sample path's, nothing lost, and a repeated run is bit-identical.
#[test]
fn two_axes_on_the_lean_path_match_the_per_sample_path_and_repeat() {
    let lim = Limits::new(0.3, 3.0, Some(100.0)).expect("limits");
    let axes = vec![
        crate::common::printer_x()
            .compile(DriverMode::Full)
            .expect("x"),
        crate::common::printer_y()
            .compile(DriverMode::Full)
            .expect("y"),
    ];
    let mj = plant(axes, MujocoConfig::default());
    for kind in [ProfileKind::SCurve, ProfileKind::Trapezoid] {
        let p = kind.rest_to_rest(0.0, 0.01, &lim).expect("plan");
        let profiles = [p.clone(), p.clone()];
        let a = run_lean(&mj, &profiles, DT, 0.3);
        let b = run(&mj, &profiles, DT, 0.3);
        assert_eq!(a, run_lean(&mj, &profiles, DT, 0.3), "bit-identical repeat");
        let (t_end, target) = (p.duration_s(), p.end().p);
        for (i, name) in ["x", "y"].iter().enumerate() {
            let (ra, rb) = (
                peak(&post_move(&a, t_end, target, i)),
                peak(&post_move(&b, t_end, target, i)),
            );
            let d = (ra / rb - 1.0) * 100.0;
            let last = &a.last().expect("a").1[i];
            eprintln!(
                "{kind} {name}: residual lean {:.3} um, per-sample {:.3} um ({d:+.2} %), max load angle {:.1} deg",
                ra * 1e6,
                rb * 1e6,
                last.max_load_angle_rad.expect("motor").to_degrees()
            );
            assert!(d.abs() <= ENGINES_PCT, "{kind} {name}: {d} %");
            assert_eq!(last.lost_steps, 0);
        }
    }
}

/// A sample that fails the checks (here a blow-up limit of 1 um, exceeded early in the
/// move) ends the call there, and the state is at that sample: what `observe` then shows
/// is that sample (commanded position bit for bit, toolhead within 1e-9 of the
/// interpolated one), close to the per-sample path's at the same time.
#[test]
fn a_failed_sample_leaves_the_state_at_that_sample() {
    let lim = Limits::new(0.3, 3.0, Some(100.0)).expect("limits");
    let p = ProfileKind::SCurve
        .rest_to_rest(0.0, 0.01, &lim)
        .expect("plan");
    for driver in [DriverMode::Linear, DriverMode::Full] {
        let mj = plant(
            vec![
                crate::common::printer_preset(true)
                    .compile(driver)
                    .expect("y"),
            ],
            MujocoConfig::default(),
        );
        let mut st = mj.initial_state(&[p.start()]).expect("state");
        // The first piece of the profile (constant jerk), whole samples only.
        let first = p.iter().next().expect("a segment").2.duration_s();
        let n = (first / DT).floor() as usize;
        let cmds: Vec<_> = (0..n).map(|i| p.state_at(i as f64 * DT)).collect();
        let (mut c, mut h) = (vec![0.0; n], vec![0.0; n]);
        let blowup = 1e-6;
        let k = mj
            .step_samples(&mut st, &cmds, DT, blowup, &mut c, &mut h)
            .expect("no step fails")
            .expect("implemented");
        assert!(k < n, "the limit is exceeded within the piece");
        let mut o = [Observation::default()];
        mj.observe(&st, &mut o);
        let per_sample = run(&mj, std::slice::from_ref(&p), DT, 0.0);
        let (t, ref_o) = &per_sample[k];
        eprintln!(
            "{driver}: stopped after {k} of {n} samples (t = {t:.4} s): toolhead - command {:.3e} m (interpolated {:.3e}, per-sample path {:.3e})",
            o[0].toolhead_m - o[0].commanded_m,
            h[k - 1] - c[k - 1],
            ref_o[0].toolhead_m - ref_o[0].commanded_m
        );
        assert_eq!(o[0].commanded_m, c[k - 1]);
        assert!((o[0].toolhead_m - o[0].commanded_m).abs() > blowup);
        assert!((o[0].toolhead_m - h[k - 1]).abs() < 1e-9);
        assert!((o[0].toolhead_m - ref_o[0].toolhead_m).abs() < 1e-8);
        assert!(
            (h[k - 2] - c[k - 2]).abs() <= blowup,
            "the samples before pass"
        );
    }
}
