//! What the exporters share: refusing a value the firmware would not accept, making a
//! comment line of free text, comments written above the values they explain
//! ([`Note`]), and the `M201 X Y` and `M204 P T` lines of RepRapFirmware and Marlin.

use crate::error::GcodeError;

/// The error for exporting `value` as `key`.
pub(crate) fn refuse(key: &str, value: impl ToString, allowed: impl Into<String>) -> GcodeError {
    GcodeError::ExportValue {
        key: key.to_string(),
        value: value.to_string(),
        allowed: allowed.into(),
    }
}

/// One comment line's text: control characters (line breaks) become spaces.
pub(crate) fn comment_text(text: &str) -> String {
    text.chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect()
}

/// A comment written into an export above the line of the value it explains: `key` is
/// the setting (Klipper's option name, e.g. `shaper_freq_x` or `max_accel`; a
/// RepRapFirmware command and parameter, e.g. `M593 F`), or empty for the header.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Note {
    /// The setting the comment explains (empty: the file as a whole).
    pub key: String,
    /// The comment's text (line breaks become spaces).
    pub text: String,
}

/// `text` with each note as a `marker`-comment line above the first line that `is_line_of`
/// says writes its key, and the header notes after the leading comment lines. Notes whose
/// key no line writes are left out.
pub(crate) fn annotate(
    text: &str,
    notes: &[Note],
    marker: &str,
    is_line_of: impl Fn(&str, &str) -> bool,
) -> String {
    let mut out = String::with_capacity(text.len() + 80 * notes.len());
    let mut header_done = false;
    let mut used = vec![false; notes.len()];
    for line in text.lines() {
        if !header_done && !line.starts_with(marker) {
            header_done = true;
            for n in notes.iter().filter(|n| n.key.is_empty()) {
                out.push_str(&format!("{marker} {}\n", comment_text(&n.text)));
            }
        }
        for (i, n) in notes.iter().enumerate() {
            if !n.key.is_empty() && !used[i] && is_line_of(line, &n.key) {
                used[i] = true;
                out.push_str(&format!("{marker} {}\n", comment_text(&n.text)));
            }
        }
        out.push_str(line);
        out.push('\n');
    }
    out
}

/// The `M204` line (`P` printing, `T` travel acceleration, mm/s^2, each written only when
/// given; empty when neither is), or an error for one that is not finite and above 0.
pub(crate) fn m204_line(print: Option<f64>, travel: Option<f64>) -> Result<String, GcodeError> {
    accel_line("M204", [("P", print), ("T", travel)])
}

/// The `M201` line of X and Y (each axis's acceleration cap, mm/s^2, written only when
/// given; empty when neither is), or an error for one that is not finite and above 0.
/// Both firmwares cap every move's acceleration per axis by `M201` as well as by `M204`
/// (Marlin's `Planner::_populate_block` in `Marlin/src/module/planner.cpp`,
/// RepRapFirmware's `DDA::InitStandardMove` in `src/Movement/DDA.cpp`), so an `M204` above
/// `M201` is not what the printer runs.
pub(crate) fn m201_line(x: Option<f64>, y: Option<f64>) -> Result<String, GcodeError> {
    accel_line("M201", [("X", x), ("Y", y)])
}

/// `command` with each given word's acceleration (mm/s^2; empty when none is given), or
/// an error naming `command word` for one that is not finite and above 0.
fn accel_line(command: &str, words: [(&str, Option<f64>); 2]) -> Result<String, GcodeError> {
    let mut line = String::new();
    for (word, v) in words {
        if let Some(a) = v {
            if !(a.is_finite() && a > 0.0) {
                let key = format!("{command} {word}");
                return Err(refuse(&key, a, "a finite acceleration > 0 mm/s^2"));
            }
            line.push_str(&format!(" {word}{a}"));
        }
    }
    Ok(if line.is_empty() {
        line
    } else {
        format!("{command}{line}\n")
    })
}
