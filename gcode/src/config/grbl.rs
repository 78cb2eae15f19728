//! GRBL's settings (`$$`, the `$N=V` lines it prints and takes; grbl/settings.c
//! `settings_store_global_setting`, doc/markdown/settings.md of gnea/grbl, grblHAL's
//! settings.h for `$398`) read into plain data, and the planner settings they make.
//!
//! A settings file is what `$$` prints, one `$N=V` a line (GRBL 0.9 adds a comment in
//! parentheses; `ok` lines and `[...]` messages of a console copy are skipped). The
//! settings settle uses:
//!
//! | setting | meaning | unit |
//! |---|---|---|
//! | `$11` | junction deviation | mm |
//! | `$12` | arc tolerance | mm |
//! | `$20` | soft limits (needs `$22` homing) | 0/1 |
//! | `$30`, `$31` | `S` of full and of minimum spindle speed / laser power | rpm (or the laser's scale) |
//! | `$32` | laser mode (grblHAL: 1 laser, 2 lathe) | 0/1 |
//! | `$100`-`$102` | steps per mm of X, Y, Z | steps/mm |
//! | `$110`-`$112` | maximum rate of X, Y, Z | mm/min |
//! | `$120`-`$122` | acceleration of X, Y, Z | mm/s^2 |
//! | `$130`-`$132` | maximum travel of X, Y, Z | mm |
//! | `$398` | planner blocks (grblHAL; a reboot applies it) | blocks |
//!
//! The others (step pulse, inversion masks, homing speeds, ...) do not change the
//! planned motion and are kept as read (`other`). GRBL refuses negative values (error:4).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use settle_planner::firmware::grbl::GrblConfig;

use super::budget::Budget;
use super::machine::ConfigNote;
use crate::error::GcodeError;
use crate::read::dialect::Dialect;
use crate::read::event::EventKind;
use crate::read::setting::Setting;

/// GRBL's settings, with GRBL's `DEFAULTS_GENERIC` (grbl/defaults.h) for those a file
/// does not set.
#[derive(Debug, Clone, PartialEq)]
pub struct GrblSettings {
    /// `$100`-`$102`, steps/mm.
    pub steps_per_mm: [f64; 3],
    /// `$110`-`$112`, mm/min.
    pub max_rate_mm_min: [f64; 3],
    /// `$120`-`$122`, mm/s^2.
    pub accel_mm_s2: [f64; 3],
    /// `$130`-`$132`, mm.
    pub max_travel_mm: [f64; 3],
    /// `$11`, mm.
    pub junction_deviation_mm: f64,
    /// `$12`, mm.
    pub arc_tolerance_mm: f64,
    /// `$20`.
    pub soft_limits: bool,
    /// `$22`.
    pub homing: bool,
    /// `$30`: `S` at full power or speed.
    pub spindle_max: f64,
    /// `$31`.
    pub spindle_min: f64,
    /// `$32`: the laser mode.
    pub laser_mode: bool,
    /// `$398` (grblHAL): planner blocks (GRBL 1.1 on an Arduino: 16, compiled in).
    pub planner_blocks: u16,
    /// Every other setting read, by number.
    pub other: BTreeMap<u16, f64>,
    /// The files read.
    pub files: Vec<PathBuf>,
    /// What the reader noted.
    pub notes: Vec<ConfigNote>,
}

impl Default for GrblSettings {
    fn default() -> Self {
        Self::new()
    }
}

/// Why `$30` at or below `$31` is refused: GRBL then has no PWM range, and the two GRBLs
/// disagree on whether `S0` works the material.
const NO_PWM_RANGE: &str = "$30 above $31 (set $31 first when lowering both): with $30 at or below $31 GRBL has no PWM range and runs the spindle or laser at full power for every S, S0 included (spindle_compute_pwm_value, gnea/grbl grbl/spindle_control.c), where grblHAL turns it off at S0 (spindle_set_rpm, spindle_control.c): which moves work is not known";

impl GrblSettings {
    /// GRBL's `DEFAULTS_GENERIC` (grbl/defaults.h): 250 steps/mm, 500 mm/min,
    /// 10 mm/s^2, 200 mm of travel on every axis, junction deviation 0.01 mm, arc
    /// tolerance 0.002 mm, soft limits and homing off, `S` 0-1000, laser mode off; the
    /// 16-block planner buffer of grbl/planner.h.
    pub fn new() -> Self {
        Self {
            steps_per_mm: [250.0; 3],
            max_rate_mm_min: [500.0; 3],
            accel_mm_s2: [10.0; 3],
            max_travel_mm: [200.0; 3],
            junction_deviation_mm: 0.01,
            arc_tolerance_mm: 0.002,
            soft_limits: false,
            homing: false,
            spindle_max: 1000.0,
            spindle_min: 0.0,
            laser_mode: false,
            planner_blocks: 16,
            other: BTreeMap::new(),
            files: Vec::new(),
            notes: Vec::new(),
        }
    }

