//! Parameters of one command: letter-value words (`X12.5 E0.4 P"zvd" X`) and Klipper's
//! `KEY=VALUE` pairs.
//!
//! Numbers in letter words are plain decimals (`-12.5`, `.5`, `3.`): no exponent, because
//! `E` is a parameter letter (`X1E5` is X = 1 and E = 5 in Klipper's `klippy/gcode.py`
//! splitting and in Marlin's `parser.h`), except in RepRapFirmware, which reads an `E`
//! right after a digit as the number's exponent ([`Params::with_exponents`]). Klipper's
//! `KEY=VALUE` values are read as Python's `float()` would (exponents allowed); NaN and
//! infinities are refused everywhere.

use crate::read::lex::skip_ws;

/// One letter parameter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Value {
    /// Not on the line.
    Absent,
    /// The letter alone (`G28 X`).
    Flag,
    /// A number (may be NaN or infinite: range checks belong to the command).
    Num(f64),
    /// A quoted string: byte range of its content in the argument text.
    Str(usize, usize),
    /// A colon-separated list of numbers (RepRapFirmware `E3000:3000`, `H0.2:0.3`): byte
    /// range of the list in the argument text.
    List(usize, usize),
}

/// Why the parameters could not be read.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum ParamError {
    /// Text that is not a parameter at this 0-based offset in the arguments.
    Syntax { at: usize, what: &'static str },
    /// A value that is not a number: parameter, offset, the text.
    NotANumber { param: char, at: usize, end: usize },
    /// A parameter twice.
    Duplicate { param: char, at: usize },
}

/// The letter parameters of one command, indexed by letter.
#[derive(Debug, Clone)]
pub(crate) struct Params {
    values: [Value; 26],
    /// 0-based offset in the arguments of each parameter's letter.
    at: [usize; 26],
    present: u32,
    /// Numbers take an exponent after a digit ([`Params::with_exponents`]).
    exponents: bool,
}

impl Default for Params {
    fn default() -> Self {
        Params {
            values: [Value::Absent; 26],
            at: [0; 26],
            present: 0,
            exponents: false,
        }
    }
}

impl Params {
    /// Parameters as RepRapFirmware reads them: an `E` (or `e`) right after a digit is the
    /// number's exponent (`X1.5e2` is X = 150), not the `E` parameter
    /// (`StringParser::Seen` skips an `E` that follows a digit; the number is read by
    /// `SafeStrtof`, src/GCodes/GCodeBuffer/StringParser.cpp).
    pub(crate) fn with_exponents() -> Self {
        Params {
            exponents: true,
            ..Params::default()
        }
    }

