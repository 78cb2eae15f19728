//! `settle import klipper printer.cfg` / `settle import rrf config.g` / `settle import
//! marlin m503.txt`: a scenario that reproduces the user's current settings as its
//! baseline, and a search around them.
//!
//! Read through settle-gcode's configuration readers (Klipper's includes and SAVE_CONFIG,
//! RepRapFirmware's macros, Marlin's `M503` reply as a terminal saves it; a present but
//! malformed value is an error naming the file, line and key; sections and commands
//! settle does not need are ignored):
//! - limits: Klipper `[printer]` `max_velocity`, `max_accel`; RepRapFirmware and Marlin
//!   `M203` (the lower of X and Y) and the lower of `M201` (per axis) and `M204 P`
//!   (printing moves); a Marlin reply without `M203`, `M201` or `M204` is refused (its
//!   limits would be Marlin's example configuration's, not the printer's);
//! - the shaper per axis: Klipper `[input_shaper]` `shaper_type_x/y`, `shaper_freq_x/y`,
//!   `damping_ratio_x/y` (frequency 0: off); RepRapFirmware's one `M593` for all axes;
//!   Marlin's `M593 X`/`M593 Y` (its built-in ZV shaper per axis, `F0`: off);
//! - microsteps per mm per axis (Klipper `[stepper_*]`, RepRapFirmware `M92`/`M350`,
//!   Marlin `M92`), for the TMC4361A export;
//! - RepRapFirmware's and Marlin's `M201` per axis, written as `[tune.axis.<name>]
//!   max_accel_mm_s2`: both cap every move's acceleration by it, so `settle tune`'s
//!   `rrf.g` and `marlin.gcode` raise it with `M201` where it is below the recommended
//!   acceleration.
//!
//! Marlin's `M205` (junction deviation `J`, or a `CLASSIC_JERK` build's X and Y jerks)
//! sets the speed through corners; the scenario's moves start and end at rest, so it has
//! no place there: it is a note (`settle gcode --firmware marlin --config` follows it).
//!
//! The scenario written runs the current settings as its own point (`[move]` trapezoids,
//! `[limits]`, `[shaper]` of the first axis), marks them in `[current]` among a `[sweep]`
//! of shapers, frequencies and accelerations around them (for `settle sweep`), and holds a
//! `[tune]` table for `settle tune` (the firmware's candidates, every axis with its current
//! settings in `[tune.axis.<name>]`, a 5 % frequency tolerance; where the machine's modes
//! carry their identified `frequency_sigma_hz`, `settle tune` uses the wider of that and
//! their 2-sigma band). The machine is the one
//! given (`--machine`, a machine file from `settle identify` or written by hand); without
//! it the preset `printer_xy` stands in, and the report says so.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use settle_gcode::Dialect;
use settle_gcode::config::{
    KlipperConfig, MarlinSettings, RrfConfig, ShaperSetting as FirmwareShaper,
};

use crate::error::{Error, Location};
use crate::input::machine_form::MachineForm;
use crate::output::atomic::write_atomic;
use crate::workflows::tune::firmware::{Candidates, MarlinShaping};
use crate::workflows::tune::grid::{identified_band, tuning_modes};
use crate::workflows::{Exit, Report};
use settle_planner::firmware::Firmware;
use settle_planner::firmware::marlin::MarlinJerk;

/// Shaper frequencies of the search, as multiples of the current one.
pub const FREQUENCY_SCALES: [f64; 5] = [0.9, 0.95, 1.0, 1.05, 1.1];
/// Accelerations of the sweep around the current settings, as multiples of the current
/// one.
pub const ACCEL_SCALES: [f64; 3] = [0.5, 0.75, 1.0];
/// Accelerations `settle tune` searches above the current one, as multiples of it, up to
/// the highest the machine allows ([`top_accel`]).
pub const ACCEL_SCALES_ABOVE: [f64; 5] = [1.25, 1.5, 2.0, 3.0, 4.0];
/// Robustness of the imported search (percent): a winner must still work with the real
/// mode this far off the identified one. Kept when the machine's modes carry their
/// identified sigmas: those are the statistical uncertainty of one measurement (often
/// under 0.1 %), while a gantry's modes move by percents with the toolhead's position,
/// the load and the belt tension.
pub const FREQUENCY_TOLERANCE_PCT: f64 = 5.0;
/// The preset that stands in when no machine is given.
pub const STAND_IN_PRESET: &str = "printer_xy";

/// What `settle import` reads and writes.
#[derive(Debug, Clone)]
pub struct ImportOptions {
    /// `klipper`, `marlin` or `rrf`.
    pub firmware: Firmware,
    /// printer.cfg, config.g or Marlin's reply to `M503`.
    pub config: PathBuf,
    /// The machine file (`settle identify`'s, or written by hand).
    pub machine: Option<PathBuf>,
    /// The scenario to write (default: `<config name>_import.toml` beside the config).
    pub out: Option<PathBuf>,
    /// Replace a scenario already at `out` (refused without it: an earlier import, or a
    /// scenario edited since, would be lost).
    pub force: bool,
}

/// One axis's current settings.
#[derive(Debug, Clone, PartialEq)]
pub struct AxisNow {
    /// `x`, `y`.
    pub name: String,
    /// The shaper in `shaper.type` syntax with frequency (Hz) and damping ratio; `None`:
    /// not shaped.
    pub shaper: Option<(String, f64, f64)>,
    /// Microsteps per mm.
    pub usteps_per_mm: Option<f64>,
    /// The axis's own acceleration cap, mm/s^2 (Marlin's and RepRapFirmware's `M201`;
    /// Klipper has none but `max_accel`).
    pub max_accel_mm_s2: Option<f64>,
}

