//! What settle needs from a Klipper configuration, with Klipper's defaults and checks:
//! `[printer]` (`klippy/toolhead.py`, the kinematics modules), `[input_shaper]`
//! (`klippy/extras/input_shaper.py`), `[stepper_x|y|z]` (`klippy/stepper.py`) and their
//! `[tmc2130|tmc2208|tmc2209|tmc2240|tmc2660|tmc5160 stepper_*]` drivers
//! (`klippy/extras/tmc*.py`). An option of `[printer]` or `[input_shaper]` that Klipper
//! does not read is refused, as Klipper refuses it (see `unused`). Other sections and
//! their options are not read.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::klipper_files::{Loaded, load};
use super::klipper_shaper::{self, Family};
use super::klipper_values::{Range, Values, invalid};
use super::machine::{AxisDrive, ConfigNote, ShaperSetting, Xyz};
use crate::error::{GcodeError, Location};
// Klipper takes any max_velocity and max_accel above 0; settle takes them up to the bound
// its G-code reader puts on SET_VELOCITY_LIMIT and M204 (1e9): at max_velocity 1e300 no
// move can be planned (its square overflows) and every run of an import would fail.
use crate::read::cmd::SANE;

/// The kinematics Klipper has modules for (`klippy/kinematics/`).
const KINEMATICS: [&str; 12] = [
    "cartesian",
    "corexy",
    "corexz",
    "hybrid_corexy",
    "hybrid_corexz",
    "generic_cartesian",
    "delta",
    "deltesian",
    "rotary_delta",
    "polar",
    "winch",
    "none",
];

/// Klipper's default `minimum_cruise_ratio` (`klippy/toolhead.py`): half of each move's
/// acceleration is spent on the way to cruise speed at most.
pub const DEFAULT_MINIMUM_CRUISE_RATIO: f64 = 0.5;
/// Klipper's default `square_corner_velocity`, mm/s (`klippy/toolhead.py`).
pub const DEFAULT_SQUARE_CORNER_VELOCITY_MM_S: f64 = 5.0;
/// Klipper's default damping ratio for input shapers (`shaper_defs.DEFAULT_DAMPING_RATIO`):
/// "a good all-round value for most printers" (`docs/Config_Reference.md`).
pub const DEFAULT_DAMPING_RATIO: f64 = 0.1;
/// Klipper's default `shaper_type` (`klippy/extras/input_shaper.py`).
pub const DEFAULT_SHAPER_TYPE: &str = "mzv";
/// The highest shaper frequency read, Hz (Klipper's `shaper_freq_<axis>`, Marlin's
/// `M593 F`). Neither firmware sets an upper limit, but a shaper tuned above 1 kHz lasts
/// under a millisecond and cancels nothing a printer's belts or frame carry (their modes
/// are tens to a few hundred Hz); RepRapFirmware refuses `M593` above the same 1000 Hz
/// (`gcode/src/config/rrf.rs`). A larger value is a slip, refused at its line.
pub const MAX_SHAPER_FREQUENCY_HZ: f64 = 1000.0;
/// Klipper's default `full_steps_per_rotation` (`klippy/stepper.py`): a 1.8 degree motor.
pub const DEFAULT_FULL_STEPS_PER_ROTATION: u32 = 200;

/// The `[printer]` section.
#[derive(Debug, Clone, PartialEq)]
pub struct KlipperPrinter {
    /// `kinematics` (`cartesian`, `corexy`, ...).
    pub kinematics: String,
    /// `max_velocity`, mm/s.
    pub max_velocity_mm_s: f64,
    /// `max_accel`, mm/s^2.
    pub max_accel_mm_s2: f64,
    /// `minimum_cruise_ratio` (0 ..< 1, default 0.5). An older configuration's
    /// `max_accel_to_decel` is read as `1 - min(1, max_accel_to_decel / max_accel)`, as
    /// Klipper read it from 2023-12 until it removed the option on 2025-08-11
    /// (`docs/Config_Changes.md`); before that, its default `max_accel / 2` gave 0.5 too.
    pub minimum_cruise_ratio: f64,
    /// `square_corner_velocity`, mm/s (default 5).
    pub square_corner_velocity_mm_s: f64,
    /// `max_z_velocity`, mm/s (default and upper bound: `max_velocity`).
    pub max_z_velocity_mm_s: f64,
    /// `max_z_accel`, mm/s^2 (default and upper bound: `max_accel`).
    pub max_z_accel_mm_s2: f64,
}

