//! TMC4361A register values of an S-shaped ramp: export for a given clock frequency and
//! microsteps per length unit, and import back.
//!
//! Register addresses, widths and unit formats (TMC4361A datasheet, register table of the
//! ramp generator; the same facts are in Trinamic's/ADI's TMC-API,
//! `tmc/ic/TMC4361A/TMC4361A_Register.h` and `TMC4361A_Fields.h`):
//!
//! | register | addr | bits | unit and format |
//! |---|---|---|---|
//! | VMAX     | 0x24 | signed 32     | pps, 24.8 fixed point (24 integer, 8 fractional bits) |
//! | VSTART   | 0x25 | unsigned 31   | pps, 23.8 fixed point |
//! | VSTOP    | 0x26 | unsigned 31   | pps, 23.8 fixed point |
//! | AMAX     | 0x28 | unsigned 24   | pps^2, 22.2 fixed point; with `direct_acc_val_en`: delta-v per clock cycle, `a[pps^2] = AMAX / 2^37 * fCLK^2` |
//! | DMAX     | 0x29 | unsigned 24   | as AMAX |
//! | BOW1..4  | 0x2D..0x30 | unsigned 24 | pps^3, integer; with `direct_bow_val_en`: delta-a per clock cycle, `j[pps^3] = BOW / 2^53 * fCLK^3` |
//! | CLK_FREQ | 0x31 | unsigned 25   | Hz, 4 MHz ..= 32 MHz |
//! | XTARGET  | 0x37 | signed 32     | microsteps |
//!
//! "pps" is (micro)steps per second. A physical value `x` (in the caller's length unit `u`)
//! becomes `x * usteps_per_unit` steps; the register value is that, scaled by the format
//! and rounded to the nearest integer, so import(export(x)) is within half an LSB of `x`
//! and export(import(r)) == r.
//!
//! In the default (frequency) mode the clock frequency only appears in CLK_FREQ; in the
//! direct modes it scales the acceleration and bow values. VMAX is exported as a magnitude
//! (positioning mode takes the direction from XTARGET - XACTUAL).

use crate::PlanError;
use crate::tmc::SRampParams;

/// Register addresses (TMC4361A).
pub mod addr {
    /// VMAX.
    pub const VMAX: u8 = 0x24;
    /// VSTART.
    pub const VSTART: u8 = 0x25;
    /// VSTOP.
    pub const VSTOP: u8 = 0x26;
    /// AMAX.
    pub const AMAX: u8 = 0x28;
    /// DMAX.
    pub const DMAX: u8 = 0x29;
    /// BOW1 (BOW2..BOW4 follow at +1, +2, +3).
    pub const BOW1: u8 = 0x2D;
    /// CLK_FREQ.
    pub const CLK_FREQ: u8 = 0x31;
    /// XTARGET.
    pub const XTARGET: u8 = 0x37;
}

/// How physical units map to the chip: clock, microsteps per length unit, and the two
/// GENERAL_CONF switches that change the acceleration and bow formats.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TmcUnits {
    /// Clock frequency fCLK (Hz, 4e6 ..= 32e6; integer, as written to CLK_FREQ).
    pub f_clk_hz: u32,
    /// Microsteps per length unit (e.g. 80 * 16 for 80 full steps/mm at 16 microsteps).
    pub usteps_per_unit: f64,
    /// GENERAL_CONF.direct_acc_val_en: AMAX/DMAX in delta-v per clock cycle.
    pub direct_acc: bool,
    /// GENERAL_CONF.direct_bow_val_en: BOW1..4 in delta-a per clock cycle.
    pub direct_bow: bool,
}

/// The ramp registers as raw integers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RegisterSet {
    /// XTARGET (microsteps).
    pub xtarget: i32,
    /// VMAX (24.8 pps, a magnitude).
    pub vmax: i32,
    /// VSTART (23.8 pps).
    pub vstart: u32,
    /// VSTOP (23.8 pps).
    pub vstop: u32,
    /// AMAX.
    pub amax: u32,
    /// DMAX.
    pub dmax: u32,
    /// BOW1..BOW4.
    pub bow: [u32; 4],
    /// CLK_FREQ (Hz).
    pub clk_freq: u32,
}

impl RegisterSet {
    /// `(address, value as written over SPI)` for every register, in address order.
    pub fn writes(&self) -> [(u8, u32); 11] {
        [
            (addr::VMAX, self.vmax as u32),
            (addr::VSTART, self.vstart),
            (addr::VSTOP, self.vstop),
            (addr::AMAX, self.amax),
            (addr::DMAX, self.dmax),
            (addr::BOW1, self.bow[0]),
            (addr::BOW1 + 1, self.bow[1]),
            (addr::BOW1 + 2, self.bow[2]),
            (addr::BOW1 + 3, self.bow[3]),
            (addr::CLK_FREQ, self.clk_freq),
            (addr::XTARGET, self.xtarget as u32),
        ]
    }
}

