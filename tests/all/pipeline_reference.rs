//! The whole pipeline (scenario -> planner -> stepped plant -> streaming metrics) against
//! the closed form: the post-move metrics of every quickstart run are recomputed from the
//! closed-form residual e(t) at the same sample times, with no plant involved. The modal
//! backend must agree to 1e-6 (it is exact); rapier, the default, within validate's 2 %
//! residual threshold and one sample of settle time.

use std::path::Path;

use settle::measure::accumulator::Accumulator;
use settle::spec::backend::Backend;
use settle_sim::Mode;
use settle_sim::closed_form::residual_at;

fn check(backend: Backend, rel_tol: f64, settle_tol_s: f64) {
    let path = Path::new(crate::support::manifest_dir()).join("scenarios/quickstart.toml");
    let (_, mut runs) = settle::load_runs(&path).expect("quickstart");
    settle::execute::set_backend(&path, &mut runs, backend).expect("backend");
    let mut worst = 0.0f64;
    for spec in &runs {
        let got = settle::execute::execute(spec, None).expect("runs");
        let lim = spec.limits_si().expect("limits");
        let prof = spec
            .profile
            .rest_to_rest(spec.start_mm * 1e-3, spec.distance_mm * 1e-3, &lim)
            .expect("plan");
        let modes: Vec<Mode> = spec.machine.sim_modes("x").expect("modes");
        let t_end = prof.duration_s();
        let target = prof.end().p;
        let mut acc = Accumulator::new(&[target], &[1.0], t_end, &spec.bands_um);
        let dt = 1.0 / spec.sample_rate_hz;
        let n = (spec.window_s * spec.sample_rate_hz).ceil() as usize;
        for i in 0..=n {
            let t = t_end + i as f64 * dt;
            let e: f64 = modes
                .iter()
                .map(|m| m.weight() * residual_at(&prof, m, t))
                .sum();
            acc.push(t, &[target], &[target + e]);
        }
        let want = acc.finish();
        let ctx = format!("run {} ({} {} mm)", spec.id, spec.profile, spec.distance_mm);
        worst =
            worst.max((got.residual_peak_um - want.residual_peak_um).abs() / want.residual_peak_um);
        let close = |a: f64, b: f64| (a - b).abs() <= rel_tol * b.abs().max(1e-3);
        assert_eq!(got.move_time_s, want.move_time_s, "{ctx}");
        assert!(
            close(got.residual_peak_um, want.residual_peak_um),
            "{ctx}: peak {} vs {}",
            got.residual_peak_um,
            want.residual_peak_um
        );
        assert!(
            close(got.residual_rms_um, want.residual_rms_um),
            "{ctx}: rms {} vs {}",
            got.residual_rms_um,
            want.residual_rms_um
        );
        for (b, (g, w)) in got
            .settle_time_s
            .iter()
            .zip(&want.settle_time_s)
            .enumerate()
        {
            match (g, w) {
                (Some(g), Some(w)) => {
                    assert!((g - w).abs() <= settle_tol_s, "{ctx} band {b}: {g} vs {w}")
                }
                _ => assert_eq!(g, w, "{ctx} band {b}"),
            }
        }
    }
    eprintln!("{backend}: worst residual peak error {worst:.2e} of the closed form");
}

#[test]
fn quickstart_post_move_metrics_equal_the_closed_form_on_modal() {
    check(Backend::Modal, 1e-6, 1e-9);
}

#[test]
fn quickstart_post_move_metrics_match_the_closed_form_on_rapier() {
    // validate's residual threshold; settle times within one sample (0.1 ms).
    check(Backend::Rapier, 0.02, 1e-4);
}
