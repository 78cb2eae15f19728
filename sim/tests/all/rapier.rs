//! The rapier backend against the modal reference and the closed form: the linear
//! (stiff-spring) driver mode within validate's thresholds, free-decay frequency and
//! numerical damping, step-size convergence, bit-identical repeats.

use crate::common::{printer_x, printer_y, run, stage_x};
use settle_planner::{Limits, Profile, ProfileKind};
use settle_sim::closed_form::LinearResponse;
use settle_sim::machine::AxisMachine;
use settle_sim::{
    AxisModel, BeltModel, DriverMode, ModalPlant, Observation, RapierOptions, RapierPlant,
};

const DT: f64 = 1e-4;

fn frozen(max_step_s: Option<f64>) -> RapierOptions {
    RapierOptions {
        max_step_s,
        belt: BeltModel::Frozen,
    }
}

fn post_move(trace: &[(f64, Vec<Observation>)], t_end: f64, target: f64) -> Vec<(f64, f64)> {
    trace
        .iter()
        .filter(|(t, _)| *t >= t_end)
        .map(|(t, o)| (*t, o[0].toolhead_m - target))
        .collect()
}

fn machines() -> Vec<(&'static str, AxisMachine, Limits)> {
    let printer = Limits::new(0.3, 3.0, Some(100.0)).expect("limits");
    let stage = Limits::new(0.05, 2.0, Some(200.0)).expect("limits");
    vec![
        ("printer x", printer_x(), printer),
        ("printer y (frame mode)", printer_y(), printer),
        ("ball-screw stage", stage_x(), stage),
    ]
}

/// The stiff-spring (linear) driver on rapier reproduces the modal reference: residual
/// peak within 2 % of the closed form, the whole toolhead trace within 1 % of the
/// residual, settle-relevant error below 0.1 um.
#[test]
fn linear_driver_on_rapier_matches_the_modal_reference() {
    for (name, m, lim) in machines() {
        let axis = m.compile(DriverMode::Linear).expect("compile");
        for kind in [ProfileKind::Trapezoid, ProfileKind::SCurve] {
            for d in [0.002, 0.01, 0.05] {
                let p = kind.rest_to_rest(0.0, d, &lim).expect("plan");
                let modal = ModalPlant::new(vec![axis.clone()], DT).expect("modal");
                let rapier = RapierPlant::new(vec![axis.clone()], frozen(None)).expect("rapier");
                let a = run(&modal, std::slice::from_ref(&p), DT, 0.4);
                let b = run(&rapier, std::slice::from_ref(&p), DT, 0.4);
                let (t_end, target) = (p.duration_s(), p.end().p);
                let cf = LinearResponse::new(&axis, &p).expect("closed form");
                let ea = post_move(&a, t_end, target);
                let eb = post_move(&b, t_end, target);
                let peak = |e: &[(f64, f64)]| e.iter().map(|x| x.1.abs()).fold(0.0, f64::max);
                let peak_cf = ea
                    .iter()
                    .map(|(t, _)| cf.error_at(*t).abs())
                    .fold(0.0, f64::max);
                let (pa, pb) = (peak(&ea), peak(&eb));
                assert!(
                    (pa - peak_cf).abs() <= 1e-7 * peak_cf.max(1e-9),
                    "{name} {kind} {d}: modal {pa} vs closed form {peak_cf}"
                );
                let rel = (pb - peak_cf).abs() / peak_cf.max(0.1e-6);
                assert!(
                    rel <= 0.02,
                    "{name} {kind} {d}: rapier residual {pb} vs closed form {peak_cf}: {rel}"
                );
                let worst = ea
                    .iter()
                    .zip(&eb)
                    .map(|(x, y)| (x.1 - y.1).abs())
                    .fold(0.0, f64::max);
                assert!(
                    worst <= (0.01 * pa).max(0.1e-6),
                    "{name} {kind} {d}: trace differs by {worst} m (residual {pa})"
                );
            }
        }
    }
}

