//! The input shapers in force, and how each firmware's shaper commands change them.
//!
//! - Klipper `SET_INPUT_SHAPER` (klippy/extras/input_shaper.py, `InputShaperParams.update`):
//!   `SHAPER_TYPE` sets every axis, else `SHAPER_TYPE_X/Y/Z`; frequencies and damping
//!   ratios per axis; a frequency of 0 turns the axis's shaping off (its type is kept).
//!   Unset values keep theirs. The default type is `mzv`, damping 0.1. A type Klipper's
//!   `shaper_defs.py` does not know (settle's `marlin:`/`rrf:` names among them) is an
//!   error, as in `printer.cfg` ([`crate::config`]'s check).
//! - Marlin `M593` (`Marlin/src/gcode/feature/input_shaping/M593.cpp`): the stepper's ZV
//!   shaper on X and Y (or the axes named), `F` (0 off) and `D` (0..=1), run as
//!   Marlin/src/module/stepper.cpp computes it (`marlin:m593`: not Klipper's `zv`). `M493`
//!   (`Marlin/src/gcode/feature/ft_motion/M493.cpp`): FT_MOTION on or off (`S`), and per
//!   axis (X and Y unless named) the shaper `C` (0 none, 1..8 ZV..MZV), frequency `A`,
//!   damping `I`, vibration tolerance `Q`. The two are kept apart; under `M493 S1`
//!   `Stepper::isr` skips `shaping_isr()`, so only FT_MOTION's shaper runs, and after
//!   `M493 S0` only `M593`'s ([`ShaperState::settings`]).
//! - Prusa-Firmware-Buddy `M593` (lib/Marlin/Marlin/src/gcode/feature/input_shaper/M593.cpp,
//!   `M593_internal`): with any of `T`, `F`, `D`, `R`, each axis named (X, Y and Z when
//!   none is) takes the values given over its own, or over the printer's defaults when
//!   its shaper is off; `F0` turns it off; a frequency is clamped to 10..=100 Hz
//!   (`clamp_frequency_to_safe_values`, input_shaper_config.cpp; 10..=150 Hz on the
//!   MINI, [`PrusaModel::shaper_max_hz`]). `T` 0..5 is ZV, ZVD, MZV (Klipper's), EI, 2HUMP_EI, 3HUMP_EI
//!   (`prusa:`), 6 no shaper; `R` the EI family's vibration reduction (tolerance `1/R`).
//! - RepRapFirmware `M593` (`AxisShaper::Configure`, src/Movement/AxisShaper.cpp, 3.6):
//!   one shaper for the motion (here X and Y), type `P` (reduced as `GetReducedString`
//!   reduces it: `"EI-2"` is `ei2`), frequency `F` (default 40 Hz; 5.722 to 1000 Hz, the
//!   reader's check), damping `S` (default 0.05, `DefaultDamping` in AxisShaper.h); a
//!   frequency or damping given while the type is `none` selects `zvd`; `L` (3.5's
//!   reduction limit) is not read. A `custom` shaper is refused (settle does not model
//!   it); `H` and `T`, read for `custom` only, are ignored with another type.

use settle_planner::PlanError;
use settle_planner::shaper::{MarlinShaper, PrusaShaper, RrfShaper, Shaper, ShaperType};

use crate::config::{RRF_DEFAULT_SHAPER, klipper_shaper, rrf_shaper_name};
use crate::read::limits::{AxisFlags, FtShaper, LimitChange};
use settle_planner::firmware::Firmware;
use settle_planner::firmware::marlin::PrusaModel;

/// An input shaper on one axis: which, and the mode it is tuned to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShaperSetting {
    /// The shaper (bare names are Klipper's, `marlin:` and `rrf:` the other firmwares').
    pub shaper_type: ShaperType,
    /// Frequency it is tuned to (Hz).
    pub frequency_hz: f64,
    /// Damping ratio it is tuned to.
    pub damping_ratio: f64,
}

