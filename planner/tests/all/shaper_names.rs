//! Shaper names: every firmware's families parse, `Display` parses back to the same kind,
//! Klipper kinds print what Klipper's `shaper_type` accepts, and bad names say what is
//! allowed.

use settle_planner::PlanError;
use settle_planner::firmware::Firmware;
use settle_planner::shaper::{MarlinShaper, RrfShaper, ShaperType};

#[test]
fn display_round_trips_for_every_family_and_parameters() {
    let mut kinds: Vec<ShaperType> = ShaperType::KLIPPER
        .into_iter()
        .chain(ShaperType::MARLIN)
        .chain(ShaperType::RRF)
        .collect();
    kinds.extend([
        ShaperType::Mzv { n: 4, t: 0.8 },
        ShaperType::Mzv { n: 5, t: 1.1 },
        ShaperType::Mzv {
            n: 3,
            t: 0.6666666666,
        },
        ShaperType::Mzv { n: 4, t: 1.0 },
        ShaperType::Ei { v_tol: 0.03 },
        ShaperType::MarlinM593,
        ShaperType::Marlin {
            shaper: MarlinShaper::TwoHei,
            v_tol: 0.1,
            ftm_fs_hz: 2000,
        },
        ShaperType::Marlin {
            shaper: MarlinShaper::Zvdd,
            v_tol: 0.05,
            ftm_fs_hz: 500,
        },
        ShaperType::Rrf {
            shaper: RrfShaper::Ei3,
            step_clock_hz: 937_500,
        },
    ]);
    for k in kinds {
        let text = k.to_string();
        assert_eq!(k.name(), text);
        assert_eq!(ShaperType::parse(&text).expect(&text), k, "{text}");
        assert_eq!(text.parse::<ShaperType>().expect(&text), k);
        assert_eq!(ShaperType::parse(&text.to_uppercase()).expect(&text), k);
    }
}

#[test]
fn written_forms() {
    let cases: &[(&str, &str)] = &[
        ("zv", "zv"),
        ("MZV", "mzv"),
        ("klipper:mzv", "mzv"),
        ("mzv(n=3,t=0.75)", "mzv"),
        ("mzv(t=0)", "mzv"),
        ("mzv(n=4, t=0.8)", "mzv(n=4,t=0.8)"),
        ("mzv(4,0.8)", "mzv(n=4,t=0.8)"),
        ("mzv(n=4)", "mzv(n=4,t=0.75)"),
        ("ei", "ei"),
        ("ei(v_tol=0.05)", "ei"),
        ("ei(0.02)", "ei(v_tol=0.02)"),
        ("ei()", "ei"),
        ("2hump_ei", "2hump_ei"),
        ("3HUMP_EI", "3hump_ei"),
        ("marlin:zvddd", "marlin:zvddd"),
        ("Marlin:2HEI(v_tol=0.1)", "marlin:2hei(v_tol=0.1)"),
        ("marlin:mzv(ftm_fs=1000)", "marlin:mzv"),
        ("rrf:ei2", "rrf:ei2"),
        ("rrf:zvd(step_clock=937500)", "rrf:zvd(step_clock=937500)"),
    ];
    for (written, canonical) in cases {
        let k = ShaperType::parse(written).expect(written);
        assert_eq!(k.to_string(), *canonical, "{written}");
    }
    // mzv(n=4, tau=1.2): t = tau (n - 1) / (n + 2 tau - 2) = 3.6 / 4.4.
    match ShaperType::parse("mzv(n=4,tau=1.2)").expect("tau") {
        ShaperType::Mzv { n: 4, t } => assert!((t - 3.6 / 4.4).abs() < 1e-15),
        other => panic!("{other:?}"),
    }
    assert_eq!(
        ShaperType::parse("zvd").expect("zvd").firmware(),
        Firmware::Klipper
    );
    assert_eq!(
        ShaperType::parse("marlin:zvd").expect("m").firmware(),
        Firmware::Marlin
    );
    assert_eq!(
        ShaperType::parse("rrf:zvd").expect("r").firmware(),
        Firmware::Rrf
    );
    assert_eq!(MarlinShaper::from_m493_code(6), Some(MarlinShaper::TwoHei));
    assert_eq!(MarlinShaper::from_m493_code(0), None);
    assert_eq!(MarlinShaper::from_m493_code(9), None);
    // M493 C codes 1..=8 in MarlinDocumentation's order, and back.
    assert_eq!(MarlinShaper::Zv.m493_code(), 1);
    assert_eq!(MarlinShaper::Ei.m493_code(), 5);
    assert_eq!(MarlinShaper::Mzv.m493_code(), 8);
    for f in MarlinShaper::ALL {
        assert_eq!(MarlinShaper::from_m493_code(f.m493_code()), Some(f));
    }
}

#[test]
fn bad_names_list_what_is_allowed() {
    for bad in ["zvdd", "rrf:zv", "marlin:2hump_ei", "prusa:zv", "", "mzv2"] {
        match ShaperType::parse(bad) {
            Err(PlanError::UnknownShaper { name, allowed }) => {
                assert_eq!(name, bad);
                assert_eq!(allowed, ShaperType::ALLOWED);
                let text = PlanError::UnknownShaper { name, allowed }.to_string();
                assert!(
                    text.starts_with(&format!("unknown shaper `{bad}`")),
                    "{text}"
                );
                for family in ["2hump_ei", "marlin:zvdd", "rrf:ei3", "mzv(n=N,t=T)"] {
                    assert!(text.contains(family), "{text}");
                }
            }
            other => panic!("{bad}: {other:?}"),
        }
    }
    for (bad, says) in [
        ("mzv(n=4.0)", "whole number"),
        ("mzv(n=4,t=0.8,tau=1)", "not both"),
        ("mzv(n=4,0.8)", "do not mix"),
        ("mzv(k=4)", "takes n, t, tau"),
        ("zv(3)", "takes none"),
        ("ei(v_tol=-0.1)", "non-negative"),
        ("ei(v_tol=0.1", "closed"),
        ("marlin:zv(v_tol=0.1)", "takes ftm_fs"),
        ("marlin:ei(v_tol=1.5)", "0..=1"),
        ("marlin:ei(ftm_fs=0)", "> 0"),
        ("rrf:ei2(step_clock=0)", "> 0"),
        ("ei(v_tol=0.1,v_tol=0.2)", "too many"),
        ("mzv(n=4,n=5)", "twice"),
    ] {
        match ShaperType::parse(bad) {
            Err(e @ PlanError::InvalidShaper { .. }) => {
                assert!(e.to_string().contains(says), "{bad}: {e}")
            }
            other => panic!("{bad}: {other:?}"),
        }
    }
}
