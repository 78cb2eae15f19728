//! Fitting a physical value into a chip register: scale, round to the nearest integer,
//! refuse what does not fit (overflow, a nonzero value that rounds to zero, a zero the chip
//! forbids) with an error naming the chip, the register and its range; and the register
//! file text both chips' exports write.

use std::fmt::Write as _;

use crate::PlanError;

/// A register's width and what it forbids.
#[derive(Debug, Clone, Copy)]
pub(super) struct Field {
    pub chip: &'static str,
    pub name: &'static str,
    /// Smallest and largest raw value.
    pub min: i64,
    pub max: i64,
    /// The physical value of one LSB (caller's units).
    pub lsb: f64,
}

impl Field {
    fn err(&self, value: f64, reason: String) -> PlanError {
        PlanError::Register {
            chip: self.chip,
            register: self.name,
            value,
            reason,
        }
    }

    /// The raw register value of `value`.
    pub fn raw(&self, value: f64) -> Result<i64, PlanError> {
        let r = (value / self.lsb).round();
        if !r.is_finite() {
            return Err(self.err(value, "not a finite number".into()));
        }
        if r == 0.0 && value != 0.0 {
            return Err(self.err(
                value,
                format!("rounds to 0 (one LSB is {} in these units)", self.lsb),
            ));
        }
        if r < self.min as f64 || r > self.max as f64 {
            return Err(self.err(
                value,
                format!(
                    "needs {r:.0} LSB, the register holds {}..={} ({}..={} in these units)",
                    self.min,
                    self.max,
                    self.min as f64 * self.lsb,
                    self.max as f64 * self.lsb
                ),
            ));
        }
        Ok(r as i64)
    }

    /// Check a raw value read back.
    pub fn check_raw(&self, raw: i64) -> Result<f64, PlanError> {
        if raw < self.min || raw > self.max {
            return Err(self.err(
                raw as f64 * self.lsb,
                format!("raw {raw} outside {}..={}", self.min, self.max),
            ));
        }
        Ok(raw as f64 * self.lsb)
    }
}

/// One register write: name, address, value as sent over SPI, and a note (unit).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RegisterWrite {
    /// Register name as in the datasheet.
    pub name: &'static str,
    /// Address.
    pub addr: u8,
    /// The 32-bit datagram payload (two's complement for signed registers).
    pub value: u32,
    /// What the value means.
    pub note: String,
}

impl RegisterWrite {
    /// A write of `value` to register `name` at `addr`, with what it means.
    pub fn new(name: &'static str, addr: u8, value: u32, note: String) -> Self {
        Self {
            name,
            addr,
            value,
            note,
        }
    }
}

/// The register file as text: `#` comment lines, then `NAME 0xAA = value  ; note`.
pub fn register_file_text(header: &[String], writes: &[RegisterWrite]) -> String {
    let mut out = String::new();
    for h in header {
        let _ = writeln!(out, "# {h}");
    }
    for w in writes {
        let _ = writeln!(
            out,
            "{:<9} 0x{:02X} = {:<11} ; {}",
            w.name, w.addr, w.value, w.note
        );
    }
    out
}
