//! The four-jerk and PVT-step profile kinds (`fourjerk`, `pvt_sym`, `pvt_asym`) through
//! [`ProfileKind`]: names, parse/Display, rest-to-rest moves that reach the target within
//! the limits, their parameters, and their errors.
//!
//! Case count: `SETTLE_PLANNER_CASES` (default 100,000; this suite uses a hundredth).

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use settle_planner::fourjerk::FourJerkLimits;
use settle_planner::pvt::{self, PvtLimits};
use settle_planner::{Limits, PlanError, ProfileKind, ProfileParams};

fn cases() -> usize {
    std::env::var("SETTLE_PLANNER_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(100_000usize)
        .div_ceil(100)
}

#[test]
fn names_parse_and_display_round_trip() {
    let names: Vec<&str> = ProfileKind::ALL.iter().map(|k| k.name()).collect();
    assert_eq!(
        names,
        ["trapezoid", "scurve", "fourjerk", "pvt_sym", "pvt_asym"]
    );
    assert_eq!(ProfileKind::ALLOWED, names.join(", "));
    for k in ProfileKind::ALL {
        assert_eq!(ProfileKind::parse(&k.to_string()), Ok(k));
    }
    match ProfileKind::parse("tmc") {
        Err(PlanError::UnknownKind { name, allowed }) => {
            assert_eq!((name.as_str(), allowed), ("tmc", ProfileKind::ALLOWED))
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn new_kinds_reach_the_target_within_the_limits() {
    let mut rng = ChaCha8Rng::seed_from_u64(50);
    let lu =
        |rng: &mut ChaCha8Rng, lo: f64, hi: f64| rng.random_range(f64::ln(lo)..f64::ln(hi)).exp();
    for _ in 0..cases() {
        let lim = Limits::new(
            lu(&mut rng, 1e-2, 1e2),
            lu(&mut rng, 1e-1, 1e3),
            Some(lu(&mut rng, 1.0, 1e5)),
        )
        .expect("limits");
        let d = lu(&mut rng, 1e-6, 1e1) * if rng.random_bool(0.5) { 1.0 } else { -1.0 };
        let p0 = rng.random_range(-1.0..1.0);
        let params = ProfileParams {
            pvt_asym_ki: rng.random_range(0.35..0.95),
            fourjerk_jerk_scale: [0; 4].map(|_| rng.random_range(0.2..1.0)),
            fourjerk_dmax_scale: rng.random_range(0.3..2.0),
        };
        let s_curve = ProfileKind::SCurve
            .rest_to_rest(p0, d, &lim)
            .expect("scurve");
        for kind in [
            ProfileKind::FourJerk,
            ProfileKind::PvtSym,
            ProfileKind::PvtAsym,
        ] {
            let ctx = format!("{kind} d={d} {lim:?} {params:?}");
            let p = kind
                .rest_to_rest_with(p0, d, &lim, &params)
                .unwrap_or_else(|e| panic!("{e}: {ctx}"));
            let e = p.end();
            assert!((e.p - (p0 + d)).abs() <= 1e-9 * (1.0 + d.abs()), "{ctx}");
            assert!(
                e.v.abs() <= 1e-9 * lim.vmax() && e.a.abs() <= 1e-7 * lim.amax(),
                "{e:?} {ctx}"
            );
            match kind {
                ProfileKind::FourJerk => {
                    let j = lim.jmax().expect("jmax");
                    let l = FourJerkLimits::new(
                        lim.vmax(),
                        lim.amax(),
                        lim.amax() * params.fourjerk_dmax_scale,
                        params.fourjerk_jerk_scale.map(|s| s * j),
                    )
                    .expect("limits");
                    // Oriented along the move: in the axis frame a negative move has the
                    // limits mirrored.
                    let l = if d > 0.0 { l } else { l.mirrored() };
                    if let Err(err) = crate::fourjerk_check::check_profile(&p, &l) {
                        panic!("{err}: {ctx}");
                    }
                    // Jerks no larger than jmax and DMAX <= AMAX: never faster than the
                    // S-curve (a smaller feasible set).
                    if params.fourjerk_dmax_scale <= 1.0 {
                        assert!(
                            p.duration_s() >= s_curve.duration_s() * (1.0 - 1e-9),
                            "{ctx}"
                        );
                    }
                }
                _ => {
                    // The kind is the PVT step; its limits are checked on the knots (with
                    // the allowance for the rounding of knot data, see pvt::check).
                    let m = if kind == ProfileKind::PvtSym {
                        pvt::step::symmetric(p0, d, &lim)
                    } else {
                        pvt::step::asymmetric(p0, d, params.pvt_asym_ki, &lim)
                    }
                    .expect("pvt");
                    assert_eq!(m.profile, p, "{ctx}");
                    let pl = PvtLimits {
                        vmax: lim.vmax(),
                        amax: lim.amax(),
                        jmax: lim.jmax(),
                        accel_jump_tol: 0.0,
                    };
                    if let Err(v) = pvt::check(&m, &pl) {
                        panic!("{v}: {ctx}");
                    }
                }
            }
        }
    }
}

#[test]
fn defaults_and_errors() {
    let lim = Limits::new(1.0, 2.0, Some(10.0)).expect("limits");
    // Default four jerks equal jmax and DMAX = AMAX: the S-curve.
    let s = ProfileKind::SCurve
        .rest_to_rest(0.0, 1.7, &lim)
        .expect("scurve");
    let f = ProfileKind::FourJerk
        .rest_to_rest(0.0, 1.7, &lim)
        .expect("fourjerk");
    assert!(
        (f.duration_s() - s.duration_s()).abs() < 1e-12 && (s.duration_s() - 2.4).abs() < 1e-12
    );
    // A zero move is empty for every kind.
    for k in ProfileKind::ALL {
        assert_eq!(
            k.rest_to_rest(3.0, 0.0, &lim).expect("plan").duration_s(),
            0.0
        );
    }
    let no_jerk = Limits::new(1.0, 2.0, None).expect("limits");
    for (k, name) in [
        (ProfileKind::FourJerk, "fourjerk"),
        (ProfileKind::PvtSym, "pvt_sym"),
        (ProfileKind::PvtAsym, "pvt_asym"),
    ] {
        assert_eq!(
            k.rest_to_rest(0.0, 1.0, &no_jerk),
            Err(PlanError::MissingJerkLimit { kind: name })
        );
    }
    let bad = ProfileParams {
        pvt_asym_ki: 0.2,
        ..ProfileParams::default()
    };
    assert!(matches!(
        ProfileKind::PvtAsym.rest_to_rest_with(0.0, 1.0, &lim, &bad),
        Err(PlanError::InvalidLimit { name: "ki", .. })
    ));
}
