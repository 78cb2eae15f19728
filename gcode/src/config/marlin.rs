//! Marlin's settings as its `M503` (Report Settings) prints them, read into the planner's
//! starting configuration.
//!
//! `M503` answers with the G-code that would set every setting again
//! (Marlin/src/module/settings.cpp `MarlinSettings::report`, each command's `M20x_report`
//! in Marlin/src/gcode/config/M200-M205.cpp and M92.cpp, `M593_report` in
//! Marlin/src/gcode/feature/input_shaping/M593.cpp): a heading comment
//! (`echo:; Max feedrates (units/s):`; Marlin 1.x prints its headings without the `; `),
//! then the command (`echo:  M203 X500.00 Y500.00 Z5.00 E25.00`). A terminal copy of
//! that reply is read as it arrives: each line's `echo:`, OctoPrint's `Recv: `, the
//! lines the terminal sent (`Send: M503`, Pronterface's `>>> M503` and `SENDING:M503`),
//! `ok`, comments (`;`, `//`), blank lines and CRLF are dropped.
//!
//! The commands the planner uses are followed exactly as the same commands in a G-code
//! file are ([`crate::job`]'s Marlin rules, the same reader and the same driver): `M203`,
//! `M201`, `M204`, `M205`, `M593` (Marlin's stepper ZV per axis, `marlin:m593`) and `M493`
//! of Marlin's current report (FT_MOTION on or off and its shapers,
//! [`ft_report_is_current`]). `M92` (steps per mm)
//! sets the planner's step counts of X, Y, Z, E, which a G-code file's `M92` does not
//! (settle's G-code reader does not follow it). `M205` prints `J` in a build with
//! junction deviation and `X Y Z E` in one with `CLASSIC_JERK` (M205_report): a reply
//! whose `M205` has jerks and no `J` comes from a classic-jerk build, and the planner
//! follows classic jerk. Every other command of the reply is listed once as read and not
//! used; a value the job's own commands would have refused is an error naming the line.
//!
//! A Prusa-Firmware-Buddy printer (a Marlin derivative) is read from its replies to
//! `M115`, `M503` and `M593` in one log ([`MarlinSettings::parse_prusa`]); such a log
//! read as Marlin's is refused at its first Buddy line.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use settle_planner::firmware::marlin::{
    MarlinConfig, MarlinJerk, PLANNER_STEPS_MULTIPLIER, PrusaModel,
};

use super::budget::Budget;
use super::machine::ConfigNote;
use crate::error::{GcodeError, Location};
use crate::job::driver::{Driver, LimitOutcome};
use crate::job::shapers::ShaperState;
use crate::job::{JobConfig, PlannerConfig, PrusaPrinter, ShaperSetting};
use crate::read::cmd::Check;
use crate::read::dialect::Dialect;
use crate::read::event::{EventKind, Note};
use crate::read::limit_parse::{
    FT_DAMPING, FT_FREQUENCY, FT_OVERSHOOT, FT_SMOOTHING_S, STEPS_PER_MM,
};
use crate::read::limits::LimitChange;
use settle_planner::firmware::Firmware;
use settle_planner::shaper::ShaperType;

/// Marlin's settings from an `M503` reply: the planner's starting configuration and
/// shapers.
#[derive(Debug, Clone)]
pub struct MarlinSettings {
    /// The planner's settings: Marlin's example configuration ([`MarlinConfig::new`])
    /// changed by the reply's `M92`, `M203`, `M201`, `M204` and `M205`.
    pub planner: MarlinConfig,
    /// The `M593` shapers of X, Y, Z (`None`: not shaped).
    pub shapers: [Option<ShaperSetting>; 3],
    /// `M92` as read, steps per mm of X, Y, Z, E (`None` where the reply has none).
    pub steps_per_mm: [Option<f64>; 4],
    /// Whether the reply's `M205` shows a `CLASSIC_JERK` build (jerks, no `J`).
    pub classic_jerk: bool,
    /// The planner commands followed, in order (`M203`, `M201`, ...), with their lines.
    pub followed: Vec<(u64, &'static str)>,
    /// The file read.
    pub files: Vec<PathBuf>,
    /// What the reader noted: commands read and not used, values Marlin keeps.
    pub notes: Vec<ConfigNote>,
    /// Prusa-Firmware-Buddy ([`MarlinSettings::read_prusa`]): the printer, from the
    /// `M115` reply's `MACHINE_TYPE` (its line) or the MK4 when the log has none.
    pub prusa: Option<PrusaPrinter>,
}

impl MarlinSettings {
    /// What a Marlin printer starts a file with, from this reply: the planner's `M92`,
    /// `M203`, `M201`, `M204` and `M205` settings and the `M593` shapers. Everything else
    /// is [`JobConfig::defaults`]'.
    pub fn job_config(&self) -> Result<JobConfig, GcodeError> {
        self.planner
            .validate()
            .map_err(|e| GcodeError::JobSetting {
                key: "M503 settings",
                reason: e.to_string(),
            })?;
        let mut cfg = match &self.prusa {
            Some(printer) => JobConfig::prusa(printer.clone())?,
            None => JobConfig::defaults(Firmware::Marlin)?,
        };
        cfg.planner = match self.prusa {
            Some(_) => PlannerConfig::Prusa(self.planner),
            None => PlannerConfig::Marlin(self.planner),
        };
        cfg.shapers = self.shapers;
        Ok(cfg)
    }

    /// The firmware the settings are for: Marlin, or Prusa-Firmware-Buddy.
    pub fn firmware(&self) -> Firmware {
        if self.prusa.is_some() {
            Firmware::Prusa
        } else {
            Firmware::Marlin
        }
    }
}

/// The commands of an `M503` reply the planner follows.
const PLANNER_COMMANDS: [&str; 6] = ["M92", "M201", "M203", "M204", "M205", "M593"];

/// Commands of a RepRapFirmware config.g that Marlin does not have (no case for them in
/// Marlin's dispatcher, `GcodeSuite::process_parsed_command`, Marlin/src/gcode/gcode.cpp),
/// so that no `M503` reply holds one: a file with one is a config.g, whose `M203` is in
/// mm/min where Marlin's is in mm/s ([`rrf_only`]).
const RRF_ONLY: [(&str, &str); 8] = [
    ("M98", "call a macro"),
    ("M550", "machine name"),
    ("M551", "password"),
    ("M558", "Z probe type"),
    ("M574", "endstops"),
    ("M584", "drive mapping"),
    ("M586", "network protocols"),
    ("M950", "create a heater, fan, GPIO or servo port"),
];

/// What a RepRapFirmware-only command ([`RRF_ONLY`]) does; `None` for any other.
fn rrf_only(command: &str) -> Option<&'static str> {
    RRF_ONLY
        .iter()
        .find(|(c, _)| *c == command)
        .map(|(_, what)| *what)
}

/// What settle does not model, for the commands `M503` prints (settings.cpp).
fn unused_reason(command: &str) -> Option<&'static str> {
    Some(match command {
        "G21" => "units (millimetres)",
        "M149" => "temperature units",
        "M86" => "hotend idle timeout",
        "M104" => "hotend temperature (auto temperature)",
        "M210" => "homing feedrates",
        "M255" | "M256" => "display",
        "M306" => "model predictive temperature control",
        "M401" => "probe deployment (BLTouch high speed mode)",
        "M200" => "filament diameter (volumetric extrusion)",
        "M206" => "home offset",
        "M207" | "M208" | "M209" => "firmware retraction",
        "M145" => "material preheat presets",
        "M217" => "tool change",
        "M218" => "hotend offsets",
        "M281" => "servo angles",
        "M301" | "M304" | "M309" => "PID tuning",
        "M305" => "thermistor",
        "M412" => "filament runout sensor",
        "M413" => "power-loss recovery",
        "M414" => "language",
        "M420" | "M421" | "G29" => "bed leveling",
        "M425" => "backlash compensation",
        "M493" | "M494" => "FT_MOTION (write its M493/M494 at the top of the G-code to follow it)",
        "M540" => "endstop abort",
        "M552" | "M553" | "M554" => "network",
        "M569" => "driver chopper mode",
        "M575" => "serial baud rate",
        "M592" => "nonlinear extrusion",
        "M603" => "filament change lengths",
        "M665" | "M666" => "delta or dual-endstop geometry",
        "M672" => "Duet Smart Effector",
        "M710" => "controller fan",
        "M851" => "probe offset",
        "M852" => "skew correction",
        "M871" => "probe temperature compensation",
        "M900" => "linear advance",
        "M906" => "stepper currents",
        "M913" => "hybrid threshold",
        "M914" => "sensorless homing",
        "M919" => "driver chopper timing",
        "M7219" => "MAX7219 display",
        _ => return None,
    })
}

