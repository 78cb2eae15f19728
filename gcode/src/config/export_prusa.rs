//! Input shaping written as G-code for Prusa-Firmware-Buddy (the MK4, MK4S, MK3.5, XL,
//! CORE One and MINI), as its `M593` takes it (lib/Marlin/Marlin/src/gcode/feature/
//! input_shaper/M593.cpp): one `M593 <axis> T<type> F<Hz> D<zeta>` line per axis (`R`, the
//! vibration reduction, for the EI family; `F0` for an axis left unshaped), then `M593 W`,
//! which stores the shapers in the printer's EEPROM. `M201 X Y` and `M204 P T` follow, as
//! for Marlin, when accelerations are given: Buddy plans with Marlin's planner, which caps
//! each move by both. Numbers are written shortest-exact, so settle's G-code reader
//! (`--firmware prusa`) reads back the same values bit for bit.
//!
//! What Buddy would not run as written is refused: a frequency outside the 10 to 100 Hz it
//! clamps `F` to (`clamp_frequency_to_safe_values`, lib/Marlin/Marlin/src/feature/
//! input_shaper/input_shaper_config.hpp; 150 Hz on the MINI only), a damping ratio of 1 or
//! more (`input_shaper::get` in input_shaper.cpp halts the printer on one), a shaper that is
//! not one of its six.

use settle_planner::shaper::ShaperType;

use super::export_marlin::{accel_lines, key_matches};
use super::export_text::{Note, annotate, comment_text, refuse};
use crate::error::GcodeError;
use crate::job::shapers::{prusa_code, prusa_common_hz};

/// One axis's shaper (`M593 <axis> T F D [R]`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PrusaAxisShaper {
    /// `X` or `Y`.
    pub axis: char,
    /// The shaper, its frequency (Hz) and damping ratio; `None` writes `F0` alone (no
    /// shaping on the axis).
    pub shaper: Option<(ShaperType, f64, f64)>,
}

/// What to write for Prusa-Firmware-Buddy.
#[derive(Debug, Clone, PartialEq)]
pub struct PrusaExport {
    /// What produced the values (a scenario, a command line); written as a comment.
    pub produced_by: String,
    /// The axes' shapers, in the order written.
    pub axes: Vec<PrusaAxisShaper>,
    /// `M201 X`, `M201 Y`: the axes' acceleration caps, mm/s^2 (each only when given).
    pub max_accel_xy_mm_s2: [Option<f64>; 2],
    /// `M204 P`: acceleration of printing moves, mm/s^2 (only when given).
    pub print_accel_mm_s2: Option<f64>,
    /// `M204 T`: acceleration of travel moves, mm/s^2 (only when given).
    pub travel_accel_mm_s2: Option<f64>,
}

impl PrusaExport {
    /// The lines with each note as a `;` comment above the line it names ([`Note::key`]:
    /// the command and its first word, e.g. `M593 X F`, `M204 P`), or an error naming the
    /// first value the firmware would not run as written.
    pub fn to_config_with_notes(&self, notes: &[Note]) -> Result<String, GcodeError> {
        let text = self.to_config()?;
        Ok(annotate(&text, notes, ";", |line, key| {
            key_matches("M593", line, key)
        }))
    }

    /// The lines, or an error naming the first value the firmware would not run as
    /// written.
    pub fn to_config(&self) -> Result<String, GcodeError> {
        let by = comment_text(&self.produced_by);
        let mut out = format!(
            "; Written by settle: {by}\n\
             ; Prusa-Firmware-Buddy input shaper (M593; MK4, MK4S, MK3.5, XL, CORE One, MINI):\n\
             ; send these lines or print this file once; M593 W stores the shapers.\n"
        );
        for a in &self.axes {
            out.push_str(&Self::axis_line(a)?);
        }
        if !self.axes.is_empty() {
            out.push_str("M593 W\n");
        }
        let accel = accel_lines(
            self.max_accel_xy_mm_s2,
            self.print_accel_mm_s2,
            self.travel_accel_mm_s2,
        )?;
        if !accel.is_empty() {
            out.push_str(&accel);
            out.push_str(
                "; PrusaSlicer writes M201 and M204 at the start of every job from Printer Settings >\n\
                 ; Machine limits (\"Emit to G-code\"): set the same values there, or a job's own replace them.\n",
            );
        }
        Ok(out)
    }

