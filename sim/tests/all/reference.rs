//! The modal plant against the closed form, and the closed form against the physics it
//! claims (DESIGN.md's undamped S-curve formula, cancellation at whole periods, static
//! deflection, free decay).
//!
//! Random case count: `SETTLE_SIM_CASES` (default 2,000).

use std::f64::consts::{PI, TAU};

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use settle_planner::{Limits, Profile, Sample, Segment, State, scurve, trapezoid};
use settle_sim::closed_form::{residual_at, residual_envelope, undamped_scurve_residual};
use settle_sim::{AxisModel, ModalPlant, ModalState, Mode, Plant};

/// The modal plant of one axis with these modes.
fn plant_of(modes: &[Mode], dt: f64) -> ModalPlant {
    ModalPlant::new(vec![AxisModel::from_modes("x", modes).expect("axis")], dt).expect("plant")
}

/// Deflection e and rate e' of mode `i`.
fn mode_state(st: &ModalState, i: usize) -> (f64, f64) {
    (st.axes[0].r()[i], st.axes[0].rd()[i])
}

/// Free-vibration envelope of the first mode.
fn amplitude(st: &ModalState, mode: &Mode) -> f64 {
    ModalPlant::free_amplitude(st, 0, 0, mode.omega(), mode.damping_ratio())
}