/// The settings read from a firmware configuration.
#[derive(Debug, Clone, PartialEq)]
pub struct Current {
    /// The firmware.
    pub firmware: Firmware,
    /// Highest speed (mm/s).
    pub vmax_mm_s: f64,
    /// Acceleration of printing moves (mm/s^2).
    pub amax_mm_s2: f64,
    /// X and Y.
    pub axes: Vec<AxisNow>,
    /// What the reader noted.
    pub notes: Vec<String>,
    /// Marlin: the input shaper of the printer's build (`[tune] marlin_shaping`); `None`
    /// for the other firmwares.
    pub marlin_shaping: Option<MarlinShaping>,
    /// Where the settings were read, by the firmware's key (`printer.max_accel`,
    /// `input_shaper.shaper_freq_x`, `M201`, `M593`): the file and line an error about a
    /// setting settle cannot run names. Empty where the reader keeps no lines.
    pub set_at: BTreeMap<String, Location>,
}

impl Current {
    /// The candidates `settle tune` searches for this firmware (and Marlin build).
    pub fn candidates(&self) -> Candidates {
        Candidates::of(self.firmware).with_marlin_shaping(self.marlin_shaping.unwrap_or_default())
    }
}

/// What `settle import` wrote.
#[derive(Debug, Clone)]
pub struct Imported {
    /// The settings read.
    pub current: Current,
    /// The scenario text.
    pub scenario: String,
    /// Where it was written.
    pub out: PathBuf,
    /// The axes the scenario tunes (those the machine has).
    pub axes: Vec<String>,
    /// Notes for the user (the stand-in machine, what the reader skipped).
    pub notes: Vec<String>,
}

impl Imported {
    /// What the command prints.
    pub fn report(&self) -> Report {
        let mut r = Report::new(Exit::Ok);
        r.out(format!("Wrote {}", self.out.display()));
        for a in &self.current.axes {
            let sh = a
                .shaper
                .as_ref()
                .map_or("no shaper".to_string(), |(n, f, z)| {
                    format!("{n} @ {f} Hz (zeta {z})")
                });
            r.out(format!(
                "current {}: {sh}, {} mm/s^2, {} mm/s",
                a.name, self.current.amax_mm_s2, self.current.vmax_mm_s
            ));
        }
        r.out(format!(
            "next: settle tune {} (axes {})",
            self.out.display(),
            self.axes.join(", ")
        ));
        for n in &self.notes {
            r.err(format!("note: {n}"));
        }
        r
    }
}

/// A configuration reader's error as the harness's, at its file, line and key.
pub(crate) fn config_error(path: &Path, e: settle_gcode::GcodeError) -> Error {
    let e = match e {
        settle_gcode::GcodeError::Io { source, .. } => return Error::read(path, source),
        settle_gcode::GcodeError::File(f) => return (*f).into(),
        e => e,
    };
    let text = e.to_string();
    match e.location() {
        Some(at) => {
            let prefix = format!("{at}: ");
            let key = match &e {
                // GRBL's `$110` as it is written; `section.key` elsewhere.
                settle_gcode::GcodeError::ConfigValue { section, key, .. } if section == "$" => {
                    Some(format!("${key}"))
                }
                settle_gcode::GcodeError::ConfigValue { section, key, .. } => {
                    Some(format!("{section}.{key}"))
                }
                settle_gcode::GcodeError::ConfigSetting { key, .. } => Some(key.clone()),
                _ => None,
            };
            Error::Input {
                at: Location {
                    file: PathBuf::from(at.source_name.as_ref()),
                    line: usize::try_from(at.line).ok(),
                    column: at.column,
                    key,
                },
                message: match &e {
                    settle_gcode::GcodeError::ConfigSetting { reason, .. } => reason.clone(),
                    _ => text.strip_prefix(&prefix).unwrap_or(&text).to_string(),
                },
            }
        }
        None => match e {
            settle_gcode::GcodeError::JobSetting { key, reason } => {
                Error::input_key(path, key, reason)
            }
            // These name their file first: the file is said once.
            settle_gcode::GcodeError::ConfigMissing {
                ref source_name, ..
            }
            | settle_gcode::GcodeError::ConfigNoSection {
                ref source_name, ..
            } => {
                let prefix = format!("{source_name}: ");
                Error::input(
                    PathBuf::from(source_name.as_ref()),
                    text.strip_prefix(&prefix).unwrap_or(&text),
                )
            }
            _ => Error::input(path, text),
        },
    }
}

/// A configuration reader's place as the harness's, with the firmware's `key`.
fn harness_location(at: &settle_gcode::Location, key: &str) -> Location {
    Location {
        file: PathBuf::from(at.source_name.as_ref()),
        line: usize::try_from(at.line).ok(),
        column: None,
        key: Some(key.to_string()),
    }
}

fn shaper_now(s: &FirmwareShaper, dialect: Dialect) -> Option<(String, f64, f64)> {
    s.type_name(dialect)
        .map(|n| (n, s.frequency_hz, s.damping_ratio))
}

