//! `report.html` of `settle tune`: the report's own text and tables (tune.md, so the two
//! agree), laid out with one section per axis holding that axis's tables and its Pareto
//! figure, a section of the exported files, and every candidate (rounded, sortable and
//! filterable; candidates.csv holds every digit).

use std::path::PathBuf;

use super::Outcome;
use crate::error::Error;
use crate::output::html::{Cell, Figure, Image, InputFile, Provenance, Report, Section, Table};

/// What the page is made of.
#[derive(Debug)]
pub struct Page<'a> {
    /// The scenario's name.
    pub name: &'a str,
    /// tune.md.
    pub markdown: &'a str,
    /// Every tuned axis's outcome.
    pub axes: &'a [(String, Outcome)],
    /// The Pareto figure (SVG file) of each axis, in the order of `axes`.
    pub figures: &'a [PathBuf],
    /// The exported files: name and text.
    pub exports: [(&'a str, &'a str); 5],
    /// Where the numbers come from.
    pub provenance: Provenance,
}

/// The report's Markdown split at the headings starting with `prefix` (`## `): the text
/// before the first, then each heading with its text.
fn split<'a>(md: &'a str, prefix: &str) -> (String, Vec<(&'a str, String)>) {
    let mut head = String::new();
    let mut parts: Vec<(&str, String)> = Vec::new();
    for line in md.lines() {
        if let Some(h) = line.strip_prefix(prefix) {
            parts.push((h.trim(), String::new()));
            continue;
        }
        let to = parts.last_mut().map_or(&mut head, |(_, t)| t);
        to.push_str(line);
        to.push('\n');
    }
    (head, parts)
}

/// The paragraphs and the tables of `text`: Markdown paragraphs (an image line, a code
/// block and bold marks left out), and each `| ... |` table titled `title` with the
/// paragraph just before it and those after it (up to the next table) as its note; the
/// paragraphs before the first table are returned apart.
fn blocks(text: &str, title: &str) -> (Vec<String>, Vec<Table>) {
    let mut intro: Vec<String> = Vec::new();
    let mut tables: Vec<Table> = Vec::new();
    let mut open: Option<Table> = None;
    let mut pending: Vec<String> = Vec::new();
    let mut para = String::new();
    let mut in_code = false;
    let flush = |para: &mut String, pending: &mut Vec<String>| {
        if !para.trim().is_empty() {
            pending.push(para.trim().replace("**", ""));
        }
        para.clear();
    };
    // The paragraphs since the last table: to its note, or to the intro.
    let settle = |pending: &mut Vec<String>, tables: &mut Vec<Table>, intro: &mut Vec<String>| {
        match tables.last_mut() {
            Some(t) => append(&mut t.note, pending),
            None => intro.append(pending),
        }
        pending.clear();
    };
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            in_code = !in_code;
            continue;
        }
        if in_code || line.starts_with("![") {
            continue;
        }
        let row: Option<Vec<String>> = line.trim_start().starts_with('|').then(|| {
            line.trim()
                .trim_matches('|')
                .split('|')
                .map(|c| c.trim().replace("**", ""))
                .collect()
        });
        match (row, open.as_mut()) {
            (Some(r), Some(t)) => {
                if !r.iter().all(|c| c.chars().all(|ch| "-:".contains(ch))) {
                    t.rows.push(r.into_iter().map(cell).collect());
                }
            }
            (Some(r), None) => {
                flush(&mut para, &mut pending);
                let before = pending.pop().unwrap_or_default();
                settle(&mut pending, &mut tables, &mut intro);
                open = Some(Table {
                    title: title.to_string(),
                    note: before,
                    header: r,
                    rows: Vec::new(),
                });
            }
            (None, _) => {
                if let Some(t) = open.take() {
                    tables.push(t);
                }
                if line.trim().is_empty() {
                    flush(&mut para, &mut pending);
                } else {
                    if !para.is_empty() {
                        para.push(' ');
                    }
                    para.push_str(line.trim());
                }
            }
        }
    }
    flush(&mut para, &mut pending);
    tables.extend(open);
    settle(&mut pending, &mut tables, &mut intro);
    (intro, tables)
}

