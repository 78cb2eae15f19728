//! `report.html`: one self-contained file a user opens in a browser to see what won, by how
//! much, and every run.
//!
//! The caller describes the report as plain data ([`Report`]) and [`render`] writes the page:
//! inline style and script, no network (a content policy forbids every fetch), no fonts
//! beyond the system's, figures inline (SVG markup) or as `data:` URIs (PNG). Every text is
//! escaped. The renderer reads no clock and no environment: the same [`Report`] gives the
//! same bytes.
//!
//! Without JavaScript the page reads and prints as plain HTML: every table is a real
//! `<table>` with every row. With JavaScript every table sorts by a click on its header
//! (numbers as numbers; `inf`, NaN and empty cells last in both directions), and a table of
//! more than ten rows gets a filter over all cells, a filter per column (a list of values for
//! a text column with few distinct values, e.g. `status`; for a number column `>x`, `<=x`,
//! `=x` or `a..b`, otherwise a substring) and pages of 100 rows. A table of more than
//! [`LAZY_ROWS`] rows (text and numbers only) is written inside `<noscript>`: without
//! JavaScript the browser parses it as the same table; with JavaScript it stays text that
//! the script splits into rows and shows a page at a time, building no DOM rows beyond the
//! page, so 100,000 runs open, sort and filter without hanging the page.
//!
//! ```
//! use settle::output::html::{Provenance, Report, Table, render};
//!
//! let runs = Table::from_csv("All runs", "run,status,move_time_s\n0,ok,0.05\n1,ok,inf\n")?;
//! let page = render(&Report {
//!     title: "demo".into(),
//!     runs: Some(runs),
//!     provenance: Provenance {
//!         date: "2025-01-01".into(),
//!         ..Provenance::default()
//!     },
//!     ..Report::default()
//! });
//! assert!(page.starts_with("<!DOCTYPE html>"));
//! assert!(page.contains("<th data-type=\"num\">move_time_s</th>"));
//! # Ok::<(), settle::output::html::CsvError>(())
//! ```
//!
//! # Script hooks
//!
//! Opening the page with a fragment `#selftest` (parameters joined by `&`) drives one table
//! through its real event handlers once the page is loaded and writes what happened as JSON
//! into `<pre id="selftest-result">`, for a headless browser's `--dump-dom`:
//! - `grid=ID`: the table's section id (`runs` by default; `table-N` for the N-th named
//!   table, `failed`);
//! - `col=NAME`: clicks that column's header twice; `asc` and `desc` are the column's shown
//!   cells after each click (first page), `asc_aria`/`desc_aria` the header's `aria-sort`;
//! - `filter=TEXT`: types into the filter over all cells; `colfilter=NAME:VALUE` sets one
//!   column's filter; `matched` is the count of rows that pass, `shown` the rows on the page.
//!
//! The result also holds `rows` (the table's row count), `columns` (its header), `lazy`,
//! `sections` (per section of [`Report::sections`]: its `id`, `title`, and the count of its
//! `tables`, `figures` and drawn `svgs` (an inline SVG with a non-empty box)),
//! `errors` (script errors caught on the page), `images` (the natural width of every
//! `<img>`, 0 when it did not decode), `rects` (page-space boxes in CSS pixels, `x`, `y`,
//! `w`, `h`: `table`, the table's visible box, and `figure`, the first figure's image) and
//! timings in ms (`init_ms`, `sort_ms`, `filter_ms`).

mod csv;
mod escape;
mod grid;
mod model;
mod page;

pub use csv::CsvError;
pub use grid::LAZY_ROWS;
pub use model::{
    BandWinner, Cell, FailedRun, Figure, Gain, Image, InputFile, Provenance, Reference, Report,
    Rows, Section, Stat, Table,
};

/// The page for `report`: a complete HTML document (UTF-8). A figure given as a file
/// ([`Image::SvgFile`]) that cannot be read is left out; [`render_to`] reports it.
pub fn render(report: &Report) -> String {
    page::page(report)
}

/// Write the page for `report` to `w` as it is made (the page is never held whole);
/// `runs_csv` (title, CSV text) is the table of every run when `report.runs` is `None`,
/// written as `Table::from_csv(title, text)` would be, one record at a time; a table of
/// `report.tables` without rows gets those `rows` makes, as if it held them. The bytes are
/// [`render`]'s of the report with those rows. Errors: a figure file that cannot be read,
/// or a failed write (`path` is the file the error names).
pub fn render_to(
    report: &Report,
    runs_csv: Option<(&str, &str)>,
    rows: &dyn Rows,
    w: impl std::io::Write,
    path: &std::path::Path,
) -> Result<(), crate::error::Error> {
    let mut sink = Sink::new(w);
    let done = page::page_to(&mut sink, report, runs_csv, rows);
    sink.finish(path)?;
    done
}

/// Where the page is written: text is appended to it.
pub(crate) trait Out: std::fmt::Write {
    /// Append `s`.
    fn push_str(&mut self, s: &str);
    /// Append `c`.
    fn push(&mut self, c: char);
}

impl Out for String {
    fn push_str(&mut self, s: &str) {
        String::push_str(self, s);
    }

    fn push(&mut self, c: char) {
        String::push(self, c);
    }
}

/// A writer as an [`Out`]: the first write error is kept, and nothing more is written.
pub(crate) struct Sink<W: std::io::Write> {
    w: W,
    error: Option<std::io::Error>,
}

impl<W: std::io::Write> Sink<W> {
    /// Text written to `w`.
    pub(crate) fn new(w: W) -> Self {
        Self { w, error: None }
    }

    /// Flush the writer; the first write error, naming `path`.
    pub(crate) fn finish(mut self, path: &std::path::Path) -> Result<(), crate::error::Error> {
        if let Some(e) = self.error.take() {
            return Err(crate::error::Error::write(path, e));
        }
        std::io::Write::flush(&mut self.w).map_err(|e| crate::error::Error::write(path, e))
    }
}

impl<W: std::io::Write> std::fmt::Write for Sink<W> {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        if self.error.is_none()
            && let Err(e) = self.w.write_all(s.as_bytes())
        {
            self.error = Some(e);
        }
        if self.error.is_some() {
            return Err(std::fmt::Error);
        }
        Ok(())
    }
}

impl<W: std::io::Write> Out for Sink<W> {
    fn push_str(&mut self, s: &str) {
        let _ = std::fmt::Write::write_str(self, s);
    }

    fn push(&mut self, c: char) {
        let _ = std::fmt::Write::write_char(self, c);
    }
}