/// A `[stepper_x|y|z]` section with its driver.
#[derive(Debug, Clone, PartialEq)]
pub struct KlipperStepper {
    /// Resolution, current, travel.
    pub drive: AxisDrive,
    /// `rotation_distance`, mm of travel per turn of the last gear.
    pub rotation_distance_mm: f64,
    /// `full_steps_per_rotation` (default 200).
    pub full_steps_per_rotation: u32,
    /// `gear_ratio`, the product of its `a:b` pairs (1 without).
    pub gear_ratio: f64,
    /// The driver chip of its `[tmc... stepper_*]` section (`tmc2209`), if any.
    pub driver: Option<String>,
}

/// The settings settle reads from a Klipper configuration, as Klipper would use them.
#[derive(Debug, Clone, PartialEq)]
pub struct KlipperConfig {
    /// `[printer]`.
    pub printer: KlipperPrinter,
    /// `[input_shaper]` per axis (`None` without the section: no shaping).
    pub input_shaper: Option<Xyz<ShaperSetting>>,
    /// `[stepper_x]`, `[stepper_y]`, `[stepper_z]` where present.
    pub steppers: Xyz<Option<KlipperStepper>>,
    /// The files read, the main one first, then includes in the order read.
    pub files: Vec<PathBuf>,
    /// What was read in a way worth knowing (SAVE_CONFIG values overridden, old options).
    pub notes: Vec<ConfigNote>,
    /// Where each option in effect was set, by `section.key` (lower case): the file and
    /// line an error about a value read here names.
    pub set_at: BTreeMap<String, Location>,
}

impl KlipperConfig {
    /// Reads the configuration file at `path` with its includes.
    pub fn read(path: impl AsRef<Path>) -> Result<Self, GcodeError> {
        Self::build(load(path.as_ref(), None)?, path.as_ref())
    }

    /// Reads `text` as the configuration file at `path` (which names it in errors and
    /// anchors its includes; it need not exist unless `text` includes relative files).
    pub fn parse(text: &str, path: impl AsRef<Path>) -> Result<Self, GcodeError> {
        Self::build(load(path.as_ref(), Some(text))?, path.as_ref())
    }

    fn build(loaded: Loaded, main: &Path) -> Result<Self, GcodeError> {
        let v = Values {
            store: &loaded.store,
        };
        let mut notes = loaded.notes;
        let main: Arc<str> = Arc::from(main.display().to_string());
        let skipped = |e| with_skipped(e, &loaded.skipped);
        let printer = printer(v, &main, &mut notes).map_err(skipped)?;
        let input_shaper = match loaded.store.section("input_shaper") {
            Some(_) => Some(Xyz {
                x: shaper(v, "x")?,
                y: shaper(v, "y")?,
                z: shaper(v, "z")?,
            }),
            None => None,
        };
        let steppers = Xyz {
            x: stepper(v, "stepper_x", &mut notes).map_err(skipped)?,
            y: stepper(v, "stepper_y", &mut notes).map_err(skipped)?,
            z: stepper(v, "stepper_z", &mut notes).map_err(skipped)?,
        };
        let allowed_printer = printer_options(&printer.kinematics);
        unused(v, "printer", &allowed_printer, &loaded.autosave, &mut notes)?;
        unused(
            v,
            "input_shaper",
            &SHAPER_OPTIONS,
            &loaded.autosave,
            &mut notes,
        )?;
        let set_at = loaded
            .store
            .sections()
            .iter()
            .flat_map(|sec| {
                sec.options.iter().filter_map(|o| {
                    let at = &loaded.store.get(&sec.name, &o.key)?.at;
                    Some((format!("{}.{}", sec.name, o.key), at.clone()))
                })
            })
            .collect();
        Ok(KlipperConfig {
            printer,
            input_shaper,
            steppers,
            files: loaded.files,
            notes,
            set_at,
        })
    }
}

