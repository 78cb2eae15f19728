//! One GRBL block: its `G` and `M` commands by modal group, and its value words left for
//! [`crate::read::params::Params`] (grbl/gcode.c `gc_execute_line`, step 2).
//!
//! GRBL reads several commands on a line, at most one per modal group (error:21), and
//! words without spaces (`G1X10Y5S300`). Letters it does not know (`E`, `A`, `B`, `C`,
//! `D`, `H`, `O`, `Q`, `U`, `V`, `W`) are refused (error:20), as are `G` and `M` codes it
//! does not have: this reader refuses them too, naming the line, because GRBL would not
//! run the line at all.

use crate::error::GcodeError;
use crate::read::arc::Plane;
use crate::read::cmd::Cmd;

/// The motion modes (modal group 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum MotionMode {
    /// G0.
    Seek,
    /// G1.
    Linear,
    /// G2.
    CwArc,
    /// G3.
    CcwArc,
    /// G80: no motion mode (axis words are an error).
    None,
}

impl MotionMode {
    /// G1, G2 or G3: a feed move (the laser may fire).
    pub(crate) fn is_feed(self) -> bool {
        matches!(
            self,
            MotionMode::Linear | MotionMode::CwArc | MotionMode::CcwArc
        )
    }
}

/// The non-modal commands (modal group 0).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum NonModal {
    /// G4.
    Dwell,
    /// G10 (L2, L20).
    SetCoordinateData,
    /// G28 or G30 (index 0, 1).
    GoHome(usize),
    /// G28.1 or G30.1 (index 0, 1).
    SetHome(usize),
    /// G53.
    AbsoluteOverride,
    /// G92.
    SetOffset,
    /// G92.1.
    ResetOffset,
}

/// The spindle states (modal group M7).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(crate) enum Spindle {
    /// M5.
    #[default]
    Off,
    /// M3.
    Cw,
    /// M4.
    Ccw,
}

/// Program flow (modal group M4).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Flow {
    /// M0.
    Pause,
    /// M1 (ignored by GRBL: optional stop not supported).
    OptionalStop,
    /// M2 or M30.
    End,
}

/// The commands of one block (`None`: not on the line).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Words {
    pub(crate) motion: Option<MotionMode>,
    pub(crate) non_modal: Option<NonModal>,
    /// G17, G18 or G19.
    pub(crate) plane: Option<Plane>,
    /// G91 (true) or G90.
    pub(crate) relative: Option<bool>,
    /// G93 (true) or G94.
    pub(crate) inverse_time: Option<bool>,
    /// G20 (true) or G21.
    pub(crate) inches: Option<bool>,
    /// G54-G59 (0-5).
    pub(crate) coord_select: Option<usize>,
    /// G43.1 (true) or G49.
    pub(crate) tool_length: Option<bool>,
    pub(crate) spindle: Option<Spindle>,
    /// M7/M8 (true) or M9.
    pub(crate) coolant: Option<bool>,
    pub(crate) flow: Option<Flow>,
    /// M6: GRBL has no tool change and refuses the line (error:20); senders change tools
    /// themselves.
    pub(crate) tool_change: Option<bool>,
    /// The `S` word.
    pub(crate) s: Option<f64>,
}

/// Reads a number as GRBL's `read_float` does (`[+-]digits[.digits]`) from `b[i..]`:
/// the value and the index after it.
fn number(b: &[u8], mut i: usize) -> Option<(f64, usize)> {
    let start = i;
    if matches!(b.get(i), Some(b'+' | b'-')) {
        i += 1;
    }
    let digits_at = i;
    while i < b.len() && (b[i].is_ascii_digit() || b[i] == b'.') {
        i += 1;
    }
    if i == digits_at {
        return None;
    }
    let text = std::str::from_utf8(&b[start..i]).ok()?;
    text.parse::<f64>().ok().map(|v| (v, i))
}

/// Sets a modal-group slot once (error:21 on a second command of the group).
fn once<T>(slot: &mut Option<T>, value: T, cmd: &Cmd, at: usize) -> Result<(), GcodeError> {
    if slot.is_some() {
        return Err(GcodeError::Unsupported {
            at: cmd.at(Some(at)),
            command: cmd.name(),
            why: "two commands of one modal group on a line: GRBL refuses the line (error:21, grbl/gcode.c)",
        });
    }
    *slot = Some(value);
    Ok(())
}