impl ShaperSetting {
    /// The shaper's impulses (its firmware's checks apply, and settle's lowest frequency,
    /// [`settle_planner::shaper::MIN_FREQUENCY_HZ`]).
    pub fn build(&self) -> Result<Shaper, PlanError> {
        let min = settle_planner::shaper::MIN_FREQUENCY_HZ;
        if self.frequency_hz < min {
            return Err(PlanError::InvalidShaper {
                name: self.shaper_type.to_string(),
                reason: format!(
                    "frequency {} Hz is below {min} Hz, the lowest settle runs (a shaper lasts about one period)",
                    self.frequency_hz
                ),
            });
        }
        Shaper::new(self.shaper_type, self.frequency_hz, self.damping_ratio)
    }
}

/// One axis's shaper state as its firmware keeps it.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Axis {
    /// The family (`None`: no shaper selected).
    shaper_type: Option<ShaperType>,
    frequency_hz: f64,
    damping_ratio: f64,
    /// Prusa: the `M593 T` type (0..=6), which keeps its number while `R` changes;
    /// [`NOT_PRUSA`] for a shaper the job started with that is none of Prusa's.
    prusa_type: u32,
    /// Prusa: the vibration reduction `M593 R` (the EI family's tolerance is `1/R`).
    vibration_reduction: f64,
}

/// Prusa-Firmware-Buddy's `M593 T` of Klipper's `mzv`.
const PRUSA_MZV: u32 = 2;
/// Prusa-Firmware-Buddy's `M593 T` of no shaper (`Type::null`).
const PRUSA_NULL: u32 = 6;
/// The `prusa_type` of a shaper that is not one of Prusa's.
const NOT_PRUSA: u32 = u32::MAX;
/// Prusa-Firmware-Buddy's lowest safe frequency, Hz (`frequency_safe_min`,
/// input_shaper_config.hpp; the highest is [`PrusaModel::shaper_max_hz`]).
const PRUSA_SAFE_MIN_HZ: f64 = 10.0;
/// The shaper frequencies every Prusa-Firmware-Buddy printer runs as designed, Hz: from
/// `frequency_safe_min` (10 Hz) to the lowest [`PrusaModel::shaper_max_hz`] (100 Hz; the MINI
/// takes up to 150). What a configuration written for any of them may hold.
pub fn prusa_common_hz() -> (f64, f64) {
    let max = PrusaModel::ALL.map(PrusaModel::shaper_max_hz);
    (
        PRUSA_SAFE_MIN_HZ,
        max.into_iter().fold(f64::INFINITY, f64::min),
    )
}
/// Prusa-Firmware-Buddy's default vibration reduction (`M593 R`).
const PRUSA_VIBRATION_REDUCTION: f64 = 20.0;

/// Prusa-Firmware-Buddy's `M593 T` of its EI (`Type::ei`).
const PRUSA_EI: u32 = 3;

/// A printer's shapers as Prusa-Firmware-Buddy ships them (`axis_x_default`,
/// `axis_y_default`, `axis_z_default`, input_shaper_config.hpp), as `M593 T` and
/// frequency: MZV at 50.7 Hz on X and 40.6 Hz on Y (the MK4 and MK3.5 builds), 118.2 and
/// 32.8 Hz (MINI), 35.8 and 35.4 Hz (XL), EI at 60 and 50 Hz (CORE One); damping 0.1,
/// vibration reduction 20; none on Z. What an axis whose shaper is off takes when an
/// `M593` sets part of it.
fn prusa_defaults(model: PrusaModel) -> [(u32, f64); 3] {
    let (code, x, y) = match model {
        PrusaModel::Mini => (PRUSA_MZV, 118.2, 32.8),
        PrusaModel::Xl => (PRUSA_MZV, 35.8, 35.4),
        PrusaModel::CoreOne => (PRUSA_EI, 60.0, 50.0),
        PrusaModel::Mk4 | PrusaModel::Mk3_5 => (PRUSA_MZV, 50.7, 40.6),
    };
    [(code, x), (code, y), (PRUSA_NULL, 0.0)]
}

