//! Input shaper and motion settings written as a Klipper configuration snippet that pastes
//! cleanly: one `[input_shaper]` section with per-axis `shaper_type_x/y`,
//! `shaper_freq_x/y`, `damping_ratio_x/y`, and a `[printer]` section only for the limits
//! given. Numbers are written shortest-exact, so [`KlipperConfig`] reads back the same
//! values bit for bit.
//!
//! Where to paste it follows from how Klipper reads its files (`klippy/configfile.py`):
//! a section named again continues the first and a later value wins, so the snippet goes
//! at the end of `printer.cfg` (or in a file included there); and values outside the
//! SAVE_CONFIG block win over the block's, so it goes above that block and overrides what
//! `SHAPER_CALIBRATE` saved.
//!
//! [`KlipperConfig`]: super::KlipperConfig

use super::export_text::{Note, annotate, comment_text, refuse};
use super::klipper::MAX_SHAPER_FREQUENCY_HZ;
use super::klipper_shaper;
use super::machine::ShaperSetting;
use crate::error::GcodeError;

/// What to write.
#[derive(Debug, Clone, PartialEq)]
pub struct KlipperExport {
    /// What produced the values (a scenario, a command line); written as a comment.
    pub produced_by: String,
    /// The X axis's shaper: `name` in Klipper's `shaper_type` syntax (`mzv`,
    /// `mzv(n=4,t=0.8)`, `ei(v_tol=0.03)`), frequency in Hz (0 turns shaping off),
    /// damping ratio.
    pub x: ShaperSetting,
    /// The Y axis's shaper.
    pub y: ShaperSetting,
    /// `max_accel`, mm/s^2 (written only when given).
    pub max_accel_mm_s2: Option<f64>,
    /// `minimum_cruise_ratio`, 0 ..< 1 (written only when given).
    pub minimum_cruise_ratio: Option<f64>,
    /// `square_corner_velocity`, mm/s (written only when given).
    pub square_corner_velocity_mm_s: Option<f64>,
}

fn axis(out: &mut String, letter: char, s: &ShaperSetting) -> Result<(), GcodeError> {
    let family = klipper_shaper::check(&s.name).map_err(|why| {
        refuse(
            &format!("shaper_type_{letter}"),
            &s.name,
            format!("{} ({why})", klipper_shaper::ALLOWED),
        )
    })?;
    // Klipper takes any frequency >= 0 (`minval=0.` in klippy/extras/input_shaper.py);
    // settle's reader of printer.cfg takes up to MAX_SHAPER_FREQUENCY_HZ back.
    if !(s.frequency_hz.is_finite() && (0.0..=MAX_SHAPER_FREQUENCY_HZ).contains(&s.frequency_hz)) {
        return Err(refuse(
            &format!("shaper_freq_{letter}"),
            s.frequency_hz,
            format!(
                "0 (shaping off) to {MAX_SHAPER_FREQUENCY_HZ} Hz, the most settle reads back from printer.cfg"
            ),
        ));
    }
    if !(0.0..=family.max_damping_ratio).contains(&s.damping_ratio) {
        return Err(refuse(
            &format!("damping_ratio_{letter}"),
            s.damping_ratio,
            format!("0 to {} for {}", family.max_damping_ratio, family.name),
        ));
    }
    out.push_str(&format!(
        "shaper_type_{letter}: {}\nshaper_freq_{letter}: {}\ndamping_ratio_{letter}: {}\n",
        s.name, s.frequency_hz, s.damping_ratio
    ));
    Ok(())
}

impl KlipperExport {
    /// The snippet with each note as a `#` comment above the option it names
    /// ([`Note::key`], e.g. `shaper_freq_x`, `max_accel`), or an error naming the first
    /// value Klipper would refuse.
    pub fn to_config_with_notes(&self, notes: &[Note]) -> Result<String, GcodeError> {
        let text = self.to_config()?;
        Ok(annotate(&text, notes, "#", |line, key| {
            line.strip_prefix(key)
                .is_some_and(|rest| rest.starts_with(':'))
        }))
    }

    /// The snippet, or an error naming the first value Klipper would refuse.
    pub fn to_config(&self) -> Result<String, GcodeError> {
        let by = comment_text(&self.produced_by);
        let mut out = format!(
            "# Written by settle: {by}\n\
             # Paste at the end of printer.cfg, above the SAVE_CONFIG block: Klipper lets a later\n\
             # value override an earlier one, and values outside the SAVE_CONFIG block override\n\
             # the block's (klippy/configfile.py).\n\
             [input_shaper]\n"
        );
        axis(&mut out, 'x', &self.x)?;
        axis(&mut out, 'y', &self.y)?;
        let mut printer = String::new();
        if let Some(a) = self.max_accel_mm_s2 {
            if !(a.is_finite() && a > 0.0) {
                return Err(refuse("max_accel", a, "a finite acceleration > 0 mm/s^2"));
            }
            printer.push_str(&format!("max_accel: {a}\n"));
        }
        if let Some(r) = self.minimum_cruise_ratio {
            if !(0.0..1.0).contains(&r) {
                return Err(refuse("minimum_cruise_ratio", r, "0 or more and below 1"));
            }
            printer.push_str(&format!("minimum_cruise_ratio: {r}\n"));
        }
        if let Some(v) = self.square_corner_velocity_mm_s {
            if !(v.is_finite() && v >= 0.0) {
                return Err(refuse(
                    "square_corner_velocity",
                    v,
                    "a finite speed >= 0 mm/s",
                ));
            }
            printer.push_str(&format!("square_corner_velocity: {v}\n"));
        }
        if !printer.is_empty() {
            out.push_str("\n[printer]\n");
            out.push_str(&printer);
        }
        Ok(out)
    }
}
