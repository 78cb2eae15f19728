//! The input shapers in force, and how each firmware's shaper commands change them.
//!
//! - Klipper `SET_INPUT_SHAPER` (klippy/extras/input_shaper.py, `InputShaperParams.update`):
//!   `SHAPER_TYPE` sets every axis, else `SHAPER_TYPE_X/Y/Z`; frequencies and damping
//!   ratios per axis; a frequency of 0 turns the axis's shaping off (its type is kept).
//!   Unset values keep theirs. The default type is `mzv`, damping 0.1. A type Klipper's
//!   `shaper_defs.py` does not know (settle's `marlin:`/`rrf:` names among them) is an
//!   error, as in `printer.cfg` ([`crate::config`]'s check).
//! - Marlin `M593` (`Marlin/src/gcode/feature/input_shaping/M593.cpp`): the stepper's ZV
//!   shaper on X and Y (or the axes named), `F` (0 off) and `D` (0..=1). `M493`
//!   (`Marlin/src/gcode/feature/ft_motion/M493.cpp`): FT_MOTION on or off (`S`), and per
//!   axis (X and Y unless named) the shaper `C` (0 none, 1..8 ZV..MZV), frequency `A`,
//!   damping `I`, vibration tolerance `Q`.
//! - RepRapFirmware `M593` (`AxisShaper::Configure`, src/Movement/AxisShaper.cpp): one
//!   shaper for the motion (here X and Y), type `P`, frequency `F` (default 40 Hz),
//!   damping `S` (default 0.1); a frequency or damping given while the type is `none`
//!   selects `zvd`. `custom` shapers (`H`, `T`) are not supported.

use settle_planner::shaper::{MarlinShaper, RrfShaper, ShaperType};

use super::config::ShaperSetting;
use crate::config::klipper_shaper;
use crate::read::limits::{AxisFlags, FtShaper, LimitChange};
use settle_planner::firmware::Firmware;

/// One axis's shaper state as its firmware keeps it.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Axis {
    /// The family (`None`: no shaper selected).
    shaper_type: Option<ShaperType>,
    frequency_hz: f64,
    damping_ratio: f64,
}

impl Axis {
    fn setting(&self) -> Option<ShaperSetting> {
        let kind = self.shaper_type?;
        (self.frequency_hz > 0.0).then_some(ShaperSetting {
            shaper_type: kind,
            frequency_hz: self.frequency_hz,
            damping_ratio: self.damping_ratio,
        })
    }
}

