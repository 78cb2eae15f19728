//! Klipper's configuration syntax: sections and options as Python's `configparser` reads
//! them with the settings Klipper gives it (`klippy/configfile.py`,
//! `ConfigFileReader._create_fileconfig`: `RawConfigParser(strict=False,
//! inline_comment_prefixes=(';', '#'))`).
//!
//! - `[name]` starts a section; the name is everything between the first `[` and the
//!   last `]` and is case-sensitive. A section named twice continues the first (strict off).
//! - `key: value` or `key = value` (the first `:` or `=` separates); keys are lower-cased
//!   (`optionxform`); an option set twice keeps the later value.
//! - A line indented deeper than its option's line continues the value (G-code macros);
//!   values are the lines joined by newlines, trailing white space removed; blank lines
//!   inside a value are kept.
//! - Comments: whole lines starting with `#` or `;`, and `;` after white space. Klipper
//!   cuts every line at its first `#` before configparser sees it, so `#` starts a comment
//!   anywhere.
//! - A `[DEFAULT]` section's options show in every section.
//!
//! Each call of [`parse_chunk`] is one `read_file` call: it starts outside any section, as
//! Klipper's reading does after each `[include]` line.

use std::sync::Arc;

use crate::error::{GcodeError, Location};

/// One option: its lower-cased key, its value lines and where it was set.
#[derive(Debug, Clone)]
pub(crate) struct Opt {
    pub(crate) key: String,
    lines: Vec<String>,
    pub(crate) at: Location,
}

impl Opt {
    /// The value as configparser gives it.
    pub(crate) fn value(&self) -> String {
        self.lines.join("\n").trim_end().to_string()
    }
}

/// One section with its options in the order first set.
#[derive(Debug, Clone)]
pub(crate) struct Section {
    pub(crate) name: String,
    /// Where the section was first named.
    pub(crate) at: Location,
    pub(crate) options: Vec<Opt>,
}

/// Sections in the order first named.
#[derive(Debug, Clone, Default)]
pub(crate) struct Store {
    sections: Vec<Section>,
}

const DEFAULT_SECTION: &str = "DEFAULT";

impl Store {
    pub(crate) fn sections(&self) -> &[Section] {
        &self.sections
    }

    pub(crate) fn section(&self, name: &str) -> Option<&Section> {
        self.sections.iter().find(|s| s.name == name)
    }

    /// The option `key` (lower case) of `section`, or of `[DEFAULT]`.
    pub(crate) fn get(&self, section: &str, key: &str) -> Option<&Opt> {
        let find = |name: &str| {
            self.section(name)
                .and_then(|s| s.options.iter().find(|o| o.key == key))
        };
        self.section(section)?;
        find(section).or_else(|| find(DEFAULT_SECTION))
    }

    /// configparser's `has_option` (a missing section has no options; `None` asks
    /// `[DEFAULT]`).
    pub(crate) fn has_option(&self, section: Option<&str>, key: &str) -> bool {
        let key = key.to_lowercase();
        match section {
            Some(s) if s != DEFAULT_SECTION => self.get(s, &key).is_some(),
            _ => self
                .section(DEFAULT_SECTION)
                .is_some_and(|d| d.options.iter().any(|o| o.key == key)),
        }
    }

    fn section_index(&mut self, name: &str, at: Location) -> usize {
        match self.sections.iter().position(|s| s.name == name) {
            Some(i) => i,
            None => {
                self.sections.push(Section {
                    name: name.to_string(),
                    at,
                    options: Vec::new(),
                });
                self.sections.len() - 1
            }
        }
    }
}

/// configparser's section header: `[`, at least one character, the last `]` of the line.
pub(crate) fn section_header(text: &str) -> Option<&str> {
    let rest = text.strip_prefix('[')?;
    let close = rest.rfind(']')?;
    (close > 0).then(|| &rest[..close])
}

/// Where an inline `;` comment starts: at the start or after white space.
fn inline_comment(line: &str) -> Option<usize> {
    let mut prev_space = true;
    for (i, c) in line.char_indices() {
        if c == ';' && prev_space {
            return Some(i);
        }
        prev_space = c.is_whitespace();
    }
    None
}

