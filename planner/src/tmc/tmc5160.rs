//! TMC5160 ramp registers: the sixPoint ramp (VSTART -A1-> V1 -AMAX-> VMAX -DMAX-> V1
//! -D1-> VSTOP) in positioning mode, exported for the clock and the machine's microsteps
//! per unit, imported back, and written as a register file.
//!
//! The TMC5160 has no jerk (BOW) registers: within each phase its acceleration is
//! constant, so it can run trapezoids (and two-slope "sixPoint" ramps), not S-curves. A
//! jerk-limited profile has no TMC5160 register file; export it to the TMC4361A
//! ([`super::registers`]) instead.
//!
//! Addresses and widths (TMC5160/TMC5160A datasheet Rev. 1.17, register map "Ramp
//! generator motion control register set", 0x20..0x2D; checked against ADI's TMC-API
//! `tmc/ic/TMC5160/TMC5160_Register.h` and `TMC5160_Fields.h`):
//!
//! | register | addr | bits | range |
//! |---|---|---|---|
//! | RAMPMODE | 0x20 | 2  | 0 = positioning |
//! | VSTART   | 0x23 | 18 | 0 ..= 2^18 - 1 |
//! | A1       | 0x24 | 16 | 0 ..= 2^16 - 1 |
//! | V1       | 0x25 | 20 | 0 ..= 2^20 - 1 (0 disables the A1/D1 phases) |
//! | AMAX     | 0x26 | 16 | 0 ..= 2^16 - 1 |
//! | VMAX     | 0x27 | 23 | 0 ..= 2^23 - 512 |
//! | DMAX     | 0x28 | 16 | 0 ..= 2^16 - 1 |
//! | D1       | 0x2A | 16 | 1 ..= 2^16 - 1 (never 0 in positioning mode, even with V1 = 0) |
//! | VSTOP    | 0x2B | 18 | 1 ..= 2^18 - 1, and VSTOP >= VSTART |
//! | XTARGET  | 0x2D | signed 32 | microsteps |
//!
//! Units (the datasheet's "real world unit" conversion): velocities in microsteps per
//! `t = 2^24 / fCLK`, accelerations in microsteps per `ta^2 = 2^41 / fCLK^2`, so
//! `v[usteps/s] = VMAX fCLK / 2^24` and `a[usteps/s^2] = AMAX fCLK^2 / 2^41`. At the usual
//! 12 MHz internal clock one velocity LSB is 0.715 usteps/s and one acceleration LSB
//! 65.5 usteps/s^2. settle accepts clocks of 4 ..= 18 MHz (the external clock range).
//!
//! A stop velocity of 0 is written as VSTOP = 1 (the chip's least, 0.7 usteps/s at 12 MHz,
//! below which it stops at once); every other nonzero value that rounds to 0 is refused,
//! as is anything beyond a register's width.

use super::field::{Field, RegisterWrite, register_file_text};
use crate::PlanError;

const CHIP: &str = "TMC5160";

/// Register addresses (TMC5160).
pub mod addr {
    /// RAMPMODE.
    pub const RAMPMODE: u8 = 0x20;
    /// VSTART.
    pub const VSTART: u8 = 0x23;
    /// A1.
    pub const A1: u8 = 0x24;
    /// V1.
    pub const V1: u8 = 0x25;
    /// AMAX.
    pub const AMAX: u8 = 0x26;
    /// VMAX.
    pub const VMAX: u8 = 0x27;
    /// DMAX.
    pub const DMAX: u8 = 0x28;
    /// D1.
    pub const D1: u8 = 0x2A;
    /// VSTOP.
    pub const VSTOP: u8 = 0x2B;
    /// XTARGET.
    pub const XTARGET: u8 = 0x2D;
}

/// Clock and the machine's microsteps per length unit `u`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tmc5160Units {
    /// Clock fCLK (Hz, 4e6 ..= 18e6; the internal oscillator is nominally 12 MHz).
    pub f_clk_hz: u32,
    /// The machine's microsteps per unit (see
    /// [`super::TmcUnits::usteps_per_unit_of`]).
    pub usteps_per_unit: f64,
}

