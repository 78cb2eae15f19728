//! The TMC4361A S-shaped ramp: the phase distance formulas (the vendor's "1/6" form and the
//! "1/3" form proposed as its correction) checked against exact integration, every ramp
//! covering exactly its distance and meeting VSTOP, every reduced case, both directions,
//! and the symmetric case against settle's closed-form S-curve.
//!
//! Case count: `SETTLE_PLANNER_CASES` (default 100,000; the suite scales it down).

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use settle_planner::tmc::ramp::plan;
use settle_planner::tmc::{SRamp, SRampParams};
use settle_planner::{Limits, PlanError, Segment, State, scurve};

fn cases(div: usize) -> usize {
    std::env::var("SETTLE_PLANNER_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(100_000usize)
        .div_ceil(div)
}

fn log_uniform(rng: &mut ChaCha8Rng, lo: f64, hi: f64) -> f64 {
    rng.random_range(lo.ln()..hi.ln()).exp()
}

fn draw(rng: &mut ChaCha8Rng) -> SRampParams {
    let vmax = log_uniform(rng, 1e-3, 1e3);
    let mut start_stop = || {
        if rng.random_bool(0.4) {
            0.0
        } else {
            vmax * rng.random_range(0.0..1.0)
        }
    };
    let (vstart, vstop) = (start_stop(), start_stop());
    SRampParams {
        vstart,
        vmax,
        vstop,
        amax: log_uniform(rng, 1e-3, 1e3),
        dmax: log_uniform(rng, 1e-3, 1e3),
        bow: [0; 4].map(|_| log_uniform(rng, 1e-3, 1e4)),
    }
}

/// State at the start of each phase and at the end (from the profile's evaluator).
fn boundaries(r: &SRamp) -> Vec<State> {
    let mut t = 0.0;
    let mut out = Vec::with_capacity(8);
    let at = |t: f64| {
        let s = r.profile.state_at(t);
        State {
            p: s.p,
            v: s.v,
            a: s.a,
        }
    };
    out.push(at(0.0));
    for d in r.phases_s {
        t += d;
        out.push(at(t));
    }
    *out.last_mut().expect("end") = r.profile.end();
    out
}

/// The constant-jerk kinematics (`a = a0 + j t`, `v = v0 + a0 t + j t^2/2`,
/// `d = v0 t + a0 t^2/2 + j t^3/6`) rewritten with the *end* acceleration `a` and the
/// signed jerk are an identity: `d = v0 t + a t^2/2 - j t^3/3` (the "1/3" form); the
/// vendor's "1/6" form is not, with the same reading.
#[test]
fn one_third_form_is_the_end_acceleration_identity() {
    let mut rng = ChaCha8Rng::seed_from_u64(0);
    for _ in 0..1000 {
        let (v0, a0) = (rng.random_range(-5.0..5.0), rng.random_range(-5.0..5.0));
        let (j, t) = (rng.random_range(-50.0..50.0), rng.random_range(0.01..1.0));
        let s = Segment::Jerk {
            duration_s: t,
            jerk: j,
        }
        .end_state(&State {
            p: 0.0,
            v: v0,
            a: a0,
        });
        let a_end = a0 + j * t;
        let third = v0 * t + a_end * t * t / 2.0 - j * t.powi(3) / 3.0;
        let sixth = v0 * t + a_end * t * t / 2.0 - j * t.powi(3) / 6.0;
        let scale = s.p.abs().max(1e-3);
        assert!((third - s.p).abs() <= 1e-12 * scale.max(j.abs() * t.powi(3)));
        assert!(((sixth - s.p) - j * t.powi(3) / 6.0).abs() <= 1e-12 * scale.max(j.abs()));
    }
}

/// With the values a planner sends to the chip (`a` = AMAX or DMAX reached, `j2` = BOW2,
/// `j4` = BOW4, `v3`/`v7` the velocities at the start of B2/B4), the vendor's 1/6 forms
/// give the exact distances of B2 and B4, and the 1/3 forms
/// (`d3 = v3 t3 + a t3^2/2 - j2 t3^3/3`, `d7 = v7 t7 - a t7^2/2 + j4 t7^3/3`) miss them by
/// `BOW2 t3^3/6` and `BOW4 t7^3/6`. Summing the closed-form phase distances, the vendor's
/// version passes the distance check (equals XTARGET) and the 1/3 version fails it. The
/// velocity formulas `v3 = vMax - a t3 + j2 t3^2/2` and `v7 = vFinal + a t7 - j4 t7^2/2`
/// hold.
#[test]
fn phase_formulas_against_exact_integration() {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let mut checked = 0;
    while checked < 2000 {
        let p = draw(&mut rng);
        let d = log_uniform(&mut rng, 1e-4, 1e4);
        let Ok(r) = plan(0.0, d, &p) else { continue };
        let b = boundaries(&r);
        let ph = r.phases_s;
        let (a, dm) = (r.a_peak, r.d_peak);
        let [j1, j2, j3, j4] = p.bow;
        // Closed forms of each phase, from its start velocity.
        let (t1, t12, t3, t23, t5, t34, t7) = (ph[0], ph[1], ph[2], ph[3], ph[4], ph[5], ph[6]);
        let d1 = b[0].v * t1 + j1 * t1.powi(3) / 6.0;
        let d12 = b[1].v * t12 + a * t12 * t12 / 2.0;
        let (v3, v7) = (b[2].v, b[6].v);
        let d3_vendor = v3 * t3 + a * t3 * t3 / 2.0 - j2 * t3.powi(3) / 6.0;
        let d3_third = v3 * t3 + a * t3 * t3 / 2.0 - j2 * t3.powi(3) / 3.0;
        let d23 = r.v_peak * t23;
        let d5 = b[4].v * t5 - j3 * t5.powi(3) / 6.0;
        let d34 = b[5].v * t34 - dm * t34 * t34 / 2.0;
        let d7_vendor = v7 * t7 - dm * t7 * t7 / 2.0 + j4 * t7.powi(3) / 6.0;
        let d7_third = v7 * t7 - dm * t7 * t7 / 2.0 + j4 * t7.powi(3) / 3.0;
        let scale = d.max(r.v_peak * r.duration_s());
        let tol = 1e-11 * scale;
        // Exact phase distances from the profile.
        let exact3 = b[3].p - b[2].p;
        let exact7 = b[7].p - b[6].p;
        assert!((d3_vendor - exact3).abs() <= tol, "{p:?} d={d}");
        assert!((d7_vendor - exact7).abs() <= tol, "{p:?} d={d}");
        assert!(((exact3 - d3_third) - j2 * t3.powi(3) / 6.0).abs() <= tol);
        assert!(((exact7 - d7_third) + j4 * t7.powi(3) / 6.0).abs() <= tol);
        // The velocity formulas.
        assert!((r.v_peak - a * t3 + j2 * t3 * t3 / 2.0 - v3).abs() <= 1e-11 * r.v_peak);
        assert!((p.vstop + dm * t7 - j4 * t7 * t7 / 2.0 - v7).abs() <= 1e-11 * r.v_peak);
        // The distance check.
        let vendor_total = d1 + d12 + d3_vendor + d23 + d5 + d34 + d7_vendor;
        let third_total = d1 + d12 + d3_third + d23 + d5 + d34 + d7_third;
        assert!((vendor_total - d).abs() <= tol, "{vendor_total} vs {d}");
        let miss = (j2 * t3.powi(3) - j4 * t7.powi(3)) / 6.0;
        assert!(((d - third_total) - miss).abs() <= tol);
        if miss.abs() > 1e-6 * d {
            assert!(
                (third_total - d).abs() > 1e3 * tol,
                "the 1/3 form should fail"
            );
        }
        checked += 1;
    }
}

/// Distance of "accelerate from VSTART to vp, decelerate to VSTOP" in closed form (test
/// side, independent of the planner's segment integration).
fn ramp_distance(vp: f64, p: &SRampParams) -> f64 {
    fn half(v0: f64, v1: f64, alim: f64, ja: f64, jb: f64) -> f64 {
        let dv = v1 - v0;
        if dv <= 0.0 {
            return 0.0;
        }
        let k = 0.5 * (1.0 / ja + 1.0 / jb);
        let (a, hold) = if dv >= alim * alim * k {
            (alim, (dv - alim * alim * k) / alim)
        } else {
            ((dv / k).sqrt(), 0.0)
        };
        let (ta, tb) = (a / ja, a / jb);
        let d_a = v0 * ta + ja * ta.powi(3) / 6.0;
        let va = v0 + a * ta / 2.0;
        let d_h = va * hold + a * hold * hold / 2.0;
        let vb = va + a * hold;
        d_a + d_h + vb * tb + a * tb * tb / 2.0 - jb * tb.powi(3) / 6.0
    }
    // The deceleration half is the acceleration half run backwards (VSTOP -> vp with
    // BOW4 first, then BOW3).
    half(p.vstart, vp, p.amax, p.bow[0], p.bow[1]) + half(p.vstop, vp, p.dmax, p.bow[3], p.bow[2])
}

#[test]
fn every_ramp_covers_its_distance_and_meets_vstop() {
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    let mut seen = std::collections::BTreeSet::new();
    let (mut ok, mut infeasible) = (0usize, 0usize);
    for _ in 0..cases(5) {
        let p = draw(&mut rng);
        let dir = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
        // Scale distances around the ramp's natural length so every case occurs.
        let natural = ramp_distance(p.vmax, &p).max(1e-12);
        let d_min = ramp_distance(p.vstart.max(p.vstop), &p);
        let d = dir
            * if rng.random_bool(0.1) {
                d_min * rng.random_range(0.5..1.0)
            } else {
                d_min + natural * log_uniform(&mut rng, 1e-6, 1e2)
            };
        let p0 = rng.random_range(-10.0..10.0);
        // A zero distance (-0.0 included) plans in the positive direction.
        let dir = if d < 0.0 { -1.0 } else { 1.0 };
        let r = match plan(p0, d, &p) {
            Ok(r) => r,
            Err(PlanError::InfeasibleTarget { .. }) => {
                assert!(d.abs() < d_min * (1.0 + 1e-9), "{p:?} d={d} d_min={d_min}");
                infeasible += 1;
                continue;
            }
            Err(e) => panic!("{e} for {p:?} d={d}"),
        };
        ok += 1;
        seen.insert(r.case_name());
        let ctx = format!("{p:?} p0={p0} d={d} {}", r.case_name());
        let e = r.profile.end();
        let scale = d.abs().max(p0.abs());
        assert!(
            (e.p - (p0 + d)).abs() <= 1e-12 * scale + 1e-15,
            "missed by {}: {ctx} {:?}",
            e.p - (p0 + d),
            r.phases_s
        );
        assert!(
            (e.v - dir * p.vstop).abs() <= 1e-11 * p.vmax,
            "vstop: {ctx}"
        );
        assert!(
            e.a.abs() <= 1e-11 * p.amax.max(p.dmax),
            "end a {}: {ctx}",
            e.a
        );
        assert_eq!(r.profile.start().v, dir * p.vstart);
        // Limits, jerks of each phase, monotone velocity in each half.
        let jerks = [p.bow[0], 0.0, -p.bow[1], 0.0, -p.bow[2], 0.0, p.bow[3]];
        assert_eq!(r.profile.segments().len(), 7);
        for (i, (_, st, seg)) in r.profile.iter().enumerate() {
            let (a0, j) = seg.accel_and_jerk(&st);
            assert_eq!(j, dir * jerks[i], "phase {i}: {ctx}");
            let en = seg.end_state(&st);
            for a in [a0, en.a] {
                let a = a * dir;
                assert!(
                    a <= p.amax * (1.0 + 1e-12) && a >= -p.dmax * (1.0 + 1e-12),
                    "{ctx}"
                );
            }
            let dv = (en.v - st.v) * dir;
            if i < 3 {
                assert!(dv >= -1e-12 * p.vmax, "{ctx}");
            } else if i > 3 {
                assert!(dv <= 1e-12 * p.vmax, "{ctx}");
            }
            assert!(en.v.abs() <= p.vmax * (1.0 + 1e-12), "{ctx}");
        }
        // Peak velocity: VMAX with a cruise, or the highest peak that covers d (a peak a
        // hair higher overshoots).
        if r.v_peak < p.vmax {
            // Any cruise below VMAX only takes up what no representable higher peak can
            // (near VSTART/VSTOP the distance grows like sqrt(vp - vlo)).
            assert!(
                ramp_distance(r.v_peak, &p) <= d.abs() * (1.0 + 1e-10),
                "{ctx}"
            );
            let higher = (r.v_peak * (1.0 + 1e-9)).min(p.vmax);
            if higher > r.v_peak && d.abs() > d_min * (1.0 + 1e-9) {
                assert!(ramp_distance(higher, &p) > d.abs() * (1.0 - 1e-12), "{ctx}");
            }
        } else {
            assert_eq!(r.v_peak, p.vmax);
        }
        assert!(r.a_peak <= p.amax && r.d_peak <= p.dmax, "{ctx}");
        if r.phases_s[1] > 0.0 {
            assert_eq!(r.a_peak, p.amax, "{ctx}");
        }
        if r.phases_s[5] > 0.0 {
            assert_eq!(r.d_peak, p.dmax, "{ctx}");
        }
    }
    for case in [
        "acc_vel_dec",
        "acc_vel_no_dec",
        "no_acc_vel_dec",
        "no_acc_vel_no_dec",
        "acc_no_vel_dec",
        "acc_no_vel_no_dec",
        "no_acc_no_vel_dec",
        "no_acc_no_vel_no_dec",
    ] {
        assert!(
            seen.contains(case),
            "case {case} never occurred in {ok} ramps"
        );
    }
    assert!(
        infeasible > 0 && ok > 5 * infeasible,
        "{ok} ok, {infeasible} infeasible"
    );
}

#[test]
fn negative_distance_mirrors_the_ramp() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    for _ in 0..200 {
        let p = draw(&mut rng);
        let d = ramp_distance(p.vmax, &p) * log_uniform(&mut rng, 1.0, 10.0);
        let (fwd, back) = (
            plan(1.0, d, &p).expect("fwd"),
            plan(1.0, -d, &p).expect("back"),
        );
        assert_eq!(fwd.phases_s, back.phases_s);
        for k in 0..=20 {
            let t = fwd.duration_s() * k as f64 / 20.0;
            let (f, b) = (fwd.profile.state_at(t), back.profile.state_at(t));
            assert!(((f.p - 1.0) + (b.p - 1.0)).abs() <= 1e-14 * (1.0 + d));
            assert_eq!((f.v, f.a, f.j), (-b.v, -b.a, -b.j));
        }
    }
}