/// The firmwares whose configurations `settle import` reads: Klipper (printer.cfg),
/// Marlin (its reply to `M503`), Prusa-Firmware-Buddy (its replies to `M115`, `M503` and
/// `M593`) and RepRapFirmware (config.g).
pub const READ: [Firmware; 4] = [
    Firmware::Klipper,
    Firmware::Marlin,
    Firmware::Prusa,
    Firmware::Rrf,
];

/// A firmware of [`READ`] by name ([`Firmware::parse`]'s names); GRBL is refused with its
/// reason (its `$$` settings feed `settle gcode`, not a tune: GRBL has no input shaper).
pub fn parse_firmware(name: &str) -> Result<Firmware, String> {
    if Firmware::parse(name) == Some(Firmware::Grbl) {
        return Err(format!(
            "grbl is not a firmware whose configuration settle import reads: GRBL has no \
             input shaper for settle tune to set (its $$ settings are read by settle gcode \
             --firmware grbl --config); allowed: {}",
            Firmware::names(&READ)
        ));
    }
    Firmware::parse_among(
        name,
        &READ,
        "a firmware whose configuration settle import reads",
    )
}

/// Read the current settings of a firmware configuration.
pub fn read_current(firmware: Firmware, path: &Path) -> Result<Current, Error> {
    read_current_files(firmware, path).map(|(c, _)| c)
}

/// [`read_current`], with the files read (the configuration and what it includes).
pub fn read_current_files(
    firmware: Firmware,
    path: &Path,
) -> Result<(Current, Vec<PathBuf>), Error> {
    not_a_config(path, firmware, IMPORT_READS)?;
    match firmware {
        Firmware::Klipper => {
            let c = KlipperConfig::read(path).map_err(|e| config_error(path, e))?;
            // The planner's settings as `settle gcode --config` takes them: a shaper
            // Klipper would refuse is refused here too, naming its key.
            settle_gcode::job::JobConfig::from_klipper(&c).map_err(|e| config_error(path, e))?;
            let files = c.files.clone();
            let axes = [("x", &c.steppers.x), ("y", &c.steppers.y)]
                .into_iter()
                .map(|(name, st)| AxisNow {
                    name: name.into(),
                    shaper: c.input_shaper.as_ref().and_then(|s| {
                        shaper_now(if name == "x" { &s.x } else { &s.y }, Dialect::Klipper)
                    }),
                    usteps_per_mm: st.as_ref().map(|s| s.drive.microsteps_per_mm),
                    max_accel_mm_s2: None,
                })
                .collect();
            let cur = Current {
                firmware,
                vmax_mm_s: c.printer.max_velocity_mm_s,
                amax_mm_s2: c.printer.max_accel_mm_s2,
                axes,
                notes: c.notes.iter().map(ToString::to_string).collect(),
                marlin_shaping: None,
                set_at: c
                    .set_at
                    .iter()
                    .map(|(k, at)| (k.clone(), harness_location(at, k)))
                    .collect(),
            };
            Ok((cur, files))
        }
        Firmware::Rrf => {
            let c = RrfConfig::read(path).map_err(|e| config_error(path, e))?;
            settle_gcode::job::JobConfig::from_rrf(&c).map_err(|e| config_error(path, e))?;
            let files = c.files.clone();
            let shaper = shaper_now(&c.input_shaper, Dialect::Rrf);
            let axes = [("x", &c.axes.x), ("y", &c.axes.y)]
                .into_iter()
                .map(|(name, a)| AxisNow {
                    name: name.into(),
                    shaper: shaper.clone(),
                    usteps_per_mm: Some(a.drive.microsteps_per_mm),
                    max_accel_mm_s2: Some(a.max_accel_mm_s2),
                })
                .collect();
            let cur = Current {
                firmware,
                vmax_mm_s: c.axes.x.max_speed_mm_s.min(c.axes.y.max_speed_mm_s),
                amax_mm_s2: c
                    .print_accel_mm_s2
                    .min(c.axes.x.max_accel_mm_s2)
                    .min(c.axes.y.max_accel_mm_s2),
                axes,
                notes: c.notes.iter().map(ToString::to_string).collect(),
                marlin_shaping: None,
                set_at: c
                    .set_at
                    .iter()
                    .map(|(k, at)| (k.clone(), harness_location(at, k)))
                    .collect(),
            };
            Ok((cur, files))
        }
        Firmware::Marlin | Firmware::Prusa => {
            let c = if firmware == Firmware::Prusa {
                MarlinSettings::read_prusa(path)
            } else {
                MarlinSettings::read(path)
            };
            let c = c.map_err(|e| config_error(path, e))?;
            c.job_config().map_err(|e| config_error(path, e))?;
            Ok((marlin_current(&c, path)?, c.files.clone()))
        }
        other => Err(Error::input_key(
            path,
            "firmware",
            format!(
                "settle import reads klipper (printer.cfg), marlin (M503 reply), prusa (M115, M503 and M593 replies) and rrf (config.g), not {}",
                other.name()
            ),
        )),
    }
}

/// What `settle import` reads, as its refusals end.
pub(crate) const IMPORT_READS: &str = "settle import reads a printer.cfg (klipper), a config.g (rrf), the reply to M503 (marlin) or the replies to M115, M503 and M593 (prusa)";