/// The shaper of Prusa's `M593 T<code>` with vibration reduction `r` (`None`: no shaper).
fn prusa_kind(code: u32, r: f64) -> Option<ShaperType> {
    let ei = |shaper| ShaperType::Prusa {
        shaper,
        v_tol: 1.0 / r,
    };
    match code {
        0 => Some(ShaperType::Zv),
        1 => Some(ShaperType::Zvd),
        2 => Some(ShaperType::MZV),
        3 => Some(ei(PrusaShaper::Ei)),
        4 => Some(ei(PrusaShaper::TwoHumpEi)),
        5 => Some(ei(PrusaShaper::ThreeHumpEi)),
        _ => None,
    }
}

/// The `M593 T` of a shaper setting's type, for the state a job starts with (`None`: not
/// one of Prusa's).
pub(crate) fn prusa_code(kind: ShaperType) -> Option<(u32, f64)> {
    let r = PRUSA_VIBRATION_REDUCTION;
    match kind {
        ShaperType::Zv => Some((0, r)),
        ShaperType::Zvd => Some((1, r)),
        k if k == ShaperType::MZV => Some((PRUSA_MZV, r)),
        ShaperType::Prusa { shaper, v_tol } => {
            let code = PrusaShaper::ALL.iter().position(|s| *s == shaper)? as u32 + 3;
            Some((code, 1.0 / v_tol))
        }
        _ => None,
    }
}

/// A printer's shaper defaults as job settings (X and Y; Z unshaped).
pub(crate) fn prusa_shapers(model: PrusaModel) -> [Option<ShaperSetting>; 3] {
    prusa_defaults(model).map(|(code, f)| {
        prusa_kind(code, PRUSA_VIBRATION_REDUCTION).map(|shaper_type| ShaperSetting {
            shaper_type,
            frequency_hz: f,
            damping_ratio: 0.1,
        })
    })
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
    /// Marlin: the stepper's own ZV of `M593` (`Stepper::set_shaping_frequency`), kept
    /// apart from FT_MOTION's `M493` shapers in `axes`, as Marlin keeps them apart. A build
    /// may have both: SanityCheck.h's "Input Shaping requirements" and "Fixed-Time Motion
    /// limitations" do not forbid INPUT_SHAPING_X/Y with FT_MOTION.
    stepper: [Axis; 3],
    /// Marlin: FT_MOTION as `M493 S` last switched it (`None`: the job has not said).
    /// While it is on, `Stepper::isr` (Marlin/src/module/stepper.cpp) runs
    /// `ftMotion_stepper()` and skips `shaping_isr()` with the block and pulse phases, so
    /// `M593`'s shaping does nothing; while it is off, FT_MOTION's shapers do nothing.
    ft_on: Option<bool>,
    /// Prusa: the printer (its shipped shapers and its highest frequency).
    prusa_model: PrusaModel,
}

