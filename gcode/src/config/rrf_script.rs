//! The parts of a RepRapFirmware command file that settle does not evaluate, blanked out
//! (line numbers kept) with a note each: meta-commands (`if`, `elif`, `else`, `while` and
//! the lines indented under them, `var`, `global`, `set`, `echo`, `abort`, `break`,
//! `continue`, `skip`; the keywords of `src/GCodes/GCodeBuffer/StringParser.cpp`) and
//! commands with `{expressions}` that name anything. Only unconditional commands are
//! read: a conditional block's settings are not applied, whatever its condition would
//! give on the machine. A top-level `abort` ends the file, as it ends the firmware's
//! reading.
//!
//! An expression of numbers alone (`M906 X{2800 * 0.65}`) is worked out and its value
//! put in its place, as the firmware's `ExpressionParser` (`src/GCodes/GCodeBuffer/
//! ExpressionParser.cpp`) would: `+` and `-` bind less tightly than `*` and `/`, left to
//! right, unary `-` and `+` and brackets; `/` always divides as decimals; whole numbers
//! stay whole under `+`, `-` and `*` (a result beyond 32 bits is not guessed: the line
//! stays a note). settle works in double precision where the firmware uses single; the
//! difference is below one part in ten million.

use std::sync::Arc;

use super::machine::ConfigNote;
use crate::error::Location;

const BLOCK_KEYWORDS: [&str; 4] = ["if", "elif", "else", "while"];
const LINE_KEYWORDS: [&str; 8] = [
    "var", "global", "set", "echo", "abort", "break", "continue", "skip",
];

/// The text with what is not evaluated blanked, and a note for each part blanked.
#[derive(Debug)]
pub(crate) struct Unconditional {
    pub(crate) text: String,
    pub(crate) notes: Vec<ConfigNote>,
}

/// The code of a line: up to a `;` comment outside double quotes.
fn code(line: &str) -> &str {
    let mut quoted = false;
    for (i, c) in line.char_indices() {
        match c {
            '"' => quoted = !quoted,
            ';' if !quoted => return &line[..i],
            _ => {}
        }
    }
    line
}

/// A meta-command keyword starting `code` (already trimmed).
fn keyword(code: &str) -> Option<&str> {
    let end = code
        .find(|c: char| !c.is_ascii_lowercase())
        .unwrap_or(code.len());
    let word = &code[..end];
    let next = code[end..].chars().next();
    let ends_word = next.is_none_or(|c| !(c.is_ascii_alphanumeric() || c == '_' || c == '.'));
    (ends_word && (BLOCK_KEYWORDS.contains(&word) || LINE_KEYWORDS.contains(&word))).then_some(word)
}

/// A number as the expression parser holds it: whole (32 bits) or decimal.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Num {
    Int(i32),
    Float(f64),
}

impl Num {
    fn float(self) -> f64 {
        match self {
            Num::Int(i) => f64::from(i),
            Num::Float(f) => f,
        }
    }
}

/// An expression of numbers, operators and brackets, worked out; `None` for anything
/// else (a name, a function, a string, a division by zero, a whole number beyond 32 bits).
struct Constant<'a> {
    text: &'a [u8],
    pos: usize,
    /// Signs and brackets open around the operand being read: at most
    /// [`Constant::MAX_DEPTH`] (the reading recurses once per level).
    depth: usize,
}