/// Reads the commands of `text` (the block's code, its comments blanked) into [`Words`]
/// and blanks them in `rest` (a copy of `text` the caller provides), leaving the value
/// words `F I J K L N P R T X Y Z` for the parameter parser; `S` is read here and blanked.
pub(crate) fn read(cmd: &Cmd, text: &str, rest: &mut String) -> Result<Words, GcodeError> {
    rest.clear();
    rest.push_str(text);
    let b = text.as_bytes();
    let mut w = Words::default();
    let mut i = 0;
    let unsupported = |at: usize, why: &'static str| GcodeError::Unsupported {
        at: cmd.at(Some(at)),
        command: cmd.name(),
        why,
    };
    while i < b.len() {
        let c = b[i].to_ascii_uppercase();
        if c == b' ' || c == b'\t' {
            i += 1;
            continue;
        }
        if !c.is_ascii_alphabetic() {
            return Err(GcodeError::Syntax {
                at: cmd.at(Some(i)),
                what: "expected a letter and a number (error:1, grbl/gcode.c)",
            });
        }
        let at = i;
        let j = crate::read::lex::skip_ws(b, i + 1);
        let Some((value, end)) = number(b, j) else {
            return Err(GcodeError::Syntax {
                at: cmd.at(Some(j)),
                what: "expected a number after the letter (error:2, grbl/gcode.c)",
            });
        };
        let blank = |rest: &mut String| {
            rest.replace_range(at..end, &" ".repeat(end - at));
        };
        match c {
            b'G' | b'M' => {
                // GRBL keeps two decimals of the code (`G38.2`, `G43.1`, `G91.1`).
                let int = value.trunc();
                let mantissa = ((value - int) * 100.0).round() as u32;
                if !(0.0..=255.0).contains(&int) {
                    return Err(unsupported(
                        at,
                        "no such command in GRBL (error:20, grbl/gcode.c)",
                    ));
                }
                let n = int as u32;
                if c == b'G' {
                    g_word(&mut w, n, mantissa, cmd, at)?;
                } else {
                    m_word(&mut w, n, mantissa, cmd, at)?;
                }
                blank(rest);
            }
            b'S' => {
                if value < 0.0 {
                    return Err(cmd.out_of_range(
                        Some(j),
                        "S",
                        value,
                        "0 or more (error:4, grbl/gcode.c)",
                    ));
                }
                if w.s.replace(value).is_some() {
                    return Err(GcodeError::DuplicateParameter {
                        at: cmd.at(Some(at)),
                        command: cmd.name(),
                        param: "S".into(),
                    });
                }
                blank(rest);
            }
            b'F' | b'I' | b'J' | b'K' | b'L' | b'N' | b'P' | b'R' | b'T' | b'X' | b'Y' | b'Z' => {
                if matches!(c, b'F' | b'N' | b'P' | b'T') && value < 0.0 {
                    return Err(cmd.out_of_range(
                        Some(j),
                        &char::from(c).to_string(),
                        value,
                        "0 or more (error:4, grbl/gcode.c)",
                    ));
                }
                if matches!(c, b'N' | b'T') {
                    blank(rest);
                }
            }
            b'E' => {
                return Err(GcodeError::UnknownParameter {
                    at: cmd.at(Some(at)),
                    command: cmd.name(),
                    param: "E".into(),
                    allowed: "GRBL drives no extruder: a printer's G-code needs --firmware klipper, marlin, rrf or settle",
                });
            }
            _ => {
                return Err(GcodeError::UnknownParameter {
                    at: cmd.at(Some(at)),
                    command: cmd.name(),
                    param: char::from(c).to_string(),
                    allowed: "GRBL's words G M F I J K L N P R S T X Y Z (error:20, grbl/gcode.c)",
                });
            }
        }
        i = end;
    }
    Ok(w)
}