/// The options of `[printer]` that `klippy/toolhead.py` reads whatever the kinematics.
const TOOLHEAD_OPTIONS: [&str; 5] = [
    "kinematics",
    "max_velocity",
    "max_accel",
    "minimum_cruise_ratio",
    "square_corner_velocity",
];

/// The options of `[input_shaper]` (`klippy/extras/input_shaper.py`,
/// `InputShaperParams`, for the axes x, y and z).
const SHAPER_OPTIONS: [&str; 10] = [
    "shaper_type",
    "shaper_type_x",
    "shaper_type_y",
    "shaper_type_z",
    "damping_ratio_x",
    "damping_ratio_y",
    "damping_ratio_z",
    "shaper_freq_x",
    "shaper_freq_y",
    "shaper_freq_z",
];

/// Options of `[printer]` Klipper removed (`docs/Config_Changes.md`): Klipper now refuses
/// them as it refuses any option it does not read, but none of them sets a speed, an
/// acceleration or a shaper (they tuned how far ahead the host queued moves, and how far a
/// step could stray from its time), so a configuration written before the removal still
/// says everything settle reads: settle notes them and reads on. `max_accel_to_decel`,
/// removed too, is read (see [`KlipperPrinter::minimum_cruise_ratio`]).
const REMOVED_PRINTER_OPTIONS: [(&str, &str); 6] = [
    ("buffer_time_low", "2023-12-07"),
    ("buffer_time_high", "2023-12-07"),
    ("buffer_time_start", "2023-12-07"),
    ("move_flush_time", "2023-12-07"),
    ("max_stepper_error", "2025-10-03"),
    ("max_accel_to_decel", "2025-08-11"),
];

/// The options of `[printer]` Klipper reads with `kinematics` (`klippy/toolhead.py` and
/// the module `klippy/kinematics/<kinematics>.py`).
fn printer_options(kinematics: &str) -> Vec<&'static str> {
    const Z: [&str; 2] = ["max_z_velocity", "max_z_accel"];
    let own: &[&str] = match kinematics {
        "cartesian" | "corexy" | "corexz" | "hybrid_corexy" | "hybrid_corexz"
        | "generic_cartesian" => &Z,
        "delta" => &[
            "max_z_velocity",
            "max_z_accel",
            "delta_radius",
            "print_radius",
            "minimum_z_position",
        ],
        "deltesian" => &[
            "max_z_velocity",
            "max_z_accel",
            "min_angle",
            "print_width",
            "minimum_z_position",
            "slow_ratio",
        ],
        // rotary_delta.py reads no max_z_accel.
        "rotary_delta" => &[
            "max_z_velocity",
            "shoulder_radius",
            "shoulder_height",
            "minimum_z_position",
        ],
        "polar" => &["max_z_velocity", "max_z_accel", "max_angular_velocity"],
        // winch.py and none.py read nothing of [printer].
        _ => &[],
    };
    TOOLHEAD_OPTIONS.iter().chain(own).copied().collect()
}

/// Klipper's check for options nobody read (`ConfigValidate.check_unused` in
/// `klippy/configfile.py`): an option of `section` that is not in `allowed` (nor set by the
/// SAVE_CONFIG block, which Klipper never refuses) stops Klipper with "Option '<option>' is
/// not valid in section '<section>'"; settle refuses it likewise, at its line. Options of
/// `[printer]` that Klipper removed are noted instead (`REMOVED_PRINTER_OPTIONS`).
fn unused(
    v: Values,
    section: &str,
    allowed: &[&str],
    autosave: &[(String, String)],
    notes: &mut Vec<ConfigNote>,
) -> Result<(), GcodeError> {
    let Some(sec) = v.store.section(section) else {
        return Ok(());
    };
    for o in &sec.options {
        let key = o.key.as_str();
        if allowed.contains(&key) || autosave.iter().any(|(s, k)| s == section && k == key) {
            continue;
        }
        if section == "printer"
            && let Some((_, date)) = REMOVED_PRINTER_OPTIONS.iter().find(|(k, _)| *k == key)
        {
            if key != "max_accel_to_decel" {
                notes.push(ConfigNote::at(
                    o.at.clone(),
                    format!(
                        "{key} is not read: Klipper removed it on {date} and now refuses it (docs/Config_Changes.md); it sets no speed, acceleration or shaper"
                    ),
                ));
            }
            continue;
        }
        let with = match section {
            "printer" => v
                .text(section, "kinematics")
                .map(|(_, k)| format!(" with kinematics {k}"))
                .unwrap_or_default(),
            _ => String::new(),
        };
        return Err(GcodeError::ConfigSetting {
            at: o.at.clone(),
            key: format!("{section}.{key}"),
            reason: format!(
                "Klipper does not know this option of [{section}]{with} and refuses to start (\"Option '{key}' is not valid in section '{section}'\", klippy/configfile.py); allowed: {}",
                allowed.join(", ")
            ),
        });
    }
    Ok(())
}