/// Why a shaper command cannot be followed.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum ShaperProblem {
    /// A shaper name the firmware does not know, and the names it does.
    UnknownName(String, &'static str),
    /// A shaper settle does not model.
    Unsupported(&'static str),
}

/// The `M593 P` types RepRapFirmware takes that settle models.
const RRF_ALLOWED: &str =
    "none, zvd, zvdd, zvddd, mzv, ei2, ei3 (M593 P; \"custom\" is not modelled)";

/// The shapers in force on X, Y, Z.
#[derive(Debug, Clone)]
pub(crate) struct ShaperState {
    firmware: Firmware,
    axes: [Axis; 3],
    /// Marlin: FT_MOTION switched off by `M493 S0` (its shapers then do nothing).
    ft_off: bool,
}

impl ShaperState {
    /// The state at the start of the file, from the job's settings.
    pub(crate) fn new(firmware: Firmware, initial: &[Option<ShaperSetting>; 3]) -> Self {
        let (default_kind, default_f, default_z) = match firmware {
            Firmware::Rrf => (None, 40.0, 0.1),
            Firmware::Klipper => (Some(ShaperType::MZV), 0.0, 0.1),
            Firmware::Marlin | Firmware::Grbl | Firmware::Settle | Firmware::Tmc4361a => {
                (None, 0.0, 0.1)
            }
        };
        let axes = initial.map(|s| match s {
            Some(s) => Axis {
                shaper_type: Some(s.shaper_type),
                frequency_hz: s.frequency_hz,
                damping_ratio: s.damping_ratio,
            },
            None => Axis {
                shaper_type: default_kind,
                frequency_hz: default_f,
                damping_ratio: default_z,
            },
        });
        Self {
            firmware,
            axes,
            ft_off: false,
        }
    }

    /// The settings in force (X, Y, Z).
    pub(crate) fn settings(&self) -> [Option<ShaperSetting>; 3] {
        std::array::from_fn(|i| {
            let a = &self.axes[i];
            match a.shaper_type {
                Some(ShaperType::Marlin { .. }) if self.ft_off => None,
                _ => a.setting(),
            }
        })
    }

    /// Apply `change` if it is a shaper command of this firmware; `Ok(true)` when it is
    /// one (the firmware then waits for a standstill and shapes what follows with the
    /// new settings), `Ok(false)` when `change` is not about shaping here.
    pub(crate) fn apply(&mut self, change: &LimitChange) -> Result<bool, ShaperProblem> {
        match (self.firmware, change) {
            (
                Firmware::Klipper,
                LimitChange::InputShaper {
                    shaper_type,
                    shaper_type_xyz,
                    frequency_hz_xyz,
                    damping_ratio_xyz,
                },
            ) => {
                let any = shaper_type.is_some()
                    || shaper_type_xyz.iter().any(Option::is_some)
                    || frequency_hz_xyz.iter().any(Option::is_some)
                    || damping_ratio_xyz.iter().any(Option::is_some);
                for i in 0..3 {
                    let name = shaper_type.as_ref().or(shaper_type_xyz[i].as_ref());
                    let a = &mut self.axes[i];
                    if let Some(name) = name {
                        // Klipper's own names only (`klippy/extras/shaper_defs.py`): not
                        // settle's `marlin:`/`rrf:` ones, which Klipper refuses.
                        let unknown =
                            || ShaperProblem::UnknownName(name.clone(), klipper_shaper::ALLOWED);
                        klipper_shaper::check(name).map_err(|_| unknown())?;
                        let kind = ShaperType::parse(name).map_err(|_| unknown())?;
                        a.shaper_type = Some(kind);
                    }
                    if let Some(f) = frequency_hz_xyz[i] {
                        a.frequency_hz = f;
                    }
                    if let Some(z) = damping_ratio_xyz[i] {
                        a.damping_ratio = z;
                    }
                }
                Ok(any)
            }
            (
                Firmware::Marlin,
                LimitChange::MarlinInputShaping {
                    axes,
                    frequency_hz,
                    damping_ratio,
                },
            ) => {
                for a in self.marlin_axes(axes) {
                    if let Some(z) = damping_ratio.filter(|z| (0.0..=1.0).contains(z)) {
                        a.damping_ratio = z;
                    }
                    if let Some(f) = frequency_hz {
                        a.shaper_type = Some(ShaperType::Zv);
                        a.frequency_hz = *f;
                    }
                }
                Ok(frequency_hz.is_some() || damping_ratio.is_some())
            }
            (
                Firmware::Marlin,
                LimitChange::FtMotion {
                    enabled,
                    axes,
                    shaper,
                    frequency_hz,
                    damping_ratio,
                    vibration_tolerance,
                    ..
                },
            ) => {
                if let Some(on) = enabled {
                    self.ft_off = !on;
                }
                for a in self.marlin_axes(axes) {
                    if let Some(s) = shaper {
                        a.shaper_type = marlin_kind(*s);
                    }
                    if let Some(f) = frequency_hz {
                        a.frequency_hz = *f;
                    }
                    if let Some(z) = damping_ratio {
                        a.damping_ratio = *z;
                    }
                    if let (Some(q), Some(ShaperType::Marlin { v_tol, .. })) =
                        (vibration_tolerance, a.shaper_type.as_mut())
                    {
                        *v_tol = *q;
                    }
                }
                Ok(enabled.is_some()
                    || shaper.is_some()
                    || frequency_hz.is_some()
                    || damping_ratio.is_some()
                    || vibration_tolerance.is_some())
            }
            (
                Firmware::Rrf,
                LimitChange::RrfInputShaping {
                    shaper,
                    frequency_hz,
                    damping_ratio,
                    reduction_limit,
                    amplitudes,
                    durations_s,
                },
            ) => {
                if !amplitudes.is_empty() || !durations_s.is_empty() {
                    return Err(ShaperProblem::Unsupported(
                        "RepRapFirmware custom shapers (M593 H/T) are not modelled",
                    ));
                }
                let kind = match shaper.as_deref() {
                    None => None,
                    Some("none") => Some(None),
                    Some("custom") => {
                        return Err(ShaperProblem::Unsupported(
                            "RepRapFirmware custom shapers (M593 P\"custom\") are not modelled",
                        ));
                    }
                    Some(name) => {
                        let family = RrfShaper::ALL
                            .into_iter()
                            .find(|f| f.name() == name)
                            .ok_or_else(|| {
                                ShaperProblem::UnknownName(name.to_string(), RRF_ALLOWED)
                            })?;
                        Some(Some(ShaperType::rrf(family)))
                    }
                };
                let seen =
                    frequency_hz.is_some() || damping_ratio.is_some() || reduction_limit.is_some();
                for a in &mut self.axes[..2] {
                    if let Some(f) = frequency_hz {
                        a.frequency_hz = *f;
                    }
                    if let Some(z) = damping_ratio {
                        a.damping_ratio = *z;
                    }
                    match kind {
                        Some(k) => a.shaper_type = k,
                        None if seen && a.shaper_type.is_none() => {
                            a.shaper_type = Some(ShaperType::rrf(RrfShaper::Zvd));
                        }
                        None => {}
                    }
                }
                Ok(shaper.is_some() || frequency_hz.is_some() || damping_ratio.is_some())
            }
            _ => Ok(false),
        }
    }

    /// The axes a Marlin `M593`/`M493` applies to: those named, else X and Y.
    fn marlin_axes(&mut self, named: &AxisFlags) -> impl Iterator<Item = &mut Axis> {
        let none = !(named.x || named.y || named.z);
        let pick = [named.x || none, named.y || none, named.z];
        self.axes
            .iter_mut()
            .zip(pick)
            .filter_map(|(a, p)| p.then_some(a))
    }
}

/// The shaper of `M493 C`.
fn marlin_kind(s: FtShaper) -> Option<ShaperType> {
    let family = match s {
        FtShaper::None => return None,
        FtShaper::Zv => MarlinShaper::Zv,
        FtShaper::Zvd => MarlinShaper::Zvd,
        FtShaper::Zvdd => MarlinShaper::Zvdd,
        FtShaper::Zvddd => MarlinShaper::Zvddd,
        FtShaper::Ei => MarlinShaper::Ei,
        FtShaper::Ei2 => MarlinShaper::TwoHei,
        FtShaper::Ei3 => MarlinShaper::ThreeHei,
        FtShaper::Mzv => MarlinShaper::Mzv,
    };
    Some(ShaperType::marlin(family))
}
