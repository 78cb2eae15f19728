//! TMC4361A register values of an S-shaped ramp: export for a given clock frequency and
//! the machine's microsteps per length unit, import back, and the register file.
//!
//! Register addresses, widths and unit formats of the ramp generator (TMC4361A datasheet,
//! Rev. 1.22 2017-JAN-12, register map of the ramp generator, addresses 0x20..0x37; the
//! same facts transcribed in ADI's TMC-API `tmc/ic/TMC4361A/TMC4361A_Register.h` and
//! `TMC4361A_Fields.h`, which these were checked against):
//!
//! | register | addr | bits | unit and format |
//! |---|---|---|---|
//! | RAMPMODE | 0x20 | 3             | bit 2: positioning mode; bits 1:0: 2 = S-shaped ramp |
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
//! becomes `x * usteps_per_unit` steps, where `usteps_per_unit` is the machine's own
//! (full steps per revolution x microsteps / travel per revolution, see
//! [`TmcUnits::usteps_per_unit_of`]); the register value is that, scaled by the format and
//! rounded to the nearest integer, so import(export(x)) is within half an LSB of `x` and
//! export(import(r)) == r. What the chip cannot hold is refused, naming the register and
//! its range: a value above the register's width, a nonzero value that rounds to 0, and a
//! zero VMAX, AMAX, DMAX or BOW (an S-ramp with them never arrives). The jerks are where
//! the chip is tightest: in frequency mode one BOW LSB is 1 pps^3 and the largest
//! 16,777,215 pps^3, i.e. 13,107 mm/s^3 at 1280 microsteps/mm; the direct mode reaches
//! further with coarser steps.
//!
//! In the default (frequency) mode the clock frequency only appears in CLK_FREQ; in the
//! direct modes it scales the acceleration and bow values. VMAX is exported as a magnitude
//! (positioning mode takes the direction from XTARGET - XACTUAL).

use super::field::{Field, RegisterWrite, register_file_text};
use crate::PlanError;
use crate::tmc::SRampParams;

const CHIP: &str = "TMC4361A";

/// Register addresses (TMC4361A).
pub mod addr {
    /// GENERAL_CONF (holds `direct_acc_val_en`, bit 1, and `direct_bow_val_en`, bit 2).
    pub const GENERAL_CONF: u8 = 0x00;
    /// RAMPMODE.
    pub const RAMPMODE: u8 = 0x20;
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

/// RAMPMODE for an S-shaped ramp in positioning mode (bit 2 set, profile 2).
pub const RAMPMODE_S_POSITIONING: u32 = 0b110;

/// How physical units map to the chip: clock, microsteps per length unit, and the two
/// GENERAL_CONF switches that change the acceleration and bow formats.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TmcUnits {
    /// Clock frequency fCLK (Hz, 4e6 ..= 32e6; integer, as written to CLK_FREQ).
    pub f_clk_hz: u32,
    /// The machine's microsteps per length unit (e.g. 80 * 16 = 1280 for 80 full steps/mm
    /// at 16 microsteps). No default: it is the machine's.
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
    /// `(address, value as written over SPI)` for every ramp value, in address order.
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

    /// The register file of a move: RAMPMODE (S-shaped positioning), the ramp values and
    /// XTARGET last (writing it starts the move), each with its physical meaning in `u`.
    pub fn register_file(&self, u: &TmcUnits) -> Vec<RegisterWrite> {
        let w = RegisterWrite::new;
        let (vl, al, bl) = (u.velocity_lsb(), u.accel_lsb(), u.bow_lsb());
        let mut out = vec![
            w("CLK_FREQ", addr::CLK_FREQ, self.clk_freq, "Hz".into()),
            w(
                "RAMPMODE",
                addr::RAMPMODE,
                RAMPMODE_S_POSITIONING,
                "S-shaped ramp, positioning mode".into(),
            ),
            w(
                "VSTART",
                addr::VSTART,
                self.vstart,
                format!("{} u/s", f64::from(self.vstart) * vl),
            ),
            w(
                "VSTOP",
                addr::VSTOP,
                self.vstop,
                format!("{} u/s", f64::from(self.vstop) * vl),
            ),
            w(
                "VMAX",
                addr::VMAX,
                self.vmax as u32,
                format!("{} u/s", f64::from(self.vmax) * vl),
            ),
            w(
                "AMAX",
                addr::AMAX,
                self.amax,
                format!("{} u/s^2", f64::from(self.amax) * al),
            ),
            w(
                "DMAX",
                addr::DMAX,
                self.dmax,
                format!("{} u/s^2", f64::from(self.dmax) * al),
            ),
        ];
        for (i, name) in ["BOW1", "BOW2", "BOW3", "BOW4"].into_iter().enumerate() {
            out.push(w(
                name,
                addr::BOW1 + i as u8,
                self.bow[i],
                format!("{} u/s^3", f64::from(self.bow[i]) * bl),
            ));
        }
        out.push(w(
            "XTARGET",
            addr::XTARGET,
            self.xtarget as u32,
            format!(
                "{} u (microsteps, signed)",
                f64::from(self.xtarget) * u.position_lsb()
            ),
        ));
        out
    }

