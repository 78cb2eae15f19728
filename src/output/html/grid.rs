//! A [`Table`] as HTML: a real `<table>` that reads without JavaScript and prints, and that
//! the page's script makes sortable, filterable and paged.
//!
//! Small tables are written as DOM rows. A table of more than [`LAZY_ROWS`] plain rows (text
//! and numbers whose shown text is their exact value) is written inside `<noscript>`: with
//! JavaScript off the browser parses it as the same table; with JavaScript on it stays
//! unparsed text that the script splits into rows itself and shows one page at a time, so a
//! table of 100,000 runs costs no DOM nodes beyond the visible page.

use super::Out;
use super::escape::push_escaped;
use super::model::{Cell, Table};

/// Above this many rows a plain table is written for the script to page (see the module
/// doc). Parsing a row of about 25 cells into the DOM costs a browser tens of microseconds,
/// so 5,000 DOM rows open in a fraction of a second.
pub const LAZY_ROWS: usize = 5_000;

/// Whether column `j` sorts as numbers: all its cells are numbers or empty, and one is a
/// number.
fn numeric_column(t: &Table, j: usize) -> bool {
    let mut any = false;
    for row in &t.rows {
        match row.get(j) {
            Some(Cell::Number { .. }) => any = true,
            None => {}
            Some(Cell::Text(s)) if s.is_empty() => {}
            Some(_) => return false,
        }
    }
    any
}

/// The sort key of a number cell when its shown text does not parse to exactly its value
/// (e.g. `71.2 ms`, or a rounded value): the script sorts by this instead of the text.
fn sort_key(cell: &Cell) -> Option<String> {
    match cell {
        Cell::Number { value, text } => {
            let same = text
                .parse::<f64>()
                .is_ok_and(|x| x.to_bits() == value.to_bits() || (x.is_nan() && value.is_nan()));
            (!same).then(|| value.to_string())
        }
        _ => None,
    }
}

/// Whether every cell can be written as a bare `<td>text` (the form the script splits).
fn plain(t: &Table) -> bool {
    t.rows
        .iter()
        .flatten()
        .all(|c| !matches!(c, Cell::Link { .. }) && sort_key(c).is_none())
}

/// Write table `t` as a section with id `id`: heading, note, then the grid.
pub(crate) fn push_table(out: &mut impl Out, id: &str, t: &Table) {
    push_table_at(out, id, t, "h2");
}

/// [`push_table`] with the heading element `h` (`h3` for a table inside a section).
pub(crate) fn push_table_at(out: &mut impl Out, id: &str, t: &Table, h: &str) {
    let numeric: Vec<bool> = (0..t.header.len()).map(|j| numeric_column(t, j)).collect();
    let lazy = t.rows.len() > LAZY_ROWS && plain(t);
    push_head(out, id, &t.title, &t.note, &t.header, &numeric, lazy, h);
    for row in &t.rows {
        push_row(out, row, t.header.len(), &numeric, lazy);
    }
    push_tail(out, lazy);
}

/// Write table `t` (its rows left out) as [`push_table`] writes it with rows `row(0)`,
/// `row(1)`, ... up to the first `None`, one row at a time (two passes: the columns' types
/// first), so no row is kept.
pub(crate) fn push_made_table(
    out: &mut impl Out,
    id: &str,
    t: &Table,
    row: impl Fn(usize) -> Option<Vec<Cell>>,
) {
    let columns = t.header.len();
    // numeric_column and plain, a row at a time.
    let mut any = vec![false; columns];
    let mut other = vec![false; columns];
    let mut plain = true;
    let mut rows = 0;
    while let Some(r) = row(rows) {
        for (j, cell) in r.iter().enumerate().take(columns) {
            match cell {
                Cell::Number { .. } => any[j] = true,
                Cell::Text(s) if s.is_empty() => {}
                _ => other[j] = true,
            }
        }
        plain &= r
            .iter()
            .all(|c| !matches!(c, Cell::Link { .. }) && sort_key(c).is_none());
        rows += 1;
    }
    let numeric: Vec<bool> = any.iter().zip(&other).map(|(a, o)| *a && !o).collect();
    let lazy = rows > LAZY_ROWS && plain;
    push_head(out, id, &t.title, &t.note, &t.header, &numeric, lazy, "h2");
    for k in 0..rows {
        if let Some(r) = row(k) {
            push_row(out, &r, columns, &numeric, lazy);
        }
    }
    push_tail(out, lazy);
}

/// Write CSV text as [`push_table`] writes `Table::from_csv(title, text)`, one record at a
/// time (two passes over the text; no row kept), so a runs table of 100,000 runs costs no
/// memory per run. Nothing is written, and `false` returned, when `from_csv` would fail.
///
/// A table from CSV is always plain: its cells are text, or numbers whose text is the
/// value they were parsed from.
pub(crate) fn push_csv_table(out: &mut impl Out, id: &str, title: &str, text: &str) -> bool {
    let Some((header, numeric, rows)) = super::csv::shape(text) else {
        return false;
    };
    let lazy = rows > LAZY_ROWS;
    push_head(out, id, title, "", &header, &numeric, lazy, "h2");
    for r in super::csv::Records::new(text).skip(1) {
        let Ok((_, row)) = r else { break };
        push_row(
            out,
            &super::csv::typed(row, &numeric),
            header.len(),
            &numeric,
            lazy,
        );
    }
    push_tail(out, lazy);
    true
}

