//! Unit tests of the shaper definitions against closed forms and Klipper's figures.

use std::f64::consts::SQRT_2;

use super::*;
use crate::{Limits, ProfileKind};

/// Klipper's calibration evaluates shapers against modes of damping 0.075, 0.1 and 0.15
/// (`TEST_DAMPING_RATIOS` in shaper_calibrate.py) and keeps the worst.
const TEST_DAMPING_RATIOS: [f64; 3] = [0.075, 0.1, 0.15];

/// The outermost frequencies (relative to the shaper frequency, scanned over 0.3..2.5 in
/// steps of 0.0005) where the worst remaining vibration over the test damping ratios stays
/// <= `tol`. The shaper is tuned with Klipper's default damping 0.1.
fn band(kind: ShaperType, tol: f64) -> (f64, f64) {
    let s = Shaper::new(kind, 1.0, 0.1).expect("shaper");
    let v = |r: f64| {
        TEST_DAMPING_RATIOS
            .iter()
            .map(|&z| s.remaining_vibration(r, z))
            .fold(0.0, f64::max)
    };
    let inside: Vec<f64> = (0..4400)
        .map(|i| 0.3 + 0.0005 * f64::from(i))
        .filter(|&r| v(r) <= tol)
        .collect();
    (inside[0], inside[inside.len() - 1])
}

#[test]
fn durations_equal_klippers_definitions() {
    // ZV 0.5, MZV 0.75, ZVD 1 and EI 1 damped periods `1/(f sqrt(1 - zeta^2))`;
    // 2HUMP_EI and 3HUMP_EI end at their last time polynomial (in units of 1/f):
    // 1.49920 - 0.09297 z - 0.28338 z^2 + 1.85710 z^3 and
    // 1.99960 - 0.28231 z + 0.61536 z^2 + 5.40450 z^3 (shaper_defs.py).
    let f = 40.0;
    let last = |c: [f64; 4], z: f64| (c[0] + z * (c[1] + z * (c[2] + z * c[3]))) / f;
    for z in [0.0, 0.1] {
        let df = (1.0f64 - z * z).sqrt();
        for (kind, expect) in [
            (ShaperType::Zv, 0.5 / (f * df)),
            (ShaperType::MZV, 0.75 / (f * df)),
            (ShaperType::Zvd, 1.0 / (f * df)),
            (ShaperType::EI, 1.0 / (f * df)),
            (
                ShaperType::TwoHumpEi,
                last([1.49920, -0.09297, -0.28338, 1.85710], z),
            ),
            (
                ShaperType::ThreeHumpEi,
                last([1.99960, -0.28231, 0.61536, 5.40450], z),
            ),
        ] {
            let s = Shaper::new(kind, f, z).expect("shaper");
            assert!((s.duration_s() - expect).abs() < 1e-15, "{kind} zeta {z}");
        }
    }
}

#[test]
fn five_percent_bands_are_near_klippers_table() {
    // Klipper's table (docs/Resonance_Compensation.md, "vibration reduction 20x (5%
    // vibration tolerance)"): MZV +-4%, ZVD +-15%, EI +-20%, 2HUMP_EI -40..+45%,
    // 3HUMP_EI -50..+60% of the shaper frequency; the page calls them approximate.
    // Computed against Klipper's test damping ratios the outer edges are
    // MZV 0.9530..1.0610, ZVD 0.8420..1.1640, EI 0.7755..1.2280, 2HUMP_EI 0.6045..1.4385,
    // 3HUMP_EI 0.4820..1.6025 (the same scan run on shaper_defs.py and
    // shaper_calibrate.py's `_estimate_shaper` gives these figures): each within 3 points
    // of the table.
    for (kind, lo, hi) in [
        (ShaperType::MZV, 0.96, 1.04),
        (ShaperType::Zvd, 0.85, 1.15),
        (ShaperType::EI, 0.80, 1.20),
        (ShaperType::TwoHumpEi, 0.60, 1.45),
        (ShaperType::ThreeHumpEi, 0.50, 1.60),
    ] {
        let (l, h) = band(kind, 0.05);
        assert!(
            (l - lo).abs() < 0.03 && (h - hi).abs() < 0.03,
            "{kind}: 5% band {l:.4}..{h:.4}, Klipper's table {lo}..{hi}"
        );
    }
    let (l, h) = band(ShaperType::EI, 0.05);
    assert!(
        (l - 0.7755).abs() < 1e-9 && (h - 1.2280).abs() < 1e-9,
        "{l} {h}"
    );
    // ZV: zero at its own frequency and damping, but above 5% within 10% of it.
    let z = 0.1;
    let zv = Shaper::new(ShaperType::Zv, 1.0, z).expect("zv");
    assert!(zv.remaining_vibration(1.0, z) < 1e-12);
    assert!(zv.remaining_vibration(0.9, z) > 0.05 && zv.remaining_vibration(1.1, z) > 0.05);
}