/// A free decay on rapier has the analytic frequency (within 0.5 %) and damping (numerical
/// damping within 10 % of the physical), measured by the matrix pencil.
#[test]
fn free_decay_frequency_and_damping_on_rapier() {
    for (name, m, lim) in machines() {
        let axis = m.compile(DriverMode::Linear).expect("compile");
        let p = ProfileKind::Trapezoid
            .rest_to_rest(0.0, 0.01, &lim)
            .expect("plan");
        let cf = LinearResponse::new(&axis, &p).expect("closed form");
        let rapier = RapierPlant::new(vec![axis.clone()], frozen(None)).expect("rapier");
        let b = run(&rapier, std::slice::from_ref(&p), DT, 0.4);
        let e: Vec<f64> = post_move(&b, p.duration_s(), p.end().p)
            .iter()
            .step_by(2)
            .take(600)
            .map(|x| x.1)
            .collect();
        let fit = settle_identify::fit::pencil::fit(&e, 2.0 * DT, 2 * axis.lumped.dof())
            .expect("pencil fit");
        let (f, z, _) = cf.modes()[0];
        let got = fit
            .iter()
            .min_by(|a, b| {
                (a.frequency_hz - f)
                    .abs()
                    .total_cmp(&(b.frequency_hz - f).abs())
            })
            .expect("a mode");
        let df = got.frequency_hz / f - 1.0;
        let dz = got.damping_ratio / z - 1.0;
        eprintln!(
            "{name}: {f:.3} Hz zeta {z:.4}: rapier {:.3} Hz ({:+.4} %), zeta {:.4} ({:+.3} %)",
            got.frequency_hz,
            df * 100.0,
            got.damping_ratio,
            dz * 100.0
        );
        assert!(df.abs() <= 0.005, "{name}: frequency error {df}");
        assert!(dz.abs() <= 0.10, "{name}: numerical damping {dz}");
    }
}

/// Halving the step halves the error at least twice over (second order): the
/// toolhead trace against the modal reference, for steps of 4, 2, 1 and 0.5 x 1e-4 s.
#[test]
fn rapier_converges_with_the_step_size() {
    let lim = Limits::new(0.3, 3.0, Some(100.0)).expect("limits");
    let axis = printer_x().compile(DriverMode::Linear).expect("compile");
    let p = ProfileKind::Trapezoid
        .rest_to_rest(0.0, 0.01, &lim)
        .expect("plan");
    // Sample every 0.4 ms so that every step size divides the sample period.
    let dt = 4e-4;
    let modal = ModalPlant::new(vec![axis.clone()], dt).expect("modal");
    let a = run(&modal, std::slice::from_ref(&p), dt, 0.3);
    let mut errors = Vec::new();
    for h in [4e-4, 2e-4, 1e-4, 0.5e-4] {
        let rapier = RapierPlant::new(vec![axis.clone()], frozen(Some(h))).expect("rapier");
        let b = run(&rapier, std::slice::from_ref(&p), dt, 0.3);
        let worst = a
            .iter()
            .zip(&b)
            .map(|(x, y)| (x.1[0].toolhead_m - y.1[0].toolhead_m).abs())
            .fold(0.0, f64::max);
        errors.push((h, worst));
    }
    eprintln!("step size -> worst toolhead error vs modal: {errors:?}");
    for w in errors.windows(2) {
        let ratio = w[0].1 / w[1].1;
        assert!(
            ratio >= 3.0,
            "halving {} -> {} s reduced the error only {ratio:.2}x: {errors:?}",
            w[0].0,
            w[1].0
        );
    }
}

fn full_trace(axis: &AxisModel, p: &Profile) -> Vec<(f64, Vec<Observation>)> {
    let rapier = RapierPlant::new(vec![axis.clone()], RapierOptions::default()).expect("rapier");
    run(&rapier, std::slice::from_ref(p), DT, 0.2)
}

