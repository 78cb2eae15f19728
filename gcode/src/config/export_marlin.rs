//! Input shaping written as Marlin G-code, for either of Marlin's two input shapers (the
//! build has one or the other):
//!
//! - [`MarlinExport`]: Fixed-Time Motion (`FT_MOTION`, Marlin 2.1.3 and later), with `M493`
//!   as MarlinDocumentation's `_gcode/M493.md` documents it: `M493 S1` turns Fixed-Time
//!   Motion on, and one `M493 <axis> C<shaper> A<Hz> I<zeta>` line per axis (`Q<vtol>` for
//!   the EI family) sets that axis's shaper: Marlin shapes X and Y apart, and the page asks
//!   for both to be set.
//! - [`MarlinZvExport`]: the built-in ZV shaper (`INPUT_SHAPING_X`/`_Y`, Marlin 2.1.2 and
//!   later), one `M593 <axis> F<Hz> D<zeta>` line per axis, `F0` for an axis left unshaped
//!   (Marlin/src/gcode/feature/input_shaping/M593.cpp takes `D` from 0 to 1, and `F` 0 or
//!   above a bound of its stepper timer); `F` is held to the 1 to 1000 Hz settle's G-code
//!   reader takes back.
//!
//! `M493 A` is refused outside `FTM_MIN_SHAPE_FREQ` (10 Hz) to `FTM_FS / 2`, where Marlin's
//! `M493` answers `?Invalid` and keeps the old frequency (`ft_config_t::goodBaseFreq`,
//! Marlin/src/module/ft_motion.h).
//!
//! Both write `M201 X Y` and `M204 P T` after the shapers, the same lines, when
//! accelerations are given (Marlin caps each move by both). The settings live in EEPROM
//! (`M500` keeps them). Numbers are written shortest-exact, so settle's G-code reader
//! reads back the same values bit for bit.

use super::export_text::{Note, annotate, comment_text, m201_line, m204_line, refuse};
use crate::FtShaper;
use crate::error::GcodeError;
use crate::read::limit_parse::{FTM_MIN_SHAPE_FREQ_HZ, SHAPER_FREQUENCY};

/// Marlin's default trajectory rate `FTM_FS` (Hz, Configuration_adv.h): the highest shaper
/// frequency it takes is half of it.
const DEFAULT_FTM_FS_HZ: u32 = 1000;

/// One axis's shaper (`M493 C A I Q`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FtAxisShaper {
    /// `X`, `Y` or `Z`.
    pub axis: char,
    /// `C`: the shaper; [`FtShaper::None`] writes `C0` alone (no shaping on the axis).
    pub shaper: FtShaper,
    /// `A`: frequency, Hz.
    pub frequency_hz: f64,
    /// `I`: damping ratio zeta.
    pub damping_ratio: f64,
    /// `Q`: vibration tolerance of the EI family (written only when given).
    pub vibration_tolerance: Option<f64>,
}

/// What to write.
#[derive(Debug, Clone, PartialEq)]
pub struct MarlinExport {
    /// What produced the values (a scenario, a command line); written as a comment.
    pub produced_by: String,
    /// The trajectory rate `FTM_FS` the shapers were designed for (Hz); one other than
    /// Marlin's default is said in the header (it is compiled in).
    pub ftm_fs_hz: u32,
    /// The axes' shapers, in the order written.
    pub axes: Vec<FtAxisShaper>,
    /// `M201 X`, `M201 Y`: the axes' acceleration caps, mm/s^2 (each written only when
    /// given, on one line before `M204`).
    pub max_accel_xy_mm_s2: [Option<f64>; 2],
    /// `M204 P`: acceleration of printing moves, mm/s^2 (written only when given).
    pub print_accel_mm_s2: Option<f64>,
    /// `M204 T`: acceleration of travel moves, mm/s^2 (written only when given).
    pub travel_accel_mm_s2: Option<f64>,
}

/// Whether the note keyed `key` belongs above `line`: the same command, and for the
/// per-axis shaper command `per_axis` (`M493`, `M593`) the same axis word.
pub(super) fn key_matches(per_axis: &str, line: &str, key: &str) -> bool {
    let mut l = line.split_whitespace();
    let mut k = key.split_whitespace();
    match (k.next(), k.next()) {
        (Some(c), Some(w)) if c == per_axis => l.next() == Some(c) && l.next() == Some(w),
        (Some(c), _) => l.next() == Some(c),
        _ => false,
    }
}

