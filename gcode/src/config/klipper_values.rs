//! Typed option values with Klipper's checks (`klippy/configfile.py` `ConfigWrapper`:
//! `getfloat`, `getint`, `getboolean`, `getlists` and their `minval`/`maxval`/`above`/
//! `below` limits). Numbers are read as Python's `float()`/`int()` read them (surrounding
//! white space allowed, `1e3` for floats), except that infinities, NaN and `_` digit
//! separators are refused. A present but malformed value is an error naming the file,
//! line, section and option and what is allowed.

use super::ini::{Opt, Store};
use crate::error::GcodeError;

/// A `getfloat`/`getint` range: every bound given must hold.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Range {
    pub(crate) min: Option<f64>,
    pub(crate) max: Option<f64>,
    pub(crate) above: Option<f64>,
    pub(crate) below: Option<f64>,
}

impl Range {
    pub(crate) const ANY: Range = Range {
        min: None,
        max: None,
        above: None,
        below: None,
    };

    pub(crate) fn above(v: f64) -> Range {
        Range {
            above: Some(v),
            ..Range::ANY
        }
    }

    pub(crate) fn min(v: f64) -> Range {
        Range {
            min: Some(v),
            ..Range::ANY
        }
    }

    pub(crate) fn max(self, v: f64) -> Range {
        Range {
            max: Some(v),
            ..self
        }
    }

    pub(crate) fn below(self, v: f64) -> Range {
        Range {
            below: Some(v),
            ..self
        }
    }

    fn holds(&self, v: f64) -> bool {
        self.min.is_none_or(|m| v >= m)
            && self.max.is_none_or(|m| v <= m)
            && self.above.is_none_or(|m| v > m)
            && self.below.is_none_or(|m| v < m)
    }

    fn describe(&self, what: &str) -> String {
        let mut parts = vec![what.to_string()];
        for (op, b) in [
            (">=", self.min),
            (">", self.above),
            ("<=", self.max),
            ("<", self.below),
        ] {
            if let Some(b) = b {
                parts.push(format!("{op} {b}"));
            }
        }
        parts.join(" ")
    }
}

/// Typed access to one configuration's options.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Values<'a> {
    pub(crate) store: &'a Store,
}

/// The error for `opt` of `section` holding `value`.
pub(crate) fn invalid(opt: &Opt, section: &str, value: &str, allowed: String) -> GcodeError {
    GcodeError::ConfigValue {
        at: opt.at.clone(),
        section: section.to_string(),
        key: opt.key.clone(),
        value: value.into(),
        allowed: allowed.into(),
    }
}

impl<'a> Values<'a> {
    /// The option and its value, if set.
    pub(crate) fn text(&self, section: &str, key: &str) -> Option<(&'a Opt, String)> {
        self.store.get(section, key).map(|o| (o, o.value()))
    }

    /// A number parsed as `T`, checked against `range`; `what` names the kind for errors.
    fn number<T: std::str::FromStr + Copy>(
        &self,
        section: &str,
        key: &str,
        range: Range,
        what: &str,
        as_f64: fn(T) -> f64,
    ) -> Result<Option<T>, GcodeError> {
        let Some((opt, value)) = self.text(section, key) else {
            return Ok(None);
        };
        match value.trim().parse::<T>() {
            Ok(v) if as_f64(v).is_finite() && range.holds(as_f64(v)) => Ok(Some(v)),
            _ => Err(invalid(opt, section, &value, range.describe(what))),
        }
    }

    /// `getfloat`.
    pub(crate) fn float(
        &self,
        section: &str,
        key: &str,
        range: Range,
    ) -> Result<Option<f64>, GcodeError> {
        self.number(section, key, range, "a finite number", |v| v)
    }

    /// `getint`.
    pub(crate) fn int(
        &self,
        section: &str,
        key: &str,
        range: Range,
    ) -> Result<Option<i64>, GcodeError> {
        self.number(section, key, range, "a whole number", |v| v as f64)
    }

    /// `getboolean` (configparser's `BOOLEAN_STATES`, any case).
    pub(crate) fn boolean(&self, section: &str, key: &str) -> Result<Option<bool>, GcodeError> {
        let Some((opt, value)) = self.text(section, key) else {
            return Ok(None);
        };
        match value.to_lowercase().as_str() {
            "1" | "yes" | "true" | "on" => Ok(Some(true)),
            "0" | "no" | "false" | "off" => Ok(Some(false)),
            _ => Err(invalid(
                opt,
                section,
                &value,
                "true/false, yes/no, on/off or 1/0".to_string(),
            )),
        }
    }

    /// A stepper's `gear_ratio` (`klippy/stepper.py` `parse_gear_ratio`): comma-separated
    /// `a:b` pairs, the product of `a / b` (1 when absent or empty).
    pub(crate) fn gear_ratio(&self, section: &str) -> Result<f64, GcodeError> {
        let Some((opt, value)) = self.text(section, "gear_ratio") else {
            return Ok(1.0);
        };
        let bad = || {
            invalid(
                opt,
                section,
                &value,
                "pairs of positive numbers like `80:16` or `57:11, 2:1`".to_string(),
            )
        };
        let mut ratio = 1.0;
        for pair in value.split(',').map(str::trim).filter(|p| !p.is_empty()) {
            let nums: Vec<f64> = pair
                .split(':')
                .map(|x| x.trim().parse::<f64>())
                .collect::<Result<_, _>>()
                .map_err(|_| bad())?;
            match nums.as_slice() {
                [a, b] if a.is_finite() && b.is_finite() && *a > 0.0 && *b > 0.0 => {
                    ratio *= a / b;
                }
                _ => return Err(bad()),
            }
        }
        Ok(ratio)
    }
}
