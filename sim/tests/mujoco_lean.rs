//! The MuJoCo lean path ([`Plant::step_samples`]): RK4 steps spanning several 10 kHz
//! samples (`|lambda| h <= MujocoConfig::long_lambda_h`, the full driver's held torque at
//! `w_e h <= MujocoConfig::long_explicit_w_h`) with the samples in between interpolated
//! (cubic Hermite). What the harness reports without a recording comes from here, so this
//! checks it against `settle validate`'s thresholds (frequency 0.5 %, residual 2 %,
//! engines 3 %) and against the per-sample path (one step per sample, `|lambda| h <= 0.2`)
//! and a converged reference (`|lambda| h <= 0.05`).

#![cfg(feature = "mujoco")]

mod common;
mod lean_support;

use common::run;
use lean_support::run_lean;
use settle_planner::{Limits, Profile, ProfileKind};
use settle_sim::machine::{AxisMachine, Frame, Transmission};
use settle_sim::mujoco::{MujocoConfig, MujocoPlant};
use settle_sim::{AxisModel, DriverMode, ModalPlant, Mode, Observation, Plant};

/// `settle validate`'s frequency threshold (%).
const FREQUENCY_PCT: f64 = 0.5;
/// `settle validate`'s residual threshold (%).
const RESIDUAL_PCT: f64 = 2.0;
/// `settle validate`'s engines threshold (%).
const ENGINES_PCT: f64 = 3.0;
const DT: f64 = 1e-4;

/// The `printer_xy` preset's Y axis (as in `mujoco_step_budget.rs`).
fn preset_y() -> AxisMachine {
    let mut a = common::printer_y();
    a.carriage_kg = 0.2;
    a.beam_kg = 0.93;
    if let Transmission::Belt(b) = &mut a.transmission {
        b.ea_n = 30_000.0;
        b.span_mm = 350.0;
        b.carriage_at_zero_mm = 175.0;
        b.damping_ratio = 0.08;
    }
    a.frame = Some(Frame {
        mass_kg: 5.0,
        stiffness_n_per_m: 2.84e6,
        damping_ratio: 0.05,
    });
    a
}

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
fn ringing(e: &[f64]) -> settle_sim::pencil::MeasuredMode {
    let y: Vec<f64> = e.iter().take(1200).step_by(2).copied().collect();
    let fit = settle_sim::pencil::fit(&y, 2.0 * DT, 8).expect("pencil fit");
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
    let axis = preset_y().compile(driver).expect("y");
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
