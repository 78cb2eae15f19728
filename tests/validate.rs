//! `settle validate`'s checks as integration tests, for every backend this build has:
//! frequency within 0.5 %, residual within 2 % of the closed form, settle times within 3 %
//! of the modal reference, numerical damping within 10 % of the physical, engines within
//! 3 % of each other.

use settle::run::Backend;
use settle::validate::{self, markdown};

fn check(backend: Backend) -> validate::Report {
    let report = validate::run(&[backend]).expect("backend available");
    let table = markdown(&report);
    assert!(report.pass(), "{table}");
    // Every case ran on the modal reference and on this backend.
    let cases = validate::cases().len();
    assert!(cases >= 24, "{cases} cases");
    let n = report.rows.iter().filter(|r| r.backend == backend).count();
    assert_eq!(n, cases, "{table}");
    report
}

#[test]
fn validate_passes_on_the_modal_backend() {
    let report = check(Backend::Modal);
    // The modal backend is the exact solution: its errors are rounding.
    for r in &report.rows {
        assert!(r.f_err_pct().abs() < 1e-5, "{}: {}", r.case, r.f_err_pct());
        assert!(
            r.residual_err_pct().abs() < 1e-4,
            "{}: {}",
            r.case,
            r.residual_err_pct()
        );
        assert!(
            r.damping_pct().abs() < 1e-4,
            "{}: {}",
            r.case,
            r.damping_pct()
        );
    }
}

#[test]
fn validate_passes_on_rapier() {
    let report = check(Backend::Rapier);
    let worst = |f: fn(&validate::Row) -> f64| {
        report
            .rows
            .iter()
            .filter(|r| r.backend == Backend::Rapier)
            .map(|r| f(r).abs())
            .fold(0.0, f64::max)
    };
    eprintln!(
        "rapier worst: frequency {:.4} %, numerical damping {:.3} %, residual {:.3} %",
        worst(validate::Row::f_err_pct),
        worst(validate::Row::damping_pct),
        worst(validate::Row::residual_err_pct)
    );
    // The model-effects table covers every physical machine's 10 mm moves.
    assert!(report.effects.len() >= 6, "{}", markdown(&report));
}

#[test]
fn validate_without_mujoco_says_how_to_get_it() {
    if Backend::Mujoco.available() {
        return;
    }
    let e = validate::run(&[Backend::Mujoco]).expect_err("not built");
    assert!(e.contains("scripts/setup-mujoco.sh"), "{e}");
}