impl Constant<'_> {
    fn eval(text: &str) -> Option<Num> {
        let mut p = Constant {
            text: text.as_bytes(),
            pos: 0,
            depth: 0,
        };
        let v = p.binary(0)?;
        p.skip_space();
        (p.pos == p.text.len()).then_some(v)
    }

    fn skip_space(&mut self) {
        while self.text.get(self.pos).is_some_and(u8::is_ascii_whitespace) {
            self.pos += 1;
        }
    }

    /// Operands joined by operators binding tighter than `level` (0: `+ -`, 1: `* /`).
    fn binary(&mut self, level: u8) -> Option<Num> {
        let mut v = if level == 0 {
            self.binary(1)?
        } else {
            self.unary()?
        };
        loop {
            self.skip_space();
            let op = match (level, self.text.get(self.pos)) {
                (0, Some(&c)) if c == b'+' || c == b'-' => c,
                (1, Some(&c)) if c == b'*' || c == b'/' => c,
                _ => return Some(v),
            };
            self.pos += 1;
            let w = if level == 0 {
                self.binary(1)?
            } else {
                self.unary()?
            };
            v = match (op, v, w) {
                (b'/', _, _) if w.float() == 0.0 => return None,
                (b'/', _, _) => Num::Float(v.float() / w.float()),
                (_, Num::Int(a), Num::Int(b)) => Num::Int(match op {
                    b'+' => a.checked_add(b)?,
                    b'-' => a.checked_sub(b)?,
                    _ => a.checked_mul(b)?,
                }),
                (b'+', _, _) => Num::Float(v.float() + w.float()),
                (b'-', _, _) => Num::Float(v.float() - w.float()),
                _ => Num::Float(v.float() * w.float()),
            };
        }
    }

    /// The most signs and brackets an operand may sit in: deeper is not worked out (the
    /// line stays a note) rather than read by a recursion as deep as the line is long.
    const MAX_DEPTH: usize = 64;

    fn unary(&mut self) -> Option<Num> {
        self.skip_space();
        let c = *self.text.get(self.pos)?;
        if !matches!(c, b'-' | b'+' | b'(') {
            return self.number();
        }
        if self.depth == Self::MAX_DEPTH {
            return None;
        }
        self.depth += 1;
        let v = self.signed_or_bracketed(c);
        self.depth -= 1;
        v
    }

    /// The operand after a sign or an opening bracket `c`.
    fn signed_or_bracketed(&mut self, c: u8) -> Option<Num> {
        match c {
            b'-' => {
                self.pos += 1;
                Some(match self.unary()? {
                    Num::Int(i) => Num::Int(i.checked_neg()?),
                    Num::Float(f) => Num::Float(-f),
                })
            }
            b'+' => {
                self.pos += 1;
                self.unary()
            }
            b'(' => {
                self.pos += 1;
                let v = self.binary(0)?;
                self.skip_space();
                (self.text.get(self.pos) == Some(&b')')).then(|| {
                    self.pos += 1;
                    v
                })
            }
            _ => None,
        }
    }

    /// Digits with at most one decimal point (`12`, `0.65`, `.5`).
    fn number(&mut self) -> Option<Num> {
        let start = self.pos;
        while self
            .text
            .get(self.pos)
            .is_some_and(|c| c.is_ascii_digit() || *c == b'.')
        {
            self.pos += 1;
        }
        let word = std::str::from_utf8(&self.text[start..self.pos]).ok()?;
        if word.contains('.') {
            word.parse::<f64>().ok().map(Num::Float)
        } else {
            word.parse::<i32>().ok().map(Num::Int)
        }
    }
}

/// `code` with each `{expression}` outside quotes replaced by its value, when every one
/// is numbers alone; `None` when one is not (or a brace is not closed).
fn constants_worked_out(code: &str) -> Option<String> {
    let mut out = String::with_capacity(code.len());
    let mut quoted = false;
    let mut rest = code;
    while let Some(c) = rest.chars().next() {
        if c == '{' && !quoted {
            let close = rest.find('}')?;
            let value = Constant::eval(&rest[1..close])?;
            match value {
                Num::Int(i) => out.push_str(&i.to_string()),
                Num::Float(f) => out.push_str(&f.to_string()),
            }
            rest = &rest[close + 1..];
            continue;
        }
        if c == '"' {
            quoted = !quoted;
        }
        out.push(c);
        rest = &rest[c.len_utf8()..];
    }
    Some(out)
}

fn has_expression(code: &str) -> bool {
    let mut quoted = false;
    code.chars().any(|c| {
        if c == '"' {
            quoted = !quoted;
        }
        c == '{' && !quoted
    })
}

/// A line as a note quotes it ([`crate::excerpt`]).
fn shown(line: &str) -> std::borrow::Cow<'_, str> {
    crate::excerpt(line, crate::QUOTED_CHARS)
}