fn missing(source: &Arc<str>, section: &str, key: &str, why: &'static str) -> GcodeError {
    GcodeError::ConfigMissing {
        source_name: source.clone(),
        section: section.to_string(),
        key: key.to_string(),
        why: why.to_string(),
    }
}

/// A required option missing where includes were skipped: the error names the first
/// skipped include, whose file may have set it.
fn with_skipped(e: GcodeError, skipped: &[(Location, String)]) -> GcodeError {
    match (e, skipped.first()) {
        (
            GcodeError::ConfigMissing {
                source_name,
                section,
                key,
                why,
            },
            Some((at, what)),
        ) => GcodeError::ConfigMissing {
            source_name,
            section,
            key,
            why: format!(
                "{why}; {} [include]s of files that are not there were skipped, the first {what} at {at}: copy the files beside the configuration",
                skipped.len()
            ),
        },
        // Not a fragment, perhaps: the section may be in a file that is not there.
        (
            GcodeError::ConfigNoSection {
                source_name,
                section,
                ..
            },
            Some((at, what)),
        ) => GcodeError::ConfigNoSection {
            source_name,
            section,
            why: format!(
                "Klipper requires it, with kinematics, max_velocity and max_accel (klippy/toolhead.py); {} [include]s of files that are not there were skipped, the first {what} at {at}: copy the files beside the configuration",
                skipped.len()
            ),
        },
        (e, _) => e,
    }
}

fn printer(
    v: Values,
    main: &Arc<str>,
    notes: &mut Vec<ConfigNote>,
) -> Result<KlipperPrinter, GcodeError> {
    const S: &str = "printer";
    let file = |s: &str| {
        v.store
            .section(s)
            .map_or(main.clone(), |sec| sec.at.source_name.clone())
    };
    let required = "Klipper requires it (klippy/toolhead.py)";
    if v.store.section(S).is_none() {
        return Err(GcodeError::ConfigNoSection {
            source_name: main.clone(),
            section: S.to_string(),
            why: "the file is a fragment of a configuration, not a whole printer.cfg (Klipper requires [printer] with kinematics, max_velocity and max_accel: klippy/toolhead.py); give the printer.cfg that includes it".to_string(),
        });
    }
    let kinematics = match v.text(S, "kinematics") {
        Some((_, k)) if KINEMATICS.contains(&k.as_str()) => k,
        Some((opt, k)) => {
            return Err(invalid(
                opt,
                S,
                &k,
                format!("one of {}", KINEMATICS.join(", ")),
            ));
        }
        None => return Err(missing(&file(S), S, "kinematics", required)),
    };
    let max_velocity_mm_s = v
        .float(S, "max_velocity", Range::above(0.0).max(SANE))?
        .ok_or_else(|| missing(&file(S), S, "max_velocity", required))?;
    let max_accel_mm_s2 = v
        .float(S, "max_accel", Range::above(0.0).max(SANE))?
        .ok_or_else(|| missing(&file(S), S, "max_accel", required))?;
    let minimum_cruise_ratio = match v.float(
        S,
        "minimum_cruise_ratio",
        Range::min(0.0).below(1.0),
    )? {
        Some(r) => r,
        None => match v.float(S, "max_accel_to_decel", Range::above(0.0))? {
            Some(atd) => {
                let r = 1.0 - (atd / max_accel_mm_s2).min(1.0);
                if let Some((opt, _)) = v.text(S, "max_accel_to_decel") {
                    notes.push(ConfigNote::at(
                        opt.at.clone(),
                        format!(
                            "max_accel_to_decel = {atd} read as minimum_cruise_ratio = {r} (Klipper removed the option on 2025-08-11 and now refuses it; docs/Config_Changes.md)"
                        ),
                    ));
                }
                r
            }
            None => DEFAULT_MINIMUM_CRUISE_RATIO,
        },
    };
    let square_corner_velocity_mm_s = v
        .float(S, "square_corner_velocity", Range::min(0.0).max(SANE))?
        .unwrap_or(DEFAULT_SQUARE_CORNER_VELOCITY_MM_S);
    let max_z_velocity_mm_s = v
        .float(
            S,
            "max_z_velocity",
            Range::above(0.0).max(max_velocity_mm_s),
        )?
        .unwrap_or(max_velocity_mm_s);
    let max_z_accel_mm_s2 = v
        .float(S, "max_z_accel", Range::above(0.0).max(max_accel_mm_s2))?
        .unwrap_or(max_accel_mm_s2);
    Ok(KlipperPrinter {
        kinematics,
        max_velocity_mm_s,
        max_accel_mm_s2,
        minimum_cruise_ratio,
        square_corner_velocity_mm_s,
        max_z_velocity_mm_s,
        max_z_accel_mm_s2,
    })
}