    /// Parses `args` (the text after a letter-number command).
    pub(crate) fn parse(&mut self, args: &str) -> Result<(), ParamError> {
        let mut old = self.present;
        while old != 0 {
            self.values[old.trailing_zeros() as usize] = Value::Absent;
            old &= old - 1;
        }
        self.present = 0;
        let b = args.as_bytes();
        let mut i = skip_ws(b, 0);
        while i < b.len() {
            let c = b[i];
            if !c.is_ascii_alphabetic() {
                let what = if c == b'{' {
                    "expressions in braces are not evaluated by this reader"
                } else {
                    "expected a parameter letter"
                };
                return Err(ParamError::Syntax { at: i, what });
            }
            let letter = c.to_ascii_uppercase();
            let slot = usize::from(letter - b'A');
            if self.present & (1 << slot) != 0 {
                return Err(ParamError::Duplicate {
                    param: char::from(letter),
                    at: i,
                });
            }
            let at = i;
            i = skip_ws(b, i + 1);
            // `XNaN`, `Finf`: Marlin's strtof and Klipper's float() would read these.
            let word = &b[i..b.len().min(i + 3)];
            if word.eq_ignore_ascii_case(b"nan") || word.eq_ignore_ascii_case(b"inf") {
                let end = args[i..].find([' ', '\t']).map_or(b.len(), |k| i + k);
                return Err(ParamError::NotANumber {
                    param: char::from(letter),
                    at: i,
                    end,
                });
            }
            let value = match b.get(i) {
                Some(b'"') => {
                    let start = i + 1;
                    let mut j = start;
                    loop {
                        match b.get(j) {
                            None => {
                                return Err(ParamError::Syntax {
                                    at: i,
                                    what: "unterminated quoted string",
                                });
                            }
                            Some(b'"') if b.get(j + 1) == Some(&b'"') => j += 2,
                            Some(b'"') => break,
                            Some(_) => j += 1,
                        }
                    }
                    i = j + 1;
                    Value::Str(start, j)
                }
                Some(b'{') => {
                    return Err(ParamError::Syntax {
                        at: i,
                        what: "expressions in braces are not evaluated by this reader",
                    });
                }
                Some(&d) if d.is_ascii_digit() || d == b'-' || d == b'+' || d == b'.' => {
                    let start = i;
                    let mut j = i + 1;
                    let mut list = false;
                    loop {
                        while j < b.len() && (b[j].is_ascii_digit() || b[j] == b'.') {
                            j += 1;
                        }
                        // RepRapFirmware: an `E` right after a digit is the number's
                        // exponent, not a parameter.
                        if self.exponents
                            && b[j - 1].is_ascii_digit()
                            && matches!(b.get(j), Some(b'e' | b'E'))
                        {
                            let mut k = j + 1;
                            if matches!(b.get(k), Some(b'-' | b'+')) {
                                k += 1;
                            }
                            let digits = b[k..].iter().take_while(|c| c.is_ascii_digit()).count();
                            // Without digits the text is no number (the firmware would
                            // drop the `E`): refused below as not a number.
                            j = k + digits;
                        }
                        // `:` continues a list with the next number.
                        if b.get(j) == Some(&b':') {
                            list = true;
                            j += 1;
                            if matches!(b.get(j), Some(b'-' | b'+')) {
                                j += 1;
                            }
                            continue;
                        }
                        break;
                    }
                    // The value must end at white space, the end or the next letter.
                    let ends_well =
                        j == b.len() || b[j] == b' ' || b[j] == b'\t' || b[j].is_ascii_alphabetic();
                    let parsed = if !ends_well {
                        None
                    } else if list {
                        args[start..j]
                            .split(':')
                            .all(|x| x.parse::<f64>().is_ok())
                            .then_some(Value::List(start, j))
                    } else {
                        decimal(&b[start..j])
                            .or_else(|| args[start..j].parse::<f64>().ok())
                            .map(Value::Num)
                    };
                    match parsed {
                        Some(v) => {
                            i = j;
                            v
                        }
                        None => {
                            let mut end = j;
                            while end < b.len() && b[end] != b' ' && b[end] != b'\t' {
                                end += 1;
                            }
                            return Err(ParamError::NotANumber {
                                param: char::from(letter),
                                at: start,
                                end,
                            });
                        }
                    }
                }
                _ => Value::Flag,
            };
            self.values[slot] = value;
            self.at[slot] = at;
            self.present |= 1 << slot;
            i = skip_ws(b, i);
        }
        Ok(())
    }

    /// The value of parameter `letter` (upper case).
    pub(crate) fn get(&self, letter: u8) -> Value {
        self.values[usize::from(letter - b'A')]
    }

    /// Whether `letter` is on the line.
    pub(crate) fn has(&self, letter: u8) -> bool {
        self.present & (1 << (letter - b'A')) != 0
    }

    /// Offset of `letter` in the arguments.
    pub(crate) fn at(&self, letter: u8) -> usize {
        self.at[usize::from(letter - b'A')]
    }

    /// The first letter on the line that is not in `allowed` (upper-case letters).
    pub(crate) fn first_not_in(&self, allowed: &[u8]) -> Option<u8> {
        let mask = allowed.iter().fold(0u32, |m, &c| m | (1 << (c - b'A')));
        let extra = self.present & !mask;
        (extra != 0).then(|| b'A' + extra.trailing_zeros() as u8)
    }

    /// Whether no parameter is on the line.
    pub(crate) fn is_empty(&self) -> bool {
        self.present == 0
    }
}