    /// The register file as text, headed by the units it was computed for.
    pub fn register_file_text(&self, u: &TmcUnits) -> String {
        let header = vec![
            format!(
                "{CHIP} ramp registers: {} microsteps per unit u, fCLK {} Hz",
                u.usteps_per_unit, self.clk_freq
            ),
            format!(
                "GENERAL_CONF (0x{:02X}) must have direct_acc_val_en = {}, direct_bow_val_en = {}",
                addr::GENERAL_CONF,
                u8::from(u.direct_acc),
                u8::from(u.direct_bow)
            ),
        ];
        register_file_text(&header, &self.register_file(u))
    }
}

const U24_MAX: i64 = (1 << 24) - 1;
const U31_MAX: i64 = (1 << 31) - 1;

impl TmcUnits {
    /// Microsteps per unit of a stepper axis: `full_steps_per_rev * microsteps /
    /// travel_per_rev` (Klipper's `full_steps_per_rotation * microsteps /
    /// rotation_distance`), e.g. 200 * 16 / 40 mm = 80 per mm.
    pub fn usteps_per_unit_of(
        full_steps_per_rev: u32,
        microsteps: u32,
        travel_per_rev: f64,
    ) -> f64 {
        f64::from(full_steps_per_rev) * f64::from(microsteps) / travel_per_rev
    }

