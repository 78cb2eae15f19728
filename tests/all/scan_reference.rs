//! The scan metrics against the closed form: on `scenarios/ci_scan.toml` (one 40 Hz,
//! zeta 0.05 mode, ideal fly axis) the step axis's error at re-entry, simulated on the
//! modal backend and interpolated between samples, equals the closed-form deflection of the
//! mode (`settle_sim::closed_form::residual_at`) `reentry - step_start` after the step
//! starts; the settled flag and the step's settle time agree with the closed form sampled
//! finely.

use crate::support::extra;
use std::path::Path;

use settle::spec::backend::Backend;
use settle_planner::ProfileParams;
use settle_sim::Mode;
use settle_sim::closed_form::residual_at;

#[test]
fn reentry_error_and_settling_equal_the_closed_form_on_modal() {
    let path = Path::new(crate::support::manifest_dir()).join("scenarios/ci_scan.toml");
    let (_, mut runs) = settle::load_runs(&path).expect("loads");
    settle::execute::set_backend(&path, &mut runs, Backend::Modal).expect("modal");
    let mode = Mode::new(40.0, 0.05, 1.0).expect("mode");
    for spec in &runs {
        spec.state::<settle::studies::scan::ScanSpec>()
            .expect("scan run");
        let m = settle::execute::execute(spec, None).expect("runs");
        let r = settle::studies::scan::raster(spec).expect("plans");
        let tr = r.turnarounds[0];
        let step = spec
            .profile
            .rest_to_rest_with(
                0.0,
                spec.distance_mm * 1e-3,
                &spec.limits_si().expect("limits"),
                &ProfileParams::default(),
            )
            .expect("step");
        // The deflection e (m) at time tau after the step's start, for tau >= its end.
        let e = |tau: f64| residual_at(&step, &mode, tau).abs() * 1e6;
        let want = e(tr.reentry_s - tr.step_start_s);
        let got = extra(&m, "scan_reentry_error_um");
        assert!(
            (got - want).abs() <= 1e-3 * want + 1e-4,
            "run {} ({} {} mm): re-entry error {got} um, closed form {want} um",
            spec.id,
            spec.profile,
            spec.distance_mm
        );
        // Settled over the next line and the step's settle time, from the closed form
        // sampled every 10 us from the step's end to the next exit.
        let t_step = step.duration_s();
        let line_end = tr.reentry_s + r.overhead.line_s - tr.step_start_s;
        let n = ((line_end - t_step) / 1e-5) as usize;
        let samples: Vec<(f64, f64)> = (0..=n)
            .map(|i| {
                let tau = t_step + i as f64 * 1e-5;
                (tau, e(tau))
            })
            .collect();
        let line_peak = samples
            .iter()
            .filter(|(tau, _)| *tau >= tr.reentry_s - tr.step_start_s)
            .map(|s| s.1)
            .fold(0.0, f64::max);
        let got_peak = extra(&m, "scan_line_residual_peak_um");
        assert!(
            (got_peak - line_peak).abs() <= 2e-3 * line_peak + 1e-4,
            "{got_peak} {line_peak}"
        );
        for band in &spec.bands_um {
            let settled = extra(&m, &format!("scan_settled_{band}um"));
            assert_eq!(settled, f64::from(u8::from(line_peak <= *band)));
            let got_s = extra(&m, &format!("scan_step_settle_time_s_{band}um"));
            let last_out = samples.iter().rev().find(|(_, x)| x > band);
            match last_out {
                None => assert_eq!(got_s, 0.0),
                Some((tau, _)) if *tau >= line_end - 1e-4 => assert!(got_s.is_infinite()),
                Some((tau, _)) => assert!(
                    (got_s - (tau - t_step)).abs() <= 1.1e-4,
                    "run {} band {band}: {got_s} vs {}",
                    spec.id,
                    tau - t_step
                ),
            }
        }
    }
}
