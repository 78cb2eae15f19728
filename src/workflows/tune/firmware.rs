//! `--firmware` / `[tune] firmware`: which candidates a firmware (or motion chip) can run
//! (the firmware is settle-planner's [`Firmware`]).
//!
//! - Klipper, Marlin and RepRapFirmware plan trapezoids (constant-acceleration phases;
//!   Klipper's `klippy/toolhead.py` `Move`, RepRapFirmware's `DDA`, Marlin's planner
//!   without its optional Bezier jerk), each shaping with its own shaper set
//!   (`ShaperType::KLIPPER`, `ShaperType::MARLIN`, `ShaperType::RRF`).
//! - The TMC4361A's ramp generator runs S-shaped ramps (BOW1..4: `scurve` and `fourjerk`)
//!   and has no input shaper.
//! - `any`: every profile kind and Klipper's shapers (settle's default set).
//!
//! Marlin has two input shapers, chosen when the firmware is built ([`MarlinShaping`],
//! `[tune] marlin_shaping`): Fixed-Time Motion (`FT_MOTION`, Marlin 2.1.3+, `M493`, the
//! eight shapers of `ShaperType::MARLIN`) and the built-in ZV shaper (`INPUT_SHAPING_X` /
//! `INPUT_SHAPING_Y`, Marlin 2.1.2+, `M593`), whose one shaper is `marlin:m593`
//! (`ShaperType::MarlinM593`, the ZV of Marlin/src/module/stepper.cpp, as settle-gcode
//! reads `M593`).

use settle_planner::ProfileKind;
use settle_planner::firmware::Firmware;
use settle_planner::shaper::{PrusaShaper, ShaperType};

/// The firmwares `settle tune` searches for (and exports to): Klipper, Marlin,
/// Prusa-Firmware-Buddy, RepRapFirmware and the TMC4361A.
pub const TUNED: [Firmware; 5] = [
    Firmware::Klipper,
    Firmware::Marlin,
    Firmware::Prusa,
    Firmware::Rrf,
    Firmware::Tmc4361a,
];

/// Names `--firmware` takes.
pub const ALLOWED: &str = "klipper, marlin, prusa, rrf, tmc4361a, any";

/// Which of Marlin's input shapers the printer's build has (`[tune] marlin_shaping`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum MarlinShaping {
    /// Fixed-Time Motion (`FT_MOTION`, Marlin 2.1.3+): `M493`, eight shapers per axis.
    #[default]
    FtMotion,
    /// The built-in ZV shaper (`INPUT_SHAPING_X`/`_Y`, Marlin 2.1.2+): `M593 F D` per
    /// axis (Marlin/src/gcode/feature/input_shaping/M593.cpp).
    InputShaping,
}

impl MarlinShaping {
    /// Names `[tune] marlin_shaping` takes.
    pub const ALLOWED: &'static str = "ft_motion, input_shaping";

    /// Parse a name of [`MarlinShaping::ALLOWED`].
    pub fn parse(name: &str) -> Result<Self, String> {
        match name {
            "ft_motion" => Ok(MarlinShaping::FtMotion),
            "input_shaping" => Ok(MarlinShaping::InputShaping),
            _ => Err(format!(
                "unknown Marlin shaping `{name}`; allowed: {}",
                Self::ALLOWED
            )),
        }
    }

    /// Its name as [`MarlinShaping::parse`] takes it.
    pub fn name(self) -> &'static str {
        match self {
            MarlinShaping::FtMotion => "ft_motion",
            MarlinShaping::InputShaping => "input_shaping",
        }
    }
}

/// The candidates `settle tune` restricts itself to: those a firmware of [`TUNED`] runs,
/// or (`any`) every one; for Marlin, with the input shaper of its build.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Candidates(Option<Firmware>, MarlinShaping);

impl Candidates {
    /// No restriction.
    pub const ANY: Candidates = Candidates(None, MarlinShaping::FtMotion);