    fn check(&self) -> Result<(), PlanError> {
        if !(4_000_000..=32_000_000).contains(&self.f_clk_hz) {
            return Err(PlanError::Register {
                chip: CHIP,
                register: "CLK_FREQ",
                value: f64::from(self.f_clk_hz),
                reason: "the clock must be 4 MHz ..= 32 MHz".into(),
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

    fn field(&self, name: &'static str, min: i64, max: i64, lsb: f64) -> Field {
        Field {
            chip: CHIP,
            name,
            min,
            max,
            lsb,
        }
    }
}

/// Register values of a ramp to absolute target position `target` (u).
pub fn export(target: f64, p: &SRampParams, u: &TmcUnits) -> Result<RegisterSet, PlanError> {
    u.check()?;
    p.validate()?;
    let (vl, al, bl) = (u.velocity_lsb(), u.accel_lsb(), u.bow_lsb());
    let i32_range = (i64::from(i32::MIN), i64::from(i32::MAX));
    let mut bow = [0u32; 4];
    for (i, name) in ["BOW1", "BOW2", "BOW3", "BOW4"].into_iter().enumerate() {
        bow[i] = u.field(name, 1, U24_MAX, bl).raw(p.bow[i])? as u32;
    }
    Ok(RegisterSet {
        xtarget: u
            .field("XTARGET", i32_range.0, i32_range.1, u.position_lsb())
            .raw(target)
            .or_else(|e| {
                // A target that rounds to microstep 0 is a move to 0, not a refusal.
                if (target / u.position_lsb()).abs() < 0.5 {
                    Ok(0)
                } else {
                    Err(e)
                }
            })? as i32,
        vmax: u.field("VMAX", 1, i32_range.1, vl).raw(p.vmax)? as i32,
        vstart: u.field("VSTART", 0, U31_MAX, vl).raw(p.vstart)? as u32,
        vstop: u.field("VSTOP", 0, U31_MAX, vl).raw(p.vstop)? as u32,
        amax: u.field("AMAX", 1, U24_MAX, al).raw(p.amax)? as u32,
        dmax: u.field("DMAX", 1, U24_MAX, al).raw(p.dmax)? as u32,
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
    let (vl, al, bl) = (u.velocity_lsb(), u.accel_lsb(), u.bow_lsb());
    let v31 = |name, raw: u32| u.field(name, 0, U31_MAX, vl).check_raw(i64::from(raw));
    let a24 = |name, raw: u32| u.field(name, 0, U24_MAX, al).check_raw(i64::from(raw));
    let b24 = |name, raw: u32| u.field(name, 0, U24_MAX, bl).check_raw(i64::from(raw));
    let params = SRampParams {
        vstart: v31("VSTART", r.vstart)?,
        vmax: f64::from(r.vmax).abs() * vl,
        vstop: v31("VSTOP", r.vstop)?,
        amax: a24("AMAX", r.amax)?,
        dmax: a24("DMAX", r.dmax)?,
        bow: [
            b24("BOW1", r.bow[0])?,
            b24("BOW2", r.bow[1])?,
            b24("BOW3", r.bow[2])?,
            b24("BOW4", r.bow[3])?,
        ],
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
    fn what_the_chip_cannot_hold_is_refused_by_name() {
        let u = TmcUnits {
            f_clk_hz: 16_000_000,
            usteps_per_unit: 1.0,
            direct_acc: false,
            direct_bow: false,
        };
        // AMAX 1e7 pps^2 needs 4e7 LSB of 1/4 pps^2: above 24 bits.
        let p = SRampParams::symmetric(1.0, 1e7, 1.0);
        match export(0.0, &p, &u) {
            Err(
                e @ PlanError::Register {
                    register: "AMAX", ..
                },
            ) => {
                let text = e.to_string();
                assert!(
                    text.contains("TMC4361A") && text.contains("16777215"),
                    "{text}"
                );
            }
            other => panic!("{other:?}"),
        }
        // A jerk of 0.4 pps^3 rounds to BOW = 0: the ramp would never leave B1.
        let p = SRampParams {
            bow: [1.0, 1.0, 0.4, 1.0],
            ..SRampParams::symmetric(1.0, 1.0, 1.0)
        };
        assert!(matches!(
            export(0.0, &p, &u),
            Err(PlanError::Register {
                register: "BOW3",
                ..
            })
        ));
        // 2^24 pps^3 is one more than BOW holds.
        let p = SRampParams::symmetric(1.0, 1.0, 16_777_216.0);
        assert!(matches!(
            export(0.0, &p, &u),
            Err(PlanError::Register {
                register: "BOW1",
                ..
            })
        ));
        let bad_clock = TmcUnits {
            f_clk_hz: 1_000_000,
            ..u
        };
        assert!(matches!(
            export(0.0, &SRampParams::symmetric(1.0, 1.0, 1.0), &bad_clock),
            Err(PlanError::Register {
                register: "CLK_FREQ",
                ..
            })
        ));
    }

    #[test]
    fn register_file_lists_rampmode_and_ends_with_xtarget() {
        // 200 full steps x 16 microsteps per 40 mm = 80 microsteps per mm.
        let usteps = TmcUnits::usteps_per_unit_of(200, 16, 40.0);
        assert_eq!(usteps, 80.0);
        let u = TmcUnits {
            f_clk_hz: 16_000_000,
            usteps_per_unit: usteps,
            direct_acc: false,
            direct_bow: false,
        };
        let r = export(20.0, &SRampParams::symmetric(100.0, 2000.0, 1e5), &u).expect("export");
        let file = r.register_file(&u);
        assert_eq!(file[1].name, "RAMPMODE");
        assert_eq!((file[1].addr, file[1].value), (0x20, 6));
        let last = file.last().expect("writes");
        assert_eq!((last.name, last.addr, last.value), ("XTARGET", 0x37, 1600));
        // 100 mm/s * 80 = 8000 pps = 2,048,000 in 24.8; 2000 mm/s^2 * 80 * 4 = 640,000;
        // 1e5 mm/s^3 * 80 = 8,000,000 pps^3.
        let text = r.register_file_text(&u);
        assert!(text.contains("VMAX      0x24 = 2048000"), "{text}");
        assert!(text.contains("AMAX      0x28 = 640000"), "{text}");
        assert!(text.contains("BOW4      0x30 = 8000000"), "{text}");
        assert!(text.contains("80 microsteps per unit"), "{text}");
    }
}