/// Refuses a file that is not `firmware`'s configuration, before a reader takes it for
/// one: a G-code job (a slicer writes M201, M203 and M204 into every job, and
/// RepRapFirmware's defaults stand in for what a config.g does not set), a scenario, a
/// machine file, a recording or a model, and another firmware's configuration where its
/// reader would read it as this one's (RepRapFirmware's reader takes Marlin's `M203` in
/// mm/s as mm/min) or fail at its first line ([`settle_files::looks`]), named with the
/// command that reads it, then what the asking command reads (`reads`): `settle import`
/// ([`IMPORT_READS`]) and `settle gcode --config` both ask. (A zero
/// byte alone is left to the reader: a terminal's log of a serial line may hold one from
/// a reset. A Marlin reply copied without its `echo:` prefixes and holding `M906` or
/// `M569` looks like a config.g here, so Marlin's and Prusa's readers, not this, refuse a
/// config.g: at its first command that only RepRapFirmware has.)
pub(crate) fn not_a_config(path: &Path, firmware: Firmware, reads: &str) -> Result<(), Error> {
    use settle_files::looks::Looks;
    let limit = crate::input::file::limit::FIRMWARE_CONFIG;
    let Some(looks) = settle_files::looks::file(path, limit) else {
        return Ok(());
    };
    let (expected, foreign): (&str, &[Looks]) = match firmware {
        Firmware::Klipper => (
            "a Klipper configuration",
            &[Looks::RrfConfig, Looks::MarlinReply],
        ),
        Firmware::Rrf => (
            "a RepRapFirmware configuration",
            &[Looks::KlipperConfig, Looks::MarlinReply],
        ),
        Firmware::Marlin => ("Marlin's reply to M503", &[Looks::KlipperConfig]),
        Firmware::Prusa => (
            "a Prusa's replies to M115, M503 and M593",
            &[Looks::KlipperConfig],
        ),
        Firmware::Grbl => (
            "GRBL's $$ settings",
            &[Looks::KlipperConfig, Looks::RrfConfig, Looks::MarlinReply],
        ),
        Firmware::Settle | Firmware::Tmc4361a => ("a firmware configuration", &[]),
    };
    let expected = match looks {
        Looks::GcodeJob
        | Looks::Bgcode
        | Looks::SlicedThreeMf
        | Looks::ThreeMf
        | Looks::Ufp
        | Looks::StlBinary
        | Looks::StlAscii
        | Looks::Scenario
        | Looks::MachineFile
        | Looks::Recording
        | Looks::Json => "a firmware configuration",
        l if foreign.contains(&l) => expected,
        _ => return Ok(()),
    };
    Err(Error::Input {
        at: Location {
            line: Some(1),
            ..Location::file(path)
        },
        message: format!(
            "{}, not {expected}: {}; {reads}",
            looks.what(),
            looks.then()
        ),
    })
}

/// A length, speed or acceleration of Marlin's planner (m, m/s, m/s^2) in the millimetres
/// `M503` printed: `M503` prints two or three decimals, so rounding to a millionth gives
/// back the printed number (the planner keeps `value * 1e-3`).
fn marlin_mm(v_m: f64) -> f64 {
    (v_m * 1e9).round() / 1e6
}

