//! `settle validate`'s checks as integration tests, for every backend this build has:
//! frequency within 0.5 %, residual within 2 % of the closed form, settle times within 3 %
//! of the modal reference, numerical damping within 10 % of the physical, engines within
//! 3 % of each other.

use settle::spec::backend::Backend;
use settle::workflows::validate::{self, markdown};

fn check(backend: Backend) -> validate::Validation {
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

/// With MuJoCo built: every check passes on MuJoCo, each of its rows is compared with
/// rapier (the engines check), and the model-effects table shows the full stepper driver on
/// both engines without lost steps.
#[cfg(feature = "mujoco")]
#[test]
fn validate_passes_on_mujoco_against_rapier() {
    let report = validate::run(&[Backend::Rapier, Backend::Mujoco]).expect("both built");
    let table = markdown(&report);
    assert!(report.pass(), "{table}");
    let mujoco: Vec<_> = report
        .rows
        .iter()
        .filter(|r| r.backend == Backend::Mujoco)
        .collect();
    assert_eq!(mujoco.len(), validate::cases().len(), "{table}");
    assert!(mujoco.iter().all(|r| r.engine_pct.is_some()), "{table}");
    assert!(report.effects.len() >= 6, "{table}");
    for e in &report.effects {
        let engines: Vec<Backend> = e.full_driver.iter().map(|f| f.0).collect();
        assert_eq!(engines, [Backend::Rapier, Backend::Mujoco], "{table}");
        assert!(e.full_driver.iter().all(|f| f.3 == 0), "{table}");
    }
    assert!(table.contains("+ full stepper driver (mujoco)"), "{table}");
}
