//! One command being interpreted: its name and place for error messages, and checked
//! access to its parameter values.

use std::sync::Arc;

use crate::error::{GcodeError, Location};
use crate::read::params::{KeyValues, ParamError, Params, Value};

/// A range check for a parameter value, with the text that tells the user what is allowed.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Check {
    pub(crate) ok: fn(f64) -> bool,
    pub(crate) allowed: &'static str,
}

/// [`crate::MAX_LIMIT_VALUE`].
pub(crate) const SANE: f64 = crate::MAX_LIMIT_VALUE;
/// [`crate::MIN_LIMIT_VALUE`].
pub(crate) const SANE_SMALL: f64 = crate::MIN_LIMIT_VALUE;

pub(crate) const FINITE: Check = Check {
    ok: |v| v.abs() <= SANE,
    allowed: "a finite number up to 1e9 in size",
};
pub(crate) const POSITIVE: Check = Check {
    ok: |v| (SANE_SMALL..=SANE).contains(&v),
    allowed: "from 1e-9 to 1e9",
};
pub(crate) const NON_NEGATIVE: Check = Check {
    ok: |v| (0.0..=SANE).contains(&v),
    allowed: "0 or more, up to 1e9",
};
pub(crate) const FRACTION: Check = Check {
    ok: |v| (0.0..=1.0).contains(&v),
    allowed: "0 to 1",
};
pub(crate) const BELOW_ONE: Check = Check {
    ok: |v| (0.0..1.0).contains(&v),
    allowed: "0 or more and below 1",
};
pub(crate) const BOOL: Check = Check {
    ok: |v| v == 0.0 || v == 1.0,
    allowed: "0 or 1",
};
pub(crate) const SMALL_INT: Check = Check {
    ok: |v| v.fract() == 0.0 && (0.0..=255.0).contains(&v),
    allowed: "a whole number 0 to 255",
};

/// The command's name.
#[derive(Debug, Clone, Copy)]
pub(crate) enum CmdName<'a> {
    Code {
        letter: u8,
        number: u32,
        sub: Option<u32>,
    },
    Named(&'a str),
    /// A GRBL block (several commands on a line): its text.
    Block(&'a str),
}

/// A command in its place.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Cmd<'a> {
    pub(crate) name: CmdName<'a>,
    pub(crate) source: &'a Arc<str>,
    pub(crate) line: u64,
    /// Offset of the argument text in the line.
    pub(crate) args_at: usize,
    /// The argument text.
    pub(crate) args: &'a str,
}