/// Blanks what `text` (from `source`) holds that settle does not evaluate.
pub(crate) fn unconditional(text: &str, source: &Arc<str>) -> Unconditional {
    let at = |line: u64| Location {
        source_name: source.clone(),
        line,
        column: None,
    };
    let mut out = String::with_capacity(text.len());
    let mut notes = Vec::new();
    // The open block: its keyword line's indentation, first line, last line, text.
    let mut block: Option<(usize, u64, u64, String)> = None;
    let mut aborted = false;
    let close = |block: &mut Option<(usize, u64, u64, String)>, notes: &mut Vec<ConfigNote>| {
        if let Some((_, first, last, head)) = block.take() {
            let lines = if last > first {
                format!("lines {first}-{last}")
            } else {
                format!("line {first}")
            };
            notes.push(ConfigNote::at(
                at(first),
                format!(
                    "`{}` ({lines}) is not run: settle reads only unconditional commands and evaluates no conditions",
                    shown(&head)
                ),
            ));
        }
    };
    for (line, no) in text.split('\n').zip(1u64..) {
        let code = code(line).trim_end_matches('\r');
        let trimmed = code.trim();
        let keep = if aborted {
            false
        } else if trimmed.is_empty() {
            true
        } else {
            let indent = code.len() - code.trim_start().len();
            match &mut block {
                Some((level, _, last, _)) if indent > *level => {
                    *last = no;
                    false
                }
                _ => {
                    close(&mut block, &mut notes);
                    match keyword(trimmed) {
                        Some(k) if BLOCK_KEYWORDS.contains(&k) => {
                            block = Some((indent, no, no, trimmed.to_string()));
                            false
                        }
                        Some(k) => {
                            aborted = k == "abort" && indent == 0;
                            let what = if aborted {
                                "ends the file: nothing after it is read"
                            } else {
                                "is not evaluated"
                            };
                            notes.push(ConfigNote::at(
                                at(no),
                                format!("`{}` {what}", shown(trimmed)),
                            ));
                            false
                        }
                        None if has_expression(trimmed) => {
                            match constants_worked_out(code) {
                                Some(worked) => {
                                    out.push_str(&worked);
                                    out.push_str(&line[code.len()..]);
                                }
                                None => notes.push(ConfigNote::at(
                                    at(no),
                                    format!(
                                        "`{}` is not read: settle works out only {{expressions}} of numbers alone",
                                        shown(trimmed)
                                    ),
                                )),
                            }
                            false
                        }
                        None => true,
                    }
                }
            }
        };
        if keep {
            out.push_str(line);
        }
        out.push('\n');
    }
    close(&mut block, &mut notes);
    Unconditional { text: out, notes }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_meta_commands_and_expressions_are_blanked() {
        let text = "M92 X80 ; steps\nif boards[1].shortName == \"1LC\"\n  M92 E690\n\n  ; comment\n  M906 X1500\nelse\n  M92 E420\nM350 X16 ; after\nvar accel = 3000\nM201 X{var.accel}\nM550 P\"{not an expression}\"\nsetting_macro\nabort \"stop\"\nM92 X1\n";
        let src: Arc<str> = Arc::from("config.g");
        let u = unconditional(text, &src);
        let kept: Vec<(usize, &str)> = u
            .text
            .split('\n')
            .enumerate()
            .filter(|(_, l)| !l.trim().is_empty())
            .map(|(i, l)| (i + 1, l))
            .collect();
        assert_eq!(
            kept,
            [
                (1, "M92 X80 ; steps"),
                (5, "  ; comment"),
                (9, "M350 X16 ; after"),
                (12, "M550 P\"{not an expression}\""),
                (13, "setting_macro"),
            ]
        );
        let notes: Vec<String> = u.notes.iter().map(ToString::to_string).collect();
        assert_eq!(notes.len(), 5, "{notes:?}");
        assert!(
            notes[0].starts_with("config.g:2: `if boards[1]"),
            "{}",
            notes[0]
        );
        assert!(notes[0].contains("(lines 2-6)"), "{}", notes[0]);
        assert!(notes[1].contains("`else` (lines 7-8)"), "{}", notes[1]);
        assert!(
            notes[2].starts_with("config.g:10: `var accel"),
            "{}",
            notes[2]
        );
        assert!(notes[3].contains("expressions"), "{}", notes[3]);
        assert!(notes[4].contains("ends the file"), "{}", notes[4]);
    }

    #[test]
    fn expressions_of_numbers_are_worked_out() {
        let v = |t: &str| Constant::eval(t);
        assert_eq!(v("2800 * 0.65"), Some(Num::Float(2800.0 * 0.65)));
        assert_eq!(v("1 + 2 * 3"), Some(Num::Int(7)));
        assert_eq!(v("(1 + 2) * 3"), Some(Num::Int(9)));
        assert_eq!(v("10 - 4 - 3"), Some(Num::Int(3)));
        assert_eq!(v("7 / 2"), Some(Num::Float(3.5)));
        assert_eq!(v("-(2) * -.5"), Some(Num::Float(1.0)));
        for bad in [
            "var.x",
            "1 / 0",
            "2147483647 + 1",
            "(1",
            "1 2",
            "",
            "max(1, 2)",
            "1e3",
        ] {
            assert_eq!(v(bad), None, "{bad}");
        }
        // Signs and brackets to 64 levels are worked out; deeper is not read (a line of
        // 300,000 brackets or a million signs overflowed the stack).
        let nested = |n: usize| format!("{}1{}", "(".repeat(n), ")".repeat(n));
        assert_eq!(v(&nested(63)), Some(Num::Int(1)));
        assert_eq!(v(&format!("-{}", nested(63))), Some(Num::Int(-1)));
        assert_eq!(v(&nested(65)), None);
        assert_eq!(v(&nested(300_000)), None);
        assert_eq!(v(&format!("{}1", "-".repeat(1_000_000))), None);
        assert_eq!(v(&format!("{}1", "-".repeat(64))), Some(Num::Int(1)));
        // Such a line is a note that quotes its first 120 characters, not all of them.
        let src: Arc<str> = Arc::from("config.g");
        let long = format!("M906 X{{{}}}", nested(300_000));
        let u = unconditional(&long, &src);
        let note = u.notes[0].to_string();
        assert!(
            note.contains(&format!("`{}...`", &long[..120])),
            "{}",
            &note[..200]
        );
        assert!(note.len() < 300, "{} bytes", note.len());
        let src: Arc<str> = Arc::from("config.g");
        let u = unconditional(
            "M906 X{2800 * 0.65} Y{1+1}:{3} I30 ; {comment}\nM906 X{move.axes[0].current}\n",
            &src,
        );
        assert_eq!(
            u.text, "M906 X1820 Y2:3 I30 ; {comment}\n\n\n",
            "{:?}",
            u.notes
        );
        assert_eq!(u.notes.len(), 1);
        assert!(u.notes[0].to_string().starts_with("config.g:2:"));
    }
}