/// Reads lines (already cut at `#`, with their 1-based numbers in `source`) into `store`.
pub(crate) fn parse_chunk<'a>(
    store: &mut Store,
    source: &Arc<str>,
    lines: impl IntoIterator<Item = (u64, &'a str)>,
) -> Result<(), GcodeError> {
    let at = |line: u64| Location {
        source_name: source.clone(),
        line,
        column: None,
    };
    let mut section: Option<usize> = None;
    let mut option: Option<usize> = None;
    let mut indent_level = 0usize;
    for (no, line) in lines {
        let full_comment = {
            let t = line.trim();
            t.starts_with('#') || t.starts_with(';')
        };
        let comment = if full_comment {
            Some(0)
        } else {
            inline_comment(line)
        };
        let value = line[..comment.unwrap_or(line.len())].trim();
        if value.is_empty() {
            // A blank line inside a value stays in it (`empty_lines_in_values`), unless
            // the line held a comment.
            if let (None, Some(s), Some(o)) = (comment, section, option) {
                self::push_line(store, s, o, String::new());
            }
            continue;
        }
        let indent = line.len() - line.trim_start().len();
        if let (Some(s), Some(o)) = (section, option)
            && indent > indent_level
        {
            self::push_line(store, s, o, value.to_string());
            continue;
        }
        indent_level = indent;
        if let Some(name) = section_header(value) {
            section = Some(store.section_index(name, at(no)));
            option = None;
            continue;
        }
        let Some(s) = section else {
            return Err(GcodeError::ConfigSyntax {
                at: at(no),
                // Not echoed: a file that does not start as a configuration (a wrong
                // include, `/etc/shadow`) is not repeated on the terminal.
                what: "text before any [section]: a Klipper configuration file starts with a `[section]` header (is this a printer.cfg?)".to_string(),
            });
        };
        let Some(sep) = value.find([':', '=']) else {
            return Err(GcodeError::ConfigSyntax {
                at: at(no),
                what: format!(
                    "`{value}` is not `key: value`, `[section]`, a comment or an indented continuation"
                ),
            });
        };
        let key = value[..sep].trim_end().to_lowercase();
        if key.is_empty() {
            return Err(GcodeError::ConfigSyntax {
                at: at(no),
                what: format!(
                    "`{value}` has no option name before `{}`",
                    &value[sep..=sep]
                ),
            });
        }
        let first = value[sep + 1..].trim().to_string();
        let opts = &mut store.sections[s].options;
        let new = Opt {
            key,
            lines: vec![first],
            at: at(no),
        };
        option = Some(match opts.iter().position(|o| o.key == new.key) {
            Some(i) => {
                opts[i] = new;
                i
            }
            None => {
                opts.push(new);
                opts.len() - 1
            }
        });
    }
    Ok(())
}

fn push_line(store: &mut Store, section: usize, option: usize, line: String) {
    store.sections[section].options[option].lines.push(line);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Store, GcodeError> {
        let mut store = Store::default();
        let source: Arc<str> = Arc::from("t.cfg");
        let lines: Vec<(u64, String)> = text
            .split('\n')
            .zip(1..)
            .map(|(l, n)| (n, l.split('#').next().unwrap_or("").to_string()))
            .collect();
        parse_chunk(
            &mut store,
            &source,
            lines.iter().map(|(n, l)| (*n, l.as_str())),
        )?;
        Ok(store)
    }

    #[test]
    fn configparser_rules() {
        let s = parse(
            "[printer]\nKinematics = corexy ; comment\nmax_accel: 3000;not a comment\n\
             [gcode_macro X]\ngcode:\n  G28\n\n  G1 X1 # c\n; whole-line comment\nafter: 1\n\
             [printer]\nmax_velocity : 300\n  [not a section]\n[ spaced ]\n  max_accel: 5\nx=1\n",
        )
        .expect("valid");
        let v = |sec: &str, key: &str| s.get(sec, key).map(Opt::value);
        assert_eq!(v("printer", "kinematics").as_deref(), Some("corexy"));
        assert_eq!(
            v("printer", "max_accel").as_deref(),
            Some("3000;not a comment")
        );
        // Deeper indentation continues the value, even a `[...]` line.
        assert_eq!(
            v("printer", "max_velocity").as_deref(),
            Some("300\n[not a section]")
        );
        assert_eq!(
            v("gcode_macro X", "gcode").as_deref(),
            Some("\nG28\n\nG1 X1")
        );
        assert_eq!(v("gcode_macro X", "after").as_deref(), Some("1"));
        // An indented line right after a header is an option; the name keeps its spaces.
        assert_eq!(v(" spaced ", "max_accel").as_deref(), Some("5"));
        assert_eq!(v(" spaced ", "x").as_deref(), Some("1"));
        assert_eq!(s.get("printer", "max_accel").map(|o| o.at.line), Some(3));
        assert!(s.has_option(Some("printer"), "MAX_ACCEL"));
        assert!(!s.has_option(Some("nope"), "max_accel"));
    }

    #[test]
    fn defaults_and_errors() {
        let s = parse("[DEFAULT]\nmicrosteps: 16\n[stepper_x]\nstep_pin: PA1\n").expect("valid");
        assert_eq!(
            s.get("stepper_x", "microsteps").map(Opt::value).as_deref(),
            Some("16")
        );
        assert!(s.get("stepper_y", "microsteps").is_none());
        let e = parse("\nmax_accel: 3\n").expect_err("no section");
        assert_eq!(e.line(), Some(2));
        let e = parse("[printer]\nmax_accel 3\n").expect_err("no separator");
        assert_eq!(e.line(), Some(2));
        let e = parse("[printer]\n: 3\n").expect_err("no key");
        assert!(e.to_string().contains("no option name"), "{e}");
    }
}
