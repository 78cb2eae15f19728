//! TMC5160 register export: a hand-computed register file, round trips, and what the chip
//! cannot hold.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use settle_planner::PlanError;
use settle_planner::tmc::TmcUnits;
use settle_planner::tmc::tmc5160::{SixPointRamp, Tmc5160Registers, Tmc5160Units, export, import};

fn units() -> Tmc5160Units {
    Tmc5160Units {
        f_clk_hz: 12_000_000,
        // 200 full steps x 16 microsteps per 40 mm (a GT2 20-tooth pulley).
        usteps_per_unit: TmcUnits::usteps_per_unit_of(200, 16, 40.0),
    }
}

#[test]
fn hand_computed_trapezoid() {
    // 80 usteps/mm at 12 MHz:
    // VMAX: 150 mm/s = 12,000 usteps/s; x 2^24 / 12e6 = 16,777.216 -> 16,777.
    // AMAX: 3000 mm/s^2 = 240,000 usteps/s^2; x 2^41 / 12e6^2 = 3,665.04 -> 3,665.
    // DMAX: 2000 mm/s^2 = 160,000 usteps/s^2 -> 2,443.36 -> 2,443; D1 = DMAX; V1 = 0.
    // XTARGET: 123.456 mm x 80 = 9,876.48 -> 9,876. VSTOP: 0 is written as 1.
    let r = export(
        123.456,
        &SixPointRamp::trapezoid(150.0, 3000.0, 2000.0),
        &units(),
    )
    .expect("export");
    assert_eq!(
        r,
        Tmc5160Registers {
            vstart: 0,
            a1: 3665,
            v1: 0,
            amax: 3665,
            vmax: 16777,
            dmax: 2443,
            d1: 2443,
            vstop: 1,
            xtarget: 9876,
        }
    );
    let text = r.register_file_text(&units());
    assert!(text.contains("no jerk registers"), "{text}");
    assert!(text.contains("VMAX      0x27 = 16777"), "{text}");
    assert!(text.contains("D1        0x2A = 2443"), "{text}");
    assert!(
        text.lines()
            .last()
            .expect("lines")
            .starts_with("XTARGET   0x2D = 9876")
    );
}

#[test]
fn round_trips() {
    let mut rng = ChaCha8Rng::seed_from_u64(5160);
    for _ in 0..2000 {
        let u = Tmc5160Units {
            f_clk_hz: rng.random_range(4_000_000..=18_000_000),
            usteps_per_unit: rng.random_range(1.0f64..5000.0),
        };
        let r = Tmc5160Registers {
            vstart: rng.random_range(0..1000),
            a1: rng.random_range(1..1 << 16),
            v1: rng.random_range(0..1 << 20),
            amax: rng.random_range(1..1 << 16),
            vmax: rng.random_range(1000..(1 << 23) - 512),
            dmax: rng.random_range(1..1 << 16),
            d1: rng.random_range(1..1 << 16),
            vstop: rng.random_range(1000..1 << 18),
            xtarget: rng.random(),
        };
        let (x, p) = import(&r, &u).expect("import");
        assert_eq!(export(x, &p, &u).expect("export"), r, "{u:?}");
        // Physical values come back within half an LSB.
        let (x2, p2) = import(&export(x * 1.0000001, &p, &u).expect("export"), &u).expect("i");
        assert!((x2 - x * 1.0000001).abs() <= 0.5 * u.position_lsb() + 1e-9 * x.abs());
        assert!((p2.vmax - p.vmax).abs() <= 0.5 * u.velocity_lsb() + 1e-12 * p.vmax);
    }
}

#[test]
fn refusals_name_the_register() {
    let u = units();
    let cases: [(SixPointRamp, &str); 5] = [
        // 2^23 - 512 LSB of 0.7153 usteps/s are 75,000 mm/s at 80 usteps/mm: 80,000 does not fit.
        (SixPointRamp::trapezoid(80_000.0, 3000.0, 3000.0), "VMAX"),
        // 65,535 acceleration LSB at 80 usteps/mm are 53,645 mm/s^2.
        (
            SixPointRamp {
                amax: 60_000.0,
                ..SixPointRamp::trapezoid(100.0, 3000.0, 3000.0)
            },
            "AMAX",
        ),
        // Half an LSB (0.41 mm/s^2) rounds to zero.
        (
            SixPointRamp {
                amax: 0.3,
                ..SixPointRamp::trapezoid(100.0, 3000.0, 3000.0)
            },
            "AMAX",
        ),
        (
            SixPointRamp {
                d1: 0.0,
                ..SixPointRamp::trapezoid(100.0, 3000.0, 3000.0)
            },
            "D1",
        ),
        (
            SixPointRamp {
                vstart: 5.0,
                vstop: 1.0,
                ..SixPointRamp::trapezoid(100.0, 3000.0, 3000.0)
            },
            "VSTOP",
        ),
    ];
    for (p, register) in cases {
        match export(10.0, &p, &u) {
            Err(e @ PlanError::Register { .. }) => {
                let text = e.to_string();
                assert!(
                    text.starts_with(&format!("TMC5160 register {register}:")),
                    "{text}"
                );
            }
            other => panic!("{register}: {other:?}"),
        }
    }
    let slow = Tmc5160Units {
        f_clk_hz: 20_000_000,
        ..u
    };
    assert!(export(1.0, &SixPointRamp::trapezoid(100.0, 3000.0, 3000.0), &slow).is_err());
}
