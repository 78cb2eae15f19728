//! MuJoCo backend, single modes (`Lumped::from_modes`): measured frequency and numerical
//! damping against the analytic mode, residual vibration after trapezoid and S-curve moves
//! against the closed form, whole traces against the exact modal plant, bit-identical
//! repeats and step-size convergence.
//!
//! Thresholds: `settle validate`'s (frequency 0.5 %, residual 2 %, engines 3 %) and, because
//! RK4 at the default step is far better than that, tighter ones that catch a loss of
//! accuracy (e.g. a wrong integrator or a command that lags by a step).

use crate::mujoco_support::{Interval, ModalOne, MujocoOne, OneAxis, schedule};
use settle_planner::{Limits, Profile, Sample, State, scurve, trapezoid};
use settle_sim::Mode;
use settle_sim::closed_form::residual_envelope;
use settle_sim::lumped::Lumped;
use settle_sim::mujoco::{Integrator, MujocoConfig, MujocoModel};

/// Sample period of the runs (s), as the harness uses.
const DT: f64 = 1e-3;

fn modes() -> Vec<Mode> {
    vec![
        Mode::new(40.0, 0.05, 1.0).expect("mode"),
        Mode::new(40.0, 0.02, 1.0).expect("mode"),
        Mode::new(120.0, 0.02, 1.0).expect("mode"),
    ]
}

fn moves() -> Vec<(&'static str, Profile)> {
    let mut out = Vec::new();
    let trap = Limits::new(0.3, 5.0, None).expect("limits");
    let sc = Limits::new(0.3, 5.0, Some(200.0)).expect("limits");
    for d in [0.002, 0.02, 0.1] {
        out.push((
            "trapezoid",
            trapezoid::rest_to_rest(0.0, d, &trap).expect("plan"),
        ));
        out.push(("s-curve", scurve::rest_to_rest(0.0, d, &sc).expect("plan")));
    }
    out
}

/// Free vibration from a deflection `e0` with the command at rest: the damped frequency from
/// the mean spacing of the downward zero crossings (equally spaced by pi/wd in the exact
/// solution), the decay rate from a least-squares line through ln A(t) at every step, with
/// `A = sqrt(e^2 + ((e' + zeta w e)/wd)^2)` the exact solution's envelope (an integrator's
/// ripple on it averages out over the 40 periods). Returns (relative frequency error,
/// measured zeta - physical zeta).
fn free_vibration(mode: &Mode, config: MujocoConfig) -> (f64, f64) {
    let l = Lumped::from_modes(&[*mode]).expect("lumped");
    let model = MujocoModel::new(&l, config).expect("model");
    let e0 = 1e-4;
    let mut sim = model
        .state(&[e0], &[0.0], &State::default())
        .expect("state");
    let (w, wd, z) = (mode.omega(), mode.omega_d(), mode.damping_ratio());
    let h = model.nominal_step_s();
    let periods = 40.0;
    let steps = (periods * std::f64::consts::TAU / wd / h).round() as usize;
    let rest = Sample::default();
    let mut crossings = Vec::new();
    let (mut t_prev, mut e_prev) = (0.0, e0);
    // Sums for the least-squares slope of ln A against t.
    let (mut st, mut sy, mut stt, mut sty, mut count) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for _ in 0..steps {
        model.step(&mut sim, &rest, h).expect("step");
        let (t, e, ed) = (sim.time_s(), sim.q()[0], sim.qd()[0]);
        if e_prev > 0.0 && e <= 0.0 {
            crossings.push(t_prev + (t - t_prev) * e_prev / (e_prev - e));
        }
        (t_prev, e_prev) = (t, e);
        let y = e.hypot((ed + z * w * e) / wd).ln();
        (st, sy, stt, sty, count) = (st + t, sy + y, stt + t * t, sty + t * y, count + 1.0);
    }
    let n = crossings.len();
    assert!(n >= 30, "only {n} crossings");
    let period = (crossings[n - 1] - crossings[0]) / (n - 1) as f64;
    let freq_err = (std::f64::consts::TAU / period - wd) / wd;
    let slope = (count * sty - st * sy) / (count * stt - st * st);
    (freq_err, -slope / w - z)
}