/// The current settings of a Marlin `M503` reply, or of a Prusa-Firmware-Buddy log (read
/// by settle-gcode's [`MarlinSettings`]).
fn marlin_current(c: &MarlinSettings, path: &Path) -> Result<Current, Error> {
    let firmware = c.firmware();
    // The baseline is the reply's: without these the speed or acceleration would be
    // Marlin's example configuration's (MarlinSettings starts from it), not the printer's.
    for (command, what) in [
        ("M203", "max feedrates"),
        ("M201", "max accelerations"),
        ("M204", "printing acceleration"),
    ] {
        if !c.followed.iter().any(|(_, f)| *f == command) {
            return Err(Error::input_key(
                path,
                command,
                format!(
                    "the M503 reply has no {command} line ({what}): the baseline needs the printer's own M203, M201 and M204 (send M503 to the printer and save its whole reply)"
                ),
            ));
        }
    }
    let p = &c.planner;
    let vmax = marlin_mm(p.max_feedrate_m_s[0].min(p.max_feedrate_m_s[1]));
    let amax = marlin_mm(
        p.print_accel_m_s2
            .min(p.max_accel_m_s2[0])
            .min(p.max_accel_m_s2[1]),
    );
    // A limit that rounds to nothing at a millionth of a millimetre ([`marlin_mm`]) is no
    // speed or acceleration a move can have.
    for (value, command, what) in [
        (vmax, "M203", "the lower of X and Y max feedrates (mm/s)"),
        (
            amax,
            if p.print_accel_m_s2 < p.max_accel_m_s2[0].min(p.max_accel_m_s2[1]) {
                "M204"
            } else {
                "M201"
            },
            "the printing acceleration, the lowest of M204 P and M201 X and Y (mm/s^2)",
        ),
    ] {
        if value <= 0.0 {
            let line = c
                .followed
                .iter()
                .rev()
                .find(|(_, f)| *f == command)
                .map(|(l, _)| usize::try_from(*l).unwrap_or(0));
            return Err(Error::Input {
                at: Location {
                    file: path.to_path_buf(),
                    line,
                    column: None,
                    key: Some(command.to_string()),
                },
                message: format!(
                    "{what} rounds to 0 at the millionth of a millimetre settle reads: no move can have it; allowed: at least 0.000001"
                ),
            });
        }
    }
    let axes = ["x", "y"]
        .into_iter()
        .enumerate()
        .map(|(i, name)| AxisNow {
            name: name.into(),
            // M593 is Marlin's stepper ZV (settle-gcode reads it as `marlin:m593`); `F0` is
            // no shaper.
            shaper: c.shapers[i].map(|s| (s.shaper_type.name(), s.frequency_hz, s.damping_ratio)),
            // Marlin's steps per mm count microsteps; Buddy's `M92` counts its planner's
            // steps (quarter steps of it are planned, PLANNER_STEPS_MULTIPLIER), not the
            // driver's microsteps: none is given.
            usteps_per_mm: c.steps_per_mm[i].filter(|_| firmware != Firmware::Prusa),
            // M201, which the reply has (checked above).
            max_accel_mm_s2: Some(marlin_mm(p.max_accel_m_s2[i])),
        })
        .collect();
    let mut notes: Vec<String> = c.notes.iter().map(ToString::to_string).collect();
    let corner = match p.jerk {
        MarlinJerk::JunctionDeviation { deviation_m, .. } => {
            format!("M205 J{} (junction deviation, mm)", marlin_mm(deviation_m))
        }
        MarlinJerk::Classic { max_jerk_m_s, .. } => format!(
            "M205 X{} Y{} (classic jerk of a CLASSIC_JERK build, mm/s)",
            marlin_mm(max_jerk_m_s[0]),
            marlin_mm(max_jerk_m_s[1])
        ),
    };
    notes.push(format!(
        "{corner} read, not in the scenario: it sets the speed through corners, and the scenario's moves start and end at rest (settle gcode --firmware {firmware} --config follows it)"
    ));
    if let Some((line, name)) = c.prusa.as_ref().and_then(|p| p.named_at.as_ref()) {
        notes.push(format!(
            "{}:{line}: the printer is a Prusa {name} (M115's MACHINE_TYPE): the {}'s settings stand for what the replies do not give",
            path.display(),
            c.prusa.as_ref().map_or("MK4", |p| p.model.name())
        ));
    }
    // An older report's `M493` with FT_MOTION off is noted; the current report's lines
    // are followed (settle-gcode's `MarlinSettings`), their shapers in the baseline when
    // FT_MOTION is on.
    let m493_noted = c
        .notes
        .iter()
        .any(|n| n.text.starts_with("M493 (FT_MOTION"));
    let has_m493 = m493_noted || c.followed.iter().any(|(_, f)| *f == "M493");
    let has_m593 = c.followed.iter().any(|(_, f)| *f == "M593");
    if m493_noted {
        notes.push(
            "the reply has FT_MOTION's M493: the current shaper is read from M593 only (none here if the reply has no M593); FT_MOTION's shaper is not part of the baseline".into(),
        );
    }
    // M503 prints `M593 X/Y` when the build has Marlin's built-in input shaping
    // (M593_report, Marlin/src/gcode/feature/input_shaping/M593.cpp) and `M493` when it
    // has Fixed-Time Motion; the export must be the one the build runs. A reply with
    // neither comes from a build with no input shaper: either export needs a new build,
    // and settle tunes for the built-in ZV shaper (INPUT_SHAPING_X/Y in
    // Configuration_adv.h), the shaper of the older release (Marlin 2.1.2; FT_MOTION
    // needs 2.1.3).
    let shaping = if firmware == Firmware::Prusa {
        None
    } else if has_m493 {
        Some(MarlinShaping::FtMotion)
    } else {
        if !has_m593 {
            notes.push(
                "the reply has neither M593 nor M493: this build has no input shaper; the scenario tunes Marlin's built-in ZV shaper (marlin_shaping = \"input_shaping\", M593: INPUT_SHAPING_X and INPUT_SHAPING_Y in Configuration_adv.h, Marlin 2.1.2 or later); set marlin_shaping = \"ft_motion\" for a Fixed-Time Motion build (M493)".into(),
            );
        }
        Some(MarlinShaping::InputShaping)
    };
    // The last line of each command (the one whose values hold).
    let set_at = c
        .followed
        .iter()
        .map(|(line, command)| {
            let at = Location {
                file: path.to_path_buf(),
                line: usize::try_from(*line).ok(),
                column: None,
                key: Some((*command).to_string()),
            };
            ((*command).to_string(), at)
        })
        .collect();
    Ok(Current {
        firmware,
        vmax_mm_s: vmax,
        amax_mm_s2: amax,
        axes,
        notes,
        marlin_shaping: shaping,
        set_at,
    })
}

/// A TOML string.
fn q(s: &str) -> String {
    toml::Value::String(s.to_string()).to_string()
}

/// A list of numbers in TOML.
fn list(xs: &[f64]) -> String {
    let items: Vec<String> = xs.iter().map(|x| format!("{x:?}")).collect();
    format!("[{}]", items.join(", "))
}

/// `x * k` for each `k`, rounded to `step`, with `x` itself exact, sorted, deduplicated.
fn around(x: f64, scales: &[f64], step: f64) -> Vec<f64> {
    let mut v: Vec<f64> = scales
        .iter()
        .map(|k| {
            if *k == 1.0 {
                x
            } else if step < 1.0 {
                // n / 10 rather than n * 0.1: the double nearest the decimal.
                (x * k / step).round() / (1.0 / step).round()
            } else {
                (x * k / step).round() * step
            }
        })
        .filter(|v| *v > 0.0)
        .collect();
    v.sort_by(f64::total_cmp);
    v.dedup();
    v
}