/// The `M201 X Y` and `M204 P T` lines both exports end with (each only when given).
pub(super) fn accel_lines(
    max_accel_xy_mm_s2: [Option<f64>; 2],
    print_accel_mm_s2: Option<f64>,
    travel_accel_mm_s2: Option<f64>,
) -> Result<String, GcodeError> {
    let [x, y] = max_accel_xy_mm_s2;
    Ok(m201_line(x, y)? + &m204_line(print_accel_mm_s2, travel_accel_mm_s2)?)
}

impl MarlinExport {
    /// The lines with each note as a `;` comment above the line it names ([`Note::key`]:
    /// the command and its first word, e.g. `M493 X A`, `M204 P`), or an error naming the
    /// first value the firmware would refuse.
    pub fn to_config_with_notes(&self, notes: &[Note]) -> Result<String, GcodeError> {
        let text = self.to_config()?;
        Ok(annotate(&text, notes, ";", |line, key| {
            key_matches("M493", line, key)
        }))
    }

    /// The lines, or an error naming the first value the firmware would refuse.
    pub fn to_config(&self) -> Result<String, GcodeError> {
        let by = comment_text(&self.produced_by);
        let mut out = format!(
            "; Written by settle: {by}\n\
             ; Marlin Fixed-Time Motion (FT_MOTION, Marlin 2.1.3 or later): send these lines,\n\
             ; then M500 to keep them.\n"
        );
        if self.ftm_fs_hz != DEFAULT_FTM_FS_HZ {
            out.push_str(&format!(
                "; Designed for FTM_FS = {} Hz (Configuration_adv.h; Marlin's default is {DEFAULT_FTM_FS_HZ}).\n",
                self.ftm_fs_hz
            ));
        }
        out.push_str("M493 S1\n");
        for a in &self.axes {
            out.push_str(&self.axis_line(a)?);
        }
        out.push_str(&accel_lines(
            self.max_accel_xy_mm_s2,
            self.print_accel_mm_s2,
            self.travel_accel_mm_s2,
        )?);
        Ok(out)
    }

    /// One axis's `M493` line.
    fn axis_line(&self, a: &FtAxisShaper) -> Result<String, GcodeError> {
        let axis = a.axis;
        if !matches!(axis, 'X' | 'Y' | 'Z') {
            return Err(refuse("M493 axis", axis, "X, Y or Z"));
        }
        let code = a.shaper.code();
        if a.shaper == FtShaper::None {
            return Ok(format!("M493 {axis} C0\n"));
        }
        let f_max = f64::from(self.ftm_fs_hz) / 2.0;
        if !(a.frequency_hz >= FTM_MIN_SHAPE_FREQ_HZ && a.frequency_hz <= f_max) {
            return Err(refuse(
                &format!("M493 {axis} A"),
                a.frequency_hz,
                format!(
                    "FTM_MIN_SHAPE_FREQ = {FTM_MIN_SHAPE_FREQ_HZ} Hz up to FTM_FS / 2 = {f_max} Hz: Marlin's M493 answers ?Invalid to another frequency and keeps the old one (goodBaseFreq, Marlin/src/module/ft_motion.h)"
                ),
            ));
        }
        if !(0.01..1.0).contains(&a.damping_ratio) {
            return Err(refuse(
                &format!("M493 {axis} I"),
                a.damping_ratio,
                "0.01 to under 1",
            ));
        }
        let mut line = format!(
            "M493 {axis} C{code} A{} I{}",
            a.frequency_hz, a.damping_ratio
        );
        if let Some(q) = a.vibration_tolerance {
            if !(0.0..=1.0).contains(&q) {
                return Err(refuse(&format!("M493 {axis} Q"), q, "0 to 1"));
            }
            line.push_str(&format!(" Q{q}"));
        }
        line.push('\n');
        Ok(line)
    }
}

/// One axis's ZV shaper (`M593 <axis> F D`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ZvAxisShaper {
    /// `X` or `Y` (the axes Marlin's `INPUT_SHAPING_X`/`_Y` shape).
    pub axis: char,
    /// `F`: frequency, Hz; 0 writes `F0` alone (no shaping on the axis).
    pub frequency_hz: f64,
    /// `D`: damping ratio zeta.
    pub damping_ratio: f64,
}

/// What to write for Marlin's built-in ZV shaper.
#[derive(Debug, Clone, PartialEq)]
pub struct MarlinZvExport {
    /// What produced the values (a scenario, a command line); written as a comment.
    pub produced_by: String,
    /// The axes' shapers, in the order written.
    pub axes: Vec<ZvAxisShaper>,
    /// `M201 X`, `M201 Y`: as [`MarlinExport::max_accel_xy_mm_s2`].
    pub max_accel_xy_mm_s2: [Option<f64>; 2],
    /// `M204 P`: as [`MarlinExport::print_accel_mm_s2`].
    pub print_accel_mm_s2: Option<f64>,
    /// `M204 T`: as [`MarlinExport::travel_accel_mm_s2`].
    pub travel_accel_mm_s2: Option<f64>,
}

