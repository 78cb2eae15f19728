//! What both exporters share: refusing a value the firmware would not accept, and
//! making a comment line of free text.

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
