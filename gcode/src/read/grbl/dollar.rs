//! GRBL's `$` lines (grbl/system.c `system_execute_line`): `$N=V` settings, `$H` homing,
//! and the commands that only report or unlock.

use crate::error::{GcodeError, Location};
use crate::read::event::{EventKind, Note};
use crate::read::grbl::GrblState;
use crate::read::limits::AxisFlags;
use crate::read::motion::Motion;
use crate::read::setting::Setting;

/// What a `$` line does.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Dollar {
    /// Events to emit.
    Events,
    /// Nothing for motion: counted among the ignored commands under this name.
    Ignored(&'static str),
}

/// Runs the `$` line `text` (its code, comments cut; it starts with `$`).
pub(crate) fn line(
    state: &mut GrblState,
    motion: &mut Motion,
    text: &str,
    at: &dyn Fn(Option<usize>) -> Location,
    out: &mut Vec<EventKind>,
) -> Result<Dollar, GcodeError> {
    let body: String = text[1..]
        .chars()
        .filter(|c| !c.is_whitespace())
        .collect::<String>()
        .to_ascii_uppercase();
    let unsupported = |why: &'static str| GcodeError::Unsupported {
        at: at(None),
        command: format!("${}", body.split('=').next().unwrap_or("")),
        why,
    };
    // Commands that need an idle machine answer error:8 while it moves.
    let busy = |what: String, out: &mut Vec<EventKind>| {
        out.push(EventKind::Note(Note::IgnoredByFirmware {
            command: what,
            reason: "GRBL runs $ commands only while idle (error:8, grbl/system.c); the machine is still moving here",
        }));
        Ok(Dollar::Events)
    };
    match body.as_str() {
        "" | "$" | "#" | "G" | "I" | "N" | "C" => return Ok(Dollar::Ignored("$ (report)")),
        "X" => return Ok(Dollar::Ignored("$X")),
        "SLP" => return Err(unsupported("$SLP puts GRBL to sleep: the job cannot go on")),
        _ => {}
    }
    if body.starts_with("J=") {
        return Err(unsupported(
            "jogging ($J=) is interactive; a job settle replays moves with G0-G3",
        ));
    }
    if body.starts_with("RST=") || body.starts_with('N') || body.starts_with("I=") {
        return Ok(Dollar::Ignored("$ (stored data)"));
    }
    if let Some(which) = body.strip_prefix('H') {
        if state.moving {
            return busy(format!("${body}"), out);
        }
        let axes = match which {
            "" => AxisFlags {
                x: true,
                y: true,
                z: true,
                e: false,
            },
            "X" | "Y" | "Z" => AxisFlags {
                x: which == "X",
                y: which == "Y",
                z: which == "Z",
                e: false,
            },
            _ => return Err(unsupported("$H homes all axes, or one with $HX, $HY, $HZ")),
        };
        motion.home_axes(axes);
        out.push(EventKind::Note(Note::Homed { axes }));
        return Ok(Dollar::Events);
    }
    let Some((n, v)) = body.split_once('=') else {
        return Err(unsupported(
            "not a GRBL $ command: settings are $N=VALUE (error:3, grbl/system.c)",
        ));
    };
    let number = n
        .parse::<u16>()
        .map_err(|_| unsupported("a setting's number is a whole number 0-65535"))?;
    // grbl/nuts_bolts.c `read_float`: a sign, digits and one point; "'E' notation will not
    // be recognized". No digit is error:2; anything after the number (`1e300`, `3000mm`)
    // is error:3 (grbl/system.c `system_execute_line`).
    let digits = v.trim_start_matches(['-', '+']);
    let number_len = digits
        .char_indices()
        .scan(false, |point, (i, c)| match c {
            '0'..='9' => Some(i + 1),
            '.' if !*point => {
                *point = true;
                Some(i + 1)
            }
            _ => None,
        })
        .last()
        .unwrap_or(0);
    if !digits[..number_len].contains(|c: char| c.is_ascii_digit()) {
        return Err(unsupported(
            "a setting's value is a number (error:2, grbl/system.c)",
        ));
    }
    if number_len < digits.len() {
        return Err(unsupported(
            "a setting's value is a plain decimal: GRBL reads no exponent and nothing after the number (error:3, grbl/system.c; grbl/nuts_bolts.c read_float)",
        ));
    }
    let value = v
        .parse::<f64>()
        .ok()
        .filter(|x| x.is_finite())
        .ok_or_else(|| unsupported("a setting's value is a number (error:2, grbl/system.c)"))?;
    let out_of_range = |allowed| GcodeError::OutOfRange {
        at: at(None),
        command: format!("${number}"),
        param: "value".into(),
        value,
        allowed,
    };
    if value < 0.0 {
        return Err(out_of_range("0 or more (error:4, grbl/settings.c)"));
    }
    // The bound the reader puts on every motion word of the other dialects.
    if value > crate::read::cmd::SANE {
        return Err(out_of_range("0 to 1e9"));
    }
    if state.moving {
        return busy(format!("${number}={v}"), out);
    }
    match number {
        // grbl/settings.c: any non-zero value; grblHAL's $32 is a mode (1 laser, 2 lathe).
        32 => state.laser_mode = value.trunc() == 1.0,
        30 => state.spindle_range[1] = value,
        31 => state.spindle_range[0] = value,
        _ => {}
    }
    out.push(EventKind::Setting(Setting::Grbl { number, value }));
    Ok(Dollar::Events)
}
