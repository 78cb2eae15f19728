//! Reading a Klipper `printer.cfg` with everything it pulls in, as `klippy/configfile.py`
//! does (`ConfigFileReader`, `ConfigAutoSave.load_main_config`):
//!
//! - `\r\n` line ends become `\n`; each line is cut at its first `#`.
//! - `[include PATTERN]` (at the start of a line) reads the files PATTERN matches,
//!   relative to the including file's folder, sorted by name, in place: what they set
//!   overrides what came before and is overridden by what follows. A pattern with
//!   wildcards may match none. A pattern without wildcards must match a file for Klipper
//!   (`_resolve_include` raises "Include file ... does not exist"), and a link to nothing
//!   fails when Klipper opens it; settle reads on without such a file and lists each one
//!   as a note (file and line of the `[include]`): a configuration copied off the printer
//!   (a backup repository) lacks the files that were links out of the configuration
//!   folder (KAMP, Happy Hare, mainsail.cfg, moonraker-timelapse), and what they would
//!   set is then not known. Included files may include others; a file that is already
//!   being read is an include cycle.
//! - The SAVE_CONFIG block: everything after the exact three-line header
//!   `#*# <---------------------- SAVE_CONFIG ---------------------->` ... at the end of
//!   the main file, each line prefixed `#*# `. It is read after the rest (includes
//!   included), with one rule that surprises: an option the rest of the configuration
//!   already sets is dropped from the block (`_strip_duplicates`), so the value outside
//!   the block wins. (`SAVE_CONFIG` itself comments out such lines of the main file when
//!   it writes the block, and refuses to save over a value set in an included file.) A
//!   block with lines that lack the prefix, or a second header, is ignored whole, as
//!   Klipper ignores it with a warning in its log.

use std::path::{Component, Path, PathBuf};
use std::sync::Arc;

use super::budget::Budget;
use super::glob::{glob, has_magic};
use super::ini::{Store, parse_chunk, section_header};
use super::machine::ConfigNote;
use crate::error::{GcodeError, Location};

/// The header line of the SAVE_CONFIG block, with the newline before it and the two lines
/// after it (`AUTOSAVE_HEADER` in `klippy/configfile.py`).
pub(crate) const AUTOSAVE_HEADER: &str = "\n#*# <---------------------- SAVE_CONFIG ---------------------->\n#*# DO NOT EDIT THIS BLOCK OR BELOW. The contents are auto-generated.\n#*#\n";

/// Everything read: the options, the files in the order read, and notes.
#[derive(Debug)]
pub(crate) struct Loaded {
    pub(crate) store: Store,
    pub(crate) files: Vec<PathBuf>,
    pub(crate) notes: Vec<ConfigNote>,
    /// The `[include]`s skipped because their file is not there: where, and the include.
    pub(crate) skipped: Vec<(Location, String)>,
    /// The options the SAVE_CONFIG block sets (after its duplicates are dropped), as
    /// `(section, option)` in lower case: Klipper never refuses these as unused
    /// (`ConfigValidate.check_unused` adds them to the options read).
    pub(crate) autosave: Vec<(String, String)>,
}

/// `path` made absolute and normalised lexically (Python's `os.path.abspath`).
pub(crate) fn absolute(path: &Path) -> PathBuf {
    let joined = match std::env::current_dir() {
        Ok(cwd) if path.is_relative() => cwd.join(path),
        _ => path.to_path_buf(),
    };
    let mut out = PathBuf::new();
    for c in joined.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                out.pop();
            }
            other => out.push(other),
        }
    }
    out
}

struct Ctx {
    store: Store,
    budget: Budget,
    files: Vec<PathBuf>,
    /// Files being read (absolute), outermost first.
    stack: Vec<PathBuf>,
    notes: Vec<ConfigNote>,
    skipped: Vec<(Location, String)>,
}