impl ShaperState {
    /// The state at the start of the file, from the job's settings.
    pub(crate) fn new(firmware: Firmware, initial: &[Option<ShaperSetting>; 3]) -> Self {
        let (default_kind, default_f, default_z) = match firmware {
            // `AxisShaper::AxisShaper`: off, 40 Hz and damping 0.05 waiting for a type
            // (`DefaultDamping` 0.05 in 3.6's src/Movement/AxisShaper.h; 3.5's was 0.1).
            Firmware::Rrf => (None, RRF_DEFAULT_SHAPER.1, RRF_DEFAULT_SHAPER.2),
            Firmware::Klipper => (Some(ShaperType::MZV), 0.0, 0.1),
            Firmware::Marlin
            | Firmware::Prusa
            | Firmware::Grbl
            | Firmware::Settle
            | Firmware::Tmc4361a => (None, 0.0, 0.1),
        };
        let none = Axis {
            shaper_type: default_kind,
            frequency_hz: default_f,
            damping_ratio: default_z,
            prusa_type: PRUSA_NULL,
            vibration_reduction: PRUSA_VIBRATION_REDUCTION,
        };
        // Marlin: a starting `marlin:m593` is the stepper's, any other FT_MOTION's.
        let is_m593 = |s: &Option<ShaperSetting>| {
            firmware == Firmware::Marlin
                && s.is_some_and(|s| s.shaper_type == ShaperType::MarlinM593)
        };
        let stepper = std::array::from_fn(|i| {
            let s = &initial[i];
            match s {
                Some(s) if is_m593(&initial[i]) => Axis {
                    shaper_type: Some(s.shaper_type),
                    frequency_hz: s.frequency_hz,
                    damping_ratio: s.damping_ratio,
                    ..none
                },
                _ => none,
            }
        });
        let axes = initial.map(|s| match s {
            Some(_) if is_m593(&s) => none,
            Some(s) => {
                let (prusa_type, vibration_reduction) =
                    prusa_code(s.shaper_type).unwrap_or((NOT_PRUSA, PRUSA_VIBRATION_REDUCTION));
                Axis {
                    shaper_type: Some(s.shaper_type),
                    frequency_hz: s.frequency_hz,
                    damping_ratio: s.damping_ratio,
                    prusa_type,
                    vibration_reduction,
                }
            }
            None => none,
        });
        Self {
            firmware,
            axes,
            stepper,
            ft_on: None,
            prusa_model: PrusaModel::Mk4,
        }
    }

    /// Prusa: `M593` as `model`'s firmware runs it (the MK4's otherwise).
    pub(crate) fn with_prusa_model(mut self, model: PrusaModel) -> Self {
        self.prusa_model = model;
        self
    }

    /// The settings in force (X, Y, Z). Marlin: FT_MOTION's shaper while `M493 S1` has
    /// it on, `M593`'s after `M493 S0`; before any `M493 S`, FT_MOTION's where one is
    /// selected, else `M593`'s.
    pub(crate) fn settings(&self) -> [Option<ShaperSetting>; 3] {
        std::array::from_fn(|i| {
            let (ft, stepper) = (&self.axes[i], &self.stepper[i]);
            if self.firmware != Firmware::Marlin {
                return ft.setting();
            }
            match self.ft_on {
                Some(true) => ft.setting(),
                Some(false) => stepper.setting(),
                None => ft.setting().or_else(|| stepper.setting()),
            }
        })
    }