/// With VSTART = VSTOP = 0, AMAX = DMAX and four equal bows the ramp is the time-optimal
/// rest-to-rest S-curve: equal to settle's closed form `scurve::rest_to_rest`.
#[test]
fn symmetric_ramp_equals_the_closed_form_s_curve() {
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    for _ in 0..cases(20) {
        let (v, a, j) = (
            log_uniform(&mut rng, 1e-3, 1e3),
            log_uniform(&mut rng, 1e-3, 1e3),
            log_uniform(&mut rng, 1e-3, 1e4),
        );
        let d = log_uniform(&mut rng, 1e-6, 1e4);
        let r = plan(0.0, d, &SRampParams::symmetric(v, a, j)).expect("ramp");
        let s = scurve::rest_to_rest(0.0, d, &Limits::new(v, a, Some(j)).expect("lim"))
            .expect("s-curve");
        let rel = (r.duration_s() - s.duration_s()).abs() / s.duration_s();
        assert!(
            rel <= 1e-9,
            "v={v} a={a} j={j} d={d}: {} vs {}",
            r.duration_s(),
            s.duration_s()
        );
    }
}

#[test]
fn too_short_for_the_start_stop_transition_is_an_error() {
    let p = SRampParams {
        vstart: 1.0,
        vmax: 2.0,
        vstop: 0.0,
        amax: 1.0,
        dmax: 1.0,
        bow: [10.0; 4],
    };
    // Decelerating from 1 to 0 at DMAX 1 with bows 10 needs 0.5 + 0.05 = 0.55 (distance of
    // a 1.1 s decel with the jerk phases: v t - ... = 0.55 exactly by symmetry).
    assert!(matches!(
        plan(0.0, 0.5, &p),
        Err(PlanError::InfeasibleTarget { .. })
    ));
    let r = plan(0.0, 0.55, &p).expect("exactly the transition");
    assert!((r.duration_s() - 1.1).abs() < 1e-12, "{}", r.duration_s());
    assert_eq!(r.v_peak, 1.0);
}