fn append(note: &mut String, more: &[String]) {
    for p in more {
        if !note.is_empty() {
            note.push(' ');
        }
        note.push_str(p);
    }
}

/// A Markdown cell: a number when it parses as one (sorted as a number), else text.
fn cell(c: String) -> Cell {
    match c.parse::<f64>() {
        Ok(value) => Cell::Number { value, text: c },
        Err(_) => Cell::text(c),
    }
}

/// The tables of a `## ` part split further at its `### ` headings.
fn part_tables(text: &str) -> (Vec<String>, Vec<Table>) {
    let (intro, subs) = split(text, "### ");
    let (paragraphs, mut tables) = blocks(&intro, "");
    for (title, body) in subs {
        let (extra, t) = blocks(&body, title);
        if t.is_empty() {
            // A part without a table (a paragraph of its own): a note-only table would
            // be empty, so its text stays with the section's intro.
            tables.push(Table {
                title: title.to_string(),
                note: extra.join(" "),
                header: Vec::new(),
                rows: Vec::new(),
            });
        } else {
            tables.extend(t.into_iter().map(|mut t| {
                if !extra.is_empty() {
                    let mut note = extra.join(" ");
                    append(&mut note, std::slice::from_ref(&t.note));
                    t.note = note;
                }
                t
            }));
        }
    }
    tables.retain(|t| !t.header.is_empty() || !t.note.is_empty());
    (paragraphs, tables)
}

/// The page (see the module documentation).
pub fn page(p: Page<'_>) -> Result<String, Error> {
    let (head, parts) = split(p.markdown, "## ");
    let (_, head_tables) = blocks(&head, "");
    let mut intro: Vec<String> = head
        .lines()
        .filter(|l| l.starts_with("**Stand-in machine.**"))
        .map(|l| l.replace("**", ""))
        .collect();
    let mut tables: Vec<Table> = head_tables;
    let mut sections: Vec<Section> = Vec::new();
    for (title, body) in &parts {
        if let Some(axis) = title.strip_prefix("Axis ") {
            let k = p.axes.iter().position(|(a, _)| a == axis).unwrap_or(0);
            let (paragraphs, t) = part_tables(body);
            let figures = p
                .figures
                .get(k)
                .map(|f| Figure {
                    title: format!(
                        "Pareto front, axis {axis}: move time vs residual of every candidate"
                    ),
                    image: Image::SvgFile(f.clone()),
                })
                .into_iter()
                .collect();
            sections.push(Section {
                id: format!("axis-{}", axis.replace('+', "-")),
                title: (*title).to_string(),
                intro: paragraphs,
                tables: t,
                figures,
                texts: Vec::new(),
            });
        } else if *title == "Export" {
            sections.push(Section {
                id: "export".into(),
                title: "Export".into(),
                intro: vec!["The files written beside this report, to paste into the firmware's configuration.".into()],
                tables: Vec::new(),
                figures: Vec::new(),
                texts: p
                    .exports
                    .iter()
                    .map(|(name, text)| InputFile {
                        name: (*name).to_string(),
                        text: (*text).to_string(),
                    })
                    .collect(),
            });
        } else {
            let (paragraphs, mut t) = blocks(body, title);
            if t.is_empty() {
                intro.extend(paragraphs);
            } else {
                if let Some(first) = t.first_mut() {
                    let mut note = paragraphs.join(" ");
                    append(&mut note, std::slice::from_ref(&first.note));
                    first.note = note;
                }
                tables.append(&mut t);
            }
        }
    }
    let report = Report {
        title: format!("{} (tune)", p.name),
        intro,
        tables,
        sections,
        runs: Some(super::candidates::table(p.axes)),
        provenance: p.provenance,
        ..Report::default()
    };
    let mut bytes = Vec::new();
    let path = PathBuf::from(crate::output::sweep_files::REPORT);
    crate::output::html::render_to(&report, None, &(), &mut bytes, &path)?;
    String::from_utf8(bytes).map_err(|e| Error::input(&path, e.to_string()))
}