    /// What `firmware` runs (Marlin: with Fixed-Time Motion).
    pub fn of(firmware: Firmware) -> Self {
        Candidates(Some(firmware), MarlinShaping::FtMotion)
    }

    /// The same, with Marlin's input shaper `shaping` (it matters only for Marlin).
    pub fn with_marlin_shaping(self, shaping: MarlinShaping) -> Self {
        Candidates(self.0, shaping)
    }

    /// Marlin's input shaper these candidates are for.
    pub fn marlin_shaping(self) -> MarlinShaping {
        self.1
    }

    /// The firmware, `None` for any.
    pub fn firmware(self) -> Option<Firmware> {
        self.0
    }

    /// Parse a name of [`ALLOWED`] (or another name of a firmware, [`Firmware::parse`]).
    pub fn parse(name: &str) -> Result<Self, String> {
        if name.eq_ignore_ascii_case("any") {
            return Ok(Self::ANY);
        }
        match Firmware::parse(name) {
            Some(f) if TUNED.contains(&f) => Ok(Self::of(f)),
            Some(Firmware::Grbl) => Err(format!(
                "grbl is not a firmware settle tune searches for: GRBL has no input shaper and \
                 settle writes no GRBL settings (settle gcode --firmware grbl replays a GRBL \
                 job); allowed: {ALLOWED}"
            )),
            Some(f) => Err(format!(
                "{f} is not a firmware settle tune searches for; allowed: {ALLOWED}"
            )),
            None => Err(format!("unknown firmware `{name}`; allowed: {ALLOWED}")),
        }
    }