    /// Marlin, once `M493 S` has switched FT_MOTION: whether it is on, and the shapers set
    /// that do not run (`M593`'s while it is on, FT_MOTION's while it is off).
    pub(crate) fn marlin_idle(&self) -> Option<(bool, [Option<ShaperSetting>; 3])> {
        let on = self.ft_on.filter(|_| self.firmware == Firmware::Marlin)?;
        let idle = if on { &self.stepper } else { &self.axes };
        Some((on, std::array::from_fn(|i| idle[i].setting())))
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
                for a in marlin_axes(&mut self.stepper, axes) {
                    if let Some(z) = damping_ratio.filter(|z| (0.0..=1.0).contains(z)) {
                        a.damping_ratio = z;
                    }
                    if let Some(f) = frequency_hz {
                        a.shaper_type = Some(ShaperType::MarlinM593);
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
                    self.ft_on = Some(*on);
                }
                for a in marlin_axes(&mut self.axes, axes) {
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
                Firmware::Prusa,
                LimitChange::PrusaInputShaping {
                    axes,
                    shaper_type,
                    frequency_hz,
                    damping_ratio,
                    vibration_reduction,
                    ..
                },
            ) => {
                let any = shaper_type.is_some()
                    || frequency_hz.is_some()
                    || damping_ratio.is_some()
                    || vibration_reduction.is_some();
                if !any {
                    return Ok(false);
                }
                let none = !(axes.x || axes.y || axes.z);
                let pick = [axes.x || none, axes.y || none, axes.z || none];
                let defaults = prusa_defaults(self.prusa_model);
                let max_hz = self.prusa_model.shaper_max_hz();
                for (i, a) in self.axes.iter_mut().enumerate() {
                    if !pick[i] {
                        continue;
                    }
                    if *frequency_hz == Some(0.0) {
                        a.frequency_hz = 0.0;
                        continue;
                    }
                    let mut retype = a.frequency_hz == 0.0;
                    if retype {
                        // Off: the printer's defaults are the base (`axis_defaults`).
                        let (code, f) = defaults[i];
                        (a.prusa_type, a.frequency_hz) = (code, f);
                        a.damping_ratio = if code == PRUSA_NULL { 0.0 } else { 0.1 };
                        a.vibration_reduction = if code == PRUSA_NULL {
                            0.0
                        } else {
                            PRUSA_VIBRATION_REDUCTION
                        };
                    }
                    if let Some(t) = shaper_type {
                        a.prusa_type = *t;
                        retype = true;
                    }
                    if let Some(f) = frequency_hz {
                        a.frequency_hz = *f;
                    }
                    if let Some(z) = damping_ratio {
                        a.damping_ratio = *z;
                    }
                    if let Some(r) = vibration_reduction {
                        a.vibration_reduction = *r;
                        retype |= a.prusa_type != NOT_PRUSA;
                    }
                    a.frequency_hz = a.frequency_hz.clamp(PRUSA_SAFE_MIN_HZ, max_hz);
                    if retype {
                        a.shaper_type = prusa_kind(a.prusa_type, a.vibration_reduction);
                    }
                }
                Ok(true)
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
                // `H` and `T` are read for a `custom` shaper only, which settle does not
                // model: for another type RepRapFirmware does not read them.
                let _ = (amplitudes, durations_s);
                let name = shaper.as_deref().map(rrf_shaper_name);
                let kind = match name.as_deref() {
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
                // `L` (3.5's reduction limit) is read no more in 3.6 and selects nothing.
                let _ = reduction_limit;
                let seen = frequency_hz.is_some() || damping_ratio.is_some();
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
}

/// The axes of `state` a Marlin `M593`/`M493` applies to: those named, else X and Y.
/// `M493 E` names the extruder alone (`apply_xy = !parser.seen("XYZE")`,
/// `GcodeSuite::M493` in Marlin/src/gcode/feature/ft_motion/M493.cpp), whose shaper
/// settle does not plan: no axis of `state`.
fn marlin_axes<'a>(
    state: &'a mut [Axis; 3],
    named: &AxisFlags,
) -> impl Iterator<Item = &'a mut Axis> {
    let none = !(named.x || named.y || named.z || named.e);
    let pick = [named.x || none, named.y || none, named.z];
    state
        .iter_mut()
        .zip(pick)
        .filter_map(|(a, p)| p.then_some(a))
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

#[cfg(test)]
mod tests {
    use super::*;

    fn m593(axes: &str, t: Option<u32>, f: Option<f64>, d: Option<f64>) -> LimitChange {
        LimitChange::PrusaInputShaping {
            axes: AxisFlags {
                x: axes.contains('X'),
                y: axes.contains('Y'),
                z: axes.contains('Z'),
                e: false,
            },
            shaper_type: t,
            frequency_hz: f,
            damping_ratio: d,
            vibration_reduction: None,
            weight_frequency_delta_hz: None,
            weight_mass_limit_g: None,
            save: false,
        }
    }

    fn kinds(s: &ShaperState) -> [Option<(String, f64, f64)>; 3] {
        s.settings()
            .map(|a| a.map(|a| (a.shaper_type.name(), a.frequency_hz, a.damping_ratio)))
    }

    fn one(name: &str, f: f64, d: f64) -> Option<(String, f64, f64)> {
        Some((name.to_string(), f, d))
    }

    #[test]
    fn prusa_m593_takes_the_printers_defaults_and_range() {
        // The MINI: MZV at 118.2 / 32.8 Hz; frequencies up to 150 Hz.
        let mini = PrusaModel::Mini;
        let mut s = ShaperState::new(Firmware::Prusa, &prusa_shapers(mini)).with_prusa_model(mini);
        assert_eq!(
            kinds(&s),
            [one("mzv", 118.2, 0.1), one("mzv", 32.8, 0.1), None]
        );
        assert_eq!(s.apply(&m593("X", None, Some(140.0), None)), Ok(true));
        assert_eq!(s.apply(&m593("Y", None, Some(170.0), None)), Ok(true));
        assert_eq!(
            kinds(&s)[..2],
            [one("mzv", 140.0, 0.1), one("mzv", 150.0, 0.1)]
        );
        // The CORE One: EI (vibration reduction 20) at 60 / 50 Hz, what an axis turned off
        // starts again from.
        let core = PrusaModel::CoreOne;
        let mut s = ShaperState::new(Firmware::Prusa, &prusa_shapers(core)).with_prusa_model(core);
        assert_eq!(
            kinds(&s),
            [one("prusa:ei", 60.0, 0.1), one("prusa:ei", 50.0, 0.1), None]
        );
        assert_eq!(s.apply(&m593("Y", None, Some(0.0), None)), Ok(true));
        assert_eq!(kinds(&s)[1], None);
        assert_eq!(s.apply(&m593("Y", None, None, Some(0.05))), Ok(true));
        assert_eq!(kinds(&s)[1], one("prusa:ei", 50.0, 0.05));
    }

    #[test]
    fn prusa_m593_follows_m593_internal() {
        let mut s = ShaperState::new(Firmware::Prusa, &prusa_shapers(PrusaModel::Mk4));
        assert_eq!(
            kinds(&s),
            [one("mzv", 50.7, 0.1), one("mzv", 40.6, 0.1), None]
        );
        // PrusaSlicer's end G-code: MZV, off.
        assert_eq!(s.apply(&m593("X", Some(2), Some(0.0), None)), Ok(true));
        assert_eq!(s.apply(&m593("Y", Some(2), Some(0.0), None)), Ok(true));
        assert_eq!(kinds(&s), [None, None, None]);
        // An axis that is off starts again from the MK4's default (50.7 Hz on X).
        assert_eq!(s.apply(&m593("X", None, None, Some(0.2))), Ok(true));
        assert_eq!(kinds(&s)[0], one("mzv", 50.7, 0.2));
        // Types by number; frequencies clamped to 10..=100 Hz; no axis named: all three.
        // Z starts from its default, no shaper with damping 0 and vibration reduction 0:
        // an EI of tolerance 1/0, which the firmware computes as NaN and settle refuses.
        assert_eq!(s.apply(&m593("", Some(3), Some(120.0), None)), Ok(true));
        let k = kinds(&s);
        assert_eq!(
            k[..2],
            [one("prusa:ei", 100.0, 0.2), one("prusa:ei", 100.0, 0.1)]
        );
        assert_eq!(k[2], one("prusa:ei(v_tol=inf)", 100.0, 0.0));
        assert!(
            s.settings()[2]
                .map(|z| z.build())
                .is_some_and(|b| b.is_err())
        );
        assert_eq!(s.apply(&m593("Z", Some(6), None, None)), Ok(true));
        assert_eq!(kinds(&s)[2], None);
        assert_eq!(s.apply(&m593("Y", Some(1), Some(4.0), None)), Ok(true));
        assert_eq!(kinds(&s)[1], one("zvd", 10.0, 0.1));
        // `R` changes the EI family's tolerance.
        let mut r = m593("X", None, None, None);
        if let LimitChange::PrusaInputShaping {
            vibration_reduction,
            ..
        } = &mut r
        {
            *vibration_reduction = Some(10.0);
        }
        assert_eq!(s.apply(&r), Ok(true));
        assert_eq!(kinds(&s)[0], one("prusa:ei(v_tol=0.1)", 100.0, 0.2));
        // Only W (or the weight adjustment): no shaper change here.
        assert_eq!(s.apply(&m593("", None, None, None)), Ok(false));
    }

    fn marlin_m593(axes: &str, f: Option<f64>, d: Option<f64>) -> LimitChange {
        LimitChange::MarlinInputShaping {
            axes: AxisFlags {
                x: axes.contains('X'),
                y: axes.contains('Y'),
                z: false,
                e: false,
            },
            frequency_hz: f,
            damping_ratio: d,
        }
    }

    fn m493(on: Option<bool>, axes: &str, c: Option<FtShaper>, a: Option<f64>) -> LimitChange {
        LimitChange::FtMotion {
            enabled: on,
            axis_sync: None,
            axes: AxisFlags {
                x: axes.contains('X'),
                y: axes.contains('Y'),
                z: false,
                e: axes.contains('E'),
            },
            shaper: c,
            dynamic_mode: None,
            frequency_hz: a,
            frequency_scaling: None,
            damping_ratio: None,
            vibration_tolerance: None,
        }
    }

    /// `Stepper::isr` (Marlin/src/module/stepper.cpp) runs `ftMotion_stepper()` while
    /// `ftMotion.cfg.active` and `shaping_isr()` only when it is not: `M593`'s ZV is kept
    /// (`Stepper::set_shaping_frequency`) but does nothing under `M493 S1`, and is back
    /// after `M493 S0`; FT_MOTION's `M493 C`/`A` shaper is its own, not laid on `M593`'s.
    #[test]
    fn marlin_m593_does_nothing_while_ft_motion_is_on() {
        let mut s = ShaperState::new(Firmware::Marlin, &[None; 3]);
        assert_eq!(s.apply(&marlin_m593("", Some(40.0), Some(0.1))), Ok(true));
        let m593 = one("marlin:m593", 40.0, 0.1);
        assert_eq!(kinds(&s), [m593.clone(), m593.clone(), None]);
        assert_eq!(s.apply(&m493(Some(true), "", None, None)), Ok(true));
        assert_eq!(kinds(&s), [None, None, None]);
        // FT_MOTION's ZV on X at 50 Hz (damping Marlin's, 0.1 here as settle starts it).
        let x_zv = m493(None, "X", Some(FtShaper::Zv), Some(50.0));
        assert_eq!(s.apply(&x_zv), Ok(true));
        assert_eq!(kinds(&s), [one("marlin:zv", 50.0, 0.1), None, None]);
        // M593 under FT_MOTION is stored, not run.
        assert_eq!(s.apply(&marlin_m593("Y", Some(30.0), None)), Ok(true));
        assert_eq!(kinds(&s), [one("marlin:zv", 50.0, 0.1), None, None]);
        assert_eq!(s.apply(&m493(Some(false), "", None, None)), Ok(true));
        assert_eq!(
            kinds(&s),
            [m593, one("marlin:m593", 30.0, 0.1), None],
            "M493 S0: the stepper's shaping again"
        );
    }

    /// A job that starts with `M593`'s shaper (an `M503` reply's) loses it at `M493 S1`.
    #[test]
    fn a_starting_m593_shaper_is_bypassed_by_m493_s1() {
        let m593 = ShaperSetting {
            shaper_type: ShaperType::MarlinM593,
            frequency_hz: 40.0,
            damping_ratio: 0.15,
        };
        let mut s = ShaperState::new(Firmware::Marlin, &[Some(m593), Some(m593), None]);
        assert_eq!(s.settings(), [Some(m593), Some(m593), None]);
        assert_eq!(s.apply(&m493(Some(true), "", None, None)), Ok(true));
        assert_eq!(s.settings(), [None; 3]);
    }

    /// `M493 E C1 A40` sets the extruder's shaper only: Marlin applies `C`, `A`, `I`, `Q`
    /// to X and Y only when no axis of X, Y, Z, E is named (`apply_xy =
    /// !parser.seen("XYZE")`, `GcodeSuite::M493`, Marlin/src/gcode/feature/ft_motion/
    /// M493.cpp). The old rule took an `E` alone as no axis named and set X and Y.
    #[test]
    fn marlin_m493_e_leaves_x_and_y_alone() {
        let mut s = ShaperState::new(Firmware::Marlin, &[None; 3]);
        let xy = m493(Some(true), "", Some(FtShaper::Zvd), Some(40.0));
        assert_eq!(s.apply(&xy), Ok(true));
        let zvd = one("marlin:zvd", 40.0, 0.1);
        assert_eq!(kinds(&s), [zvd.clone(), zvd.clone(), None]);
        let e = m493(None, "E", Some(FtShaper::Zv), Some(55.0));
        assert_eq!(s.apply(&e), Ok(true));
        assert_eq!(kinds(&s), [zvd.clone(), zvd, None]);
    }

    fn rrf_m593(p: Option<&str>, f: Option<f64>, z: Option<f64>, l: Option<f64>) -> LimitChange {
        LimitChange::RrfInputShaping {
            shaper: p.map(str::to_string),
            frequency_hz: f,
            damping_ratio: z,
            reduction_limit: l,
            amplitudes: Vec::new(),
            durations_s: Vec::new(),
        }
    }

    /// RepRapFirmware 3.6's `M593` as `AxisShaper::Configure` (src/Movement/AxisShaper.cpp)
    /// reads it: the damping before any `S` is `DefaultDamping`, 0.05 (AxisShaper.h; the
    /// old rule kept 3.5's 0.1); `P` is reduced by `GetReducedString`, so `"EI-2"` is
    /// `ei2` (the old rule refused it); `L` is no longer read, so `M593 L0.2` does not
    /// select `zvd` (the old rule turned shaping on); `H` and `T` are read for `custom`
    /// only (the old rule refused `M593 P"zvd" ... H...`); `custom` is refused.
    #[test]
    fn rrf_m593_follows_axis_shaper_configure() {
        let mut s = ShaperState::new(Firmware::Rrf, &[None; 3]);
        assert_eq!(s.apply(&rrf_m593(None, None, None, Some(0.2))), Ok(false));
        assert_eq!(kinds(&s), [None, None, None]);
        assert_eq!(s.apply(&rrf_m593(Some("zvd"), None, None, None)), Ok(true));
        let zvd = one("rrf:zvd", 40.0, 0.05);
        assert_eq!(kinds(&s), [zvd.clone(), zvd, None]);
        assert_eq!(
            s.apply(&rrf_m593(Some("ei-2"), Some(45.0), None, None)),
            Ok(true)
        );
        let ei2 = one("rrf:ei2", 45.0, 0.05);
        assert_eq!(kinds(&s), [ei2.clone(), ei2, None]);
        let mut with_lists = rrf_m593(Some("zv_dd"), None, Some(0.1), None);
        if let LimitChange::RrfInputShaping {
            amplitudes,
            durations_s,
            ..
        } = &mut with_lists
        {
            *amplitudes = vec![0.4, 0.7];
            *durations_s = vec![0.01, 0.01];
        }
        assert_eq!(s.apply(&with_lists), Ok(true));
        let zvdd = one("rrf:zvdd", 45.0, 0.1);
        assert_eq!(kinds(&s), [zvdd.clone(), zvdd, None]);
        assert!(matches!(
            s.apply(&rrf_m593(Some("custom"), None, None, None)),
            Err(ShaperProblem::Unsupported(_))
        ));
        // Off, then a frequency alone selects zvd again.
        let mut s = ShaperState::new(Firmware::Rrf, &[None; 3]);
        assert_eq!(s.apply(&rrf_m593(None, Some(52.0), None, None)), Ok(true));
        let zvd = one("rrf:zvd", 52.0, 0.05);
        assert_eq!(kinds(&s), [zvd.clone(), zvd, None]);
    }
}