#[test]
fn tuned_shapers_cancel_their_mode() {
    for kind in ShaperType::ALL {
        for z in [0.0, 0.05, 0.1, 0.2] {
            let s = Shaper::new(kind, 47.0, z).expect("shaper");
            let r = s.remaining_vibration(47.0, z);
            // ZV, MZV and ZVD vanish at their frequency; the EI family leaves up to 5%
            // there by design (it trades the notch for width).
            let limit = match kind {
                ShaperType::Zv | ShaperType::Mzv { .. } | ShaperType::Zvd => 1e-12,
                _ => 0.051,
            };
            assert!(r <= limit, "{kind} zeta {z}: {r}");
            // Weights are positive and sum to one.
            let w: Vec<f64> = s.weights().collect();
            assert!(w.iter().all(|&x| x > 0.0));
            assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-15);
        }
    }
}

#[test]
fn smoothing_matches_an_independent_evaluation() {
    // ZV undamped at f: impulses 1/2 at 0 and T = 1/(2f); shift ts = T/2. Only the
    // second impulse is at or after ts: off90 = sqrt2 * 1/2 (scv + a/2 T/2) T/2;
    // off180 = 2 * 1/2 * a/2 (T/2)^2.
    let f = 50.0;
    let (a, scv) = (5000.0, 5.0);
    let t = 0.5 / f;
    let off90 = SQRT_2 * 0.5 * (scv + a / 2.0 * t / 2.0) * t / 2.0;
    let off180 = a / 2.0 * (t / 2.0) * (t / 2.0);
    let s = Shaper::new(ShaperType::Zv, f, 0.0).expect("zv");
    assert!((s.smoothing_mm(a, scv) - off90.max(off180)).abs() < 1e-15);
    // Longer shapers smooth more (Klipper's ordering ZV < MZV < ZVD ~ EI < 2HUMP < 3HUMP).
    let sm: Vec<f64> = ShaperType::ALL
        .iter()
        .map(|&k| Shaper::new(k, f, 0.1).expect("shaper").smoothing_mm(a, scv))
        .collect();
    assert!(sm[0] < sm[1] && sm[1] < sm[2] && sm[3] < sm[4] && sm[4] < sm[5]);
}

#[test]
fn shaped_profile_is_the_weighted_sum_of_shifted_copies() {
    let lim = Limits::new(0.3, 3.0, Some(100.0)).expect("limits");
    for kind in [ProfileKind::SCurve, ProfileKind::Trapezoid] {
        let p = kind.rest_to_rest(0.01, 0.02, &lim).expect("plan");
        for sk in ShaperType::ALL {
            let s = Shaper::new(sk, 43.0, 0.07).expect("shaper");
            let q = s.apply(&p).expect("shaped");
            assert!((q.duration_s() - (p.duration_s() + s.duration_s())).abs() < 1e-12);
            let end = q.end();
            assert!(
                (end.p - 0.03).abs() < 1e-12 && end.v.abs() < 1e-12,
                "{end:?}"
            );
            let w: Vec<f64> = s.weights().collect();
            for i in 0..=400 {
                let t = q.duration_s() * i as f64 / 400.0;
                let expect: f64 = w
                    .iter()
                    .zip(s.times_s())
                    .map(|(w, ti)| w * p.state_at((t - ti).max(0.0)).p)
                    .sum();
                let got = q.state_at(t);
                assert!((got.p - expect).abs() < 1e-12, "{kind} {sk} t={t}");
                // Convex combination: the limits still hold.
                assert!(got.v.abs() <= 0.3 + 1e-12 && got.a.abs() <= 3.0 + 1e-12);
                if kind == ProfileKind::SCurve {
                    assert!(got.j.abs() <= 100.0 + 1e-9);
                }
            }
        }
    }
}

/// A PVT step ends at zero acceleration up to round-off (its knots sum the segments'
/// jerks): 1.1e-16 m/s^2 for this symmetric one. Shaping takes it as a move that ends at
/// rest; a fragment that ends accelerating is still refused.
#[test]
fn a_round_off_end_acceleration_is_zero_and_a_real_one_is_refused() {
    let lim = Limits::new(0.3, 3.0, Some(17.78)).expect("limits");
    let p = ProfileKind::PvtSym
        .rest_to_rest(0.0, 0.005, &lim)
        .expect("plan");
    let a_end = p.end().a;
    assert!(a_end != 0.0 && a_end.abs() < 1e-15, "{a_end:e}");
    let s = Shaper::new(ShaperType::Zv, 33.4, 0.1).expect("shaper");
    let q = s.apply(&p).expect("a move from rest to rest is shaped");
    let end = q.end();
    assert!(
        (end.p - 0.005).abs() < 1e-12 && end.v.abs() < 1e-12,
        "{end:?}"
    );
    assert!((q.duration_s() - (p.duration_s() + s.duration_s())).abs() < 1e-12);
    // Stopped half-way through its acceleration, the same profile is a fragment.
    let cut = crate::Profile::new(p.start(), p.segments()[..1].to_vec()).expect("profile");
    assert!(cut.end().a.abs() > 1e-3, "{:?}", cut.end());
    assert!(matches!(s.apply(&cut), Err(PlanError::InvalidInput { .. })));
}

#[test]
fn bad_input_is_rejected() {
    assert!(Shaper::new(ShaperType::EI, 0.0, 0.1).is_err());
    assert!(Shaper::new(ShaperType::EI, 40.0, 1.0).is_err());
    assert!(ShaperType::parse("2HUMP_EI").is_ok());
    assert!(matches!(
        ShaperType::parse("zvdd"),
        Err(PlanError::UnknownShaper { .. })
    ));
}
