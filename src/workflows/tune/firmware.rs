//! `--firmware` / `[tune] firmware`: which candidates a firmware (or motion chip) can run.
//!
//! - Klipper, Marlin and RepRapFirmware plan trapezoids (constant-acceleration phases;
//!   Klipper's `klippy/toolhead.py` `Move`, RepRapFirmware's `DDA`, Marlin's planner
//!   without its optional Bezier jerk), each shaping with its own shaper set
//!   (`ShaperKind::KLIPPER`, `ShaperKind::MARLIN`, `ShaperKind::RRF`).
//! - The TMC4361A's ramp generator runs S-shaped ramps (BOW1..4: `scurve` and `fourjerk`)
//!   and has no input shaper.
//! - `any`: every profile kind and Klipper's shapers (settle's default set).

use settle_planner::ProfileKind;
use settle_planner::shaper::{Firmware as ShaperFirmware, ShaperKind};

/// A firmware whose candidates `settle tune` restricts itself to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Firmware {
    /// Klipper.
    Klipper,
    /// Marlin with FT_MOTION.
    Marlin,
    /// RepRapFirmware.
    Rrf,
    /// The TMC4361A motion controller.
    Tmc4361a,
    /// No restriction.
    Any,
}

/// Names `--firmware` takes.
pub const ALLOWED: &str = "klipper, marlin, rrf, tmc4361a, any";

impl Firmware {
    /// Parse a name of [`ALLOWED`].
    pub fn parse(name: &str) -> Result<Self, String> {
        Ok(match name.to_ascii_lowercase().as_str() {
            "klipper" => Firmware::Klipper,
            "marlin" => Firmware::Marlin,
            "rrf" | "reprapfirmware" => Firmware::Rrf,
            "tmc4361a" => Firmware::Tmc4361a,
            "any" => Firmware::Any,
            _ => return Err(format!("unknown firmware `{name}`; allowed: {ALLOWED}")),
        })
    }

    /// Its name as [`Firmware::parse`] takes it.
    pub fn name(self) -> &'static str {
        match self {
            Firmware::Klipper => "klipper",
            Firmware::Marlin => "marlin",
            Firmware::Rrf => "rrf",
            Firmware::Tmc4361a => "tmc4361a",
            Firmware::Any => "any",
        }
    }

    /// The profile kinds it plans.
    pub fn kinds(self) -> Vec<ProfileKind> {
        match self {
            Firmware::Klipper | Firmware::Marlin | Firmware::Rrf => vec![ProfileKind::Trapezoid],
            Firmware::Tmc4361a => vec![ProfileKind::SCurve, ProfileKind::FourJerk],
            Firmware::Any => ProfileKind::ALL.to_vec(),
        }
    }

    /// The shapers it runs (none for the TMC4361A).
    pub fn shapers(self) -> Vec<ShaperKind> {
        match self {
            Firmware::Klipper | Firmware::Any => ShaperKind::KLIPPER.to_vec(),
            Firmware::Marlin => ShaperKind::MARLIN.to_vec(),
            Firmware::Rrf => ShaperKind::RRF.to_vec(),
            Firmware::Tmc4361a => Vec::new(),
        }
    }

    /// `Ok` when it plans `kind`, else why not.
    pub fn check_kind(self, kind: ProfileKind) -> Result<(), String> {
        if self.kinds().contains(&kind) {
            Ok(())
        } else {
            Err(format!(
                "{} does not plan `{kind}` moves; it plans: {}",
                self.name(),
                self.kinds()
                    .iter()
                    .map(|k| k.name())
                    .collect::<Vec<_>>()
                    .join(", ")
            ))
        }
    }

    /// `Ok` when it runs `shaper` (`None`, no shaping, always), else why not.
    pub fn check_shaper(self, shaper: Option<ShaperKind>) -> Result<(), String> {
        let Some(k) = shaper else {
            return Ok(());
        };
        let ok = match self {
            Firmware::Any => true,
            Firmware::Klipper => k.firmware() == ShaperFirmware::Klipper,
            Firmware::Marlin => k.firmware() == ShaperFirmware::Marlin,
            Firmware::Rrf => k.firmware() == ShaperFirmware::Rrf,
            Firmware::Tmc4361a => false,
        };
        if ok {
            Ok(())
        } else if self == Firmware::Tmc4361a {
            Err("the TMC4361A has no input shaper: give shapers = [\"none\"]".into())
        } else {
            Err(format!(
                "{} does not run the shaper `{}`; it runs: {}",
                self.name(),
                k.name(),
                self.shapers()
                    .iter()
                    .map(|s| s.name())
                    .collect::<Vec<_>>()
                    .join(", ")
            ))
        }
    }
}