/// The same run twice gives the same numbers bit for bit (full driver, varying belt).
#[test]
fn repeated_runs_are_bit_identical() {
    let lim = Limits::new(0.3, 3.0, Some(100.0)).expect("limits");
    let axis = printer_y().compile(DriverMode::Full).expect("compile");
    let p = ProfileKind::SCurve
        .rest_to_rest(0.0123, 0.0377, &lim)
        .expect("plan");
    let a = full_trace(&axis, &p);
    let b = full_trace(&axis, &p);
    assert_eq!(a.len(), b.len());
    for ((ta, oa), (tb, ob)) in a.iter().zip(&b) {
        assert_eq!(ta.to_bits(), tb.to_bits());
        let bits = |o: &Observation| {
            [
                o.toolhead_m,
                o.carriage_m.unwrap_or(0.0),
                o.motor_angle_rad.unwrap_or(0.0),
                o.currents_a.map_or(0.0, |c| c[0]),
                o.currents_a.map_or(0.0, |c| c[1]),
            ]
            .map(f64::to_bits)
        };
        assert_eq!(bits(&oa[0]), bits(&ob[0]), "t = {ta}");
    }
}

/// The belt's span stiffness: with the carriage 100 mm off centre the post-move ringing
/// on rapier (varying belt) has the frequency of the model linearised at the *end*
/// position, not the start: the physics the modal backend leaves out.
#[test]
fn varying_belt_rings_at_the_end_position_frequency() {
    let lim = Limits::new(0.3, 3.0, Some(100.0)).expect("limits");
    let axis = printer_x().compile(DriverMode::Linear).expect("compile");
    let p = ProfileKind::Trapezoid
        .rest_to_rest(0.0, 0.1, &lim)
        .expect("plan");
    let rapier = RapierPlant::new(vec![axis.clone()], RapierOptions::default()).expect("rapier");
    let b = run(&rapier, std::slice::from_ref(&p), DT, 0.4);
    let e: Vec<f64> = post_move(&b, p.duration_s(), p.end().p)
        .iter()
        .step_by(2)
        .take(600)
        .map(|x| x.1)
        .collect();
    let fit = settle_identify::fit::pencil::fit(&e, 2.0 * DT, 6).expect("fit");
    let at = |x: f64| {
        let q = axis.lumped.equilibrium(x, None).expect("equilibrium");
        axis.lumped.natural_frequencies_hz(&q)[0]
    };
    let (f_start, f_end) = (at(0.0), at(0.1));
    let measured = fit[0].frequency_hz;
    eprintln!("start {f_start:.2} Hz, end {f_end:.2} Hz, rapier rings at {measured:.2} Hz");
    assert!((f_end / f_start - 1.0).abs() > 0.05, "{f_start} {f_end}");
    assert!(
        (measured / f_end - 1.0).abs() < 0.005,
        "{measured} vs {f_end}"
    );
}

/// Towards the motor the belt stiffens (here 7.7x at 20 mm from the pulley) and the fast
/// modes rise; the step shrinks with it, so the default step stays as accurate as a
/// 10x finer one across the travel.
#[test]
fn default_step_stays_accurate_where_the_belt_is_stiff() {
    let lim = Limits::new(0.3, 3.0, Some(100.0)).expect("limits");
    let axis = printer_x().compile(DriverMode::Linear).expect("compile");
    let p = ProfileKind::Trapezoid
        .rest_to_rest(0.0, -0.18, &lim)
        .expect("plan");
    let trace = |max_step_s| {
        let plant = RapierPlant::new(
            vec![axis.clone()],
            RapierOptions {
                max_step_s,
                belt: BeltModel::Varying,
            },
        )
        .expect("rapier");
        run(&plant, std::slice::from_ref(&p), DT, 0.3)
    };
    let (a, b) = (trace(None), trace(Some(1e-5)));
    let ea = post_move(&a, p.duration_s(), p.end().p);
    let eb = post_move(&b, p.duration_s(), p.end().p);
    let peak = eb.iter().map(|x| x.1.abs()).fold(0.0, f64::max);
    let worst = ea
        .iter()
        .zip(&eb)
        .map(|(x, y)| (x.1 - y.1).abs())
        .fold(0.0, f64::max);
    eprintln!(
        "residual {:.3} um, default vs 1e-5 s step: {:.4} um",
        peak * 1e6,
        worst * 1e6
    );
    assert!(worst <= 0.01 * peak, "{worst} of {peak}");
}