const U24_MAX: f64 = ((1u32 << 24) - 1) as f64;
const U31_MAX: f64 = ((1u32 << 31) - 1) as f64;
const I32_MAX: f64 = i32::MAX as f64;
const I32_MIN: f64 = i32::MIN as f64;

impl TmcUnits {
    fn check(&self) -> Result<(), PlanError> {
        if !(4_000_000..=32_000_000).contains(&self.f_clk_hz) {
            return Err(PlanError::InvalidInput {
                reason: "CLK_FREQ must be 4 MHz ..= 32 MHz",
            });
        }
        if !(self.usteps_per_unit.is_finite() && self.usteps_per_unit > 0.0) {
            return Err(PlanError::InvalidLimit {
                name: "usteps_per_unit",
                value: self.usteps_per_unit,
            });
        }
        Ok(())
    }

    fn f(&self) -> f64 {
        f64::from(self.f_clk_hz)
    }

    /// Physical value of one LSB of XTARGET (u).
    pub fn position_lsb(&self) -> f64 {
        1.0 / self.usteps_per_unit
    }

    /// Physical value of one LSB of VMAX/VSTART/VSTOP (u/s): 1/256 pps.
    pub fn velocity_lsb(&self) -> f64 {
        1.0 / (256.0 * self.usteps_per_unit)
    }

    /// Physical value of one LSB of AMAX/DMAX (u/s^2): 1/4 pps^2, or fCLK^2/2^37 pps^2 in
    /// the direct mode.
    pub fn accel_lsb(&self) -> f64 {
        let pps2 = if self.direct_acc {
            self.f() * self.f() / 2f64.powi(37)
        } else {
            0.25
        };
        pps2 / self.usteps_per_unit
    }

    /// Physical value of one LSB of BOW1..4 (u/s^3): 1 pps^3, or fCLK^3/2^53 pps^3 in the
    /// direct mode.
    pub fn bow_lsb(&self) -> f64 {
        let pps3 = if self.direct_bow {
            self.f() * self.f() * self.f() / 2f64.powi(53)
        } else {
            1.0
        };
        pps3 / self.usteps_per_unit
    }
}

/// Round `x / lsb` into `[lo, hi]`, or the error naming the register.
fn raw(x: f64, lsb: f64, lo: f64, hi: f64, err: &'static str) -> Result<f64, PlanError> {
    let r = (x / lsb).round();
    if r.is_finite() && r >= lo && r <= hi {
        Ok(r)
    } else {
        Err(PlanError::InvalidInput { reason: err })
    }
}

/// Register values of a ramp to absolute target position `target` (u).
pub fn export(target: f64, p: &SRampParams, u: &TmcUnits) -> Result<RegisterSet, PlanError> {
    u.check()?;
    p.validate()?;
    let vl = u.velocity_lsb();
    let al = u.accel_lsb();
    let bl = u.bow_lsb();
    let bow_err = [
        "BOW1 out of range (unsigned 24 bit)",
        "BOW2 out of range (unsigned 24 bit)",
        "BOW3 out of range (unsigned 24 bit)",
        "BOW4 out of range (unsigned 24 bit)",
    ];
    let mut bow = [0u32; 4];
    for i in 0..4 {
        bow[i] = raw(p.bow[i], bl, 0.0, U24_MAX, bow_err[i])? as u32;
    }
    Ok(RegisterSet {
        xtarget: raw(
            target,
            u.position_lsb(),
            I32_MIN,
            I32_MAX,
            "XTARGET out of range (signed 32 bit microsteps)",
        )? as i32,
        vmax: raw(
            p.vmax,
            vl,
            0.0,
            I32_MAX,
            "VMAX out of range (signed 32 bit, 24.8 pps)",
        )? as i32,
        vstart: raw(
            p.vstart,
            vl,
            0.0,
            U31_MAX,
            "VSTART out of range (unsigned 31 bit, 23.8 pps)",
        )? as u32,
        vstop: raw(
            p.vstop,
            vl,
            0.0,
            U31_MAX,
            "VSTOP out of range (unsigned 31 bit, 23.8 pps)",
        )? as u32,
        amax: raw(
            p.amax,
            al,
            0.0,
            U24_MAX,
            "AMAX out of range (unsigned 24 bit)",
        )? as u32,
        dmax: raw(
            p.dmax,
            al,
            0.0,
            U24_MAX,
            "DMAX out of range (unsigned 24 bit)",
        )? as u32,
        bow,
        clk_freq: u.f_clk_hz,
    })
}