/// One axis of `[input_shaper]`: `shaper_type_<axis>` wins over `shaper_type` (the code
/// reads it with `shaper_type` as its default).
fn shaper(v: Values, axis: &str) -> Result<ShaperSetting, GcodeError> {
    const S: &str = "input_shaper";
    let type_key = format!("shaper_type_{axis}");
    let given = v.text(S, &type_key).or_else(|| v.text(S, "shaper_type"));
    let (name, family) = match given {
        Some((opt, text)) => match klipper_shaper::check(&text) {
            Ok(f) => (text, f),
            Err(why) => {
                return Err(invalid(
                    opt,
                    S,
                    &text,
                    format!("{} ({why})", klipper_shaper::ALLOWED),
                ));
            }
        },
        None => (
            DEFAULT_SHAPER_TYPE.to_string(),
            Family {
                name: "mzv",
                max_damping_ratio: 0.99,
            },
        ),
    };
    let damping_ratio = v
        .float(
            S,
            &format!("damping_ratio_{axis}"),
            Range::min(0.0).max(family.max_damping_ratio),
        )?
        .unwrap_or(DEFAULT_DAMPING_RATIO);
    let frequency_hz = v
        .float(
            S,
            &format!("shaper_freq_{axis}"),
            Range::min(0.0).max(MAX_SHAPER_FREQUENCY_HZ),
        )?
        .unwrap_or(0.0);
    Ok(ShaperSetting {
        name,
        frequency_hz,
        damping_ratio,
    })
}

/// The driver section of `stepper`: `[<chip> <stepper>]`, names split on white space as
/// Klipper splits them.
fn driver_section<'a>(v: Values<'a>, stepper: &str) -> Vec<(&'static str, &'a str)> {
    const CHIPS: [&str; 6] = [
        "tmc2130", "tmc2208", "tmc2209", "tmc2240", "tmc2660", "tmc5160",
    ];
    let mut found = Vec::new();
    for s in v.store.sections() {
        let mut words = s.name.split_whitespace();
        let Some(chip) = words.next().and_then(|w| CHIPS.iter().find(|c| **c == w)) else {
            continue;
        };
        if words.collect::<Vec<_>>().join(" ") == stepper {
            found.push((*chip, s.name.as_str()));
        }
    }
    found
}

/// `run_current`'s limits per chip (`MAX_CURRENT` of `klippy/extras/tmc2130.py` (also
/// used by tmc2208/tmc2209), `tmc2660.py`, `tmc5160.py`; tmc2240's from its `rref`).
fn run_current_range(v: Values, chip: &str, section: &str) -> Result<Range, GcodeError> {
    Ok(match chip {
        "tmc2660" => Range::min(0.1).max(2.4),
        "tmc5160" => Range::above(0.0).max(10.0),
        "tmc2240" => {
            // `_get_ifs_rms(3)`: full scale 36000 / rref, RMS.
            let rref = v
                .float(section, "rref", Range::min(12000.0).max(60000.0))?
                .unwrap_or(12000.0);
            Range::above(0.0).max(36000.0 / rref / std::f64::consts::SQRT_2)
        }
        _ => Range::above(0.0).max(2.0),
    })
}