impl Tmc5160Units {
    /// Physical value of one velocity LSB (u/s): `fCLK / 2^24` microsteps per second.
    pub fn velocity_lsb(&self) -> f64 {
        f64::from(self.f_clk_hz) / 2f64.powi(24) / self.usteps_per_unit
    }

    /// Physical value of one acceleration LSB (u/s^2): `fCLK^2 / 2^41` microsteps/s^2.
    pub fn accel_lsb(&self) -> f64 {
        let f = f64::from(self.f_clk_hz);
        f * f / 2f64.powi(41) / self.usteps_per_unit
    }

    /// Physical value of one XTARGET LSB (u): a microstep.
    pub fn position_lsb(&self) -> f64 {
        1.0 / self.usteps_per_unit
    }

    fn check(&self) -> Result<(), PlanError> {
        if !(4_000_000..=18_000_000).contains(&self.f_clk_hz) {
            return Err(PlanError::Register {
                chip: CHIP,
                register: "fCLK",
                value: f64::from(self.f_clk_hz),
                reason: "the clock must be 4 MHz ..= 18 MHz".into(),
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

    fn field(&self, name: &'static str, min: i64, bits: u32, lsb: f64) -> Field {
        Field {
            chip: CHIP,
            name,
            min,
            max: (1i64 << bits) - 1,
            lsb,
        }
    }
}

/// A sixPoint ramp in physical units (u/s, u/s^2; magnitudes).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SixPointRamp {
    /// Start velocity.
    pub vstart: f64,
    /// Acceleration from VSTART to V1.
    pub a1: f64,
    /// Velocity where the acceleration switches from A1 to AMAX (0: AMAX/DMAX only).
    pub v1: f64,
    /// Acceleration from V1 to VMAX.
    pub amax: f64,
    /// Cruise velocity.
    pub vmax: f64,
    /// Deceleration from VMAX to V1.
    pub dmax: f64,
    /// Deceleration from V1 to VSTOP.
    pub d1: f64,
    /// Stop velocity (0 is written as the chip's least, 1 LSB).
    pub vstop: f64,
}

impl SixPointRamp {
    /// A rest-to-rest trapezoid: V1 = 0 (AMAX and DMAX only; D1 = DMAX since D1 must not
    /// be 0).
    pub fn trapezoid(vmax: f64, amax: f64, dmax: f64) -> Self {
        Self {
            vstart: 0.0,
            a1: amax,
            v1: 0.0,
            amax,
            vmax,
            dmax,
            d1: dmax,
            vstop: 0.0,
        }
    }
}

/// The TMC5160 ramp registers as raw integers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Tmc5160Registers {
    /// VSTART.
    pub vstart: u32,
    /// A1.
    pub a1: u32,
    /// V1.
    pub v1: u32,
    /// AMAX.
    pub amax: u32,
    /// VMAX.
    pub vmax: u32,
    /// DMAX.
    pub dmax: u32,
    /// D1.
    pub d1: u32,
    /// VSTOP.
    pub vstop: u32,
    /// XTARGET (microsteps).
    pub xtarget: i32,
}

const VMAX_MAX: i64 = (1 << 23) - 512;

/// Register values of the ramp `p` to absolute target `target` (u).
pub fn export(
    target: f64,
    p: &SixPointRamp,
    u: &Tmc5160Units,
) -> Result<Tmc5160Registers, PlanError> {
    u.check()?;
    let (vl, al) = (u.velocity_lsb(), u.accel_lsb());
    let vmax = Field {
        max: VMAX_MAX,
        ..u.field("VMAX", 1, 23, vl)
    }
    .raw(p.vmax)?;
    let vstart = u.field("VSTART", 0, 18, vl).raw(p.vstart)?;
    let vstop = if p.vstop == 0.0 {
        1
    } else {
        u.field("VSTOP", 1, 18, vl).raw(p.vstop)?
    };
    if vstop < vstart {
        return Err(PlanError::Register {
            chip: CHIP,
            register: "VSTOP",
            value: p.vstop,
            reason: format!("must be >= VSTART ({vstart} LSB), got {vstop} LSB"),
        });
    }
    let v1 = u.field("V1", 0, 20, vl).raw(p.v1)?;
    let xtarget = (target / u.position_lsb()).round();
    if !(f64::from(i32::MIN)..=f64::from(i32::MAX)).contains(&xtarget) {
        return Err(PlanError::Register {
            chip: CHIP,
            register: "XTARGET",
            value: target,
            reason: format!("{xtarget} microsteps is outside the signed 32-bit register"),
        });
    }
    Ok(Tmc5160Registers {
        vstart: vstart as u32,
        a1: u.field("A1", 0, 16, al).raw(p.a1)? as u32,
        v1: v1 as u32,
        amax: u.field("AMAX", 1, 16, al).raw(p.amax)? as u32,
        vmax: vmax as u32,
        dmax: u.field("DMAX", 1, 16, al).raw(p.dmax)? as u32,
        d1: u.field("D1", 1, 16, al).raw(p.d1)? as u32,
        vstop: vstop as u32,
        xtarget: xtarget as i32,
    })
}

/// The target (u) and ramp a register set means (exact multiples of the LSBs).
pub fn import(r: &Tmc5160Registers, u: &Tmc5160Units) -> Result<(f64, SixPointRamp), PlanError> {
    u.check()?;
    let (vl, al) = (u.velocity_lsb(), u.accel_lsb());
    let v = |name, bits, raw: u32| u.field(name, 0, bits, vl).check_raw(i64::from(raw));
    let a = |name, raw: u32| u.field(name, 0, 16, al).check_raw(i64::from(raw));
    let vmax = Field {
        max: VMAX_MAX,
        ..u.field("VMAX", 0, 23, vl)
    }
    .check_raw(i64::from(r.vmax))?;
    Ok((
        f64::from(r.xtarget) * u.position_lsb(),
        SixPointRamp {
            vstart: v("VSTART", 18, r.vstart)?,
            a1: a("A1", r.a1)?,
            v1: v("V1", 20, r.v1)?,
            amax: a("AMAX", r.amax)?,
            vmax,
            dmax: a("DMAX", r.dmax)?,
            d1: a("D1", r.d1)?,
            vstop: v("VSTOP", 18, r.vstop)?,
        },
    ))
}

impl Tmc5160Registers {
    /// The register file of a move: RAMPMODE 0 (positioning), the ramp, XTARGET last
    /// (writing it starts the move).
    pub fn register_file(&self, u: &Tmc5160Units) -> Vec<RegisterWrite> {
        let (vl, al) = (u.velocity_lsb(), u.accel_lsb());
        let w = RegisterWrite::new;
        let v = |raw: u32| format!("{} u/s", f64::from(raw) * vl);
        let a = |raw: u32| format!("{} u/s^2", f64::from(raw) * al);
        vec![
            w("RAMPMODE", addr::RAMPMODE, 0, "positioning mode".into()),
            w("VSTART", addr::VSTART, self.vstart, v(self.vstart)),
            w("A1", addr::A1, self.a1, a(self.a1)),
            w("V1", addr::V1, self.v1, v(self.v1)),
            w("AMAX", addr::AMAX, self.amax, a(self.amax)),
            w("VMAX", addr::VMAX, self.vmax, v(self.vmax)),
            w("DMAX", addr::DMAX, self.dmax, a(self.dmax)),
            w("D1", addr::D1, self.d1, a(self.d1)),
            w("VSTOP", addr::VSTOP, self.vstop, v(self.vstop)),
            w(
                "XTARGET",
                addr::XTARGET,
                self.xtarget as u32,
                format!(
                    "{} u (microsteps, signed)",
                    f64::from(self.xtarget) * u.position_lsb()
                ),
            ),
        ]
    }

    /// The register file as text, headed by the units and the no-jerk caveat.
    pub fn register_file_text(&self, u: &Tmc5160Units) -> String {
        let header = vec![
            format!(
                "{CHIP} ramp registers: {} microsteps per unit u, fCLK {} Hz",
                u.usteps_per_unit, u.f_clk_hz
            ),
            "the TMC5160 has no jerk registers: constant acceleration within each phase".into(),
        ];
        register_file_text(&header, &self.register_file(u))
    }
}