/// The highest acceleration the machine allows a shaper on the axis of `run` (mm/s^2):
/// the largest at which one of the firmware's shapers, tuned to the axis's strongest mode
/// (at the search's highest frequency scale, designed for the mode's damping), keeps
/// Klipper's smoothing within its 0.12 mm; above it every shaper that cancels the mode
/// smooths more. `None` without a mode or a shaper.
pub fn top_accel(runs: Candidates, run: &crate::spec::run_spec::RunSpec) -> Option<f64> {
    let (f, zeta) = tuning_modes(run).first().copied()?;
    let highest = FREQUENCY_SCALES.iter().copied().fold(0.0, f64::max);
    runs.shapers()
        .into_iter()
        .filter_map(|k| {
            let (z, _) = crate::workflows::tune::target::design_damping(k, zeta);
            let sh = settle_planner::shaper::Shaper::new(k, (f * highest * 10.0).round() / 10.0, z)
                .ok()?;
            Some(crate::studies::shaping::max_accel_mm_s2(
                &sh,
                settle_planner::shaper_select::TARGET_SMOOTHING_MM,
            ))
        })
        .filter(|a| a.is_finite())
        .reduce(f64::max)
}

/// The accelerations `settle tune` searches: [`ACCEL_SCALES`] of the current one, then
/// [`ACCEL_SCALES_ABOVE`] up to `top` and `top` itself (both rounded down to 100 mm/s^2).
pub fn tune_accels(current: f64, top: Option<f64>) -> Vec<f64> {
    let mut v = around(current, &ACCEL_SCALES, 100.0);
    if let Some(top) = top.map(|t| (t / 100.0).floor() * 100.0)
        && top > current
    {
        v.extend(
            ACCEL_SCALES_ABOVE
                .iter()
                .map(|k| (current * k / 100.0).floor() * 100.0)
                // Under 100 mm/s^2 (a max_accel given in m/s^2) a multiple rounds down
                // to 0, which `settle tune` refuses.
                .filter(|a| *a > 0.0 && *a < top),
        );
        v.push(top);
    }
    v.sort_by(f64::total_cmp);
    v.dedup();
    v
}