/// The text of one line of a terminal copy that Marlin printed, without what the terminal
/// added; `None` for a line the terminal sent or an `ok`.
fn reply_text(line: &str) -> Option<&str> {
    let mut t = line.trim();
    loop {
        let before = t;
        for sent in ["Send:", "SENDING:", ">>>"] {
            if t.starts_with(sent) {
                return None;
            }
        }
        for prefix in ["Recv:", "echo:"] {
            if let Some(rest) = t.strip_prefix(prefix) {
                t = rest.trim_start();
            }
        }
        if t == before {
            break;
        }
    }
    if t == "ok" || t.starts_with("ok ") {
        return None;
    }
    Some(t)
}

/// The command a reply line holds (`M92`, `G21`, a firmware's own `C100`): a letter and
/// its number, upper case, at the line's start; `None` for a heading, a comment or a
/// message.
fn command_of(text: &str) -> Option<String> {
    let b = text.as_bytes();
    let letter = b.first()?.to_ascii_uppercase();
    if !letter.is_ascii_uppercase() {
        return None;
    }
    let digits = b[1..].iter().take_while(|c| c.is_ascii_digit()).count();
    if digits == 0 {
        return None;
    }
    let end = 1 + digits;
    if b.get(end).is_some_and(|c| c.is_ascii_alphabetic()) {
        return None; // a word such as `M503abc` or a heading
    }
    let number: u32 = text[1..end].parse().ok()?;
    Some(format!("{}{number}", letter as char))
}

/// `M92`'s values (X, Y, Z, E): steps per mm within [`STEPS_PER_MM`], as a job's `M92`; `T` (an extruder of a
/// `DISTINCT_E_FACTORS` build) is read, and only the first extruder's `E` kept.
fn steps_words(text: &str, at: &Location, steps: &mut [Option<f64>; 4]) -> Result<(), GcodeError> {
    let code = text.split(';').next().unwrap_or("");
    let mut words = code.split_whitespace();
    words.next(); // M92
    let mut extruder = 0.0;
    let mut values = Vec::new();
    for w in words {
        let (letter, value) = w.split_at(w.chars().next().map_or(0, char::len_utf8));
        let bad = |allowed: &str| GcodeError::ConfigValue {
            at: at.clone(),
            section: "M92".into(),
            key: letter.to_string(),
            value: value.into(),
            allowed: allowed.into(),
        };
        let v: f64 = value
            .parse()
            .ok()
            .filter(|v: &f64| v.is_finite())
            .ok_or_else(|| bad("a number"))?;
        match letter.to_ascii_uppercase().as_str() {
            "T" => extruder = v,
            l @ ("X" | "Y" | "Z" | "E") => {
                if !(STEPS_PER_MM.ok)(v) {
                    return Err(bad(STEPS_PER_MM.allowed));
                }
                values.push((l.as_bytes()[0], v));
            }
            _ => return Err(bad("X Y Z E (steps per mm), T (extruder)")),
        }
    }
    for (l, v) in values {
        let i = match l {
            b'X' => 0,
            b'Y' => 1,
            b'Z' => 2,
            _ if extruder == 0.0 => 3,
            _ => continue,
        };
        steps[i] = Some(v);
    }
    Ok(())
}

/// An `M494` line of the reply, or an `M493` of an older report with FT_MOTION off: not
/// followed ([`ft_report_is_current`]), but the words Marlin's commands bound are held to what the
/// job's take, so a value Marlin would refuse is named at its line: `M493`'s frequency
/// `A`, damping `I` and tolerance `Q` ([`FT_FREQUENCY`], [`FT_DAMPING`], 0 to 1), `M494`'s
/// trajectory `T` (0 to 2), overshoot `O` ([`FT_OVERSHOOT`]) and smoothing times `X Y Z E`
/// ([`FT_SMOOTHING_S`]). The other words differ between Marlin's versions (2.1.2
/// reported `M493 S<mode> P K`) and are not read.
fn ft_words(command: &str, text: &str, at: &Location) -> Result<(), GcodeError> {
    const TRAJECTORY: Check = Check {
        ok: |v| v == 0.0 || v == 1.0 || v == 2.0,
        allowed: "0, 1 or 2 (TRAPEZOIDAL, POLY5, POLY6): Marlin's M494 refuses another trajectory type (Marlin/src/gcode/feature/ft_motion/M494.cpp)",
    };
    let code = text.split(';').next().unwrap_or("");
    for w in code.split_whitespace().skip(1) {
        let (letter, value) = w.split_at(w.chars().next().map_or(0, char::len_utf8));
        let check = match (command, letter.to_ascii_uppercase().as_str()) {
            ("M493", "A") => FT_FREQUENCY,
            ("M493", "I") => FT_DAMPING,
            ("M493", "Q") => crate::read::cmd::FRACTION,
            ("M494", "T") => TRAJECTORY,
            ("M494", "O") => FT_OVERSHOOT,
            ("M494", "X" | "Y" | "Z" | "E") => FT_SMOOTHING_S,
            _ => continue,
        };
        if !value.parse::<f64>().is_ok_and(|v| (check.ok)(v)) {
            return Err(GcodeError::ConfigValue {
                at: at.clone(),
                section: command.into(),
                key: letter.to_string(),
                value: value.into(),
                allowed: check.allowed.into(),
            });
        }
    }
    Ok(())
}

/// Whether the reply's `M493` line `text` at `at` is one of Marlin's current report
/// (`GcodeSuite::M493_report`, Marlin/src/gcode/feature/ft_motion/M493.cpp:
/// `M493 S<on> [D<mode>] H<sync>`, then per shaped axis `M493 X C<shaper> A<Hz> [F<k>]
/// I<zeta> [Q<vtol>]`), which is followed as the same line of a job is (FT_MOTION on or
/// off, and each axis's shaper). Earlier releases printed one line, `M493 S<mode> A<x Hz>
/// B<y Hz> ... P<0|1> K<gain>` (2.1.3 also `G`, `L`, `O`), which does not say which
/// shaper FT_MOTION runs on each axis: with `S0` (FT_MOTION off, the stepper's `M593`
/// shaping runs) it is noted (`Ok(false)`); with FT_MOTION on it is refused, naming the
/// line.
fn ft_report_is_current(text: &str, at: &Location) -> Result<bool, GcodeError> {
    let code = text.split(';').next().unwrap_or("");
    let words: Vec<&str> = code.split_whitespace().skip(1).collect();
    let letter = |w: &str| w.chars().next().map(|c| c.to_ascii_uppercase());
    let older = words
        .iter()
        .any(|w| letter(w).is_some_and(|l| "BGKLOP".contains(l)));
    if !older {
        return Ok(true);
    }
    let mode = words
        .iter()
        .find(|w| letter(w) == Some('S'))
        .map(|w| &w[1..]);
    if mode.and_then(|m| m.parse::<f64>().ok()) == Some(0.0) {
        return Ok(false);
    }
    Err(GcodeError::ConfigValue {
        at: at.clone(),
        section: "M493".into(),
        key: "S".into(),
        value: mode.unwrap_or("").to_string().into(),
        allowed: "0 in this older report (`M493 S<mode> A B ... P K`), which does not say which shaper FT_MOTION runs on each axis: with FT_MOTION on, Marlin's stepper shaping (M593) does not run (`Stepper::isr`, Marlin/src/module/stepper.cpp) and settle cannot tell what does; send `M493` with no parameters and write its shapers as `M493 X C<shaper> A<Hz> I<zeta>` lines (Marlin's current M503 report) in place of this one".into(),
    })
}