fn stepper(
    v: Values,
    name: &str,
    notes: &mut Vec<ConfigNote>,
) -> Result<Option<KlipperStepper>, GcodeError> {
    let Some(section) = v.store.section(name) else {
        return Ok(None);
    };
    let file = &section.at.source_name;
    let rotation_distance_mm = v
        .float(name, "rotation_distance", Range::above(0.0))?
        .ok_or_else(|| {
            missing(
                file,
                name,
                "rotation_distance",
                "Klipper requires it (klippy/stepper.py)",
            )
        })?;
    let microsteps = v
        .int(name, "microsteps", Range::min(1.0).max(f64::from(u32::MAX)))?
        .ok_or_else(|| {
            missing(
                file,
                name,
                "microsteps",
                "Klipper requires it (klippy/stepper.py)",
            )
        })?;
    let full_steps = v
        .int(
            name,
            "full_steps_per_rotation",
            Range::min(1.0).max(f64::from(u32::MAX)),
        )?
        .unwrap_or(i64::from(DEFAULT_FULL_STEPS_PER_ROTATION));
    if full_steps % 4 != 0
        && let Some((opt, text)) = v.text(name, "full_steps_per_rotation")
    {
        return Err(invalid(
            opt,
            name,
            &text,
            "a whole number divisible by 4".to_string(),
        ));
    }
    let gear_ratio = v.gear_ratio(name)?;
    let position_min_mm = v.float(name, "position_min", Range::ANY)?.unwrap_or(0.0);
    let position_max_mm = v.float(name, "position_max", Range::above(position_min_mm))?;
    let drivers = driver_section(v, name);
    if drivers.len() > 1 {
        notes.push(ConfigNote {
            at: Some(section.at.clone()),
            text: format!(
                "{} driver sections name [{name}]; the first, [{}], is read",
                drivers.len(),
                drivers[0].1
            ),
        });
    }
    let (mut run_current_a_rms, mut interpolate, mut driver) = (None, None, None);
    if let Some(&(chip, sec)) = drivers.first() {
        // The TMC drivers take only these microstep settings (`TMCMicrostepHelper`).
        if (!(1..=256).contains(&microsteps) || !(microsteps as u32).is_power_of_two())
            && let Some((opt, text)) = v.text(name, "microsteps")
        {
            return Err(invalid(
                opt,
                name,
                &text,
                format!("with a {chip} driver: 1, 2, 4, 8, 16, 32, 64, 128 or 256"),
            ));
        }
        let range = run_current_range(v, chip, sec)?;
        let file = &v
            .store
            .section(sec)
            .map_or(file.clone(), |s| s.at.source_name.clone());
        run_current_a_rms = Some(v.float(sec, "run_current", range)?.ok_or_else(|| {
            missing(
                file,
                sec,
                "run_current",
                "Klipper requires it (klippy/extras/tmc*.py)",
            )
        })?);
        interpolate = Some(v.boolean(sec, "interpolate")?.unwrap_or(true));
        driver = Some(chip.to_string());
    }
    let full_steps_per_rotation = full_steps as u32;
    let microsteps = microsteps as u32;
    let microsteps_per_mm = f64::from(full_steps_per_rotation) * f64::from(microsteps) * gear_ratio
        / rotation_distance_mm;
    let (lo, hi) = super::MICROSTEPS_PER_MM;
    if !(lo..=hi).contains(&microsteps_per_mm)
        && let Some((opt, text)) = v.text(name, "rotation_distance")
    {
        return Err(invalid(
            opt,
            name,
            &text,
            format!(
                "a rotation_distance (mm) that gives {lo} to {hi:e} microsteps per mm ({full_steps_per_rotation} full steps x {microsteps} microsteps x gear ratio {gear_ratio} / {text} mm is {microsteps_per_mm:e})"
            ),
        ));
    }
    Ok(Some(KlipperStepper {
        drive: AxisDrive {
            microsteps_per_mm,
            microsteps,
            interpolate,
            run_current_a_rms,
            position_min_mm,
            position_max_mm,
        },
        rotation_distance_mm,
        full_steps_per_rotation,
        gear_ratio,
        driver,
    }))
}