/// The scenario's text; `frequency_hz` is the sweep's centre for an unshaped first axis,
/// `top` the highest acceleration the machine allows ([`top_accel`]).
#[allow(clippy::too_many_arguments)]
fn scenario_text(
    name: &str,
    machine: &str,
    cur: &Current,
    axes: &[&AxisNow],
    frequency_hz: f64,
    source: &str,
    identified_band: bool,
    top: Option<f64>,
) -> String {
    let first = axes.first().copied().unwrap_or(&cur.axes[0]);
    let fw = cur.firmware;
    let (type_now, f_now, z_now) = first.shaper.clone().unwrap_or_else(|| {
        (
            "none".into(),
            frequency_hz,
            crate::studies::shaping::DEFAULT_DAMPING_RATIO,
        )
    });
    let accels = around(cur.amax_mm_s2, &ACCEL_SCALES, 100.0);
    let tune_accels = tune_accels(cur.amax_mm_s2, top);
    let freqs = around(f_now, &FREQUENCY_SCALES, 0.1);
    let mut types = vec![q("none")];
    types.extend(cur.candidates().shapers().iter().map(|k| q(&k.name())));
    if !types.contains(&q(&type_now)) {
        types.push(q(&type_now));
    }
    let mut t = String::new();
    let _ = write!(
        t,
        "# Written by `settle import {} {source}`: the current settings as this scenario's own\n\
         # point (marked in [current] among the [sweep]) and a search around them in [tune].\n\
         #   settle sweep THIS.toml   # the sweep around the current settings\n\
         #   settle tune THIS.toml    # the recommendation per axis, with {}\n",
        fw.name(),
        match cur.marlin_shaping {
            Some(MarlinShaping::FtMotion) => "marlin.gcode (FT_MOTION's M493)",
            Some(MarlinShaping::InputShaping) => "marlin.gcode (input shaping's M593)",
            None if fw == Firmware::Prusa => "prusa.gcode (Buddy's M593)",
            None => "klipper.cfg / rrf.g",
        },
    );
    // What the reading passed over stays with the settings read (an include that was not
    // there may set some of them).
    if !cur.notes.is_empty() {
        t.push_str(
            "# What the reading of the configuration noted (it may bear on the settings below):\n",
        );
        for n in &cur.notes {
            let _ = writeln!(t, "#   - {}", n.replace('\n', " "));
        }
    }
    let _ = writeln!(
        t,
        "name = {}\ndescription = {}\n",
        q(name),
        q(&format!("Imported from {source} ({})", fw.name()))
    );
    let _ = writeln!(
        t,
        "[machine]\npreset = {}\ndriver_model = \"linear\"   # the stiff-spring driver: the exact modal backend can score every candidate\n",
        q(machine)
    );
    let _ = writeln!(
        t,
        "[move]\naxis = {}\ndistance_mm = 20.0\nprofile = \"trapezoid\"   # {} plans trapezoids\n",
        q(&first.name),
        fw.name()
    );
    let _ = writeln!(
        t,
        "[limits]\nvmax_mm_s = {:?}\namax_mm_s2 = {:?}\n",
        cur.vmax_mm_s, cur.amax_mm_s2
    );
    let _ = writeln!(
        t,
        "[shaper]   # axis {}'s current shaper\ntype = {}\nfrequency_hz = {f_now:?}\ndamping_ratio = {z_now:?}\n",
        first.name,
        q(&type_now)
    );
    let _ = writeln!(
        t,
        "[observe]\nwindow_s = 0.4\nsample_rate_hz = 5000\nbands_um = [10.0, 50.0]\n"
    );
    let _ = writeln!(
        t,
        "[sweep]   # on axis {}\n\"shaper.type\" = [{}]\n\"shaper.frequency_hz\" = {}\n\"limits.amax_mm_s2\" = {}\n",
        first.name,
        types.join(", "),
        list(&freqs),
        list(&accels)
    );
    let _ = writeln!(
        t,
        "[current]\n\"shaper.type\" = {}\n\"shaper.frequency_hz\" = {f_now:?}\n\"limits.amax_mm_s2\" = {:?}\n",
        q(&type_now),
        cur.amax_mm_s2
    );
    let names: Vec<String> = axes.iter().map(|a| q(&a.name)).collect();
    let _ = writeln!(
        t,
        "[tune]\nfirmware = {}\n{}axes = [{}]\ndistances_mm = [5.0, 20.0]\nband_um = 10.0\nfrequency_scales = {}\n{}accelerations_mm_s2 = {}\n{}",
        q(fw.name()),
        cur.marlin_shaping.map_or(String::new(), |m| format!(
            "marlin_shaping = {}   # the reply's input shaper: {}\n",
            q(m.name()),
            match m {
                MarlinShaping::FtMotion => "Fixed-Time Motion, M493",
                MarlinShaping::InputShaping => "the built-in ZV, M593",
            }
        )),
        names.join(", "),
        list(&FREQUENCY_SCALES),
        match top {
            Some(t) if t > cur.amax_mm_s2 => format!(
                "# From half the current acceleration up to {:.0} mm/s^2, the highest at which one of\n# {}'s shapers, tuned to the machine's strongest mode, stays within 0.12 mm of smoothing.\n",
                (t / 100.0).floor() * 100.0,
                fw.name()
            ),
            _ => "# Around the current acceleration: no shaper of the firmware stays within 0.12 mm of\n# smoothing above it on this machine.\n".to_string(),
        },
        list(&tune_accels),
        if identified_band {
            format!(
                "# The machine file's frequency_sigma_hz gives each axis a 2-sigma band; tune uses\n# the wider of that band and this tolerance (the drift one measurement does not see).\nfrequency_tolerance_pct = {FREQUENCY_TOLERANCE_PCT:?}"
            )
        } else {
            format!("frequency_tolerance_pct = {FREQUENCY_TOLERANCE_PCT:?}")
        }
    );
    for a in axes {
        let _ = writeln!(t, "\n[tune.axis.{}]", a.name);
        match &a.shaper {
            Some((n, f, z)) => {
                let _ = writeln!(
                    t,
                    "shaper = {}\nfrequency_hz = {f:?}\ndamping_ratio = {z:?}",
                    q(n)
                );
            }
            None => {
                let _ = writeln!(t, "shaper = \"none\"");
            }
        }
        if let Some(u) = a.usteps_per_mm {
            let _ = writeln!(t, "usteps_per_mm = {u:?}");
        }
        if let Some(m) = a.max_accel_mm_s2 {
            let _ = writeln!(
                t,
                "max_accel_mm_s2 = {m:?}   # M201 {}: {} where it is below the recommended acceleration",
                a.name.to_ascii_uppercase(),
                if cur.firmware == Firmware::Prusa {
                    "prusa.gcode raises it"
                } else {
                    "marlin.gcode / rrf.g raise it"
                }
            );
        }
    }
    t
}

/// A scenario made of the settings read that settle cannot run (`e`, against the probe
/// scenario), said against the configuration, the firmware's own key and, where the
/// reader keeps it, the line that set it.
fn settings_error(config: &Path, cur: &Current, axis: &str, e: Error) -> Error {
    let Error::Input { at, message } = e else {
        return e;
    };
    let key = at.key.unwrap_or_default();
    let key = key.strip_prefix("sweep.").unwrap_or(&key);
    let klipper = cur.firmware == Firmware::Klipper;
    // The command whose acceleration is the baseline's: an axis's M201 when it is the
    // lowest, else M204 P.
    let accel_command = if cur
        .axes
        .iter()
        .any(|a| a.max_accel_mm_s2 == Some(cur.amax_mm_s2))
    {
        "M201"
    } else {
        "M204"
    };
    let (firmware_key, line_of) = match key {
        k if k.starts_with("limits.amax") => {
            if klipper {
                (
                    "printer.max_accel".to_string(),
                    "printer.max_accel".to_string(),
                )
            } else {
                ("M201 / M204 P".to_string(), accel_command.to_string())
            }
        }
        k if k.starts_with("limits.vmax") => {
            if klipper {
                (
                    "printer.max_velocity".to_string(),
                    "printer.max_velocity".to_string(),
                )
            } else {
                ("M203".to_string(), "M203".to_string())
            }
        }
        k if k.starts_with("shaper.") => {
            if klipper {
                let option = match k {
                    "shaper.frequency_hz" => format!("shaper_freq_{axis}"),
                    "shaper.damping_ratio" => format!("damping_ratio_{axis}"),
                    _ => format!("shaper_type_{axis}"),
                };
                let section_key = format!("input_shaper.{option}");
                let line_of = if option.starts_with("shaper_type")
                    && !cur.set_at.contains_key(&section_key)
                {
                    "input_shaper.shaper_type".to_string()
                } else {
                    section_key.clone()
                };
                (section_key, line_of)
            } else {
                ("M593".to_string(), "M593".to_string())
            }
        }
        _ => (String::new(), String::new()),
    };
    let message = format!("axis {axis}: settle cannot run these settings: {message}");
    if firmware_key.is_empty() {
        return Error::input(config, message);
    }
    match cur.set_at.get(&line_of) {
        Some(set) => Error::Input {
            at: Location {
                key: Some(firmware_key),
                ..set.clone()
            },
            message,
        },
        None => Error::input_key(config, firmware_key, message),
    }
}