/// Exact powers of ten (every one up to 1e22 is a double).
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// `[+-]digits[.digits]` with at most 15 significant digits and 22 decimals, by Clinger's
/// fast path: an exact integer divided by an exact power of ten is one correctly rounded
/// IEEE division, the same bits as `str::parse`. `None` for anything else (the caller
/// falls back to `str::parse`).
fn decimal(t: &[u8]) -> Option<f64> {
    let (neg, digits) = match t.first()? {
        b'-' => (true, &t[1..]),
        b'+' => (false, &t[1..]),
        _ => (false, t),
    };
    let mut m: u64 = 0;
    let (mut n, mut frac, mut seen_dot) = (0u32, 0usize, false);
    for &c in digits {
        if c == b'.' {
            if seen_dot {
                return None;
            }
            seen_dot = true;
            continue;
        }
        if !c.is_ascii_digit() || n == 15 {
            return None;
        }
        m = m * 10 + u64::from(c - b'0');
        n += 1;
        frac += usize::from(seen_dot);
    }
    if n == 0 {
        return None;
    }
    let v = m as f64 / *POW10.get(frac)?;
    Some(if neg { -v } else { v })
}

/// Klipper-style `KEY=VALUE` parameters, keys upper-cased.
#[derive(Debug, Clone, Default)]
pub(crate) struct KeyValues {
    /// (key, value, offset of the key in the arguments).
    pairs: Vec<(String, String, usize)>,
}

impl KeyValues {
    /// Parses `args`; values may be quoted with `"` or `'` (as Klipper's `shlex` split).
    pub(crate) fn parse(&mut self, args: &str) -> Result<(), ParamError> {
        self.pairs.clear();
        let b = args.as_bytes();
        let mut i = skip_ws(b, 0);
        while i < b.len() {
            let at = i;
            let key_end = args[i..].find('=').map(|k| i + k);
            let ws_end = args[i..].find([' ', '\t']).map_or(b.len(), |k| i + k);
            let Some(eq) = key_end.filter(|&e| e < ws_end && e > i) else {
                return Err(ParamError::Syntax {
                    at,
                    what: "expected KEY=VALUE",
                });
            };
            let key = args[i..eq].to_ascii_uppercase();
            if self.pairs.iter().any(|(k, _, _)| *k == key) {
                let param = key.chars().next().unwrap_or('?');
                return Err(ParamError::Duplicate { param, at });
            }
            let mut j = eq + 1;
            let value = match b.get(j) {
                Some(&q) if q == b'"' || q == b'\'' => {
                    let close = args[j + 1..]
                        .find(char::from(q))
                        .ok_or(ParamError::Syntax {
                            at: j,
                            what: "unterminated quoted string",
                        })?;
                    let v = args[j + 1..j + 1 + close].to_string();
                    j = j + close + 2;
                    v
                }
                _ => {
                    let end = args[j..].find([' ', '\t']).map_or(b.len(), |k| j + k);
                    let v = args[j..end].to_string();
                    j = end;
                    v
                }
            };
            self.pairs.push((key, value, at));
            i = skip_ws(b, j);
        }
        Ok(())
    }