    /// One axis's `M593` line.
    fn axis_line(a: &PrusaAxisShaper) -> Result<String, GcodeError> {
        let axis = a.axis;
        if !matches!(axis, 'X' | 'Y') {
            return Err(refuse("M593 axis", axis, "X or Y"));
        }
        let Some((kind, f, zeta)) = a.shaper else {
            return Ok(format!("M593 {axis} F0\n"));
        };
        let Some((code, r)) = prusa_code(kind) else {
            return Err(refuse(
                &format!("M593 {axis} T"),
                kind.name(),
                "zv, zvd, mzv, prusa:ei, prusa:2hump_ei or prusa:3hump_ei (T0 to T5)",
            ));
        };
        let (lo, hi) = prusa_common_hz();
        if !(lo..=hi).contains(&f) {
            return Err(refuse(
                &format!("M593 {axis} F"),
                f,
                format!(
                    "{lo} to {hi} Hz (Buddy clamps other frequencies to that range; the MINI's to 150 Hz)"
                ),
            ));
        }
        if !(0.0..1.0).contains(&zeta) {
            return Err(refuse(
                &format!("M593 {axis} D"),
                zeta,
                "0 to under 1 (Buddy halts on a damping ratio of 1 or more)",
            ));
        }
        let mut line = format!("M593 {axis} T{code} F{f} D{zeta}");
        if code >= 3 {
            line.push_str(&format!(" R{r}"));
        }
        line.push('\n');
        Ok(line)
    }
}

#[cfg(test)]
mod tests {
    use settle_planner::shaper::PrusaShaper;

    use super::*;

    fn export(axes: Vec<PrusaAxisShaper>) -> PrusaExport {
        PrusaExport {
            produced_by: "test".into(),
            axes,
            max_accel_xy_mm_s2: [None; 2],
            print_accel_mm_s2: None,
            travel_accel_mm_s2: None,
        }
    }

    #[test]
    fn lines_and_their_notes() {
        let ei = ShaperType::prusa(PrusaShaper::TwoHumpEi);
        let e = PrusaExport {
            max_accel_xy_mm_s2: [Some(5000.0), None],
            print_accel_mm_s2: Some(5000.0),
            travel_accel_mm_s2: Some(5000.0),
            ..export(vec![
                PrusaAxisShaper {
                    axis: 'X',
                    shaper: Some((ShaperType::MZV, 48.2, 0.1)),
                },
                PrusaAxisShaper {
                    axis: 'Y',
                    shaper: Some((ei, 40.0, 0.05)),
                },
            ])
        };
        let notes = [
            Note {
                key: "M593 Y F".into(),
                text: "why Y".into(),
            },
            Note {
                key: "M204 P".into(),
                text: "why P".into(),
            },
        ];
        let text = e.to_config_with_notes(&notes).expect("valid");
        let lines: Vec<&str> = text.lines().skip(3).collect();
        assert_eq!(
            lines,
            [
                "M593 X T2 F48.2 D0.1",
                "; why Y",
                "M593 Y T4 F40 D0.05 R20",
                "M593 W",
                "M201 X5000",
                "; why P",
                "M204 P5000 T5000",
                "; PrusaSlicer writes M201 and M204 at the start of every job from Printer Settings >",
                "; Machine limits (\"Emit to G-code\"): set the same values there, or a job's own replace them.",
            ]
        );
        let off = export(vec![PrusaAxisShaper {
            axis: 'Y',
            shaper: None,
        }]);
        let text = off.to_config().expect("valid");
        assert!(text.ends_with("M593 Y F0\nM593 W\n"), "{text}");
    }

    #[test]
    fn what_buddy_would_not_run_is_refused() {
        let one = |shaper| {
            export(vec![PrusaAxisShaper {
                axis: 'X',
                shaper: Some(shaper),
            }])
            .to_config()
            .expect_err("refused")
            .to_string()
        };
        // Klipper's current `ei` (damping-dependent) is not Buddy's T3.
        assert!(one((ShaperType::EI, 40.0, 0.1)).contains("M593 X T"));
        assert!(one((ShaperType::MZV, 100.5, 0.1)).contains("10 to 100 Hz"));
        assert!(one((ShaperType::MZV, 9.9, 0.1)).contains("M593 X F"));
        assert!(one((ShaperType::Zv, 40.0, 1.0)).contains("halts"));
        assert!(one((ShaperType::Zv, f64::NAN, 0.1)).contains("M593 X F"));
        // The edges of the range are taken.
        for f in [10.0, 100.0] {
            let ok = export(vec![PrusaAxisShaper {
                axis: 'X',
                shaper: Some((ShaperType::Zv, f, 0.0)),
            }]);
            assert!(ok.to_config().is_ok(), "{f}");
        }
    }
}