impl Cmd<'_> {
    /// The command as a user writes it (`G1`, `G92.1`, `SET_VELOCITY_LIMIT`).
    pub(crate) fn name(&self) -> String {
        match self.name {
            CmdName::Code {
                letter,
                number,
                sub: None,
            } => format!("{}{number}", char::from(letter)),
            CmdName::Code {
                letter,
                number,
                sub: Some(s),
            } => format!("{}{number}.{s}", char::from(letter)),
            CmdName::Named(n) => n.to_ascii_uppercase(),
            CmdName::Block(text) => {
                let t = text.trim();
                let cut = t.char_indices().nth(40).map_or(t.len(), |(i, _)| i);
                t[..cut].to_ascii_uppercase()
            }
        }
    }

    /// The location of byte `offset` of the arguments (`None`: the line).
    pub(crate) fn at(&self, offset: Option<usize>) -> Location {
        Location {
            source_name: self.source.clone(),
            line: self.line,
            column: offset.map(|o| self.args_at + o + 1),
        }
    }

    pub(crate) fn param_error(&self, e: ParamError) -> GcodeError {
        match e {
            ParamError::Syntax { at, what } => GcodeError::Syntax {
                at: self.at(Some(at)),
                what,
            },
            ParamError::NotANumber { param, at, end } => GcodeError::NotANumber {
                at: self.at(Some(at)),
                command: self.name(),
                param: param.to_string(),
                text: self.args[at..end].to_string(),
            },
            // Letters glued to a number (`S3000mm`): the second `m` is a duplicate to the
            // parser, the value's units junk to the user; name the value.
            ParamError::Duplicate { at, .. }
                if matches!(self.name, CmdName::Code { .. })
                    && at > 0
                    && self.args.as_bytes()[at - 1].is_ascii_alphabetic() =>
            {
                let word_at = self.args[..at]
                    .rfind(|c: char| !(c.is_ascii_alphanumeric() || matches!(c, '.' | '-' | '+')))
                    .map_or(0, |i| i + 1);
                let end = self.args[at..]
                    .find(|c: char| !c.is_ascii_alphanumeric())
                    .map_or(self.args.len(), |i| at + i);
                let word = &self.args[word_at..end];
                GcodeError::NotANumber {
                    at: self.at(Some(word_at)),
                    command: self.name(),
                    param: word[..1].to_ascii_uppercase(),
                    text: word[1..].to_string(),
                }
            }
            ParamError::Duplicate { param, at } => {
                let param = match self.name {
                    CmdName::Named(_) => self.args[at..]
                        .split(['=', ' ', '\t'])
                        .next()
                        .unwrap_or("")
                        .to_ascii_uppercase(),
                    CmdName::Code { .. } | CmdName::Block(_) => param.to_string(),
                };
                GcodeError::DuplicateParameter {
                    at: self.at(Some(at)),
                    command: self.name(),
                    param,
                }
            }
        }
    }

    pub(crate) fn out_of_range(
        &self,
        offset: Option<usize>,
        param: &str,
        value: f64,
        allowed: &'static str,
    ) -> GcodeError {
        GcodeError::OutOfRange {
            at: self.at(offset),
            command: self.name(),
            param: param.to_string(),
            value,
            allowed,
        }
    }

    pub(crate) fn unsupported(&self, why: &'static str) -> GcodeError {
        GcodeError::Unsupported {
            at: self.at(None),
            command: self.name(),
            why,
        }
    }

    /// Fails on any parameter letter not in `allowed`.
    pub(crate) fn allow(
        &self,
        p: &Params,
        allowed: &[u8],
        text: &'static str,
    ) -> Result<(), GcodeError> {
        match p.first_not_in(allowed) {
            None => Ok(()),
            Some(l) => Err(GcodeError::UnknownParameter {
                at: self.at(Some(p.at(l))),
                command: self.name(),
                param: char::from(l).to_string(),
                allowed: text,
            }),
        }
    }

    /// The number given for `letter`, checked; `None` when absent.
    pub(crate) fn num(
        &self,
        p: &Params,
        letter: u8,
        check: Check,
    ) -> Result<Option<f64>, GcodeError> {
        let at = Some(p.at(letter));
        let param = || char::from(letter).to_string();
        match p.get(letter) {
            Value::Absent => Ok(None),
            Value::Flag => Err(GcodeError::MissingValue {
                at: self.at(at),
                command: self.name(),
                param: param(),
            }),
            Value::Str(s, e) | Value::List(s, e) => Err(GcodeError::NotANumber {
                at: self.at(at),
                command: self.name(),
                param: param(),
                text: self.args[s..e].to_string(),
            }),
            Value::Num(v) if (check.ok)(v) => Ok(Some(v)),
            Value::Num(v) => Err(self.out_of_range(at, &param(), v, check.allowed)),
        }
    }

    /// Like [`Cmd::num`], but a list (`E3000:3000`) gives its first value.
    pub(crate) fn first_num(
        &self,
        p: &Params,
        letter: u8,
        check: Check,
    ) -> Result<Option<f64>, GcodeError> {
        match p.get(letter) {
            Value::List(s, e) => {
                let text = &self.args[s..e];
                let first = text
                    .split(':')
                    .next()
                    .and_then(|x| x.parse::<f64>().ok())
                    .unwrap_or(f64::NAN);
                if (check.ok)(first) {
                    Ok(Some(first))
                } else {
                    Err(self.out_of_range(
                        Some(p.at(letter)),
                        &char::from(letter).to_string(),
                        first,
                        check.allowed,
                    ))
                }
            }
            _ => self.num(p, letter, check),
        }
    }

    /// Every number of a list (or the one number) given for `letter`.
    pub(crate) fn list(
        &self,
        p: &Params,
        letter: u8,
        check: Check,
    ) -> Result<Vec<f64>, GcodeError> {
        match p.get(letter) {
            Value::List(s, e) => {
                let mut out = Vec::new();
                for x in self.args[s..e].split(':') {
                    let v = x.parse::<f64>().unwrap_or(f64::NAN);
                    if !(check.ok)(v) {
                        return Err(self.out_of_range(
                            Some(p.at(letter)),
                            &char::from(letter).to_string(),
                            v,
                            check.allowed,
                        ));
                    }
                    out.push(v);
                }
                Ok(out)
            }
            _ => Ok(self.num(p, letter, check)?.into_iter().collect()),
        }
    }

    /// The quoted string given for `letter`.
    pub(crate) fn string(&self, p: &Params, letter: u8) -> Result<Option<String>, GcodeError> {
        match p.get(letter) {
            Value::Absent => Ok(None),
            Value::Str(s, e) => Ok(Some(self.args[s..e].replace("\"\"", "\""))),
            _ => Err(GcodeError::Syntax {
                at: self.at(Some(p.at(letter))),
                what: "expected a quoted string like P\"zvd\"",
            }),
        }
    }

    /// A number from a `KEY=VALUE` value, checked.
    pub(crate) fn kv_num(
        &self,
        kv_at: usize,
        key: &str,
        value: &str,
        check: Check,
    ) -> Result<f64, GcodeError> {
        let at = Some(kv_at);
        match value.trim().parse::<f64>() {
            Ok(v) if (check.ok)(v) => Ok(v),
            Ok(v) => Err(self.out_of_range(at, key, v, check.allowed)),
            Err(_) => Err(GcodeError::NotANumber {
                at: self.at(at),
                command: self.name(),
                param: key.to_string(),
                text: value.to_string(),
            }),
        }
    }

    /// Fails on a `KEY=VALUE` key not in `allowed`.
    pub(crate) fn kv_unknown(
        &self,
        kv: &KeyValues,
        allowed: &[&str],
        text: &'static str,
    ) -> Result<(), GcodeError> {
        match kv
            .pairs()
            .iter()
            .find(|(k, _, _)| !allowed.contains(&k.as_str()))
        {
            None => Ok(()),
            Some((k, _, at)) => Err(GcodeError::UnknownParameter {
                at: self.at(Some(*at)),
                command: self.name(),
                param: k.clone(),
                allowed: text,
            }),
        }
    }
}