fn g_word(w: &mut Words, n: u32, m: u32, cmd: &Cmd, at: usize) -> Result<(), GcodeError> {
    let bad = |why: &'static str| GcodeError::Unsupported {
        at: cmd.at(Some(at)),
        command: cmd.name(),
        why,
    };
    let plain = || {
        if m == 0 {
            Ok(())
        } else {
            Err(bad(
                "GRBL takes no decimals on this command (error:23, grbl/gcode.c)",
            ))
        }
    };
    match n {
        0..=3 => {
            plain()?;
            let mode = [
                MotionMode::Seek,
                MotionMode::Linear,
                MotionMode::CwArc,
                MotionMode::CcwArc,
            ][n as usize];
            once(&mut w.motion, mode, cmd, at)
        }
        80 => {
            plain()?;
            once(&mut w.motion, MotionMode::None, cmd, at)
        }
        38 => Err(bad(
            "G38 probing stops where the probe touches, which settle cannot know: remove the probing from the job",
        )),
        4 => {
            plain()?;
            once(&mut w.non_modal, NonModal::Dwell, cmd, at)
        }
        10 => {
            plain()?;
            once(&mut w.non_modal, NonModal::SetCoordinateData, cmd, at)
        }
        28 | 30 => {
            let k = usize::from(n == 30);
            let v = match m {
                0 => NonModal::GoHome(k),
                10 => NonModal::SetHome(k),
                _ => return Err(bad("no such command in GRBL (error:20, grbl/gcode.c)")),
            };
            once(&mut w.non_modal, v, cmd, at)
        }
        53 => {
            plain()?;
            once(&mut w.non_modal, NonModal::AbsoluteOverride, cmd, at)
        }
        92 => {
            let v = match m {
                0 => NonModal::SetOffset,
                10 => NonModal::ResetOffset,
                _ => return Err(bad("no such command in GRBL (error:20, grbl/gcode.c)")),
            };
            once(&mut w.non_modal, v, cmd, at)
        }
        17..=19 => {
            plain()?;
            let plane = match n {
                17 => Plane::Xy,
                18 => Plane::Zx,
                _ => Plane::Yz,
            };
            once(&mut w.plane, plane, cmd, at)
        }
        // G91.1 (incremental arc centres) is GRBL's only IJK mode; G90.1 is refused.
        90 | 91 if m == 10 => {
            if n == 90 {
                Err(bad(
                    "G90.1 (absolute arc centres) is not in GRBL (error:20)",
                ))
            } else {
                Ok(())
            }
        }
        90 | 91 => {
            plain()?;
            once(&mut w.relative, n == 91, cmd, at)
        }
        93 | 94 => {
            plain()?;
            once(&mut w.inverse_time, n == 93, cmd, at)
        }
        20 | 21 => {
            plain()?;
            once(&mut w.inches, n == 20, cmd, at)
        }
        40 | 61 => plain(),
        43 if m == 10 => once(&mut w.tool_length, true, cmd, at),
        49 => {
            plain()?;
            once(&mut w.tool_length, false, cmd, at)
        }
        54..=59 => {
            plain()?;
            once(&mut w.coord_select, (n - 54) as usize, cmd, at)
        }
        _ => Err(bad("no such command in GRBL (error:20, grbl/gcode.c)")),
    }
}

fn m_word(w: &mut Words, n: u32, m: u32, cmd: &Cmd, at: usize) -> Result<(), GcodeError> {
    let bad = |why: &'static str| GcodeError::Unsupported {
        at: cmd.at(Some(at)),
        command: cmd.name(),
        why,
    };
    if m != 0 {
        return Err(bad("GRBL has no Mxx.x commands (error:23, grbl/gcode.c)"));
    }
    match n {
        0 => once(&mut w.flow, Flow::Pause, cmd, at),
        1 => once(&mut w.flow, Flow::OptionalStop, cmd, at),
        2 | 30 => once(&mut w.flow, Flow::End, cmd, at),
        3 => once(&mut w.spindle, Spindle::Cw, cmd, at),
        4 => once(&mut w.spindle, Spindle::Ccw, cmd, at),
        5 => once(&mut w.spindle, Spindle::Off, cmd, at),
        7 | 8 => once(&mut w.coolant, true, cmd, at),
        9 => once(&mut w.coolant, false, cmd, at),
        6 => once(&mut w.tool_change, true, cmd, at),
        _ => Err(bad("no such command in GRBL (error:20, grbl/gcode.c)")),
    }
}