/// The note for the shapers a reply sets that do not run: `M593`'s while FT_MOTION is on
/// (`Stepper::isr`, Marlin/src/module/stepper.cpp, skips `shaping_isr()` while
/// `ftMotion.cfg.active`), FT_MOTION's while it is off; with the line of the command
/// that set them.
fn bypassed_note(shapers: &ShaperState, followed: &[(u64, &'static str)]) -> Option<(u64, String)> {
    let (on, idle) = shapers.marlin_idle()?;
    if idle.iter().all(Option::is_none) {
        return None;
    }
    Some(if on {
        (
            followed_line(followed, "M593"),
            "M593: not in force, FT_MOTION is on (M493 S1) and Marlin's stepper does not run its input shaping then (`Stepper::isr` skips `shaping_isr()`, Marlin/src/module/stepper.cpp); the shapers read are FT_MOTION's. settle carries only the shapers in force: a job that turns FT_MOTION off (M493 S0) runs unshaped here, where Marlin would run this M593 again".to_string(),
        )
    } else {
        (
            followed_line(followed, "M493"),
            "M493: FT_MOTION is off (M493 S0), so its shapers do not run; the shapers read are M593's. settle carries only the shapers in force: a job that turns FT_MOTION on (M493 S1) runs without these FT_MOTION shapers here, where Marlin would run them".to_string(),
        )
    })
}

impl MarlinSettings {
    /// Reads the `M503` reply at `path` (settle-files' reader: a regular file of at most
    /// [`settle_files::limit::FIRMWARE_CONFIG`]).
    pub fn read(path: impl AsRef<Path>) -> Result<Self, GcodeError> {
        let path = path.as_ref();
        let text = Budget::new().main(path)?;
        Self::parse(&text, path)
    }

    /// Reads `text` as the `M503` reply at `path` (which names it in errors).
    pub fn parse(text: &str, path: impl AsRef<Path>) -> Result<Self, GcodeError> {
        Self::parse_for(text, path.as_ref(), false)
    }

    /// Reads the terminal log of a Prusa-Firmware-Buddy printer at `path`
    /// ([`MarlinSettings::parse_prusa`]).
    pub fn read_prusa(path: impl AsRef<Path>) -> Result<Self, GcodeError> {
        let path = path.as_ref();
        let text = Budget::new().main(path)?;
        Self::parse_prusa(&text, path)
    }

    /// Reads `text` as a Prusa-Firmware-Buddy printer's replies to `M115`, `M503` and
    /// `M593` (the module doc's terminal rules): the printer from `M115`'s
    /// `MACHINE_TYPE:Prusa-<name>` (src/marlin_stubs/host/M115.cpp; the MK4 without it,
    /// noted), `M503` as Marlin's over that printer's settings (Buddy's `M92` reports
    /// steps per mm, `axis_steps_per_mm` (lib/Marlin/Marlin/src/gcode/config/M92.cpp), and
    /// its planner counts quarter steps, `axis_msteps_per_mm`, `PLANNER_STEPS_MULTIPLIER`
    /// times as many (lib/Marlin/Marlin/src/module/planner.h): settle plans the latter), and the shapers from the `M593`
    /// reply, which `M503` does not print (lib/Marlin/Marlin/src/gcode/feature/input_shaper/
    /// M593.cpp, `dump_current_config`): `axis X type=MZV freq=50.700001 damp=0.100000
    /// vr=20.000000` is followed as `M593 X T2 F50.700001 D0.100000 R20.000000`, `axis Z
    /// disabled` as `M593 Z F0`. A log without the `M593` reply of X and Y is refused: the
    /// printer's shapers live in its EEPROM and nothing else reports them.
    pub fn parse_prusa(text: &str, path: impl AsRef<Path>) -> Result<Self, GcodeError> {
        Self::parse_for(text, path.as_ref(), true)
    }

    fn parse_for(text: &str, path: &Path, prusa: bool) -> Result<Self, GcodeError> {
        let source: Arc<str> = Arc::from(path.display().to_string());
        let at = |line: u64| Location {
            source_name: source.clone(),
            line,
            column: None,
        };
        let mut notes = Vec::new();
        let mut unused: BTreeSet<String> = BTreeSet::new();
        let mut steps = [None; 4];
        let mut classic_jerk = false;
        let mut any = false;
        // The planner's lines, each on its own line number; the rest blank.
        let mut kept: Vec<std::borrow::Cow<'_, str>> = Vec::new();
        let mut printer: Option<PrusaPrinter> = None;
        let mut prusa_axes = [false; 3];
        let mut prusa_off = [None; 3];
        for (i, raw) in text.lines().enumerate() {
            let line = i as u64 + 1;
            if prusa && let Some(t) = reply_text(raw) {
                match prusa_reply(t, &at(line))? {
                    PrusaReply::Printer(p) => {
                        // Two M115 replies naming different printers: not one printer's log.
                        if let Some(first) = &printer
                            && first.named_at.as_ref().map(|(_, n)| n)
                                != p.named_at.as_ref().map(|(_, n)| n)
                        {
                            let (first_line, first_name) =
                                first.named_at.clone().unwrap_or_default();
                            return Err(GcodeError::ConfigValue {
                                at: at(line),
                                section: "M115".into(),
                                key: "MACHINE_TYPE".into(),
                                value: format!(
                                    "Prusa-{}",
                                    p.named_at.map(|(_, n)| n).unwrap_or_default()
                                )
                                .into(),
                                allowed: format!(
                                    "Prusa-{first_name}, the printer line {first_line} names: one printer's replies per log"
                                )
                                .into(),
                            });
                        }
                        printer.get_or_insert(p);
                        kept.push("".into());
                        continue;
                    }
                    PrusaReply::Axis(axis, m593) => {
                        any = true;
                        prusa_axes[axis] = true;
                        prusa_off[axis] = m593.ends_with(" F0").then_some(line);
                        kept.push(m593.into());
                        continue;
                    }
                    PrusaReply::Note(text) => {
                        notes.push(ConfigNote::at(at(line), text));
                        kept.push("".into());
                        continue;
                    }
                    PrusaReply::Other => {}
                }
            } else if let Some(t) = reply_text(raw)
                && (t.contains("FIRMWARE_NAME:Prusa-Firmware-Buddy")
                    || (t.starts_with("axis ") && t.contains(" type=")))
            {
                return Err(GcodeError::ConfigSyntax {
                    at: at(line),
                    what: "a Prusa-Firmware-Buddy reply (M115's or M593's): read it as a Prusa's (settle import prusa, settle gcode --firmware prusa --config), whose M593 Marlin's does not share".into(),
                });
            }
            let keep = match reply_text(raw) {
                Some(t) if !t.starts_with(';') && !t.starts_with("//") => match command_of(t) {
                    Some(c) if PLANNER_COMMANDS.contains(&c.as_str()) => {
                        any = true;
                        if c == "M92" {
                            steps_words(t, &at(line), &mut steps)?;
                            ""
                        } else {
                            if c == "M205" {
                                let code = t.split(';').next().unwrap_or("").to_uppercase();
                                let has = |l: char| {
                                    code.split_whitespace().skip(1).any(|w| w.starts_with(l))
                                };
                                classic_jerk = has('X') && !has('J');
                            }
                            t
                        }
                    }
                    Some(c) if c == "G20" => {
                        return Err(GcodeError::ConfigSyntax {
                                at: at(line),
                                what: "G20: the report's values are in inches (a Marlin built with INCH_MODE_SUPPORT); send G21, then M503, and save that reply".into(),
                            });
                    }
                    Some(c) if !prusa && c == "M493" && ft_report_is_current(t, &at(line))? => t,
                    Some(c) if let Some(what) = rrf_only(&c) => {
                        return Err(GcodeError::ConfigSyntax {
                            at: at(line),
                            what: format!(
                                "{c} ({what}) is a RepRapFirmware command that Marlin does not have, so no M503 reply holds it: this is a RepRapFirmware config.g, whose M203 is in mm/min where Marlin's is in mm/s; read it as RepRapFirmware's (settle import rrf, settle gcode --firmware rrf --config)"
                            ),
                        });
                    }
                    Some(c) => {
                        if c == "M493" || c == "M494" {
                            ft_words(&c, t, &at(line))?;
                        }
                        if unused.insert(c.clone()) {
                            let text = match unused_reason(&c) {
                                Some(what) => {
                                    format!("{c} ({what}): read, not used by settle's planner")
                                }
                                None => format!(
                                    "{c}: not a command Marlin's M503 report prints that settle knows; not used"
                                ),
                            };
                            notes.push(ConfigNote::at(at(line), text));
                        }
                        ""
                    }
                    None => "",
                },
                _ => "",
            };
            kept.push(keep.into());
        }
        if prusa && !(prusa_axes[0] && prusa_axes[1]) {
            return Err(GcodeError::ConfigSyntax {
                at: at(1),
                what: "no M593 reply for X and Y (`axis X type=... freq=...`): Prusa-Firmware-Buddy keeps its input shapers in EEPROM and its M503 does not report them; send M593 with no arguments too and save its reply with M503's".into(),
            });
        }
        if let [Some(line), Some(_), _] = prusa_off {
            // Buddy reloads the saved shapers at every print's end (`finalize_print` calls
            // `input_shaper::init`, src/common/marlin_server.cpp) and at boot: off in a reply
            // sent between jobs is the printer's saved state.
            notes.push(ConfigNote::at(
                at(line),
                "M593: the shapers of X and Y are off. Buddy reloads its saved shapers at every print's end (finalize_print, src/common/marlin_server.cpp) and at boot, so between jobs this is the printer's saved setting; a reply sent during a job shows what that job's G-code set (PrusaSlicer's MK4, MK4S, MK3.9 and MK3.5 end G-code turns them off with `M593 X T2 F0`)".to_string(),
            ));
        }
        if !any {
            return Err(GcodeError::ConfigSyntax {
                at: at(1),
                what: "not an M503 report: no M92, M201, M203, M204, M205 or M593 line (send M503 to the printer and save its reply)".into(),
            });
        }
        let printer = prusa.then(|| {
            printer.unwrap_or_else(|| {
                notes.push(ConfigNote::at(
                    at(1),
                    "no M115 reply (`MACHINE_TYPE:Prusa-<printer>`): the MK4's settings stand for what the replies do not give; send M115 too and save its reply to read the printer's own".to_string(),
                ));
                PrusaPrinter::unnamed()
            })
        });
        let (mut planner, steps_scale) = match &printer {
            Some(p) => (p.model.config(), PLANNER_STEPS_MULTIPLIER),
            None => (MarlinConfig::new(), 1.0),
        };
        for (i, s) in steps.iter().enumerate() {
            if let Some(s) = s {
                planner.steps_per_m[i] = s * steps_scale * 1e3;
            }
        }
        if classic_jerk && printer.is_none() {
            // Marlin's Configuration.h defaults (DEFAULT_XJERK ... DEFAULT_EJERK), the
            // reply's own values set below.
            planner.jerk = MarlinJerk::Classic {
                max_jerk_m_s: [10e-3, 10e-3, 0.3e-3, 5e-3],
                travel_extra_xy_jerk_m_s: 0.0,
            };
        }
        let plan_error =
            |line: u64, command: &str, e: settle_planner::PlanError| GcodeError::Plan {
                at: at(line),
                command: command.to_string(),
                source: Box::new(e),
            };
        let (config, firmware, dialect) = match &printer {
            Some(_) => (
                PlannerConfig::Prusa(planner),
                Firmware::Prusa,
                Dialect::Prusa,
            ),
            None => (
                PlannerConfig::Marlin(planner),
                Firmware::Marlin,
                Dialect::Marlin,
            ),
        };
        let mut driver = Driver::new(&config)
            .map_err(|e| plan_error(1, "M92", e))?
            .expect("Marlin's planner is a firmware's");
        let mut shapers = ShaperState::new(firmware, &[None; 3]);
        if let Some(p) = &printer {
            shapers = shapers.with_prusa_model(p.model);
        }
        let mut followed = Vec::new();
        let text = kept.join("\n");
        for event in super::located_events(&text, dialect, &source) {
            // A word the job's command refuses, named as the reply's setting.
            let (at, kind) = event.map_err(super::out_of_range_as_setting)?;
            let change = match kind {
                EventKind::Limits(c) => c,
                EventKind::Note(Note::IgnoredByFirmware { command, reason }) => {
                    notes.push(ConfigNote::at(at, format!("{command}: {reason}")));
                    continue;
                }
                _ => continue,
            };
            let command = change.command_name();
            followed.push((at.line, command));
            if let (
                Some(p),
                LimitChange::PrusaInputShaping {
                    frequency_hz: Some(f),
                    ..
                },
            ) = (&printer, &change)
            {
                let max = p.model.shaper_max_hz();
                if *f != 0.0 && !(10.0..=max).contains(f) {
                    return Err(GcodeError::ConfigValue {
                        at,
                        section: "M593".into(),
                        key: "freq".into(),
                        value: f.to_string().into(),
                        allowed: format!(
                            "10 to {max} Hz, what the {} runs (clamp_frequency_to_safe_values): a reply of another printer? Save M115's reply with it",
                            p.model.name()
                        )
                        .into(),
                    });
                }
            }
            if matches!(
                change,
                LimitChange::MarlinInputShaping { .. }
                    | LimitChange::PrusaInputShaping { .. }
                    | LimitChange::FtMotion { .. }
            ) {
                shapers
                    .apply(&change)
                    .map_err(|_| GcodeError::ConfigSyntax {
                        at: at.clone(),
                        what: format!("{command}: not followed"),
                    })?;
                continue;
            }
            let mut why = Vec::new();
            let outcome = driver
                .apply(&change, &mut why)
                .map_err(|e| plan_error(at.line, command, e))?;
            for w in why {
                notes.push(ConfigNote::at(at.clone(), format!("{command}: {w}")));
            }
            if let LimitOutcome::Ignored(w) = outcome {
                notes.push(ConfigNote::at(at.clone(), format!("{command}: {w}")));
            }
        }
        let Driver::Marlin(p) = &driver else {
            unreachable!("a Marlin driver")
        };
        let settings = shapers.settings();
        for s in settings.iter().flatten() {
            // The shaper in force is `M593`'s stepper ZV or FT_MOTION's `M493` one.
            let command = if s.shaper_type == ShaperType::MarlinM593 {
                "M593"
            } else {
                "M493"
            };
            s.build()
                .map_err(|e| plan_error(followed_line(&followed, command), command, e))?;
        }
        if let Some(note) = bypassed_note(&shapers, &followed) {
            notes.push(ConfigNote::at(at(note.0), note.1));
        }
        Ok(Self {
            planner: *p.config(),
            shapers: settings,
            steps_per_mm: steps,
            classic_jerk,
            followed,
            files: vec![path.to_path_buf()],
            notes,
            prusa: printer,
        })
    }
}

/// What a line of a Prusa-Firmware-Buddy log holds besides Marlin's `M503` reply.
enum PrusaReply {
    /// `M115`'s `MACHINE_TYPE:Prusa-<name>`: the printer.
    Printer(PrusaPrinter),
    /// An `M593` reply line of axis 0, 1 or 2 (X, Y, Z), as the `M593` that sets it.
    Axis(usize, String),
    /// A line read and not used, with why.
    Note(String),
    /// Anything else (Marlin's rules apply).
    Other,
}

/// The Prusa-Firmware-Buddy shaper names of `M593 T0`-`T6` (`filter_names`,
/// lib/Marlin/Marlin/src/feature/input_shaper/input_shaper_config.hpp).
const PRUSA_TYPES: [&str; 7] = ["ZV", "ZVD", "MZV", "EI", "EI_2HUMP", "EI_3HUMP", "Null"];

/// A reply line `text` (terminal prefixes gone) of a Prusa-Firmware-Buddy log at `at`
/// ([`MarlinSettings::parse_prusa`]).
fn prusa_reply(text: &str, at: &Location) -> Result<PrusaReply, GcodeError> {
    let bad = |key: &str, value: &str, allowed: String| GcodeError::ConfigValue {
        at: at.clone(),
        section: "M593".into(),
        key: key.to_string(),
        value: value.to_string().into(),
        allowed: allowed.into(),
    };
    if let Some(i) = text.find("MACHINE_TYPE:Prusa-") {
        let name = text[i + "MACHINE_TYPE:Prusa-".len()..]
            .split_whitespace()
            .next()
            .unwrap_or("");
        return match PrusaModel::from_printer_name(name) {
            Some(model) => Ok(PrusaReply::Printer(PrusaPrinter {
                model,
                named_at: Some((at.line, name.to_string())),
            })),
            None => Err(GcodeError::ConfigValue {
                at: at.clone(),
                section: "M115".into(),
                key: "MACHINE_TYPE".into(),
                value: format!("Prusa-{name}").into(),
                allowed: format!(
                    "a printer settle has Prusa-Firmware-Buddy settings for: {}",
                    PrusaModel::printer_names()
                )
                .into(),
            }),
        };
    }
    if text.starts_with("weight_adjust y") || text == "weight adjust y disabled" {
        return Ok(PrusaReply::Note(format!(
            "M593 `{text}`: read, not used (Buddy lowers Y's shaper frequency as the bed's load set by M74 grows; settle plans the unloaded bed, and a reply sent during a job after its M74 shows Y's frequency already lowered)"
        )));
    }
    let mut words = text.split_whitespace();
    let (Some("axis"), Some(letter)) = (words.next(), words.next()) else {
        return Ok(PrusaReply::Other);
    };
    let Some(axis) = ["X", "Y", "Z"].iter().position(|a| *a == letter) else {
        return Err(bad("axis", letter, "X, Y or Z".into()));
    };
    let rest: Vec<&str> = words.collect();
    if rest == ["disabled"] {
        return Ok(PrusaReply::Axis(axis, format!("M593 {letter} F0")));
    }
    let mut values = [None; 4];
    for w in &rest {
        let (key, value) = w.split_once('=').unwrap_or((w, ""));
        let slot = ["type", "freq", "damp", "vr"]
            .iter()
            .position(|k| *k == key);
        let Some(slot) = slot else {
            return Err(bad(
                key,
                value,
                "type, freq, damp, vr (M593's reply)".into(),
            ));
        };
        values[slot] = Some(value);
    }
    let [Some(kind), Some(freq), Some(damp), Some(vr)] = values else {
        return Err(bad(
            "axis",
            text,
            "`axis <X|Y|Z> type=<T> freq=<Hz> damp=<ratio> vr=<reduction>` or `axis <X|Y|Z> disabled`".into(),
        ));
    };
    let Some(code) = PRUSA_TYPES.iter().position(|t| *t == kind) else {
        return Err(bad("type", kind, PRUSA_TYPES.join(", ")));
    };
    let mut numbers = [0.0; 3];
    for (i, (key, v)) in [("freq", freq), ("damp", damp), ("vr", vr)]
        .into_iter()
        .enumerate()
    {
        numbers[i] = v
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| bad(key, v, "a finite number".into()))?;
    }
    let [_, damping, reduction] = numbers;
    let null = PRUSA_TYPES[code] == "Null";
    // input_shaper::get halts the printer on a damping ratio of 1 or more for every type
    // but Null (lib/Marlin/Marlin/src/feature/input_shaper/input_shaper.cpp), so no running
    // printer reports one.
    if !null && !(0.0..1.0).contains(&damping) {
        return Err(bad(
            "damp",
            damp,
            "0 to below 1 (Buddy halts at 1 or more, input_shaper::get)".into(),
        ));
    }
    // The EI family's tolerance is 1/vr (input_shaper.cpp); the other types do not read
    // vr, whose 0 an axis shows when `M593 Z F<Hz>` started it from `axis_z_default`
    // (input_shaper_config.hpp, M593.cpp `M593_set_axis_config`).
    let ei = (3..=5).contains(&code);
    if ei && reduction <= 0.0 {
        return Err(bad(
            "vr",
            vr,
            "above 0 for EI, EI_2HUMP and EI_3HUMP (their tolerance is 1/vr)".into(),
        ));
    }
    let r = if reduction > 0.0 {
        format!(" R{vr}")
    } else {
        String::new()
    };
    Ok(PrusaReply::Axis(
        axis,
        format!("M593 {letter} T{code} F{freq} D{damp}{r}"),
    ))
}

/// The line of the last `command` followed (1 when none).
fn followed_line(followed: &[(u64, &'static str)], command: &str) -> u64 {
    followed
        .iter()
        .rev()
        .find(|(_, c)| *c == command)
        .map_or(1, |(l, _)| *l)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The reply of a Marlin 2.1 build with junction deviation and input shaping, as
    /// M503 prints it (settings.cpp, M200-M205.cpp, M92.cpp, M593.cpp).
    const REPLY: &str = "echo:; Linear Units:\n\
        echo:  G21 ; (mm)\n\
        echo:; Steps per unit:\n\
        echo:  M92 X80.00 Y80.00 Z400.00 E93.00\n\
        echo:; Max feedrates (units/s):\n\
        echo:  M203 X500.00 Y450.00 Z5.00 E25.00\n\
        echo:; Max Acceleration (units/s2):\n\
        echo:  M201 X1500.00 Y1400.00 Z100.00 E5000.00\n\
        echo:; Acceleration (units/s2) (P<print-accel> R<retract-accel> T<travel-accel>):\n\
        echo:  M204 P1200.00 R1500.00 T2000.00\n\
        echo:; Advanced (B<min_segment_time_us> S<min_feedrate> T<min_travel_feedrate> J<junc_dev>):\n\
        echo:  M205 B20000.00 S0.00 T0.00 J0.08\n\
        echo:; PID settings:\n\
        echo:  M301 P21.73 I1.54 D76.55\n\
        echo:; Input Shaping:\n\
        echo:  M593 X F40.00 D0.15\n\
        echo:  M593 Y F35.50 D0.10\n\
        echo:; Stepper driver current:\n\
        echo:  M906 X580 Y580 Z580\n\
        echo:  M906 I1 Z580\n";

    fn check(s: &MarlinSettings, what: &str) {
        let p = &s.planner;
        // In mm units as the reply states them (the planner keeps metres).
        let mm = |v: [f64; 4]| v.map(|x| x * 1e-3);
        assert_eq!(p.steps_per_m, [80e3, 80e3, 400e3, 93e3], "{what}");
        assert_eq!(p.max_feedrate_m_s, mm([500.0, 450.0, 5.0, 25.0]), "{what}");
        assert_eq!(
            p.max_accel_m_s2,
            mm([1500.0, 1400.0, 100.0, 5000.0]),
            "{what}"
        );
        assert_eq!(
            [
                p.print_accel_m_s2,
                p.retract_accel_m_s2,
                p.travel_accel_m_s2,
                0.0
            ],
            mm([1200.0, 1500.0, 2000.0, 0.0]),
            "{what}"
        );
        assert_eq!(p.min_segment_time_s, 0.02, "{what}");
        assert_eq!((p.min_feedrate_m_s, p.min_travel_feedrate_m_s), (0.0, 0.0));
        let MarlinJerk::JunctionDeviation { deviation_m, .. } = p.jerk else {
            panic!("{what}: junction deviation expected")
        };
        assert_eq!(deviation_m, 0.08 * 1e-3, "{what}");
        assert!(!s.classic_jerk, "{what}");
        let x = s.shapers[0].expect("X shaped");
        let y = s.shapers[1].expect("Y shaped");
        assert_eq!(
            (x.shaper_type, x.frequency_hz, x.damping_ratio),
            (ShaperType::MarlinM593, 40.0, 0.15),
            "{what}"
        );
        assert_eq!((y.frequency_hz, y.damping_ratio), (35.5, 0.1), "{what}");
        assert_eq!(s.shapers[2], None, "{what}");
        let commands: Vec<&str> = s.followed.iter().map(|(_, c)| *c).collect();
        assert_eq!(
            commands,
            ["M203", "M201", "M204", "M205", "M593", "M593"],
            "{what}"
        );
        // G21, M301, M906: each listed once, M906's second line not again.
        let notes: Vec<String> = s.notes.iter().map(|n| n.text.clone()).collect();
        assert_eq!(notes.len(), 3, "{what}: {notes:?}");
        assert!(notes[2].starts_with("M906 (stepper currents)"), "{notes:?}");
    }

    /// The reply as Marlin prints it, and as each terminal shows it: OctoPrint's
    /// (`Send:`/`Recv:`, CRLF), Pronterface's (`>>>`, `SENDING:`), a bare copy with `//`
    /// comments and `ok`, all give the same settings.
    #[test]
    fn a_reply_reads_the_same_from_every_terminal() {
        let lines: Vec<&str> = REPLY.lines().collect();
        let octoprint = std::iter::once("Send: M503".to_string())
            .chain(lines.iter().map(|l| format!("Recv: {l}")))
            .chain(["Recv: ok".to_string()])
            .collect::<Vec<_>>()
            .join("\r\n");
        let pronterface = [">>> M503", "SENDING:M503"]
            .into_iter()
            .map(str::to_string)
            .chain(lines.iter().map(|l| (*l).to_string()))
            .chain(["ok".to_string()])
            .collect::<Vec<_>>()
            .join("\n");
        let bare = std::iter::once("// copied from the printer".to_string())
            .chain(
                lines
                    .iter()
                    .map(|l| l.trim_start_matches("echo:").to_string()),
            )
            .chain(["".to_string(), "ok".to_string()])
            .collect::<Vec<_>>()
            .join("\n");
        for (what, text) in [
            ("marlin", REPLY.to_string()),
            ("octoprint", octoprint),
            ("pronterface", pronterface),
            ("bare", bare),
        ] {
            let s = MarlinSettings::parse(&text, "m503.txt").expect(what);
            check(&s, what);
        }
    }

    /// Marlin 1.1's reply (headings without `; `, `M204 P R T`, `M205` with classic jerks
    /// and no `J`): the planner follows classic jerk with the reply's values.
    #[test]
    fn a_classic_jerk_reply_sets_classic_jerk() {
        let text = "echo:Steps per unit:\n\
                    echo:  M92 X100.00 Y100.00 Z400.00 E95.00\n\
                    echo:Maximum feedrates (units/s):\n\
                    echo:  M203 X300.00 Y300.00 Z5.00 E25.00\n\
                    echo:Maximum Acceleration (units/s2):\n\
                    echo:  M201 X500 Y500 Z100 E5000\n\
                    echo:Acceleration (units/s2): P<print_accel> R<retract_accel> T<travel_accel>\n\
                    echo:  M204 P500.00 R500.00 T1000.00\n\
                    echo:Advanced: S<min_feedrate> T<min_travel_feedrate> B<min_segment_time_us> X<max_xy_jerk> Z<max_z_jerk> E<max_e_jerk>\n\
                    echo:  M205 S0.00 T0.00 B20000 X10.00 Y8.00 Z0.40 E5.00\n";
        let s = MarlinSettings::parse(text, "m503.txt").expect("read");
        assert!(s.classic_jerk);
        let MarlinJerk::Classic { max_jerk_m_s, .. } = s.planner.jerk else {
            panic!("classic jerk expected: {:?}", s.planner.jerk)
        };
        assert_eq!(max_jerk_m_s, [10.0, 8.0, 0.4, 5.0].map(|v| v * 1e-3));
        assert_eq!(s.planner.steps_per_m[0], 100e3);
        assert_eq!(s.planner.travel_accel_m_s2, 1000.0 * 1e-3);
        assert_eq!(s.shapers, [None; 3]);
        assert!(s.notes.is_empty(), "{:?}", s.notes);
    }

    /// A value the job's own commands would have refused, a report in inches and a file
    /// that is no report: errors naming the file and the line.
    #[test]
    fn refused_values_and_other_files_are_errors_with_their_line() {
        let cases = [
            (
                "echo:  M92 X80\necho:  M201 X-500 Y500\n",
                "m503.txt:2",
                "M201",
            ),
            ("M203 X300\nM92 X0 Y80\n", "m503.txt:2", "M92"),
            // Steps per mm no machine has (the old reader took any above 0: at 1e-7 a
            // 50 mm move is no whole step, and the replay reported 60 mm of error).
            (
                "M203 X300\nM92 X1e-7 Y80\n",
                "m503.txt:2",
                "1 to 1e6 steps/mm",
            ),
            ("M92 X80 Y80 Z400 E0.5\n", "m503.txt:1", "1 to 1e6 steps/mm"),
            ("M92 X80 Y80 Z2e6\n", "m503.txt:1", "1 to 1e6 steps/mm"),
            // FT_MOTION's M493 is followed as a job's: values Marlin's M493 refuses are
            // named at their line.
            (
                "M203 X300\necho:  M493 S1 A1e308\n",
                "m503.txt:2",
                "10 to 500 Hz",
            ),
            (
                "M203 X300\necho:  M493 X C1 A5 I0.1\n",
                "m503.txt:2",
                "10 to 500 Hz",
            ),
            (
                "M203 X300\necho:  M493 X C1 A40 I1\n",
                "m503.txt:2",
                "0.01 to below 1",
            ),
            (
                "M203 X300\necho:  M493 X C5 A40 I0.1 Q2\n",
                "m503.txt:2",
                "0 to 1",
            ),
            (
                "M203 X300\necho:  M493 X C5 A40 I0.1 Qnan\n",
                "m503.txt:2",
                "`nan` is not a number",
            ),
            // M494 likewise (the old reader only noted it), and M205 B, which is followed.
            (
                "M203 X300\necho:  M494 T2 X0 Y0 Z0 E0.02 O2\n",
                "m503.txt:2",
                "1.25 to 1.875",
            ),
            ("M203 X300\necho:  M494 T3\n", "m503.txt:2", "0, 1 or 2"),
            // An older report's M493 with FT_MOTION on (2.1.2's mode 1, or 10 for its ZV)
            // does not say what shapes each axis; the current report's D1 shapes at a
            // frequency that changes as the print goes.
            (
                "M203 X300\necho:  M493 S1 A37.00 B37.00 D0 F0.00 H0.00 P0 K0.00\n",
                "m503.txt:2",
                "0 in this older report",
            ),
            (
                "M203 X300\necho:  M493 S10 A37.00 B37.00 P0 K0.00\n",
                "m503.txt:2",
                "does not say which shaper FT_MOTION runs",
            ),
            (
                "M203 X300\necho:  M493 S1 D1 H0\n",
                "m503.txt:2",
                "settle shapes at the fixed frequency A only",
            ),
            (
                "M203 X300\necho:  M494 X0.2 Y0 Z0 E0.02\n",
                "m503.txt:2",
                "0 to 0.1 s",
            ),
            (
                "M203 X300\necho:  M205 B2000000.00 S0.00 T0.00 J0.08\n",
                "m503.txt:2",
                "0 to 1000000 us",
            ),
            ("M203 X300\nM593 X F40 D1.5\n", "m503.txt:2", "M593"),
            ("echo:  G20 ; (in)\nM203 X10\n", "m503.txt:1", "G20"),
            (
                "[printer]\nmax_velocity: 300\n",
                "m503.txt:1",
                "not an M503 report",
            ),
            ("ok\nok\n", "m503.txt:1", "not an M503 report"),
        ];
        for (text, at, what) in cases {
            let e = MarlinSettings::parse(text, "m503.txt")
                .expect_err(text)
                .to_string();
            assert!(e.contains(at) && e.contains(what), "{text:?}: {e}");
        }
    }

    /// The ends of the ranges are read; an M493 of an older report (`S` a mode number,
    /// `P`, `K`) with FT_MOTION off is only noted, the current report's per-axis lines
    /// are followed.
    #[test]
    fn values_at_the_ends_of_their_ranges_are_read() {
        let text = "M92 X1 Y1000000 Z400 E93\nM493 S0 P0 K0\nM493 X C1 A10 I0.01 Q0\nM493 Y C1 A500 I0.99 Q1\nM494 T2 X0 Y0.1 Z0 E0.02 O1.875\nM494 X0.1 Y0 Z0 E0\n";
        let s = MarlinSettings::parse(text, "m503.txt").expect("read");
        assert_eq!(
            s.steps_per_mm,
            [Some(1.0), Some(1e6), Some(400.0), Some(93.0)]
        );
        let zv = |f: f64, z: f64| ShaperSetting {
            shaper_type: ShaperType::Marlin {
                shaper: settle_planner::shaper::MarlinShaper::Zv,
                v_tol: 0.0,
                ftm_fs_hz: settle_planner::shaper::MARLIN_FTM_FS_HZ,
            },
            frequency_hz: f,
            damping_ratio: z,
        };
        let mut y = zv(500.0, 0.99);
        if let ShaperType::Marlin { v_tol, .. } = &mut y.shaper_type {
            *v_tol = 1.0;
        }
        assert_eq!(s.shapers, [Some(zv(10.0, 0.01)), Some(y), None]);
        assert_eq!(s.notes.len(), 2, "{:?}", s.notes);
        assert!(
            s.notes[0].text.starts_with("M493 (FT_MOTION"),
            "{:?}",
            s.notes
        );
        assert!(
            s.notes[1].text.starts_with("M494 (FT_MOTION"),
            "{:?}",
            s.notes
        );
    }

    /// A command settle does not know is a note, once.
    #[test]
    fn an_unknown_command_is_a_note() {
        let s = MarlinSettings::parse("M203 X300\nM9999 S1\nM9999 S2\n", "m.txt").expect("read");
        assert_eq!(s.notes.len(), 1, "{:?}", s.notes);
        assert!(
            s.notes[0]
                .to_string()
                .starts_with("m.txt:2: M9999: not a command")
        );
    }

    /// A Prusa-Firmware-Buddy terminal log (gcode/tests/data/prusa/README.md).
    const PRUSA_LOG: &str = include_str!("../../tests/data/prusa/mk4s_m115_m503_m593.txt");

    #[test]
    fn a_prusa_log_gives_the_printer_its_limits_and_its_shapers() {
        let s = MarlinSettings::parse_prusa(PRUSA_LOG, "p.txt").expect("a Buddy log");
        let printer = s.prusa.clone().expect("a Prusa printer");
        assert_eq!(printer.model, PrusaModel::Mk4);
        assert_eq!(printer.named_at, Some((2, "MK4S".to_string())));
        assert_eq!(s.firmware(), Firmware::Prusa);
        let p = &s.planner;
        // Buddy's M92 reports `axis_steps_per_mm` (M92.cpp); its planner counts
        // `axis_msteps_per_mm`, 4 times as many (planner.h): 100 steps/mm are 400 planned.
        assert_eq!(p.steps_per_m, [400e3, 400e3, 1600e3, 1520e3]);
        assert_eq!(p.max_feedrate_m_s, [0.3, 0.3, 0.04, 0.1]);
        assert_eq!(p.max_accel_m_s2, [4.0, 4.0, 0.2, 2.5]);
        assert_eq!(
            (
                p.print_accel_m_s2,
                p.retract_accel_m_s2,
                p.travel_accel_m_s2
            ),
            (4.0, 2.5, 4.0)
        );
        assert!(matches!(
            p.jerk,
            MarlinJerk::Classic { max_jerk_m_s, .. } if max_jerk_m_s == [8e-3, 8e-3, 2e-3, 10e-3]
        ));
        let [x, y, z] = s.shapers;
        let (x, y) = (x.expect("X shaped"), y.expect("Y shaped"));
        assert_eq!(
            (x.shaper_type, x.frequency_hz, x.damping_ratio),
            (ShaperType::MZV, 50.700001, 0.1)
        );
        assert_eq!(
            (y.shaper_type, y.frequency_hz),
            (ShaperType::MZV, 40.599998)
        );
        assert_eq!(z, None);
        let weight = s
            .notes
            .iter()
            .find(|n| n.to_string().contains("weight_adjust"));
        assert!(
            weight
                .expect("the weight line noted")
                .to_string()
                .starts_with("p.txt:29:")
        );
        // The job starts with them: the printer's planner and shapers, not the shipped ones.
        let job = s.job_config().expect("a job configuration");
        assert_eq!(job.firmware(), Firmware::Prusa);
        assert_eq!(job.shapers, s.shapers);
    }

    #[test]
    fn a_prusa_log_reads_each_printers_shapers_and_refuses_what_buddy_would_not_print() {
        let with = |machine: &str, axes: &str| {
            let log = PRUSA_LOG
                .replace(
                    "MACHINE_TYPE:Prusa-MK4S",
                    &format!("MACHINE_TYPE:Prusa-{machine}"),
                )
                .replace(
                    "Recv: echo:axis X type=MZV freq=50.700001 damp=0.100000 vr=20.000000\n",
                    axes,
                );
            MarlinSettings::parse_prusa(&log, "p.txt")
        };
        // The CORE One's EI (M593 T3) with vibration reduction 20: tolerance 1/20; CoreXY.
        let core = with(
            "COREONE",
            "echo:axis X type=EI freq=60.000000 damp=0.100000 vr=20.000000\n",
        )
        .expect("a CORE One log");
        let x = core.shapers[0].expect("X shaped");
        assert_eq!(
            x.shaper_type,
            ShaperType::Prusa {
                shaper: settle_planner::shaper::PrusaShaper::Ei,
                v_tol: 1.0 / 20.0
            }
        );
        assert_eq!(x.frequency_hz, 60.0);
        assert_eq!(
            core.planner.kinematics,
            settle_planner::firmware::Kinematics::CoreXy
        );
        // 118.2 Hz is the MINI's shipped X shaper, above the MK4's 100 Hz.
        let mini_x = "echo:axis X type=MZV freq=118.199997 damp=0.100000 vr=20.000000\n";
        assert_eq!(
            with("MINI", mini_x).expect("a MINI log").shapers[0].map(|s| s.frequency_hz),
            Some(118.199997)
        );
        let errors = [
            (with("MK4", mini_x), "p.txt:26: [M593] freq"),
            (
                with("MK4", "echo:axis X type=ZVDD freq=50 damp=0.1 vr=20\n"),
                "p.txt:26: [M593] type",
            ),
            (
                with("MK4", "echo:axis X type=MZV freq=nan damp=0.1 vr=20\n"),
                "p.txt:26: [M593] freq",
            ),
            (with("MK3S", mini_x), "p.txt:2: [M115] MACHINE_TYPE"),
            (with("MK4", ""), "p.txt:1: no M593 reply for X and Y"),
        ];
        for (result, want) in errors {
            let e = result.expect_err(want).to_string();
            assert!(e.starts_with(want), "{e}");
        }
        // Both off (as after a PrusaSlicer job's end G-code): unshaped, and said.
        let off = PRUSA_LOG
            .replace(
                "axis X type=MZV freq=50.700001 damp=0.100000 vr=20.000000",
                "axis X disabled",
            )
            .replace(
                "axis Y type=MZV freq=40.599998 damp=0.100000 vr=20.000000",
                "axis Y disabled",
            );
        let s = MarlinSettings::parse_prusa(&off, "p.txt").expect("shapers off");
        assert_eq!(s.shapers, [None; 3]);
        let note = s.notes.iter().find(|n| n.to_string().contains("are off"));
        assert!(note.expect("said").to_string().starts_with("p.txt:26:"));
        // Buddy reloads its EEPROM shapers at every print's end (`finalize_print` calls
        // `input_shaper::init`, src/common/marlin_server.cpp): off between jobs is the
        // saved state, not what PrusaSlicer's end G-code left.
        let said = note.expect("said").to_string();
        assert!(said.contains("at every print's end"), "{said}");
        assert!(!said.contains("after every job"), "{said}");
        // Read as mainline Marlin's, the log is refused at its first Buddy line.
        let e = MarlinSettings::parse(PRUSA_LOG, "p.txt").expect_err("not Marlin's");
        assert!(e.to_string().starts_with("p.txt:2: "), "{e}");
        assert!(e.to_string().contains("settle import prusa"), "{e}");
        // Without M115's reply: the MK4's settings, said.
        let bare = PRUSA_LOG.replace("MACHINE_TYPE:Prusa-MK4S", "");
        let s = MarlinSettings::parse_prusa(&bare, "p.txt").expect("a log without M115");
        assert_eq!(
            s.prusa.map(|p| (p.model, p.named_at)),
            Some((PrusaModel::Mk4, None))
        );
        assert!(
            s.notes
                .iter()
                .any(|n| n.to_string().contains("no M115 reply"))
        );
    }

    #[test]
    fn a_prusa_reply_with_vr_0_is_read_where_buddy_does_not_use_vr() {
        // `M593 Z F40` starts Z from `axis_z_default` (type Null, damping 0, vr 0;
        // lib/Marlin/Marlin/src/feature/input_shaper/input_shaper_config.hpp) and M593.cpp's
        // `dump_axis_config` prints it as is: vr 0 is a real reply for the types that do not
        // read it (input_shaper.cpp reads vr only for EI, EI_2HUMP, EI_3HUMP).
        let z = |line: &str| {
            MarlinSettings::parse_prusa(&PRUSA_LOG.replace("axis Z disabled", line), "p.txt")
        };
        let null =
            z("axis Z type=Null freq=40.000000 damp=0.000000 vr=0.000000").expect("a Null Z");
        assert_eq!(null.shapers[2], None);
        let mzv = z("axis Z type=MZV freq=40.000000 damp=0.000000 vr=0.000000")
            .expect("an MZV Z started from axis_z_default");
        let s = mzv.shapers[2].expect("Z shaped");
        assert_eq!(
            (s.shaper_type, s.frequency_hz, s.damping_ratio),
            (ShaperType::MZV, 40.0, 0.0)
        );
        // EI's tolerance is 1/vr (input_shaper.cpp): vr 0 is refused, not a guess.
        let e = z("axis Z type=EI freq=40.000000 damp=0.000000 vr=0.000000")
            .expect_err("EI with vr 0")
            .to_string();
        assert!(e.starts_with("p.txt:28: [M593] vr"), "{e}");
        // input_shaper::get halts the printer at damping 1 (input_shaper.cpp `bsod`).
        let e = z("axis Z type=ZV freq=40.000000 damp=1.000000 vr=20.000000")
            .expect_err("damping 1")
            .to_string();
        assert!(e.starts_with("p.txt:28: [M593] damp"), "{e}");
    }

    #[test]
    fn a_prusa_log_naming_two_printers_is_refused() {
        // M115.cpp prints one `MACHINE_TYPE:Prusa-<id_str>` per reply: two different names
        // are two printers' replies in one log.
        let mini = "Recv: FIRMWARE_NAME:Prusa-Firmware-Buddy 6.2.0+8899 (Github) MACHINE_TYPE:Prusa-MINI EXTRUDER_COUNT:1\n";
        let e = MarlinSettings::parse_prusa(&format!("{PRUSA_LOG}{mini}"), "p.txt")
            .expect_err("two printers")
            .to_string();
        assert!(e.starts_with("p.txt:31: [M115] MACHINE_TYPE"), "{e}");
        assert!(e.contains("Prusa-MK4S"), "{e}");
        // The same printer's M115 twice is one printer.
        let again = PRUSA_LOG.lines().nth(1).expect("M115's reply");
        let s = MarlinSettings::parse_prusa(&format!("{PRUSA_LOG}{again}\n"), "p.txt")
            .expect("one printer");
        assert_eq!(s.prusa.expect("named").named_at, Some((2, "MK4S".into())));
    }

    #[test]
    fn a_bare_prusa_log_with_crlf_reads_as_the_terminals() {
        // The replies as the printer sends them (M115.cpp, M503's report, M593.cpp's
        // `dump_current_config`), without OctoPrint's `Recv: `, `echo:` or `Send:` lines,
        // ended by CRLF: the same printer, limits and shapers.
        let bare: String = PRUSA_LOG
            .lines()
            .filter(|l| !l.starts_with("Send:"))
            .map(|l| {
                let l = l.strip_prefix("Recv: ").unwrap_or(l);
                format!("{}\r\n", l.strip_prefix("echo:").unwrap_or(l))
            })
            .collect();
        let a = MarlinSettings::parse_prusa(PRUSA_LOG, "p.txt").expect("the terminal's");
        let b = MarlinSettings::parse_prusa(&bare, "p.txt").expect("the bare replies");
        assert_eq!(b.prusa.map(|p| p.model), a.prusa.map(|p| p.model));
        assert_eq!(b.planner, a.planner);
        assert_eq!(b.shapers, a.shapers);
        assert_eq!(b.shapers[0].map(|s| s.frequency_hz), Some(50.700001));
    }

    #[test]
    fn a_second_m593_reply_is_the_printers_later_state() {
        // Each M593 reply prints all three axes (M593.cpp `dump_current_config`): the later
        // one holds, as the later of two M503 replies does.
        let later = "Recv: echo:axis X type=ZVD freq=45.000000 damp=0.100000 vr=20.000000\nRecv: echo:axis Y disabled\nRecv: echo:axis Z disabled\n";
        let s = MarlinSettings::parse_prusa(&format!("{PRUSA_LOG}{later}"), "p.txt")
            .expect("two M593 replies");
        let x = s.shapers[0].expect("X shaped");
        assert_eq!((x.shaper_type, x.frequency_hz), (ShaperType::Zvd, 45.0));
        assert_eq!(s.shapers[1], None);
    }

    /// `M205 B` is `parser.value_ulong()` (`GcodeSuite::M205`,
    /// Marlin/src/gcode/config/M200-M205.cpp), `strtoul(value_ptr, NULL, 10)`
    /// (Marlin/src/gcode/parser.h), which stops at the `.`: `B20000.7` and `B20000.99` are
    /// 20000 us, as `B20000.00` is, and `B19999.99` is 19999 us (rounding would give 20001,
    /// 20001 and 20000).
    #[test]
    fn m205_b_is_truncated_as_strtoul_reads_it() {
        let b = |v: &str| {
            let reply = REPLY.replace("M205 B20000.00", &format!("M205 B{v}"));
            MarlinSettings::parse(&reply, "r.txt")
                .expect("an M503 reply")
                .planner
                .min_segment_time_s
        };
        assert_eq!(b("20000.7"), b("20000.00"));
        assert_eq!(b("20000.99"), 20000.0 * 1e-6);
        assert_eq!(b("19999.99"), 19999.0 * 1e-6);
    }

    /// The reply's `M593` is the stepper's ZV (`M593_report`); FT_MOTION switched on by
    /// the job (`M493 S1`) stops it, as `Stepper::isr` (Marlin/src/module/stepper.cpp)
    /// skips `shaping_isr()` while `ftMotion.cfg.active`.
    #[test]
    fn a_replys_m593_is_bypassed_by_a_jobs_m493_s1() {
        use crate::read::limits::{AxisFlags, LimitChange};
        let s = MarlinSettings::parse(REPLY, "r.txt").expect("an M503 reply");
        let mut state = ShaperState::new(Firmware::Marlin, &s.shapers);
        assert_eq!(state.settings(), s.shapers);
        assert!(s.shapers[0].is_some() && s.shapers[1].is_some());
        let on = LimitChange::FtMotion {
            enabled: Some(true),
            axis_sync: None,
            axes: AxisFlags::default(),
            shaper: None,
            dynamic_mode: None,
            frequency_hz: None,
            frequency_scaling: None,
            damping_ratio: None,
            vibration_tolerance: None,
        };
        assert_eq!(state.apply(&on), Ok(true));
        assert_eq!(state.settings(), [None; 3]);
    }

    /// FT_MOTION's block of Marlin's current M503 report (`GcodeSuite::M493_report`,
    /// Marlin/src/gcode/feature/ft_motion/M493.cpp: the `report_heading_etc` heading, then
    /// `M493 S<active> D<dynFreqMode> H<axis_sync>` and one `M493 <axis> C<shaper>
    /// A<baseFreq> F<dynFreqK> I<zeta> Q<vtol>` per shaped axis, floats with Marlin's two
    /// decimals) with FT_MOTION `on` (1) or off (0): X ZVD (C2) at 37.5 Hz, Y EI (C5) at
    /// 41.2 Hz with a tolerance of 0.08.
    fn ft_block(on: u8) -> String {
        format!(
            "echo:; Fixed-Time Motion:\n\
             echo:  M493 S{on} D0 H0\n\
             echo:  M493 X C2 A37.50 F0.00 I0.10 Q0.05\n\
             echo:  M493 Y C5 A41.20 F0.00 I0.15 Q0.08\n"
        )
    }

    /// A reply with FT_MOTION on runs FT_MOTION's shapers and not M593's (`Stepper::isr`,
    /// Marlin/src/module/stepper.cpp, runs `ftMotion_stepper()` and skips `shaping_isr()`
    /// while `ftMotion.cfg.active`): the same lines in a job do the same. With FT_MOTION
    /// off the reply's M593 runs. The old reader noted the M493 lines and kept M593's ZV
    /// in both.
    #[test]
    fn a_replys_ft_motion_takes_effect_as_in_a_job() {
        use settle_planner::shaper::{MARLIN_FTM_FS_HZ, MarlinShaper};
        let ft = |shaper, v_tol, f, z| {
            Some(ShaperSetting {
                shaper_type: ShaperType::Marlin {
                    shaper,
                    v_tol,
                    ftm_fs_hz: MARLIN_FTM_FS_HZ,
                },
                frequency_hz: f,
                damping_ratio: z,
            })
        };
        let x = ft(MarlinShaper::Zvd, 0.05, 37.5, 0.1);
        let y = ft(MarlinShaper::Ei, 0.08, 41.2, 0.15);
        let m593 = |f, z| {
            Some(ShaperSetting {
                shaper_type: ShaperType::MarlinM593,
                frequency_hz: f,
                damping_ratio: z,
            })
        };
        // REPLY's M593 lines are 16 and 17; the FT block follows at 21 to 24.
        let on = MarlinSettings::parse(&format!("{REPLY}{}", ft_block(1)), "r.txt")
            .expect("a reply with FT_MOTION on");
        assert_eq!(on.shapers, [x, y, None]);
        assert_eq!(
            on.followed
                .iter()
                .filter(|(_, c)| *c == "M493")
                .map(|(l, _)| *l)
                .collect::<Vec<_>>(),
            [22, 23, 24]
        );
        let said = on.notes.iter().map(ToString::to_string).collect::<Vec<_>>();
        assert!(
            said.iter()
                .any(|n| n.starts_with("r.txt:17: M593: not in force, FT_MOTION is on")),
            "{said:?}"
        );
        assert!(
            !said.iter().any(|n| n.contains("M493 (FT_MOTION")),
            "{said:?}"
        );
        let off = MarlinSettings::parse(&format!("{REPLY}{}", ft_block(0)), "r.txt")
            .expect("a reply with FT_MOTION off");
        assert_eq!(off.shapers, [m593(40.0, 0.15), m593(35.5, 0.1), None]);
        let said = off
            .notes
            .iter()
            .map(ToString::to_string)
            .collect::<Vec<_>>();
        assert!(
            said.iter()
                .any(|n| n.starts_with("r.txt:24: M493: FT_MOTION is off")),
            "{said:?}"
        );
        // The same lines as a job's start, after M593's: the same shapers.
        for (on, want) in [
            (1, [x, y, None]),
            (0, [m593(40.0, 0.15), m593(35.5, 0.1), None]),
        ] {
            let mut state = ShaperState::new(Firmware::Marlin, &[None; 3]);
            let job = format!(
                "M593 X F40.00 D0.15\nM593 Y F35.50 D0.10\n{}",
                ft_block(on).replace("echo:", "")
            );
            let source: Arc<str> = Arc::from("job.gcode");
            for e in super::super::located_events(&job, Dialect::Marlin, &source) {
                if let (_, EventKind::Limits(c)) = e.expect("a job's lines") {
                    state.apply(&c).expect("followed");
                }
            }
            assert_eq!(state.settings(), want, "S{on}");
        }
    }

    /// Prusa-Firmware-Buddy has no FT_MOTION: an `M493` line in its log is noted, as
    /// before, and leaves the shapers of its `M593` reply.
    #[test]
    fn a_prusa_logs_m493_is_only_noted() {
        let plain = MarlinSettings::parse_prusa(PRUSA_LOG, "p.txt").expect("a log");
        let with = MarlinSettings::parse_prusa(
            &format!("{PRUSA_LOG}Recv: echo:  M493 S1 D0 H0\n"),
            "p.txt",
        )
        .expect("a log with M493");
        assert_eq!(with.shapers, plain.shapers);
        assert!(
            with.notes
                .iter()
                .any(|n| n.text.starts_with("M493 (FT_MOTION")),
            "{:?}",
            with.notes
        );
    }
}
