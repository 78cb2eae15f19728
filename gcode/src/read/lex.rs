//! One line of G-code into a command word and its (still unparsed) parameter text.
//!
//! Accepted around the command: a line number `N123`, a checksum `*45` (verified: the XOR
//! of the line's bytes before `*`, as in the RepRap host protocol), `;` comments to the end
//! of the line and `( )` comments, a lone `%` (tape marker). Parameter values may be
//! double-quoted strings (RepRapFirmware's `M593 P"zvd"`); `;` and `(` inside quotes are
//! text.

/// What a line holds.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum LineKind<'a> {
    /// Nothing but white space (or a line number / checksum).
    Blank,
    /// Only a comment: its text after `;` (or inside the parentheses).
    Comment(&'a str),
    /// A `%` program delimiter.
    Percent,
    /// A letter-number command (`G1`, `M204`, `T0`, `G92.1`) and its parameter text.
    Code {
        /// The upper-case command letter.
        letter: u8,
        /// The command number.
        number: u32,
        /// The sub-code after a dot (`G92.1` -> 1).
        sub: Option<u32>,
        /// The text after the command word, comments and checksum removed.
        args: &'a str,
        /// 0-based byte offset of `args` in the original line (for error columns).
        args_at: usize,
    },
    /// A named command (`SET_VELOCITY_LIMIT`, a Klipper macro, an RRF meta command).
    Extended {
        /// The command name as written.
        name: &'a str,
        /// The text after the name.
        args: &'a str,
        /// 0-based byte offset of `args` in the original line.
        args_at: usize,
    },
}

/// Why a line is not G-code.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum LexError {
    /// A control character at this 0-based byte offset.
    Control { at: usize, byte: u8 },
    /// Malformed text at this 0-based byte offset.
    Syntax { at: usize, what: &'static str },
    /// A checksum that does not match.
    Checksum { at: usize, found: u32, computed: u8 },
}

/// A line's code: the text after the line number, its comments cut out.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Code<'a> {
    /// The code text (comments blanked byte for byte, so offsets match the line); starts
    /// at `at`, which is past any line number and white space.
    pub(crate) text: &'a str,
    /// 0-based byte offset of the first code character in `text` (= in the line).
    pub(crate) at: usize,
    /// The `;` comment, or the first `( )` comment.
    pub(crate) comment: Option<&'a str>,
}

impl Code<'_> {
    /// Whether the line holds nothing but comments and white space.
    pub(crate) fn is_empty(&self) -> bool {
        self.at == self.text.len()
    }
}

/// Cuts `line` into its code and comment (checksum verified, line number skipped).
/// `scratch` receives the code text when parenthesised comments must be cut out of it (the
/// common case borrows from `line`).
pub(crate) fn code<'a>(line: &'a str, scratch: &'a mut String) -> Result<Code<'a>, LexError> {
    let bytes = line.as_bytes();
    // One pass: control characters anywhere, and (outside quotes) the `;` comment, any
    // `(` comment and any `*` that may start a checksum.
    let mut in_quote = false;
    let mut code_end = bytes.len();
    let (mut has_paren, mut has_star) = (false, false);
    for (i, &b) in bytes.iter().enumerate() {
        match b {
            0..0x20 | 0x7f if b != b'\t' => return Err(LexError::Control { at: i, byte: b }),
            b'"' => in_quote = !in_quote,
            b';' if !in_quote && code_end == bytes.len() => code_end = i,
            b'(' if !in_quote && code_end == bytes.len() => has_paren = true,
            b'*' if code_end == bytes.len() => has_star = true,
            _ => {}
        }
    }
    let comment = (code_end < bytes.len()).then(|| &line[code_end + 1..]);
    let mut code = &line[..code_end];
    // A trailing `*nn` checksum over the bytes before the `*`.
    let trimmed = code.trim_end();
    if let Some(star) = trimmed.rfind('*').filter(|_| has_star) {
        let digits = &trimmed[star + 1..];
        if !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit()) {
            let computed = bytes[..star].iter().fold(0u8, |acc, &b| acc ^ b);
            let found: u32 = digits.parse().unwrap_or(u32::MAX);
            if found != u32::from(computed) {
                return Err(LexError::Checksum {
                    at: star,
                    found,
                    computed,
                });
            }
            code = &line[..star];
        }
    }
    // Offsets into `code` map to the line one to one unless parentheses are cut out.
    let mut paren_comment = None;
    let code: &'a str = if has_paren {
        cut_parentheses(code, scratch, &mut paren_comment)?;
        let s: &'a String = scratch;
        s.as_str()
    } else {
        code
    };
    let cb = code.as_bytes();
    let mut i = skip_ws(cb, 0);
    // A line number `N123`.
    if i < cb.len()
        && cb[i].eq_ignore_ascii_case(&b'N')
        && cb.get(i + 1).is_some_and(u8::is_ascii_digit)
    {
        i += 1;
        while i < cb.len() && cb[i].is_ascii_digit() {
            i += 1;
        }
        i = skip_ws(cb, i);
    }
    Ok(Code {
        text: code,
        at: i,
        comment: comment.or(paren_comment),
    })
}

