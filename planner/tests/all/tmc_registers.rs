//! TMC4361A register export/import: seeded random round trips in both directions, every
//! format mode, clocks across the chip's range; a ramp planned from imported registers
//! covers XTARGET exactly.
//!
//! Case count: `SETTLE_PLANNER_CASES` (default 100,000; this suite uses a tenth).

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use settle_planner::tmc::ramp::plan;
use settle_planner::tmc::registers::{export, import};
use settle_planner::tmc::{RegisterSet, SRampParams, TmcUnits};

fn cases() -> usize {
    std::env::var("SETTLE_PLANNER_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(100_000usize)
        .div_ceil(10)
}

fn units(rng: &mut ChaCha8Rng) -> TmcUnits {
    TmcUnits {
        f_clk_hz: rng.random_range(4_000_000..=32_000_000),
        usteps_per_unit: rng.random_range(1.0f64.ln()..1e5f64.ln()).exp(),
        direct_acc: rng.random_bool(0.5),
        direct_bow: rng.random_bool(0.5),
    }
}

/// A value whose register lies uniformly in `[1, max_raw]` (so every bit width is
/// exercised), plus a random fraction of an LSB.
fn value(rng: &mut ChaCha8Rng, lsb: f64, max_raw: f64) -> f64 {
    let raw = rng.random_range(0.0..max_raw.ln()).exp().min(max_raw - 1.0);
    (raw + rng.random_range(-0.49..0.49)).max(0.6) * lsb
}

#[test]
fn physical_round_trip_is_within_half_an_lsb() {
    let mut rng = ChaCha8Rng::seed_from_u64(10);
    for _ in 0..cases() {
        let u = units(&mut rng);
        let (vl, al, bl) = (u.velocity_lsb(), u.accel_lsb(), u.bow_lsb());
        let u24 = f64::from((1u32 << 24) - 1);
        let vmax = value(&mut rng, vl, f64::from(i32::MAX));
        // A start/stop speed below one LSB is 0 (the export refuses a nonzero value that
        // rounds to 0).
        let speed = |x: f64| if x < vl { 0.0 } else { x };
        let p = SRampParams {
            vstart: speed(rng.random_range(0.0..1.0) * vmax),
            vmax,
            vstop: speed(rng.random_range(0.0..1.0) * vmax),
            amax: value(&mut rng, al, u24),
            dmax: value(&mut rng, al, u24),
            bow: [0; 4].map(|_| value(&mut rng, bl, u24)),
        };
        let target = rng.random_range(-2e9..2e9) * u.position_lsb();
        let r = export(target, &p, &u).expect("export");
        let (x, q) = import(&r, &u).expect("import");
        let half = 0.5 + 1e-9;
        let within = |a: f64, b: f64, lsb: f64| (a - b).abs() <= half * lsb + 1e-15 * b.abs();
        assert!(within(x, target, u.position_lsb()), "{x} vs {target}");
        assert!(
            within(q.vmax, p.vmax, vl),
            "vmax {} vs {} {u:?}",
            q.vmax,
            p.vmax
        );
        assert!(within(q.vstart, p.vstart, vl) && within(q.vstop, p.vstop, vl));
        assert!(
            within(q.amax, p.amax, al) && within(q.dmax, p.dmax, al),
            "{u:?}"
        );
        for i in 0..4 {
            assert!(within(q.bow[i], p.bow[i], bl), "bow{} {u:?}", i + 1);
        }
        // And the registers of the imported values are the same registers.
        assert_eq!(export(x, &q, &u).expect("re-export"), r);
    }
}

#[test]
fn register_round_trip_is_exact() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let mut done = 0;
    while done < cases() {
        let u = units(&mut rng);
        let vmax = rng.random_range(1..=i32::MAX);
        let r = RegisterSet {
            xtarget: rng.random(),
            vmax,
            vstart: rng.random_range(0..=vmax as u32),
            vstop: rng.random_range(0..=vmax as u32),
            amax: rng.random_range(1..1 << 24),
            dmax: rng.random_range(1..1 << 24),
            bow: [0; 4].map(|_| rng.random_range(1..1 << 24)),
            clk_freq: u.f_clk_hz,
        };
        let (x, p) = import(&r, &u).expect("import");
        assert_eq!(export(x, &p, &u).expect("export"), r, "{u:?}");
        done += 1;
    }
}

#[test]
fn ramp_from_imported_registers_reaches_xtarget_exactly() {
    // 16 MHz, 80 full steps/mm at 16 microsteps = 1280 usteps/mm; units are mm.
    let u = TmcUnits {
        f_clk_hz: 16_000_000,
        usteps_per_unit: 1280.0,
        direct_acc: false,
        direct_bow: false,
    };
    let p = SRampParams {
        vstart: 1.0,
        vmax: 150.0,
        vstop: 2.0,
        amax: 3000.0,
        dmax: 2000.0,
        // BOW is 24 bit integer pps^3: at 1280 usteps/mm at most 13107 mm/s^3.
        bow: [1e4, 5e3, 8e3, 1.2e4],
    };
    let r = export(123.456, &p, &u).expect("export");
    assert_eq!(r.xtarget, 158_024); // 123.456 * 1280 = 158023.68
    let (x, q) = import(&r, &u).expect("import");
    let ramp = plan(0.0, x, &q).expect("ramp");
    let steps = ramp.profile.end().p * u.usteps_per_unit;
    assert!((steps - f64::from(r.xtarget)).abs() < 1e-6, "{steps}");
    assert!((ramp.profile.end().v - q.vstop).abs() < 1e-9);
}
