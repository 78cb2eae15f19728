//! Which firmware: the one list of names every command reads (`settle gcode --firmware`,
//! `[gcode] firmware`, `settle tune --firmware`, `[tune] firmware`, `settle import`'s first
//! argument), and what each one is to settle.
//!
//! - Klipper, Marlin and RepRapFirmware plan G-code jobs ([`crate::firmware::klipper`],
//!   [`crate::firmware::marlin`], [`crate::firmware::rrf`]) and shape with their own shaper
//!   definitions ([`crate::shaper::ShaperType::firmware`]); `rrf` is also written
//!   `reprapfirmware` or `duet` (RepRapFirmware runs on Duet boards).
//! - Prusa (`prusa`, also `buddy`): Prusa-Firmware-Buddy, the Marlin derivative of Prusa's
//!   MK4, MK4S, MINI, XL and CORE One. It plans as Marlin does (classic jerk, the same
//!   look-ahead), runs each block as a trapezoid in continuous time (its precise stepping,
//!   [`crate::firmware::marlin::MarlinStepper::PreciseStepping`]) and shapes X, Y and Z
//!   with Klipper's shapers, chosen by `M593 T`.
//! - GRBL (gnea/grbl 1.1, and grblHAL, which plans the same way) runs CNC mills and
//!   lasers: its planner is [`crate::firmware::grbl`].
//! - `settle` is settle's own jerk-limited look-ahead ([`crate::path`]): it plans G-code
//!   jobs too.
//! - The TMC4361A is a motion controller: it runs S-shaped ramps (BOW1..4), no G-code.
//!
//! Each command takes the firmwares it can use and names them when it refuses one.

use std::fmt;

/// A firmware, or settle's own planner.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Firmware {
    /// Klipper.
    Klipper,
    /// Marlin.
    Marlin,
    /// Prusa-Firmware-Buddy (Prusa's Marlin derivative).
    Prusa,
    /// RepRapFirmware.
    Rrf,
    /// GRBL and grblHAL.
    Grbl,
    /// settle's own planner.
    Settle,
    /// The TMC4361A motion controller.
    Tmc4361a,
}

impl Firmware {
    /// Every firmware, in a fixed order.
    pub const ALL: [Firmware; 7] = [
        Firmware::Klipper,
        Firmware::Marlin,
        Firmware::Prusa,
        Firmware::Rrf,
        Firmware::Grbl,
        Firmware::Settle,
        Firmware::Tmc4361a,
    ];

    /// Those that plan G-code jobs.
    pub const GCODE: [Firmware; 6] = [
        Firmware::Klipper,
        Firmware::Marlin,
        Firmware::Prusa,
        Firmware::Rrf,
        Firmware::Grbl,
        Firmware::Settle,
    ];

    /// Those that plan a printer's G-code (an extruder `E`, slicer files): all of
    /// [`Firmware::GCODE`] but GRBL.
    pub const PRINTERS: [Firmware; 5] = [
        Firmware::Klipper,
        Firmware::Marlin,
        Firmware::Prusa,
        Firmware::Rrf,
        Firmware::Settle,
    ];

    /// Its name, as [`Firmware::parse`] reads it and outputs write it (`klipper`,
    /// `marlin`, `prusa`, `rrf`, `settle`, `tmc4361a`).
    pub fn name(self) -> &'static str {
        match self {
            Firmware::Klipper => "klipper",
            Firmware::Marlin => "marlin",
            Firmware::Prusa => "prusa",
            Firmware::Rrf => "rrf",
            Firmware::Grbl => "grbl",
            Firmware::Settle => "settle",
            Firmware::Tmc4361a => "tmc4361a",
        }
    }

    /// A firmware by name (any case): its [`Firmware::name`], or `reprapfirmware` or
    /// `duet` for RepRapFirmware, `grblhal` for GRBL, `buddy` for Prusa.
    pub fn parse(name: &str) -> Option<Self> {
        let lower = name.to_ascii_lowercase();
        match lower.as_str() {
            "reprapfirmware" | "duet" => Some(Firmware::Rrf),
            "grblhal" => Some(Firmware::Grbl),
            "buddy" => Some(Firmware::Prusa),
            n => Self::ALL.into_iter().find(|f| f.name() == n),
        }
    }

    /// A firmware by name among `allowed`: the error names them (`unknown firmware `x`;
    /// allowed: klipper, rrf`, or what `f` is not for).
    pub fn parse_among(name: &str, allowed: &[Firmware], what: &str) -> Result<Self, String> {
        let list = Self::names(allowed);
        match Self::parse(name) {
            Some(f) if allowed.contains(&f) => Ok(f),
            Some(f) => Err(format!("{f} is not {what}; allowed: {list}")),
            None => Err(format!("unknown firmware `{name}`; allowed: {list}")),
        }
    }

    /// The names of `firmwares`, comma-separated.
    pub fn names(firmwares: &[Firmware]) -> String {
        firmwares
            .iter()
            .map(|f| f.name())
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// Whether it plans G-code jobs.
    pub fn plans_gcode(self) -> bool {
        Self::GCODE.contains(&self)
    }
}

impl fmt::Display for Firmware {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_parse_back_and_aliases_are_rrf() {
        for f in Firmware::ALL {
            assert_eq!(Firmware::parse(f.name()), Some(f));
            assert_eq!(Firmware::parse(&f.name().to_uppercase()), Some(f));
        }
        assert_eq!(Firmware::parse("duet"), Some(Firmware::Rrf));
        assert_eq!(Firmware::parse("RepRapFirmware"), Some(Firmware::Rrf));
        assert_eq!(Firmware::parse("grblHAL"), Some(Firmware::Grbl));
        assert_eq!(Firmware::parse("Buddy"), Some(Firmware::Prusa));
        assert_eq!(Firmware::parse("prusa"), Some(Firmware::Prusa));
        assert_eq!(Firmware::parse("linuxcnc"), None);
        let only = [Firmware::Klipper, Firmware::Rrf];
        assert_eq!(
            Firmware::parse_among("duet", &only, "read"),
            Ok(Firmware::Rrf)
        );
        assert_eq!(
            Firmware::parse_among("marlin", &only, "read here"),
            Err("marlin is not read here; allowed: klipper, rrf".into())
        );
        assert_eq!(
            Firmware::parse_among("x", &only, "read"),
            Err("unknown firmware `x`; allowed: klipper, rrf".into())
        );
    }
}