    /// Its name as [`Candidates::parse`] takes it.
    pub fn name(self) -> &'static str {
        self.0.map_or("any", Firmware::name)
    }

    /// The profile kinds it plans.
    pub fn kinds(self) -> Vec<ProfileKind> {
        match self.0 {
            None | Some(Firmware::Settle) => ProfileKind::ALL.to_vec(),
            Some(
                Firmware::Klipper
                | Firmware::Marlin
                | Firmware::Prusa
                | Firmware::Rrf
                | Firmware::Grbl,
            ) => {
                vec![ProfileKind::Trapezoid]
            }
            Some(Firmware::Tmc4361a) => vec![ProfileKind::SCurve, ProfileKind::FourJerk],
        }
    }

    /// The shapers it runs (none for the TMC4361A; Klipper's for any).
    pub fn shapers(self) -> Vec<ShaperType> {
        match self.0 {
            None | Some(Firmware::Klipper | Firmware::Settle) => ShaperType::KLIPPER.to_vec(),
            Some(Firmware::Marlin) => match self.1 {
                MarlinShaping::FtMotion => ShaperType::MARLIN.to_vec(),
                // M593's only shaper (its `T` type word is "not implemented yet" in M593.cpp).
                MarlinShaping::InputShaping => vec![ShaperType::MarlinM593],
            },
            Some(Firmware::Rrf) => ShaperType::RRF.to_vec(),
            // M593 T0..T5: Klipper's ZV, ZVD and MZV, and Prusa's EI family.
            Some(Firmware::Prusa) => {
                let mut all = vec![ShaperType::Zv, ShaperType::Zvd, ShaperType::MZV];
                all.extend(PrusaShaper::ALL.map(ShaperType::prusa));
                all
            }
            // GRBL has no input shaper.
            Some(Firmware::Tmc4361a | Firmware::Grbl) => Vec::new(),
        }
    }

    /// The shaper frequencies it runs as designed, Hz (`None`: any the shaper takes); only
    /// Prusa-Firmware-Buddy has a range: it clamps `M593 F` to 10 to 100 Hz on every printer but the MINI
    /// (`clamp_frequency_to_safe_values`, lib/Marlin/Marlin/src/feature/input_shaper/
    /// input_shaper_config.hpp).
    pub fn frequency_range(self) -> Option<(f64, f64)> {
        (self.0 == Some(Firmware::Prusa)).then(settle_gcode::job::prusa_common_hz)
    }

    /// Whether it runs a shaper designed for `frequency_hz` as designed
    /// ([`Candidates::frequency_range`]).
    pub fn takes_frequency(self, frequency_hz: f64) -> bool {
        self.frequency_range()
            .is_none_or(|(lo, hi)| (lo..=hi).contains(&frequency_hz))
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
    pub fn check_shaper(self, shaper: Option<ShaperType>) -> Result<(), String> {
        let Some(k) = shaper else {
            return Ok(());
        };
        let ok = match self.0 {
            None => true,
            Some(Firmware::Tmc4361a) => false,
            Some(Firmware::Marlin) if self.1 == MarlinShaping::InputShaping => {
                k == ShaperType::MarlinM593
            }
            Some(Firmware::Prusa) => self.shapers().contains(&k),
            Some(f) => k.firmware() == f,
        };
        if ok {
            Ok(())
        } else if self.0 == Some(Firmware::Tmc4361a) {
            Err("the TMC4361A has no input shaper: give shapers = [\"none\"]".into())
        } else if self.0 == Some(Firmware::Marlin) && self.1 == MarlinShaping::InputShaping {
            Err(format!(
                "Marlin's built-in input shaping (M593, marlin_shaping = \"input_shaping\") runs only `marlin:m593`, not `{}`",
                k.name()
            ))
        } else {
            Err(format!(
                "{} does not run {}'s shaper `{}`; it runs: {}",
                self.name(),
                k.firmware().name(),
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_the_planner_s_and_grbl_is_refused_with_its_reason() {
        assert_eq!(Candidates::parse("duet"), Ok(Candidates::of(Firmware::Rrf)));
        assert_eq!(Candidates::parse("ANY"), Ok(Candidates::ANY));
        for name in ["grbl", "grblHAL"] {
            let err = Candidates::parse(name).expect_err("refused");
            assert!(
                err.starts_with(
                    "grbl is not a firmware settle tune searches for: GRBL has no input shaper"
                ),
                "{err}"
            );
            assert!(
                err.ends_with("allowed: klipper, marlin, prusa, rrf, tmc4361a, any"),
                "{err}"
            );
        }
        assert_eq!(
            Candidates::parse("linuxcnc"),
            Err(
                "unknown firmware `linuxcnc`; allowed: klipper, marlin, prusa, rrf, tmc4361a, any"
                    .into()
            )
        );
    }

    #[test]
    fn marlin_input_shaping_runs_only_its_stepper_zv() {
        assert_eq!(
            MarlinShaping::parse("input_shaping"),
            Ok(MarlinShaping::InputShaping)
        );
        assert_eq!(
            MarlinShaping::parse("M593"),
            Err("unknown Marlin shaping `M593`; allowed: ft_motion, input_shaping".into())
        );
        let is = Candidates::of(Firmware::Marlin).with_marlin_shaping(MarlinShaping::InputShaping);
        assert_eq!(is.shapers(), [ShaperType::MarlinM593]);
        assert_eq!(is.check_shaper(Some(ShaperType::MarlinM593)), Ok(()));
        let err = is
            .check_shaper(Some(ShaperType::Zv))
            .expect_err("Klipper's zv is not M593's");
        assert!(err.contains("runs only `marlin:m593`, not `zv`"), "{err}");
        let err = is
            .check_shaper(Some(ShaperType::marlin(
                settle_planner::shaper::MarlinShaper::Zv,
            )))
            .expect_err("FT_MOTION's zv is not M593's");
        assert!(
            err.contains("runs only `marlin:m593`, not `marlin:zv`"),
            "{err}"
        );
        assert_eq!(
            Candidates::of(Firmware::Marlin).shapers(),
            ShaperType::MARLIN
        );
        assert_eq!(
            Candidates::of(Firmware::Marlin).check_shaper(Some(ShaperType::Zv)),
            Err("marlin does not run klipper's shaper `zv`; it runs: marlin:zv, marlin:zvd, marlin:zvdd, marlin:zvddd, marlin:ei, marlin:2hei, marlin:3hei, marlin:mzv".into())
        );
    }
}