impl MarlinZvExport {
    /// The lines with each note as a `;` comment above the line it names ([`Note::key`]:
    /// the command and its first word, e.g. `M593 X F`, `M204 P`), or an error naming the
    /// first value the firmware would refuse.
    pub fn to_config_with_notes(&self, notes: &[Note]) -> Result<String, GcodeError> {
        let text = self.to_config()?;
        Ok(annotate(&text, notes, ";", |line, key| {
            key_matches("M593", line, key)
        }))
    }

    /// The lines, or an error naming the first value the firmware would refuse.
    pub fn to_config(&self) -> Result<String, GcodeError> {
        let by = comment_text(&self.produced_by);
        let mut out = format!(
            "; Written by settle: {by}\n\
             ; Marlin input shaping (ZV; INPUT_SHAPING_X/Y, Marlin 2.1.2 or later): send these\n\
             ; lines, then M500 to keep them.\n"
        );
        let lowest = self
            .axes
            .iter()
            .map(|a| a.frequency_hz)
            .filter(|f| *f > 0.0)
            .fold(f64::INFINITY, f64::min);
        if lowest.is_finite() {
            // stepper.h sizes the echo buffer (ShapingQueue) for SHAPING_MIN_FREQ; below it
            // stepper.cpp's shaping_isr releases echoes early when the buffer fills, so the
            // shaper is not the one designed during fast moves.
            out.push_str(&format!(
                "; Needs SHAPING_MIN_FREQ at or below {lowest} Hz in the build (Configuration_adv.h;\n\
                 ; by default the lower of SHAPING_FREQ_X and SHAPING_FREQ_Y): below it the echo\n\
                 ; buffer is too small for fast moves and the shaping weakens.\n"
            ));
        }
        for a in &self.axes {
            out.push_str(&Self::axis_line(a)?);
        }
        out.push_str(&accel_lines(
            self.max_accel_xy_mm_s2,
            self.print_accel_mm_s2,
            self.travel_accel_mm_s2,
        )?);
        Ok(out)
    }