/// Reads `main` (its text given, or read from disk) with its includes and SAVE_CONFIG
/// block.
pub(crate) fn load(main: &Path, text: Option<&str>) -> Result<Loaded, GcodeError> {
    let mut budget = Budget::new();
    let data = match text {
        Some(t) => t.replace("\r\n", "\n"),
        None => budget.main(main)?.replace("\r\n", "\n"),
    };
    let source: Arc<str> = Arc::from(main.display().to_string());
    let mut notes = Vec::new();
    let (regular, autosave) = split_autosave(&data, &source, &mut notes);
    let mut ctx = Ctx {
        store: Store::default(),
        budget,
        files: vec![main.to_path_buf()],
        stack: vec![absolute(main)],
        notes,
        skipped: Vec::new(),
    };
    parse_file(&mut ctx, main, regular, &source)?;
    let mut notes = std::mem::take(&mut ctx.notes);
    let mut autosave_options = Vec::new();
    if let Some(mut lines) = autosave {
        strip_duplicates(&mut lines, &ctx.store, &source, &mut notes);
        let cut: Vec<(u64, &str)> = lines.iter().map(|(n, l)| (*n, cut_comment(l))).collect();
        let mut block = Store::default();
        parse_chunk(&mut block, &source, cut.iter().copied())?;
        autosave_options = block
            .sections()
            .iter()
            .flat_map(|s| {
                s.options
                    .iter()
                    .map(|o| (s.name.to_lowercase(), o.key.clone()))
            })
            .collect();
        parse_chunk(&mut ctx.store, &source, cut)?;
    }
    if let Some(s) = ctx
        .store
        .sections()
        .iter()
        .find(|s| s.name.starts_with("include "))
    {
        return Err(GcodeError::ConfigSyntax {
            at: s.at.clone(),
            what: format!(
                "[{}] is not at the start of its line: Klipper reads an include only there (klippy/configfile.py)",
                s.name
            ),
        });
    }
    Ok(Loaded {
        store: ctx.store,
        files: ctx.files,
        notes,
        skipped: ctx.skipped,
        autosave: autosave_options,
    })
}

fn cut_comment(line: &str) -> &str {
    line.find('#').map_or(line, |i| &line[..i])
}

/// Splits the main file's text into the part before the SAVE_CONFIG block and the block's
/// lines (prefix removed, with their line numbers); `None` when there is no usable block.
fn split_autosave<'a>(
    data: &'a str,
    source: &Arc<str>,
    notes: &mut Vec<ConfigNote>,
) -> (&'a str, Option<Vec<(u64, String)>>) {
    let Some(pos) = data.find(AUTOSAVE_HEADER) else {
        return (data, None);
    };
    let regular = &data[..pos];
    let rest = &data[pos + AUTOSAVE_HEADER.len()..];
    let lead = rest.len() - rest.trim_start().len();
    let first_line = 1 + data[..pos + AUTOSAVE_HEADER.len() + lead]
        .matches('\n')
        .count() as u64;
    let block = rest.trim();
    let header_line = 2 + data[..pos].matches('\n').count() as u64;
    let mut ignore = |why: &str| {
        notes.push(ConfigNote::at(
            Location {
                source_name: source.clone(),
                line: header_line,
                column: None,
            },
            format!("the SAVE_CONFIG block is ignored, as Klipper ignores it: {why}"),
        ));
    };
    if regular.contains("\n#*# ") || block.contains(AUTOSAVE_HEADER) {
        ignore("`#*# ` lines before its header, or a second header");
        return (data, None);
    }
    let mut lines = Vec::new();
    for (line, no) in block.split('\n').zip(first_line..) {
        if !block.is_empty()
            && (!line.starts_with("#*#") || (line.len() >= 4 && !line.starts_with("#*# ")))
        {
            ignore(&format!("line {no} does not start with `#*# `"));
            return (data, None);
        }
        lines.push((no, line.get(4..).unwrap_or("").to_string()));
    }
    (regular, Some(lines))
}

