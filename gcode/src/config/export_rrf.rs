//! Input shaping written as RepRapFirmware `config.g` lines: one `M593` line, because the
//! firmware has one shaper for every axis (`Move` holds a single `AxisShaper`, applied to
//! each drive in `Move::AddLinearSegments`; `M593` takes no axis), and `M201 X Y` and
//! `M204` when accelerations are given (RepRapFirmware caps each move by both). Numbers
//! are written shortest-exact, so [`RrfConfig`] reads back the same values bit for bit. When the axes were tuned apart, the caller picks the
//! one setting to write.
//!
//! [`RrfConfig`]: super::RrfConfig

use super::export_text::{Note, annotate, comment_text, m201_line, m204_line, refuse};
use super::machine::ShaperSetting;
use crate::error::GcodeError;
use crate::read::limit_parse::{RRF_MAX_SHAPER_FREQUENCY_HZ, RRF_MIN_SHAPER_FREQUENCY_HZ};

/// The `M593 P` types written (`custom` needs its impulses and is not).
const TYPES: [&str; 7] = ["none", "zvd", "zvdd", "zvddd", "mzv", "ei2", "ei3"];

/// What to write.
#[derive(Debug, Clone, PartialEq)]
pub struct RrfExport {
    /// What produced the values (a scenario, a command line); written as a comment.
    pub produced_by: String,
    /// The shaper of all axes: `name` an `M593 P` type (`zvd`, `mzv`, `ei2`, ...; a
    /// `rrf:` prefix, as in `ShaperType` names, is dropped), frequency in Hz, damping
    /// ratio.
    pub shaper: ShaperSetting,
    /// `M201 X`, `M201 Y`: the axes' acceleration caps, mm/s^2 (each written only when
    /// given, on one line before `M204`).
    pub max_accel_xy_mm_s2: [Option<f64>; 2],
    /// `M204 P`: acceleration of printing moves, mm/s^2 (written only when given).
    pub print_accel_mm_s2: Option<f64>,
    /// `M204 T`: acceleration of travel moves, mm/s^2 (written only when given).
    pub travel_accel_mm_s2: Option<f64>,
}

impl RrfExport {
    /// The lines with each note as a `;` comment above the command it names
    /// ([`Note::key`], e.g. `M593 F`, `M204 P`), or an error naming the first value the
    /// firmware would refuse.
    pub fn to_config_with_notes(&self, notes: &[Note]) -> Result<String, GcodeError> {
        let text = self.to_config()?;
        Ok(annotate(&text, notes, ";", |line, key| {
            let command = key.split_whitespace().next().unwrap_or(key);
            line.split_whitespace().next() == Some(command)
        }))
    }

    /// The lines, or an error naming the first value the firmware would refuse. Shaping
    /// off is `M593 P"none"` alone (its frequency and damping mean nothing then).
    pub fn to_config(&self) -> Result<String, GcodeError> {
        let s = &self.shaper;
        let name = s.name.strip_prefix("rrf:").unwrap_or(&s.name);
        if !TYPES.contains(&name) {
            return Err(refuse("M593 P", &s.name, TYPES.join(", ")));
        }
        let by = comment_text(&self.produced_by);
        let head = format!(
            "; Written by settle: {by}\n\
             ; RepRapFirmware has one input shaper for all axes: put these lines at the end of\n\
             ; config.g (after any M501) in place of its other M593 line.\n"
        );
        let m593 = if name == "none" {
            "M593 P\"none\"\n".to_string()
        } else {
            self.shaper_line(name)?
        };
        let mut out = format!("{head}{m593}");
        let [x, y] = self.max_accel_xy_mm_s2;
        out.push_str(&m201_line(x, y)?);
        out.push_str(&m204_line(self.print_accel_mm_s2, self.travel_accel_mm_s2)?);
        Ok(out)
    }

    /// The `M593` line of a shaper that is on.
    fn shaper_line(&self, name: &str) -> Result<String, GcodeError> {
        let s = &self.shaper;
        if !(RRF_MIN_SHAPER_FREQUENCY_HZ..=RRF_MAX_SHAPER_FREQUENCY_HZ).contains(&s.frequency_hz) {
            return Err(refuse(
                "M593 F",
                s.frequency_hz,
                format!("{RRF_MIN_SHAPER_FREQUENCY_HZ:.3} to {RRF_MAX_SHAPER_FREQUENCY_HZ} Hz"),
            ));
        }
        if !(0.0..=0.99).contains(&s.damping_ratio) {
            return Err(refuse("M593 S", s.damping_ratio, "0 to 0.99"));
        }
        Ok(format!(
            "M593 P\"{name}\" F{} S{}\n",
            s.frequency_hz, s.damping_ratio
        ))
    }
}
