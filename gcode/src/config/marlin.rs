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
//! `M201`, `M204`, `M205` and `M593` (Marlin's ZV shaper per axis). `M92` (steps per mm)
//! sets the planner's step counts of X, Y, Z, E, which a G-code file's `M92` does not
//! (settle's G-code reader does not follow it). `M205` prints `J` in a build with
//! junction deviation and `X Y Z E` in one with `CLASSIC_JERK` (M205_report): a reply
//! whose `M205` has jerks and no `J` comes from a classic-jerk build, and the planner
//! follows classic jerk. Every other command of the reply is listed once as read and not
//! used; a value the job's own commands would have refused is an error naming the line.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use settle_planner::firmware::marlin::{MarlinConfig, MarlinJerk};

use super::budget::Budget;
use super::klipper::MAX_SHAPER_FREQUENCY_HZ;
use super::machine::ConfigNote;
use crate::error::{GcodeError, Location};
use crate::job::driver::{Driver, LimitOutcome};
use crate::job::shapers::ShaperState;
use crate::job::{JobConfig, PlannerConfig, ShaperSetting};
use crate::read::dialect::Dialect;
use crate::read::event::{EventKind, Note};
use crate::read::limits::LimitChange;
use settle_planner::firmware::Firmware;

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
}

impl MarlinSettings {
    /// What a Marlin printer starts a file with, from this reply: the planner's `M92`,
    /// `M203`, `M201`, `M204` and `M205` settings and the `M593` shapers. Everything else
    /// is [`JobConfig::defaults`]'.
    pub fn job_config(&self) -> Result<JobConfig, GcodeError> {
        let mut cfg = JobConfig::defaults(Firmware::Marlin)?;
        self.planner
            .validate()
            .map_err(|e| GcodeError::JobSetting {
                key: "M503 settings",
                reason: e.to_string(),
            })?;
        cfg.planner = PlannerConfig::Marlin(self.planner);
        cfg.shapers = self.shapers;
        Ok(cfg)
    }
}

/// The commands of an `M503` reply the planner follows.
const PLANNER_COMMANDS: [&str; 6] = ["M92", "M201", "M203", "M204", "M205", "M593"];

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

/// `M92`'s values (X, Y, Z, E): steps per mm within [`super::MICROSTEPS_PER_MM`]; `T` (an extruder of a
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
                let (lo, hi) = super::MICROSTEPS_PER_MM;
                if !(lo..=hi).contains(&v) {
                    return Err(bad(&format!("steps per mm from {lo} to {hi:e}")));
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
        let path = path.as_ref();
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
        let mut kept = Vec::new();
        for (i, raw) in text.lines().enumerate() {
            let line = i as u64 + 1;
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
                    Some(c) => {
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
            kept.push(keep);
        }
        if !any {
            return Err(GcodeError::ConfigSyntax {
                at: at(1),
                what: "not an M503 report: no M92, M201, M203, M204, M205 or M593 line (send M503 to the printer and save its reply)".into(),
            });
        }
        let mut planner = MarlinConfig::new();
        for (i, s) in steps.iter().enumerate() {
            if let Some(s) = s {
                planner.steps_per_m[i] = s * 1e3;
            }
        }
        if classic_jerk {
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
        let mut driver = Driver::new(&crate::job::PlannerConfig::Marlin(planner))
            .map_err(|e| plan_error(1, "M92", e))?
            .expect("Marlin's planner is a firmware's");
        let mut shapers = ShaperState::new(Firmware::Marlin, &[None; 3]);
        let mut followed = Vec::new();
        let text = kept.join("\n");
        for event in super::located_events(&text, Dialect::Marlin, &source) {
            let (at, kind) = event?;
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
            if let LimitChange::MarlinInputShaping {
                frequency_hz: Some(f),
                ..
            } = change
                && f > MAX_SHAPER_FREQUENCY_HZ
            {
                return Err(GcodeError::ConfigValue {
                    at,
                    section: "M593".into(),
                    key: "F".into(),
                    value: f.to_string().into(),
                    allowed: format!("0 (off) or 1 to {MAX_SHAPER_FREQUENCY_HZ} Hz").into(),
                });
            }
            if matches!(change, LimitChange::MarlinInputShaping { .. }) {
                shapers
                    .apply(&change)
                    .map_err(|_| GcodeError::ConfigSyntax {
                        at: at.clone(),
                        what: "M593: not followed".into(),
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
            s.build()
                .map_err(|e| plan_error(followed_line(&followed, "M593"), "M593", e))?;
        }
        Ok(Self {
            planner: *p.config(),
            shapers: settings,
            steps_per_mm: steps,
            classic_jerk,
            followed,
            files: vec![path.to_path_buf()],
            notes,
        })
    }
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
    use settle_planner::shaper::ShaperType;

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
            (ShaperType::Zv, 40.0, 0.15),
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
            (
                "M203 X300\nM92 X80 Y1e10\n",
                "m503.txt:2",
                "(allowed: steps per mm from 1 to 1e9)",
            ),
            ("M203 X300\nM92 X0.5 Y80\n", "m503.txt:2", "from 1 to 1e9"),
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
}