/// Drops the block's options that the rest of the configuration sets (with the lines that
/// continue them), as `_strip_duplicates` comments them out.
fn strip_duplicates(
    lines: &mut [(u64, String)],
    store: &Store,
    source: &Arc<str>,
    notes: &mut Vec<ConfigNote>,
) {
    let mut section: Option<String> = None;
    let mut dropping = false;
    for (no, line) in lines.iter_mut() {
        let pruned = line
            .find(['#', ';'])
            .map_or(line.as_str(), |i| &line[..i])
            .trim_end();
        if pruned.is_empty() {
            continue;
        }
        if pruned.starts_with(char::is_whitespace) {
            if dropping {
                line.clear();
            }
            continue;
        }
        dropping = false;
        if let Some(inner) = pruned.strip_prefix('[') {
            // `pruned_line[1:-1].strip()`: the last character goes, whatever it is.
            let last = inner.chars().last().map_or(0, char::len_utf8);
            section = Some(inner[..inner.len() - last].trim().to_string());
            continue;
        }
        let field = pruned
            .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
            .map_or(pruned, |i| &pruned[..i]);
        if store.has_option(section.as_deref(), field) {
            let sec = section.as_deref().unwrap_or("DEFAULT");
            let kept = store
                .get(sec, &field.to_lowercase())
                .map(|o| o.at.to_string());
            notes.push(ConfigNote::at(
                Location {
                    source_name: source.clone(),
                    line: *no,
                    column: None,
                },
                format!(
                    "SAVE_CONFIG's [{sec}] {field} is not used: the configuration sets it outside the block{}, and Klipper keeps that value",
                    kept.map(|k| format!(" ({k})")).unwrap_or_default()
                ),
            ));
            dropping = true;
            line.clear();
        }
    }
}

/// Reads one file's text into the store, following its includes.
fn parse_file(ctx: &mut Ctx, path: &Path, data: &str, source: &Arc<str>) -> Result<(), GcodeError> {
    let mut buf: Vec<(u64, &str)> = Vec::new();
    for (line, no) in data.split('\n').zip(1u64..) {
        let cut = cut_comment(line);
        match section_header(cut).and_then(|h| h.strip_prefix("include ")) {
            Some(spec) => {
                parse_chunk(&mut ctx.store, source, buf.drain(..))?;
                let at = Location {
                    source_name: source.clone(),
                    line: no,
                    column: None,
                };
                include(ctx, path, spec.trim(), &at)?;
            }
            None => buf.push((no, cut)),
        }
    }
    parse_chunk(&mut ctx.store, source, buf)
}

/// The note for an included file that cannot be read because it is not there.
fn missing_include(at: &Location, what: &str, path: &Path, why: &str) -> ConfigNote {
    ConfigNote::at(
        at.clone(),
        format!(
            "{what} skipped: `{}` {why}; Klipper would refuse to start without it, settle reads on without it, so whatever it sets is not known here",
            path.display()
        ),
    )
}

fn include(ctx: &mut Ctx, from: &Path, spec: &str, at: &Location) -> Result<(), GcodeError> {
    let pattern = from.parent().unwrap_or(Path::new("")).join(spec);
    let what = format!("[include {spec}]");
    let mut names = glob(&pattern);
    if names.is_empty() && !has_magic(&pattern.to_string_lossy()) {
        ctx.notes
            .push(missing_include(at, &what, &pattern, "is not there"));
        ctx.skipped.push((at.clone(), what));
        return Ok(());
    }
    ctx.budget.reserve(names.len(), at, &what)?;
    names.sort_by(|a, b| a.to_string_lossy().cmp(&b.to_string_lossy()));
    for name in names {
        // A link to nothing (`glob` lists links, as Python's does).
        if std::fs::symlink_metadata(&name).is_ok_and(|m| m.file_type().is_symlink())
            && std::fs::metadata(&name).is_err()
        {
            ctx.notes
                .push(missing_include(at, &what, &name, "is a link to nothing"));
            ctx.skipped.push((at.clone(), what.clone()));
            continue;
        }
        let abs = absolute(&name);
        if ctx.stack.contains(&abs) {
            let mut chain: Vec<String> =
                ctx.stack.iter().map(|p| p.display().to_string()).collect();
            chain.push(abs.display().to_string());
            return Err(GcodeError::IncludeCycle {
                at: at.clone(),
                path: name.display().to_string(),
                chain: chain.join(" -> "),
            });
        }
        let text = ctx.budget.read(&name, at, &what)?.replace("\r\n", "\n");
        let source: Arc<str> = Arc::from(name.display().to_string());
        ctx.files.push(name.clone());
        ctx.stack.push(abs);
        parse_file(ctx, &name, &text, &source)?;
        ctx.stack.pop();
    }
    Ok(())
}