    /// One axis's `M593` line.
    fn axis_line(a: &ZvAxisShaper) -> Result<String, GcodeError> {
        let axis = a.axis;
        if !matches!(axis, 'X' | 'Y') {
            return Err(refuse("M593 axis", axis, "X or Y"));
        }
        if a.frequency_hz == 0.0 {
            return Ok(format!("M593 {axis} F0\n"));
        }
        // What settle's reader takes back (a job's or an M503 reply's M593 F).
        if !(SHAPER_FREQUENCY.ok)(a.frequency_hz) {
            return Err(refuse(
                &format!("M593 {axis} F"),
                a.frequency_hz,
                SHAPER_FREQUENCY.allowed,
            ));
        }
        if !(0.0..=1.0).contains(&a.damping_ratio) {
            return Err(refuse(&format!("M593 {axis} D"), a.damping_ratio, "0 to 1"));
        }
        Ok(format!(
            "M593 {axis} F{} D{}\n",
            a.frequency_hz, a.damping_ratio
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ei(axis: char, f: f64) -> FtAxisShaper {
        FtAxisShaper {
            axis,
            shaper: FtShaper::Ei,
            frequency_hz: f,
            damping_ratio: 0.1,
            vibration_tolerance: Some(0.05),
        }
    }

    #[test]
    fn lines_and_their_notes() {
        let e = MarlinExport {
            produced_by: "test".into(),
            ftm_fs_hz: 1000,
            axes: vec![
                ei('X', 45.2),
                FtAxisShaper {
                    shaper: FtShaper::None,
                    ..ei('Y', f64::NAN)
                },
            ],
            max_accel_xy_mm_s2: [None, Some(4000.0)],
            print_accel_mm_s2: Some(4000.0),
            travel_accel_mm_s2: Some(4000.0),
        };
        let notes = [
            Note {
                key: "M493 X A".into(),
                text: "why A".into(),
            },
            Note {
                key: "M204 P".into(),
                text: "why P".into(),
            },
            Note {
                key: "M201 Y".into(),
                text: "why Y".into(),
            },
        ];
        let text = e.to_config_with_notes(&notes).expect("valid");
        let lines: Vec<&str> = text
            .lines()
            .filter(|l| !l.starts_with("; Written"))
            .collect();
        assert_eq!(
            lines,
            [
                "; Marlin Fixed-Time Motion (FT_MOTION, Marlin 2.1.3 or later): send these lines,",
                "; then M500 to keep them.",
                "M493 S1",
                "; why A",
                "M493 X C5 A45.2 I0.1 Q0.05",
                "M493 Y C0",
                "; why Y",
                "M201 Y4000",
                "; why P",
                "M204 P4000 T4000",
            ]
        );
    }

    #[test]
    fn values_marlin_refuses_are_errors() {
        let e = |a: FtAxisShaper, fs: u32| MarlinExport {
            produced_by: String::new(),
            ftm_fs_hz: fs,
            axes: vec![a],
            max_accel_xy_mm_s2: [None; 2],
            print_accel_mm_s2: None,
            travel_accel_mm_s2: None,
        };
        let refused = |a, fs| e(a, fs).to_config().expect_err("refused").to_string();
        assert!(refused(ei('X', 500.5), 1000).contains("FTM_FS / 2 = 500 Hz"));
        assert!(e(ei('X', 500.0), 1000).to_config().is_ok());
        assert!(refused(ei('X', 300.0), 500).contains("250 Hz"));
        // Below FTM_MIN_SHAPE_FREQ (10 Hz in Configuration_adv.h) M493 answers ?Invalid.
        let low = refused(ei('X', 9.9), 1000);
        assert!(
            low.contains("M493 X A = 9.9") && low.contains("10 Hz"),
            "{low}"
        );
        assert!(e(ei('X', 10.0), 1000).to_config().is_ok());
        let z = |d| FtAxisShaper {
            damping_ratio: d,
            ..ei('Y', 40.0)
        };
        assert!(refused(z(1.0), 1000).contains("M493 Y I"));
        assert!(refused(z(0.005), 1000).contains("0.01 to under 1"));
        let q = FtAxisShaper {
            vibration_tolerance: Some(1.5),
            ..ei('X', 40.0)
        };
        assert!(refused(q, 1000).contains("M493 X Q"));
        let text = e(ei('X', 40.0), 2000).to_config().expect("valid");
        assert!(text.contains("FTM_FS = 2000 Hz"), "{text}");
    }

    #[test]
    fn zv_lines_and_their_notes() {
        let e = MarlinZvExport {
            produced_by: "test".into(),
            axes: vec![
                ZvAxisShaper {
                    axis: 'X',
                    frequency_hz: 41.3,
                    damping_ratio: 0.1,
                },
                ZvAxisShaper {
                    axis: 'Y',
                    frequency_hz: 0.0,
                    damping_ratio: f64::NAN,
                },
            ],
            max_accel_xy_mm_s2: [Some(4000.0), None],
            print_accel_mm_s2: Some(4000.0),
            travel_accel_mm_s2: Some(4000.0),
        };
        let notes = [
            Note {
                key: "M593 X D".into(),
                text: "why D".into(),
            },
            Note {
                key: "M593 Y F".into(),
                text: "why Y".into(),
            },
        ];
        let text = e.to_config_with_notes(&notes).expect("valid");
        let lines: Vec<&str> = text
            .lines()
            .filter(|l| !l.starts_with("; Written"))
            .collect();
        assert_eq!(
            lines,
            [
                "; Marlin input shaping (ZV; INPUT_SHAPING_X/Y, Marlin 2.1.2 or later): send these",
                "; lines, then M500 to keep them.",
                "; Needs SHAPING_MIN_FREQ at or below 41.3 Hz in the build (Configuration_adv.h;",
                "; by default the lower of SHAPING_FREQ_X and SHAPING_FREQ_Y): below it the echo",
                "; buffer is too small for fast moves and the shaping weakens.",
                "; why D",
                "M593 X F41.3 D0.1",
                "; why Y",
                "M593 Y F0",
                "M201 X4000",
                "M204 P4000 T4000",
            ]
        );
        let refused = |axis, f, d| {
            MarlinZvExport {
                axes: vec![ZvAxisShaper {
                    axis,
                    frequency_hz: f,
                    damping_ratio: d,
                }],
                ..e.clone()
            }
            .to_config()
            .expect_err("refused")
            .to_string()
        };
        assert!(refused('X', 40.0, 1.01).contains("M593 X D"));
        assert!(refused('Y', -3.0, 0.1).contains("M593 Y F"));
        // settle's reader takes M593 F of 1 to 1000 Hz back (limit_parse's SHAPER_FREQUENCY).
        assert!(refused('X', 1000.5, 0.1).contains("M593 X F = 1000.5"));
        assert!(refused('X', 0.5, 0.1).contains("M593 X F = 0.5"));
        assert!(refused('Z', 40.0, 0.1).contains("X or Y"));
    }
}
