//! Machine-setting and macro commands of RepRapFirmware's configuration files, read into
//! [`Setting`]s and notes (see [`crate::read::setting`] for each command's source).

use crate::error::GcodeError;
use crate::read::cmd::{Check, Cmd, NON_NEGATIVE, POSITIVE, SMALL_INT};
use crate::read::dialect::Dialect;
use crate::read::event::Note;
use crate::read::limits::AxisValues;
use crate::read::params::{Params, Value};
use crate::read::setting::Setting;

/// What a command turned out to be.
#[derive(Debug)]
pub(crate) enum Outcome {
    /// A setting to report.
    Setting(Setting),
    /// A note to report.
    Note(Note),
    /// A report of the current values (no parameters): nothing to report.
    Nothing,
    /// Not one of these commands in this dialect: count it as ignored.
    Unknown,
}

/// The axis letters RepRapFirmware accepts besides X, Y, Z and E; their values are read by
/// the firmware but not reported here.
const OTHER_AXES: &[u8] = b"UVWABCD";

/// The highest kinematics code (`KinematicsType::sixAxisDelta`).
const MAX_KINEMATICS_CODE: u32 = 14;

const MICROSTEPS: Check = Check {
    ok: |v| v.fract() == 0.0 && (1.0..=256.0).contains(&v) && (v as u32).is_power_of_two(),
    allowed: "a power of two from 1 to 256",
};

/// Fails on a letter that is neither in `own` nor an axis.
fn allow_axes(cmd: &Cmd, p: &Params, own: &[u8], text: &'static str) -> Result<(), GcodeError> {
    let mut allowed = Vec::with_capacity(own.len() + 12);
    allowed.extend_from_slice(own);
    allowed.extend_from_slice(b"XYZE");
    allowed.extend_from_slice(OTHER_AXES);
    cmd.allow(p, &allowed, text)
}

fn xyze(cmd: &Cmd, p: &Params, check: Check) -> Result<AxisValues, GcodeError> {
    Ok(AxisValues {
        x: cmd.num(p, b'X', check)?,
        y: cmd.num(p, b'Y', check)?,
        z: cmd.num(p, b'Z', check)?,
        e: cmd.first_num(p, b'E', check)?,
    })
}

/// `M208`: a `min:max` pair sets both, a single value the maximum (the minimum with `S1`).
fn limits(cmd: &Cmd, p: &Params) -> Result<Setting, GcodeError> {
    let set_minimum = cmd.num(p, b'S', SMALL_INT)? == Some(1.0);
    let (mut minimum_mm, mut maximum_mm) = (AxisValues::default(), AxisValues::default());
    for (letter, min, max) in [
        (b'X', &mut minimum_mm.x, &mut maximum_mm.x),
        (b'Y', &mut minimum_mm.y, &mut maximum_mm.y),
        (b'Z', &mut minimum_mm.z, &mut maximum_mm.z),
    ] {
        let values = cmd.list(p, letter, crate::read::cmd::FINITE)?;
        match values.as_slice() {
            [] => {}
            [v] if set_minimum => *min = Some(*v),
            [v] => *max = Some(*v),
            [lo, hi] => {
                if !(hi > lo) {
                    return Err(cmd.out_of_range(
                        Some(p.at(letter)),
                        &char::from(letter).to_string(),
                        *hi,
                        "a maximum greater than the minimum (min:max)",
                    ));
                }
                (*min, *max) = (Some(*lo), Some(*hi));
            }
            _ => {
                return Err(cmd.out_of_range(
                    Some(p.at(letter)),
                    &char::from(letter).to_string(),
                    values.len() as f64,
                    "one value, or two as min:max",
                ));
            }
        }
    }
    Ok(Setting::AxisLimits {
        minimum_mm,
        maximum_mm,
    })
}

/// An `M` command of a configuration file. `args` of `cmd` must already be in `p`.
pub(crate) fn m_code(
    dialect: Dialect,
    cmd: &Cmd,
    number: u32,
    p: &Params,
) -> Result<Outcome, GcodeError> {
    if dialect != Dialect::Rrf {
        return Ok(Outcome::Unknown);
    }
    let setting = |s| Ok(Outcome::Setting(s));
    match number {
        92 | 350 | 906 | 208 | 669 if p.is_empty() => Ok(Outcome::Nothing),
        92 => {
            allow_axes(cmd, p, b"S", "X Y Z E ... (steps/mm), S (microstepping)")?;
            // `S0` (or none): the values are for the microstepping in force.
            let at_microstepping = match cmd.num(p, b'S', NON_NEGATIVE)? {
                Some(v) if v > 0.0 => cmd.num(p, b'S', MICROSTEPS)?.map(|v| v as u32),
                _ => None,
            };
            setting(Setting::StepsPerMm {
                per_axis: xyze(cmd, p, POSITIVE)?,
                at_microstepping,
            })
        }
        350 => {
            allow_axes(
                cmd,
                p,
                b"I",
                "X Y Z E ... (microsteps), I (interpolation 0/1)",
            )?;
            setting(Setting::Microstepping {
                per_axis: xyze(cmd, p, MICROSTEPS)?,
                interpolation: cmd.num(p, b'I', NON_NEGATIVE)?.is_some_and(|v| v > 0.0),
            })
        }
        906 => {
            allow_axes(cmd, p, b"I", "X Y Z E ... (mA), I (idle current, %)")?;
            setting(Setting::MotorCurrent {
                per_axis_ma: xyze(cmd, p, NON_NEGATIVE)?,
                idle_percent: cmd.num(p, b'I', NON_NEGATIVE)?,
            })
        }
        208 => {
            allow_axes(
                cmd,
                p,
                b"S",
                "X Y Z ... (mm, or min:max), S (1: set minimums)",
            )?;
            setting(limits(cmd, p)?)
        }
        669 => match cmd.num(p, b'K', SMALL_INT)? {
            Some(k) if k as u32 <= MAX_KINEMATICS_CODE => {
                setting(Setting::Kinematics { code: k as u32 })
            }
            Some(k) => {
                Err(cmd.out_of_range(Some(p.at(b'K')), "K", k, "a kinematics code from 0 to 14"))
            }
            // Parameters of the current kinematics only.
            None => Ok(Outcome::Nothing),
        },
        665 if p.has(b'L') || p.has(b'D') => setting(Setting::Kinematics { code: 3 }),
        665 => Ok(Outcome::Nothing),
        98 => match p.get(b'P') {
            Value::Absent => Ok(Outcome::Nothing),
            _ => Ok(Outcome::Note(Note::MacroCall {
                command: "M98",
                path: cmd.string(p, b'P')?.unwrap_or_default(),
            })),
        },
        501 => Ok(Outcome::Note(Note::MacroCall {
            command: "M501",
            path: "config-override.g".to_string(),
        })),
        _ => Ok(Outcome::Unknown),
    }
}