    /// Sets `$number` to `value` (0 to 1e9, checked by the caller): `Err` with
    /// what is allowed when GRBL would refuse the value.
    pub fn apply(&mut self, number: u16, value: f64) -> Result<(), &'static str> {
        let axis = usize::from(number % 10);
        // The bound the G-code reader puts on a velocity or acceleration of any dialect.
        let positive = |v: f64| {
            if (crate::read::cmd::POSITIVE.ok)(v) {
                Ok(v)
            } else {
                Err(crate::read::cmd::POSITIVE.allowed)
            }
        };
        match number {
            100..=102 => {
                let steps = crate::read::limit_parse::STEPS_PER_MM;
                if !(steps.ok)(value) {
                    return Err(steps.allowed);
                }
                self.steps_per_mm[axis] = value;
            }
            110..=112 => self.max_rate_mm_min[axis] = positive(value)?,
            120..=122 => self.accel_mm_s2[axis] = positive(value)?,
            130..=132 => self.max_travel_mm[axis] = value,
            11 => self.junction_deviation_mm = value,
            12 => self.arc_tolerance_mm = positive(value)?,
            20 => self.soft_limits = value.trunc() != 0.0,
            22 => self.homing = value.trunc() != 0.0,
            30 if value <= self.spindle_min => return Err(NO_PWM_RANGE),
            31 if value >= self.spindle_max => return Err(NO_PWM_RANGE),
            30 => self.spindle_max = value,
            31 => self.spindle_min = value,
            32 => self.laser_mode = value.trunc() == 1.0,
            398 => {
                if !(30.0..=1000.0).contains(&value) {
                    return Err("30 to 1000 blocks (grblHAL's settings.c)");
                }
                self.planner_blocks = value as u16;
            }
            n => {
                self.other.insert(n, value);
            }
        }
        Ok(())
    }

    /// Whether `$number` changes the planned motion (or the laser mode).
    pub fn is_motion_setting(number: u16) -> bool {
        matches!(number, 11 | 12 | 32 | 100..=102 | 110..=112 | 120..=122)
    }

    /// The planner's settings.
    pub fn planner(&self) -> GrblConfig {
        GrblConfig {
            steps_per_m: self.steps_per_mm.map(|s| s * 1e3),
            max_rate_m_s: self.max_rate_mm_min.map(|r| r * 1e-3 / 60.0),
            accel_m_s2: self.accel_mm_s2.map(|a| a * 1e-3),
            junction_deviation_m: self.junction_deviation_mm * 1e-3,
            block_buffer_size: usize::from(self.planner_blocks),
        }
    }

    /// Reads the settings file at `path` (settle-files' reader: a regular file of at most
    /// [`settle_files::limit::FIRMWARE_CONFIG`]).
    pub fn read(path: impl AsRef<Path>) -> Result<Self, GcodeError> {
        let path = path.as_ref();
        let text = Budget::new().main(path)?;
        Self::parse(&text, path)
    }

    /// Reads `text` as the settings file at `path` (which names it in errors).
    pub fn parse(text: &str, path: impl AsRef<Path>) -> Result<Self, GcodeError> {
        let path = path.as_ref();
        let source: Arc<str> = Arc::from(path.display().to_string());
        let mut s = Self::new();
        s.files.push(path.to_path_buf());
        // A console copy: `ok` answers, `[...]`/`<...>` messages and the welcome line
        // (`Grbl 1.1h ['$' for help]`, grblHAL's `GrblHAL ...`: a line that starts with
        // `Grbl`, as senders such as CNCjs recognise it) are not settings.
        let kept: String = text
            .lines()
            .map(|l| {
                let t = l.trim();
                let welcome = t.get(..4).is_some_and(|w| w.eq_ignore_ascii_case("grbl"));
                if t.eq_ignore_ascii_case("ok")
                    || t.starts_with('[')
                    || t.starts_with('<')
                    || welcome
                {
                    ""
                } else {
                    l
                }
            })
            .collect::<Vec<_>>()
            .join("\n");
        for event in super::located_events(&kept, Dialect::Grbl, &source) {
            let (at, kind) = event?;
            match kind {
                EventKind::Setting(Setting::Grbl { number, value }) => {
                    s.apply(number, value)
                        .map_err(|allowed| GcodeError::ConfigValue {
                            at: at.clone(),
                            section: "$".into(),
                            key: number.to_string(),
                            value: value.to_string().into(),
                            allowed: allowed.into(),
                        })?;
                }
                _ => {
                    return Err(GcodeError::ConfigSyntax {
                        at,
                        what: "a GRBL settings file holds `$N=VALUE` lines (what `$$` prints)"
                            .into(),
                    });
                }
            }
        }
        if s.soft_limits && !s.homing {
            s.notes.push(ConfigNote {
                at: None,
                text: "$20=1 needs $22=1: GRBL refuses soft limits without homing (error:10)"
                    .into(),
            });
            s.soft_limits = false;
        }
        Ok(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `$30` at or below `$31` leaves GRBL no PWM range (gnea/grbl
    /// `spindle_compute_pwm_value` fires at full power even at S0; grblHAL's
    /// `spindle_set_rpm` turns S0 off): refused at its line. The old reader took `$30=0`.
    #[test]
    fn a_spindle_range_without_width_is_refused_at_its_line() {
        for (text, line) in [
            ("$30=0\n$31=0\n", 1),
            ("$30=1000\n$31=1000\n", 2),
            ("$31=200\n$30=100\n", 2),
        ] {
            let e = GrblSettings::parse(text, "g.txt")
                .expect_err(text)
                .to_string();
            assert!(
                e.contains(&format!("g.txt:{line}")) && e.contains("no PWM range"),
                "{text}: {e}"
            );
        }
        let s = GrblSettings::parse("$31=100\n$30=24000\n", "g.txt").expect("a range");
        assert_eq!((s.spindle_min, s.spindle_max), (100.0, 24000.0));
    }

    #[test]
    fn a_settings_dump_sets_the_planner() {
        let text = "$0=10\n$11=0.020\n$12=0.002\n$32=1\n$100=80.000\n$101=80.000 (y, step/mm)\n\
                    $110=6000\n$111=4800\n$112=500\n$120=500\n$121=400\n$122=50\n\
                    $130=400\n$131=300\n$132=50\nok\n";
        let s = GrblSettings::parse(text, "grbl.txt").expect("read");
        assert!(s.laser_mode);
        assert_eq!(s.max_travel_mm, [400.0, 300.0, 50.0]);
        assert_eq!(s.other.get(&0), Some(&10.0));
        let p = s.planner();
        assert_eq!(p.max_rate_m_s[0], 6000.0 * 1e-3 / 60.0);
        assert_eq!(p.accel_m_s2, [0.5, 0.4, 0.05]);
        assert_eq!(p.junction_deviation_m, 0.02e-3);
        assert_eq!(p.steps_per_m[1], 80e3);
        assert_eq!(p.block_buffer_size, 16);
        let bad = GrblSettings::parse("$110=0\n", "g.txt").expect_err("refused");
        assert!(bad.to_string().contains("g.txt:1"), "{bad}");
        let neg = GrblSettings::parse("$120=-5\n", "g.txt").expect_err("refused");
        assert!(neg.to_string().contains("error:4"), "{neg}");
        let junk = GrblSettings::parse("G0 X10\n", "g.txt").expect_err("refused");
        assert!(junk.to_string().contains("$N=VALUE"), "{junk}");
    }

    /// A console copy of a reset and `$$` (GRBL's and grblHAL's welcome lines, a message,
    /// the answers) reads as the settings alone; the line after the welcome is still read.
    #[test]
    fn a_console_copy_reads_as_its_settings() {
        for welcome in [
            "Grbl 1.1h ['$' for help]",
            "GrblHAL 1.1f ['$' or '$HELP' for help]",
        ] {
            let text = format!(
                "\r\n{welcome}\r\n[MSG:'$H'|'$X' to unlock]\r\n$$\r\n$110=6000\r\n$120=500\r\nok\r\n"
            );
            let s = GrblSettings::parse(&text, "console.txt").expect("read");
            assert_eq!(
                s.planner().max_rate_m_s[0],
                6000.0 * 1e-3 / 60.0,
                "{welcome}"
            );
            assert_eq!(s.planner().accel_m_s2[0], 0.5, "{welcome}");
        }
        let bad = GrblSettings::parse("Grbl 1.1h\n$110=0\n", "g.txt").expect_err("refused");
        assert!(bad.to_string().contains("g.txt:2"), "{bad}");
    }

    /// Steps per mm no machine has are refused at their line with the range (the old
    /// reader took any value above 1e-9: at `$100=0.0000001` a 10 mm move is no whole
    /// step, and the replay reported 10 mm of error); 1 and 1e6 are read.
    #[test]
    fn steps_per_mm_are_bounded() {
        for (text, line) in [
            ("$100=0.0000001\n", "g.txt:1"),
            ("$110=500\n$102=0.5\n", "g.txt:2"),
            ("$101=1000001\n", "g.txt:1"),
        ] {
            let e = GrblSettings::parse(text, "g.txt")
                .expect_err(text)
                .to_string();
            assert!(
                e.contains(line) && e.contains("1 to 1e6 steps/mm"),
                "{text}: {e}"
            );
        }
        let s = GrblSettings::parse("$100=1\n$101=1000000\n", "g.txt").expect("read");
        assert_eq!(s.steps_per_mm, [1.0, 1e6, 250.0]);
    }
}
