//! The parts of a RepRapFirmware command file that settle does not evaluate, blanked out
//! (line numbers kept) with a note each: meta-commands (`if`, `elif`, `else`, `while` and
//! the lines indented under them, `var`, `global`, `set`, `echo`, `abort`, `break`,
//! `continue`, `skip`; the keywords of `src/GCodes/GCodeBuffer/StringParser.cpp`) and
//! commands with `{expressions}`. Only unconditional commands with literal values are
//! read: a conditional block's settings are not applied, whatever its condition would
//! give on the machine. A top-level `abort` ends the file, as it ends the firmware's
//! reading.

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

fn has_expression(code: &str) -> bool {
    let mut quoted = false;
    code.chars().any(|c| {
        if c == '"' {
            quoted = !quoted;
        }
        c == '{' && !quoted
    })
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
                    "`{head}` ({lines}) is not run: settle reads only unconditional commands and evaluates no conditions"
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
                            notes.push(ConfigNote::at(at(no), format!("`{trimmed}` {what}")));
                            false
                        }
                        None if has_expression(trimmed) => {
                            notes.push(ConfigNote::at(
                                at(no),
                                format!(
                                    "`{trimmed}` is not read: settle evaluates no {{expressions}}"
                                ),
                            ));
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
}