fn cases() -> usize {
    std::env::var("SETTLE_SIM_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(2000)
}

/// Step `plant` through `profile` at `dt`, splitting steps at segment boundaries, then hold
/// the end point until `t_stop`. Returns the state at T and at `t_stop`.
fn drive(plant: &ModalPlant, profile: &Profile, dt: f64, t_stop: f64) -> (ModalState, ModalState) {
    let mut st = plant.initial_state(&[profile.start()]).expect("state");
    for (t0, s0, seg) in profile.iter() {
        let t1 = t0 + seg.duration_s();
        let mut t = t0;
        while t < t1 {
            let next = ((t / dt).floor() + 1.0) * dt;
            let next = if next <= t { t + dt } else { next }.min(t1);
            plant
                .step(&mut st, &[seg.sample(&s0, t - t0)], next - t)
                .expect("finite");
            t = next;
        }
    }
    let at_end = st.clone();
    let end = profile.end();
    let hold = Sample {
        p: end.p,
        v: 0.0,
        a: end.a,
        j: 0.0,
    };
    let mut t = profile.duration_s();
    while t < t_stop {
        let h = dt.min(t_stop - t);
        plant.step(&mut st, &[hold], h).expect("finite");
        t += h;
    }
    (at_end, st)
}

fn random_profile(rng: &mut ChaCha8Rng) -> Profile {
    let n = rng.random_range(1..8);
    let mut segs = Vec::new();
    for _ in 0..n {
        let duration_s = rng.random_range(0.0..0.05);
        segs.push(if rng.random_bool(0.5) {
            Segment::Jerk {
                duration_s,
                jerk: rng.random_range(-2e3..2e3),
            }
        } else {
            Segment::Accel {
                duration_s,
                accel: rng.random_range(-20.0..20.0),
            }
        });
    }
    // End with zero acceleration so the residual is a free vibration.
    segs.push(Segment::Accel {
        duration_s: 0.0,
        accel: 0.0,
    });
    Profile::new(State::default(), segs).expect("valid profile")
}

#[test]
fn modal_plant_matches_closed_form_residual_on_random_profiles() {
    let mut rng = ChaCha8Rng::seed_from_u64(42);
    let n = cases();
    let (mut worst_amp, mut worst_e) = (0.0f64, 0.0f64);
    for _ in 0..n {
        let profile = random_profile(&mut rng);
        let mode = Mode::new(
            rng.random_range(5.0..300.0),
            rng.random_range(0.0..0.3),
            1.0,
        )
        .expect("mode");
        let dt = [1e-4, 2.5e-4, 1e-3][rng.random_range(0..3)];
        let plant = plant_of(&[mode], dt);
        let t_end = profile.duration_s();
        let t_stop = t_end + rng.random_range(0.0..0.2);
        let (at_end, later) = drive(&plant, &profile, dt, t_stop);
        let exact = residual_envelope(&profile, &mode);
        let got = amplitude(&at_end, &mode);
        // Relative to the residual, with a floor far below any settling band (1e-12 m)
        // for profiles whose residual happens to cancel.
        let rel = (got - exact).abs() / exact.max(1e-12);
        worst_amp = worst_amp.max(rel);
        assert!(
            rel <= 1e-6,
            "amplitude {got} vs closed form {exact}: {profile:?} {mode:?}"
        );
        let e_exact = residual_at(&profile, &mode, t_stop);
        let e_rel = (mode_state(&later, 0).0 - e_exact).abs() / exact.max(1e-12);
        worst_e = worst_e.max(e_rel);
        assert!(
            e_rel <= 1e-6,
            "e({t_stop}) {} vs {e_exact}",
            mode_state(&later, 0).0
        );
    }
    eprintln!(
        "{n} random profiles: worst amplitude error {worst_amp:.2e}, worst e(t) error {worst_e:.2e} (relative to the residual)"
    );
}

#[test]
fn undamped_scurve_residual_vanishes_when_jerk_phase_is_one_period() {
    let f = 40.0;
    let mode = Mode::new(f, 0.0, 1.0).expect("mode");
    let (vmax, amax) = (0.3, 3.0);
    let jmax = amax * f; // t_jerk = amax/jmax = 1/f
    let lim = Limits::new(vmax, amax, Some(jmax)).expect("limits");
    for d in [0.005, 0.02, 0.1] {
        let prof = scurve::rest_to_rest(0.0, d, &lim).expect("plan");
        let tm = scurve::timing(d, vmax, amax, jmax);
        assert!((tm.t_jerk - 1.0 / f).abs() < 1e-15 && tm.a_peak == amax);
        let static_defl = amax / mode.omega().powi(2);
        let cf = residual_envelope(&prof, &mode);
        let plant = plant_of(&[mode], 1e-4);
        let (at_end, _) = drive(&plant, &prof, 1e-4, prof.duration_s());
        let sim = amplitude(&at_end, &mode);
        assert!(cf < 1e-9 * static_defl, "closed form {cf} at d={d}");
        assert!(sim < 1e-9 * static_defl, "plant {sim} at d={d}");
    }
    // With the jerk phase half a period longer the move rings (vmax changed too: at
    // vmax/amax = 0.1 s = 4 periods the acceleration pulse itself would cancel).
    let lim2 = Limits::new(0.33, amax, Some(amax * f / 1.5)).expect("limits");
    let prof2 = scurve::rest_to_rest(0.0, 0.1, &lim2).expect("plan");
    let r = residual_envelope(&prof2, &mode);
    assert!(r > 1e-2 * amax / mode.omega().powi(2), "{r}");
}

#[test]
fn undamped_trapezoid_residual_vanishes_when_accel_phase_is_one_period() {
    let f = 40.0;
    let mode = Mode::new(f, 0.0, 1.0).expect("mode");
    let amax = 3.0;
    let vmax = amax / f; // t_acc = vmax/amax = 1/f
    let lim = Limits::new(vmax, amax, None).expect("limits");
    let static_defl = amax / mode.omega().powi(2);
    for d in [0.01, 0.05, 0.2] {
        let prof = trapezoid::rest_to_rest(0.0, d, &lim).expect("plan");
        let cf = residual_envelope(&prof, &mode);
        let plant = plant_of(&[mode], 1e-4);
        let (at_end, _) = drive(&plant, &prof, 1e-4, prof.duration_s());
        let sim = amplitude(&at_end, &mode);
        assert!(cf < 1e-9 * static_defl, "closed form {cf} at d={d}");
        assert!(sim < 1e-9 * static_defl, "plant {sim} at d={d}");
    }
    // Triangular move whose accel phase is exactly two periods: d = amax (2/f)^2.
    let lim = Limits::new(1.0, amax, None).expect("limits");
    let prof = trapezoid::rest_to_rest(0.0, amax * (2.0 / f).powi(2), &lim).expect("plan");
    assert!(residual_envelope(&prof, &mode) < 1e-9 * static_defl);
}

#[test]
fn design_undamped_formula_equals_the_g_sum() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut worst = 0.0f64;
    for _ in 0..cases() {
        let (vmax, amax, jmax) = (
            rng.random_range(0.05..1.0),
            rng.random_range(0.5..20.0),
            rng.random_range(10.0..2000.0),
        );
        let d = rng.random_range(1e-4..0.5);
        let f = rng.random_range(5.0..200.0);
        let mode = Mode::new(f, 0.0, 1.0).expect("mode");
        let lim = Limits::new(vmax, amax, Some(jmax)).expect("limits");
        let prof = scurve::rest_to_rest(0.0, d, &lim).expect("plan");
        let tm = scurve::timing(d, vmax, amax, jmax);
        let t_acc = 2.0 * tm.t_jerk + tm.t_const_acc;
        let formula =
            undamped_scurve_residual(tm.a_peak, t_acc, tm.t_jerk, tm.t_cruise, mode.omega());
        let g = residual_envelope(&prof, &mode);
        let rel = (formula - g).abs() / g.max(1e-12);
        worst = worst.max(rel);
        assert!(
            rel < 1e-9 || (formula - g).abs() < 1e-15,
            "formula {formula} vs G-sum {g}"
        );
    }
    eprintln!("undamped S-curve formula vs G-sum: worst relative difference {worst:.2e}");
}