#[test]
fn free_vibration_frequency_and_numerical_damping() {
    let mut all = modes();
    all.push(Mode::new(40.0, 0.0, 1.0).expect("mode"));
    all.push(Mode::new(350.0, 0.0, 1.0).expect("mode"));
    eprintln!("mode                 step       |w h|   freq error   numerical zeta");
    for mode in &all {
        let config = MujocoConfig::default();
        let (f_err, z_num) = free_vibration(mode, config);
        let h = MujocoModel::new(&Lumped::from_modes(&[*mode]).expect("lumped"), config)
            .expect("model")
            .nominal_step_s();
        eprintln!(
            "{:5.0} Hz zeta {:.2}   {h:.3e}  {:.3}   {f_err:+.2e}    {z_num:+.2e}",
            mode.frequency_hz(),
            mode.damping_ratio(),
            mode.omega() * h
        );
        // `settle validate`'s threshold: frequency within 0.5%; RK4 at |w h| <= 0.2 predicts
        // (w h)^4/120 < 1.4e-5.
        assert!(f_err.abs() < 0.005, "frequency error {f_err}");
        assert!(f_err.abs() < 5e-5, "frequency error {f_err} (RK4 budget)");
        // Numerical damping far below physical: RK4 predicts (w h)^5/144 < 2.3e-6.
        assert!(z_num.abs() < 1e-5, "numerical zeta {z_num}");
        if mode.damping_ratio() > 0.0 {
            assert!(z_num.abs() < 1e-3 * mode.damping_ratio());
        }
    }
}

#[test]
fn rk4_beats_the_first_order_integrators_at_the_same_step() {
    let mode = Mode::new(120.0, 0.0, 1.0).expect("mode");
    let mut errs = Vec::new();
    for integ in [Integrator::Rk4, Integrator::Euler, Integrator::ImplicitFast] {
        let config = MujocoConfig {
            integrator: integ,
            ..MujocoConfig::default()
        };
        let (f_err, z_num) = free_vibration(&mode, config);
        eprintln!(
            "120 Hz undamped, |w h| = 0.2, {:>12}: frequency error {f_err:+.2e}, numerical zeta {z_num:+.2e}",
            integ.mjcf_name()
        );
        errs.push(f_err.abs().max(z_num.abs()));
    }
    // Semi-implicit Euler shifts the frequency by about (w h)^2/24 = 1.7e-3 at w h = 0.2.
    assert!(errs[1] > 1e-3 && errs[1] < 3e-3, "Euler {}", errs[1]);
    assert!(errs[0] * 100.0 < errs[1] && errs[0] * 100.0 < errs[2]);
}

/// Run `plant` through `intervals`, returning the toolhead trace and the state at `t_at`.
fn run<P: OneAxis>(
    plant: &P,
    start: &State,
    intervals: &[Interval],
    t_at: f64,
) -> (Vec<f64>, Option<P::S>)
where
    P::S: Clone,
{
    let mut st = plant.initial_state(start);
    let mut trace = Vec::with_capacity(intervals.len());
    let mut at = None;
    for iv in intervals {
        if at.is_none() && iv.t0 >= t_at - 1e-12 {
            at = Some(st.clone());
        }
        plant.step(&mut st, &iv.cmd, iv.h);
        trace.push(plant.toolhead_m(&st));
    }
    (trace, at)
}

/// The MuJoCo run of a mode through a move: toolhead trace and (e, e') at the move's end.
fn mujoco_run(
    mode: &Mode,
    profile: &Profile,
    t_stop: f64,
    config: MujocoConfig,
) -> (Vec<f64>, (f64, f64)) {
    let l = Lumped::from_modes(&[*mode]).expect("lumped");
    let plant = MujocoOne::new(&l, config);
    let model = plant.model();
    let mut st = plant.initial_state(&profile.start());
    let mut trace = Vec::new();
    let mut at_end = None;
    for iv in schedule(profile, DT, t_stop) {
        if at_end.is_none() && iv.t0 >= profile.duration_s() - 1e-12 {
            let x = st.command().p;
            at_end = Some((st.q()[0] - x, st.qd()[0] - st.command().v));
        }
        plant.step(&mut st, &iv.cmd, iv.h);
        trace.push(model.toolhead_m(&st));
    }
    (trace, at_end.expect("the run covers the move end"))
}