/// A scenario name from the configuration's file name.
fn name_of(config: &Path) -> String {
    let stem = config
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_default();
    let clean: String = stem
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect();
    format!(
        "{}_import",
        if clean.is_empty() { "config" } else { &clean }
    )
}

/// Import: read the configuration, find the axes the machine has and its modes, write
/// the scenario.
pub fn import(opts: &ImportOptions) -> Result<Imported, Error> {
    let (cur, files) = read_current_files(opts.firmware, &opts.config)?;
    let name = name_of(&opts.config);
    let out = opts
        .out
        .clone()
        .unwrap_or_else(|| opts.config.with_file_name(format!("{name}.toml")));
    // Never onto the configuration, a file it includes or the machine file.
    let mut inputs = settle_files::write::Inputs::of(&files);
    inputs.add(&opts.config);
    if let Some(m) = &opts.machine {
        inputs.add(m);
    }
    inputs.refuse(&out)?;
    settle_files::write::check_target(&out)?;
    if !opts.force && std::fs::symlink_metadata(&out).is_ok() {
        return Err(Error::input(
            "--force",
            format!(
                "{} already exists (an earlier import, or a scenario edited since): pass --force to overwrite it, --out FILE to write elsewhere",
                out.display()
            ),
        ));
    }
    let mut notes = cur.notes.clone();
    // The machine's axes, read here so that its errors name it (and only it).
    let machine_axes = match &opts.machine {
        Some(m) => {
            let text = crate::input::file::read_text(m, crate::input::file::limit::SETTINGS)?;
            let d = crate::input::machine_file::parse_any(&text, m)?;
            Some(match d.form {
                MachineForm::Physical(machine) => machine
                    .axes
                    .iter()
                    .map(|a| a.name.clone())
                    .collect::<Vec<_>>(),
                MachineForm::Modes(axes) => axes.iter().map(|a| a.axis.clone()).collect(),
            })
        }
        None => None,
    };
    let machine = match &opts.machine {
        Some(m) => std::path::absolute(m)
            .map_err(|e| Error::read(m, e))?
            .display()
            .to_string(),
        None => {
            notes.push(format!(
                "no --machine given: the preset `{STAND_IN_PRESET}` stands in for your printer, so the numbers are for it, not for your machine. Measure your modes (`settle identify` on a TEST_RESONANCES or M956 file) and import again with --machine machine.toml"
            ));
            STAND_IN_PRESET.to_string()
        }
    };
    // The axes the machine has, and the first one's strongest mode (the sweep's centre
    // when it has no shaper yet).
    let source = opts.config.display().to_string();
    let mut axes: Vec<&AxisNow> = Vec::new();
    let mut centre_hz = None;
    let mut band = false;
    let mut top: Option<f64> = None;
    for a in &cur.axes {
        let has_axis = machine_axes.as_ref().is_none_or(|m| m.contains(&a.name));
        if !has_axis {
            notes.push(format!(
                "the machine has no axis `{}`: it is not tuned",
                a.name
            ));
            continue;
        }
        let text = scenario_text(&name, &machine, &cur, &[a], 40.0, &source, false, None);
        let probe = out.with_file_name(format!("{name}.probe.toml"));
        // The machine has the axis: a scenario that does not load is the settings' fault
        // (a limit the firmware accepts that settle cannot run), said as such.
        let (_, runs) = crate::expand::parse_runs(&text, &probe)
            .map_err(|e| settings_error(&opts.config, &cur, &a.name, e))?;
        if let Some(run) = runs.first() {
            if centre_hz.is_none() {
                centre_hz = tuning_modes(run)
                    .first()
                    .map(|(f, _)| (f * 10.0).round() / 10.0);
            }
            band |= identified_band(run).is_some();
            if let Some(t) = top_accel(cur.candidates(), run) {
                top = Some(top.map_or(t, |m: f64| m.max(t)));
            }
            axes.push(a);
        }
    }
    if axes.is_empty() {
        return Err(Error::input(
            opts.machine
                .clone()
                .unwrap_or_else(|| PathBuf::from(STAND_IN_PRESET)),
            "the machine has neither an x nor a y axis to tune",
        ));
    }
    let text = scenario_text(
        &name,
        &machine,
        &cur,
        &axes,
        centre_hz.unwrap_or(40.0),
        &source,
        band,
        top,
    );
    // What is written must load.
    crate::expand::parse_runs(&text, &out)?;
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        crate::output::atomic::create_dir(dir)?;
    }
    write_atomic(&out, text.as_bytes())?;
    Ok(Imported {
        axes: axes.iter().map(|a| a.name.clone()).collect(),
        current: cur,
        scenario: text,
        out,
        notes,
    })
}