/// Lexes `line` (see [`code`] for `scratch`).
pub(crate) fn lex<'a>(line: &'a str, scratch: &'a mut String) -> Result<LineKind<'a>, LexError> {
    let c = code(line, scratch)?;
    let (code, cb, i) = (c.text, c.text.as_bytes(), c.at);
    if c.is_empty() {
        return Ok(match c.comment {
            Some(c) => LineKind::Comment(c),
            None => LineKind::Blank,
        });
    }
    if cb[i] == b'%' && skip_ws(cb, i + 1) == cb.len() {
        return Ok(LineKind::Percent);
    }
    let start = i;
    if !(cb[i].is_ascii_alphabetic() || cb[i] == b'_') {
        return Err(LexError::Syntax {
            at: start,
            what: "expected a command (a letter and a number like G1, or a name like SET_VELOCITY_LIMIT)",
        });
    }
    if cb[i].is_ascii_alphabetic() && cb.get(i + 1).is_some_and(u8::is_ascii_digit) {
        let letter = cb[i].to_ascii_uppercase();
        let (number, j) = digits_u32(cb, i + 1).ok_or(LexError::Syntax {
            at: start,
            what: "command number too large",
        })?;
        let (sub, j) = if cb.get(j) == Some(&b'.') && cb.get(j + 1).is_some_and(u8::is_ascii_digit)
        {
            let (s, k) = digits_u32(cb, j + 1).ok_or(LexError::Syntax {
                at: j,
                what: "command sub-code too large",
            })?;
            (Some(s), k)
        } else {
            (None, j)
        };
        return Ok(LineKind::Code {
            letter,
            number,
            sub,
            args: &code[j..],
            args_at: j,
        });
    }
    let mut j = i;
    while j < cb.len() && (cb[j].is_ascii_alphanumeric() || cb[j] == b'_') {
        j += 1;
    }
    Ok(LineKind::Extended {
        name: &code[start..j],
        args: &code[j..],
        args_at: j,
    })
}

/// Copies `code` into `scratch` with each `( ... )` comment blanked byte for byte (so
/// offsets still match the line); the first comment's text goes to `first`.
fn cut_parentheses<'a>(
    code: &'a str,
    scratch: &mut String,
    first: &mut Option<&'a str>,
) -> Result<(), LexError> {
    scratch.clear();
    let mut in_quote = false;
    let mut rest = code;
    let mut offset = 0;
    while let Some(c) = rest.chars().next() {
        if c == '"' {
            in_quote = !in_quote;
        }
        if c == '(' && !in_quote {
            let close = rest.find(')').ok_or(LexError::Syntax {
                at: offset,
                what: "`(` comment without `)`",
            })?;
            if first.is_none() {
                *first = Some(&rest[1..close]);
            }
            scratch.extend(std::iter::repeat_n(' ', close + 1));
            rest = &rest[close + 1..];
            offset += close + 1;
            continue;
        }
        scratch.push(c);
        rest = &rest[c.len_utf8()..];
        offset += c.len_utf8();
    }
    Ok(())
}

pub(crate) fn skip_ws(b: &[u8], mut i: usize) -> usize {
    while i < b.len() && (b[i] == b' ' || b[i] == b'\t') {
        i += 1;
    }
    i
}

fn digits_u32(b: &[u8], mut i: usize) -> Option<(u32, usize)> {
    let mut v: u32 = 0;
    while i < b.len() && b[i].is_ascii_digit() {
        v = v.checked_mul(10)?.checked_add(u32::from(b[i] - b'0'))?;
        i += 1;
    }
    Some((v, i))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kind(line: &str) -> Result<LineKind<'_>, LexError> {
        // Leak the scratch: a test helper only.
        let scratch: &'static mut String = Box::leak(Box::default());
        lex(line, scratch)
    }

    #[test]
    fn commands_comments_numbers_checksums() {
        assert_eq!(kind("   ").expect("test input"), LineKind::Blank);
        assert_eq!(
            kind(";LAYER:3").expect("test input"),
            LineKind::Comment("LAYER:3")
        );
        assert_eq!(
            kind("(just a note)").expect("test input"),
            LineKind::Comment("just a note")
        );
        assert_eq!(kind("%").expect("test input"), LineKind::Percent);
        match kind("N12 g01X1.5 ; move").expect("test input") {
            LineKind::Code {
                letter,
                number,
                sub,
                args,
                ..
            } => {
                assert_eq!((letter, number, sub, args), (b'G', 1, None, "X1.5 "));
            }
            other => panic!("{other:?}"),
        }
        match kind("G92.1").expect("test input") {
            LineKind::Code { number, sub, .. } => assert_eq!((number, sub), (92, Some(1))),
            other => panic!("{other:?}"),
        }
        match kind("SET_VELOCITY_LIMIT ACCEL=3000").expect("test input") {
            LineKind::Extended { name, args, .. } => {
                assert_eq!((name, args), ("SET_VELOCITY_LIMIT", " ACCEL=3000"))
            }
            other => panic!("{other:?}"),
        }
        // "N1 G1 X1" has checksum 0x4e ^ ... computed below by the same rule.
        let body = "N1 G1 X1";
        let cs = body.bytes().fold(0u8, |a, b| a ^ b);
        let good = format!("{body}*{cs}");
        assert!(matches!(
            kind(&good).expect("test input"),
            LineKind::Code { number: 1, .. }
        ));
        let bad = format!("{body}*{}", cs ^ 1);
        assert!(matches!(kind(&bad), Err(LexError::Checksum { .. })));
        match kind("G1 X1 (half) Y2").expect("test input") {
            LineKind::Code { args, .. } => assert_eq!(args, " X1        Y2"),
            other => panic!("{other:?}"),
        }
        match kind("M593 P\"zv;d\" F40 ; c").expect("test input") {
            LineKind::Code { args, .. } => assert_eq!(args, " P\"zv;d\" F40 "),
            other => panic!("{other:?}"),
        }
        assert!(matches!(
            kind("G1 X1\u{1}"),
            Err(LexError::Control { at: 5, byte: 1 })
        ));
        assert!(matches!(kind("#!x"), Err(LexError::Syntax { at: 0, .. })));
    }
}