/// The target position (u) and ramp parameters that a register set means. The values are
/// exact multiples of the LSBs; a zero limit register imports as zero (and then fails
/// [`SRampParams::validate`] when planned).
pub fn import(r: &RegisterSet, u: &TmcUnits) -> Result<(f64, SRampParams), PlanError> {
    let u = TmcUnits {
        f_clk_hz: r.clk_freq,
        ..*u
    };
    u.check()?;
    if r.vstart >= 1 << 31 || r.vstop >= 1 << 31 {
        return Err(PlanError::InvalidInput {
            reason: "VSTART/VSTOP have 31 bits",
        });
    }
    if r.amax >= 1 << 24 || r.dmax >= 1 << 24 || r.bow.iter().any(|&b| b >= 1 << 24) {
        return Err(PlanError::InvalidInput {
            reason: "AMAX, DMAX and BOW1..4 have 24 bits",
        });
    }
    let vl = u.velocity_lsb();
    let al = u.accel_lsb();
    let bl = u.bow_lsb();
    let params = SRampParams {
        vstart: f64::from(r.vstart) * vl,
        vmax: f64::from(r.vmax).abs() * vl,
        vstop: f64::from(r.vstop) * vl,
        amax: f64::from(r.amax) * al,
        dmax: f64::from(r.dmax) * al,
        bow: r.bow.map(|b| f64::from(b) * bl),
    };
    Ok((f64::from(r.xtarget) * u.position_lsb(), params))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_values_frequency_mode() {
        // 100 usteps per mm: 50 mm/s = 5000 pps = 5000 * 256 in 24.8; 1000 mm/s^2 =
        // 100000 pps^2 = 400000 in 22.2; 20000 mm/s^3 = 2e6 pps^3.
        let u = TmcUnits {
            f_clk_hz: 16_000_000,
            usteps_per_unit: 100.0,
            direct_acc: false,
            direct_bow: false,
        };
        let p = SRampParams {
            vstart: 1.0,
            vmax: 50.0,
            vstop: 0.5,
            amax: 1000.0,
            dmax: 500.0,
            bow: [20_000.0, 10_000.0, 5_000.0, 2_500.0],
        };
        let r = export(12.34, &p, &u).expect("export");
        assert_eq!(r.xtarget, 1234);
        assert_eq!(r.vmax, 5000 * 256);
        assert_eq!((r.vstart, r.vstop), (100 * 256, 50 * 256));
        assert_eq!((r.amax, r.dmax), (400_000, 200_000));
        assert_eq!(r.bow, [2_000_000, 1_000_000, 500_000, 250_000]);
        assert_eq!(r.clk_freq, 16_000_000);
        let (x, q) = import(&r, &u).expect("import");
        assert!((x - 12.34).abs() < 1e-12);
        assert_eq!(q, p);
    }

    #[test]
    fn known_values_direct_mode() {
        // fCLK = 2^24 Hz (16.777216 MHz): the acceleration LSB is 2^48/2^37 = 2048 pps^2,
        // the bow LSB 2^72/2^53 = 2^19 pps^3.
        let u = TmcUnits {
            f_clk_hz: 1 << 24,
            usteps_per_unit: 1.0,
            direct_acc: true,
            direct_bow: true,
        };
        assert_eq!(u.accel_lsb(), 2048.0);
        assert_eq!(u.bow_lsb(), 524_288.0);
        let mut p = SRampParams::symmetric(1000.0, 2048.0 * 3.0, 524_288.0 * 5.0);
        p.vstart = 0.0;
        let r = export(0.0, &p, &u).expect("export");
        assert_eq!((r.amax, r.bow[3]), (3, 5));
    }

    #[test]
    fn out_of_range_names_the_register() {
        let u = TmcUnits {
            f_clk_hz: 16_000_000,
            usteps_per_unit: 1.0,
            direct_acc: false,
            direct_bow: false,
        };
        let p = SRampParams::symmetric(1.0, 1e7, 1.0);
        assert_eq!(
            export(0.0, &p, &u),
            Err(PlanError::InvalidInput {
                reason: "AMAX out of range (unsigned 24 bit)"
            })
        );
        let bad_clock = TmcUnits {
            f_clk_hz: 1_000_000,
            ..u
        };
        assert!(export(0.0, &SRampParams::symmetric(1.0, 1.0, 1.0), &bad_clock).is_err());
    }
}