#[test]
fn constant_acceleration_gives_static_deflection() {
    let mode = Mode::new(40.0, 0.1, 1.0).expect("mode");
    let a = 2.5;
    let prof = Profile::new(
        State::default(),
        vec![Segment::Accel {
            duration_s: 1.0,
            accel: a,
        }],
    )
    .expect("profile");
    let plant = plant_of(&[mode], 1e-3);
    let (at_end, _) = drive(&plant, &prof, 1e-3, 1.0);
    // After 1 s the transient has decayed by e^{-zeta w} = e^{-25}.
    let expect = -a / mode.omega().powi(2);
    assert!(
        (mode_state(&at_end, 0).0 - expect).abs() < 1e-9 * expect.abs(),
        "{:?}",
        mode_state(&at_end, 0)
    );
}

#[test]
fn free_decay_has_the_analytic_frequency_and_damping() {
    let mode = Mode::new(55.0, 0.04, 1.0).expect("mode");
    let (w, wd, z) = (mode.omega(), mode.omega_d(), mode.damping_ratio());
    let plant = plant_of(&[mode], 1e-4);
    let mut st = plant.initial_state(&[State::default()]).expect("state");
    let e0 = 1e-4;
    st.axes[0].set_r(0, e0);
    let hold = Sample::default();
    let mut worst = 0.0f64;
    for k in 1..=5000 {
        plant.step(&mut st, &[hold], 1e-4).expect("finite");
        let t = k as f64 * 1e-4;
        // e(t) = e0 e^{-zeta w t} (cos wd t + zeta w / wd sin wd t)
        let exact = e0 * (-z * w * t).exp() * ((wd * t).cos() + z * w / wd * (wd * t).sin());
        worst = worst.max((mode_state(&st, 0).0 - exact).abs() / e0);
    }
    assert!(worst < 1e-9, "worst error {worst} of e0");
    // One period of the damped oscillation is 2 pi / wd: the phase error after 5000 steps
    // (27.5 periods) would show above.
    assert!((TAU / wd - 1.0 / 55.0 / (1.0 - z * z).sqrt()).abs() < 1e-15 && PI > 3.0);
}

/// The weights the closed form reads off the poles' residues are the modes form's own:
/// an axis built from modes gives them back (frequency, damping and weight), at rest or
/// after any move.
#[test]
fn weighted_modes_of_a_modes_axis_are_its_modes() {
    let modes = [
        Mode::new(38.0, 0.04, 0.7).expect("mode"),
        Mode::new(95.0, 0.12, 0.3).expect("mode"),
    ];
    let axis = AxisModel::from_modes("y", &modes).expect("axis");
    let limits = Limits::new(0.3, 5.0, Some(200.0)).expect("limits");
    for profile in [
        Profile::empty(State::default()),
        scurve::rest_to_rest(0.0, 0.01, &limits).expect("profile"),
    ] {
        let lr = settle_sim::closed_form::LinearResponse::new(&axis, &profile).expect("lr");
        let got = lr.weighted_modes();
        assert_eq!(got.len(), 2, "{got:?}");
        for ((f, z, w), m) in got.iter().zip(&modes) {
            assert!((f - m.omega() / TAU).abs() < 1e-9 * f, "{got:?}");
            assert!((z - m.damping_ratio()).abs() < 1e-9, "{got:?}");
            assert!((w - m.weight()).abs() < 1e-9, "{got:?}");
        }
    }
}