    /// The pairs, in line order.
    pub(crate) fn pairs(&self) -> &[(String, String, usize)] {
        &self.pairs
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn letters_numbers_flags_strings() {
        let mut p = Params::default();
        p.parse(" X1.5 y-2 E.25 F3000").expect("test input");
        assert_eq!(p.get(b'X'), Value::Num(1.5));
        assert_eq!(p.get(b'Y'), Value::Num(-2.0));
        assert_eq!(p.get(b'E'), Value::Num(0.25));
        assert_eq!(p.get(b'Z'), Value::Absent);
        p.parse("X1E5").expect("test input");
        assert_eq!(
            (p.get(b'X'), p.get(b'E')),
            (Value::Num(1.0), Value::Num(5.0))
        );
        // RepRapFirmware: an E after a digit is an exponent; after anything else, E.
        let mut r = Params::with_exponents();
        r.parse("X1.5e2 Y-2E-1 E2").expect("test input");
        assert_eq!(
            (r.get(b'X'), r.get(b'Y'), r.get(b'E')),
            (Value::Num(150.0), Value::Num(-0.2), Value::Num(2.0))
        );
        r.parse("X1.E5").expect("test input");
        assert_eq!(
            (r.get(b'X'), r.get(b'E')),
            (Value::Num(1.0), Value::Num(5.0))
        );
        r.parse("X1e-9Y2").expect("test input");
        assert_eq!(
            (r.get(b'X'), r.get(b'Y')),
            (Value::Num(1e-9), Value::Num(2.0))
        );
        r.parse("E3000:1e3").expect("test input");
        assert_eq!(r.get(b'E'), Value::List(1, 9));
        assert!(matches!(r.parse("X1e"), Err(ParamError::NotANumber { .. })));
        assert!(matches!(
            r.parse("X1e+ Y2"),
            Err(ParamError::NotANumber { .. })
        ));
        p.parse(" X Y Z10").expect("test input");
        assert_eq!(
            (p.get(b'X'), p.get(b'Y'), p.get(b'Z')),
            (Value::Flag, Value::Flag, Value::Num(10.0))
        );
        p.parse(" P\"zv\"\"d\" F40").expect("test input");
        assert_eq!(p.get(b'P'), Value::Str(3, 8));
        assert_eq!(p.first_not_in(b"PF"), None);
        assert_eq!(p.first_not_in(b"F"), Some(b'P'));
        assert!(matches!(
            p.parse("X1 X2"),
            Err(ParamError::Duplicate { param: 'X', at: 3 })
        ));
        assert!(matches!(
            p.parse("X1.2.3"),
            Err(ParamError::NotANumber {
                param: 'X',
                at: 1,
                end: 6
            })
        ));
        assert!(matches!(p.parse("X-"), Err(ParamError::NotANumber { .. })));
        p.parse("E3000:-2.5 H1").expect("test input");
        assert_eq!(p.get(b'E'), Value::List(1, 10));
        assert!(matches!(
            p.parse("E3000:"),
            Err(ParamError::NotANumber { .. })
        ));
        assert!(matches!(
            p.parse("X1 #"),
            Err(ParamError::Syntax { at: 3, .. })
        ));
        assert!(matches!(p.parse("X{1+2}"), Err(ParamError::Syntax { .. })));
        assert!(matches!(
            p.parse("Y1 XNaN"),
            Err(ParamError::NotANumber {
                param: 'X',
                at: 4,
                end: 7
            })
        ));
        assert!(matches!(
            p.parse("F-inf"),
            Err(ParamError::NotANumber { .. })
        ));
    }

    #[test]
    fn fast_decimals_match_str_parse() {
        for t in [
            "0",
            "-0",
            "12.5",
            "-.5",
            "3.",
            "+7",
            "123.456789012345",
            "0.1",
            "99999.99999",
            "1.000000000000000001",
        ] {
            let want = t.parse::<f64>().expect("test input");
            let got = decimal(t.as_bytes()).unwrap_or(want);
            assert_eq!(got.to_bits(), want.to_bits(), "{t}");
        }
        // Random decimals of 1 to 15 digits with the point anywhere (a fixed LCG).
        let mut x: u64 = 0x9e37_79b9_7f4a_7c15;
        let mut next = || {
            x = x
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            x >> 33
        };
        for _ in 0..20_000 {
            let n = 1 + (next() % 15) as usize;
            let mut t: String = (0..n)
                .map(|_| char::from(b'0' + (next() % 10) as u8))
                .collect();
            t.insert((next() as usize) % (n + 1), '.');
            if next() % 2 == 0 {
                t.insert(0, '-');
            }
            let want = t.parse::<f64>().expect("test input");
            assert_eq!(
                decimal(t.as_bytes()).map(f64::to_bits),
                Some(want.to_bits()),
                "{t}"
            );
        }
        assert_eq!(decimal(b"1234567890123456"), None); // 16 digits: left to str::parse
        assert_eq!(decimal(b"."), None);
        assert_eq!(decimal(b"1.2.3"), None);
    }

    #[test]
    fn key_values() {
        let mut kv = KeyValues::default();
        kv.parse(" accel=3000 SHAPER_TYPE='mzv' VELOCITY=2e2")
            .expect("test input");
        let keys: Vec<_> = kv
            .pairs()
            .iter()
            .map(|(k, v, _)| (k.as_str(), v.as_str()))
            .collect();
        assert_eq!(
            keys,
            [
                ("ACCEL", "3000"),
                ("SHAPER_TYPE", "mzv"),
                ("VELOCITY", "2e2")
            ]
        );
        assert!(kv.parse("ACCEL").is_err());
        assert!(kv.parse("ACCEL=1 ACCEL=2").is_err());
    }
}