/// The section's heading, note and the table's head, up to `<tbody>`.
#[allow(clippy::too_many_arguments)]
fn push_head(
    out: &mut impl Out,
    id: &str,
    title: &str,
    note: &str,
    header: &[String],
    numeric: &[bool],
    lazy: bool,
    h: &str,
) {
    out.push_str("<section class=\"table\" id=\"");
    push_escaped(out, id);
    let _ = write!(out, "\">\n<{h}>");
    push_escaped(out, title);
    let _ = writeln!(out, "</{h}>");
    if !note.is_empty() {
        out.push_str("<p class=\"note\">");
        push_escaped(out, note);
        out.push_str("</p>\n");
    }
    out.push_str(if lazy {
        "<div class=\"grid\" data-lazy>\n<noscript>"
    } else {
        "<div class=\"grid\">\n"
    });
    out.push_str("<div class=\"scroll\"><table class=\"data\">\n<thead><tr>");
    for (name, &num) in header.iter().zip(numeric) {
        out.push_str(if num {
            "<th data-type=\"num\">"
        } else {
            "<th>"
        });
        push_escaped(out, name);
        out.push_str("</th>");
    }
    out.push_str("</tr></thead>\n<tbody>\n");
}

/// One row (padded with empty cells to `columns`).
fn push_row(out: &mut impl Out, row: &[Cell], columns: usize, numeric: &[bool], lazy: bool) {
    out.push_str("<tr>");
    for j in 0..row.len().max(columns) {
        let empty = Cell::Text(String::new());
        let cell = row.get(j).unwrap_or(&empty);
        push_cell(out, cell, lazy, numeric.get(j).copied().unwrap_or(false));
    }
    out.push_str("</tr>\n");
}

/// The end of the table and its section.
fn push_tail(out: &mut impl Out, lazy: bool) {
    out.push_str("</tbody>\n</table></div>");
    if lazy {
        out.push_str("</noscript>");
    }
    out.push_str("\n</div>\n</section>\n");
}

/// One cell; `</td>` is implied by the next cell or the row's `</tr>`. In a lazy table every
/// cell is a bare `<td>` (the script adds the number class when it shows a row).
fn push_cell(out: &mut impl Out, cell: &Cell, lazy: bool, numeric: bool) {
    if lazy {
        out.push_str("<td>");
        push_escaped(out, cell.shown());
        return;
    }
    out.push_str(if numeric { "<td class=\"n\"" } else { "<td" });
    if let Some(key) = sort_key(cell) {
        out.push_str(" data-v=\"");
        push_escaped(out, &key);
        out.push('"');
    }
    out.push('>');
    match cell {
        Cell::Link { text, href } => {
            out.push_str("<a href=\"");
            push_escaped(out, href);
            out.push_str("\">");
            push_escaped(out, text);
            out.push_str("</a>");
        }
        other => push_escaped(out, other.shown()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(rows: usize, cell: impl Fn(usize) -> Cell) -> Table {
        Table {
            title: "T".into(),
            note: String::new(),
            header: vec!["a".into(), "b".into()],
            rows: (0..rows)
                .map(|i| vec![cell(i), Cell::text("x<y")])
                .collect(),
        }
    }

    #[test]
    fn small_tables_are_dom_rows_with_sort_keys_where_text_is_not_the_value() {
        let t = table(2, |i| Cell::Number {
            value: i as f64 + 0.25,
            text: format!("{:.1}", i as f64 + 0.25),
        });
        let mut out = String::new();
        push_table(&mut out, "t1", &t);
        assert!(out.contains("<th data-type=\"num\">a</th><th>b</th>"));
        assert!(out.contains("<tr><td class=\"n\" data-v=\"0.25\">0.2<td>x&lt;y</tr>"));
        assert!(!out.contains("noscript"));
    }

    #[test]
    fn large_plain_tables_are_written_for_the_script_to_page() {
        let t = table(LAZY_ROWS + 1, |i| Cell::number(i as f64));
        let mut out = String::new();
        push_table(&mut out, "runs", &t);
        assert!(out.contains("<div class=\"grid\" data-lazy>\n<noscript>"));
        assert!(out.contains("\n<tr><td>5000<td>x&lt;y</tr>\n"));
        // A link needs its markup: such a table stays in the DOM.
        let mut t = t;
        t.rows[0][1] = Cell::Link {
            text: "run 0".into(),
            href: "runs/0.mcap".into(),
        };
        let mut out = String::new();
        push_table(&mut out, "runs", &t);
        assert!(!out.contains("noscript"));
        assert!(out.contains("<td><a href=\"runs/0.mcap\">run 0</a>"));
    }
}