#[test]
fn residual_after_moves_matches_the_closed_form() {
    let mut worst = 0.0f64;
    for mode in modes() {
        let (w, wd, z) = (mode.omega(), mode.omega_d(), mode.damping_ratio());
        for (kind, profile) in moves() {
            let t_end = profile.duration_s();
            let (_, (e, ed)) = mujoco_run(&mode, &profile, t_end + DT, MujocoConfig::default());
            let got = e.hypot((ed + z * w * e) / wd);
            let exact = residual_envelope(&profile, &mode);
            // Relative to the residual, floored at 1e-3 of the static deflection under the
            // peak acceleration (moves whose residual happens to cancel).
            let static_defl = 5.0 / (w * w);
            let rel = (got - exact).abs() / exact.max(1e-3 * static_defl);
            worst = worst.max(rel);
            eprintln!(
                "{:5.0} Hz zeta {:.2} {kind:>9} {:.3} m: residual {:.4e} m vs closed form {:.4e} m ({rel:.1e})",
                mode.frequency_hz(),
                z,
                profile.end().p,
                got,
                exact
            );
            assert!(rel < 0.02, "residual off by {rel}");
            // RK4 budget: the frequency error (w h)^4/120 = 1.4e-5 moves the residual by
            // about that times w T (< 1.3e-3 for these moves), relative to the larger of
            // residual and static deflection.
            let tight = (got - exact).abs() / exact.max(static_defl);
            assert!(tight < 1e-3, "residual off by {tight} (RK4 budget)");
        }
    }
    eprintln!("worst residual error vs closed form: {worst:.2e}");
}

#[test]
fn whole_trace_matches_the_modal_plant() {
    let mut worst = 0.0f64;
    for mode in modes() {
        for (kind, profile) in moves() {
            let t_stop = profile.duration_s() + 0.3;
            let (mj, _) = mujoco_run(&mode, &profile, t_stop, MujocoConfig::default());
            let modal = ModalOne::new(&[mode], DT);
            let (reference, _) = run(
                &modal,
                &profile.start(),
                &schedule(&profile, DT, t_stop),
                t_stop,
            );
            let cmd: Vec<f64> = schedule(&profile, DT, t_stop)
                .iter()
                .map(|iv| profile.state_at(iv.t0 + iv.h).p)
                .collect();
            let peak = reference
                .iter()
                .zip(&cmd)
                .map(|(y, x)| (y - x).abs())
                .fold(0.0f64, f64::max);
            let err = mj
                .iter()
                .zip(&reference)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0f64, f64::max);
            let rel = err / peak;
            worst = worst.max(rel);
            assert!(
                rel < 0.03,
                "{kind} {mode:?}: trace off by {rel} of the peak deflection"
            );
            // RK4 budget: phase drift (w h)^4/120 * w t_stop <= 1.4e-5 * 754 * 0.4 = 4e-3
            // rad over the window, times a residual below the peak deflection.
            assert!(
                rel < 2e-3,
                "{kind} {mode:?}: trace off by {rel} (RK4 budget)"
            );
        }
    }
    eprintln!("worst toolhead trace error vs the modal plant: {worst:.2e} of the peak deflection");
}

#[test]
fn repeated_runs_are_bit_identical() {
    let mode = Mode::new(40.0, 0.02, 1.0).expect("mode");
    let (_, profile) = moves().remove(3);
    let t_stop = profile.duration_s() + 0.2;
    let (a, ea) = mujoco_run(&mode, &profile, t_stop, MujocoConfig::default());
    let (b, eb) = mujoco_run(&mode, &profile, t_stop, MujocoConfig::default());
    assert_eq!(a.len(), b.len());
    assert!(a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits()));
    assert_eq!(ea.0.to_bits(), eb.0.to_bits());
    assert_eq!(ea.1.to_bits(), eb.1.to_bits());
}

#[test]
fn error_shrinks_with_the_step_at_fourth_order() {
    let mode = Mode::new(120.0, 0.02, 1.0).expect("mode");
    let (_, profile) = moves().remove(3); // S-curve, 20 mm
    let t_stop = profile.duration_s() + 0.1;
    let modal = ModalOne::new(&[mode], DT);
    let (reference, _) = run(
        &modal,
        &profile.start(),
        &schedule(&profile, DT, t_stop),
        t_stop,
    );
    let mut errs = Vec::new();
    // |w h| of 0.75, 0.375, 0.19: 1, 2 and 4 MuJoCo steps per 1 ms sample.
    for lh in [0.8, 0.4, 0.2] {
        let config = MujocoConfig {
            max_lambda_h: lh,
            ..MujocoConfig::default()
        };
        let (mj, _) = mujoco_run(&mode, &profile, t_stop, config);
        let err = mj
            .iter()
            .zip(&reference)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0f64, f64::max);
        eprintln!("max |w h| {lh}: max toolhead error {err:.3e} m");
        errs.push(err);
    }
    // Halving the step divides an RK4 error by ~16.
    assert!(
        errs[0] / errs[1] > 10.0 && errs[1] / errs[2] > 10.0,
        "{errs:?}"
    );
}
