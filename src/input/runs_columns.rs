//! `runs.csv` read back compactly, column by column, for the outputs of a sweep (summary,
//! report, plots, ranking): what [`crate::input::runs_table::RunsTable`] gives as text
//! cells, at a few bytes per cell instead of a `String` each.
//!
//! A column is kept as the first form that holds every cell exactly:
//! - one text shared by every row (a setting the sweep does not vary, an empty `reason`);
//! - numbers, when every cell is the shortest round-trip text of its number (how runs.csv
//!   writes them: `number(cell).to_string() == cell`), 8 bytes a cell;
//! - a list of the distinct texts and each row's index into it (a profile kind, a status),
//!   4 bytes a cell.
//!
//! A cell read back is the very text of the file in every form; a number read from a
//! number column is the number its text parses to.

use std::borrow::Cow;
use std::collections::HashMap;
use std::fmt::Write as _;

use crate::input::runs_table::number;

/// One column's cells.
#[derive(Debug, Clone, PartialEq)]
enum Column {
    /// Every row's cell is this text.
    Same(String),
    /// Every cell is its number's shortest round-trip text.
    Numbers(Vec<f64>),
    /// Distinct texts and each row's index into them.
    Texts {
        values: Vec<String>,
        index: Vec<u32>,
    },
}

/// A runs table kept by column (see the module documentation).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RunsColumns {
    /// Column names, in order.
    pub header: Vec<String>,
    columns: Vec<Column>,
    rows: usize,
}

/// Whether `cell` is the shortest round-trip text of the number it parses to (`buf` is
/// scratch space).
fn is_number_text(cell: &str, buf: &mut String) -> Option<f64> {
    let x = number(cell)?;
    buf.clear();
    let _ = write!(buf, "{x}");
    (buf == cell).then_some(x)
}

/// A column being read: its cells so far, and the index of its distinct texts.
struct Builder {
    column: Column,
    lookup: HashMap<String, u32>,
    /// The rows expected (cells are reserved for them once, not grown by doubling).
    rows: usize,
}

impl Builder {
    fn push(&mut self, row: usize, cell: &str, buf: &mut String) {
        match &mut self.column {
            Column::Same(text) if row == 0 => cell.clone_into(text),
            Column::Same(text) if text == cell => {}
            Column::Same(text) => {
                let text = std::mem::take(text);
                let mut first = String::new();
                self.column = match (is_number_text(&text, &mut first), is_number_text(cell, buf)) {
                    (Some(a), Some(_)) => {
                        let mut xs = Vec::with_capacity(self.rows.max(row + 1));
                        xs.resize(row, a);
                        Column::Numbers(xs)
                    }
                    _ => {
                        self.lookup.insert(text.clone(), 0);
                        let mut index = Vec::with_capacity(self.rows.max(row + 1));
                        index.resize(row, 0);
                        Column::Texts {
                            values: vec![text],
                            index,
                        }
                    }
                };
                self.push(row, cell, buf);
            }
            Column::Numbers(xs) => match is_number_text(cell, buf) {
                Some(x) => xs.push(x),
                None => {
                    let mut values: Vec<String> = Vec::new();
                    let mut index = Vec::with_capacity(self.rows.max(xs.len() + 1));
                    self.lookup.clear();
                    for x in xs.iter() {
                        let t = x.to_string();
                        let k = match self.lookup.get(&t) {
                            Some(&k) => k,
                            None => {
                                let k = values.len() as u32;
                                self.lookup.insert(t.clone(), k);
                                values.push(t);
                                k
                            }
                        };
                        index.push(k);
                    }
                    self.column = Column::Texts { values, index };
                    self.push(row, cell, buf);
                }
            },
            Column::Texts { values, index } => {
                let k = match self.lookup.get(cell) {
                    Some(&k) => k,
                    None => {
                        let k = values.len() as u32;
                        self.lookup.insert(cell.to_string(), k);
                        values.push(cell.to_string());
                        k
                    }
                };
                index.push(k);
            }
        }
    }
}

impl RunsColumns {
    /// Parse CSV text: the same table and the same errors as
    /// [`crate::input::runs_table::RunsTable::parse`].
    pub fn parse(text: &str) -> Result<Self, String> {
        let lines = text.bytes().filter(|&b| b == b'\n').count();
        Self::read(text.as_bytes(), lines.saturating_sub(1))
    }

    /// Parse CSV from `reader`, a record at a time (see [`RunsColumns::parse`]); `rows`:
    /// the rows expected (a hint: their cells are reserved at once).
    pub fn read(reader: impl std::io::Read, rows: usize) -> Result<Self, String> {
        let mut reader = csv::ReaderBuilder::new()
            .has_headers(false)
            .flexible(true)
            .from_reader(reader);
        let mut record = csv::StringRecord::new();
        let header: Vec<String> = match reader.read_record(&mut record) {
            Ok(true) if !(record.len() == 1 && record[0].trim().is_empty()) => {
                record.iter().map(str::to_string).collect()
            }
            Err(e) => return Err(e.to_string()),
            _ => return Err("empty file: expected a header line".into()),
        };
        let mut builders: Vec<Builder> = header
            .iter()
            .map(|_| Builder {
                column: Column::Same(String::new()),
                lookup: HashMap::new(),
                rows,
            })
            .collect();
        let mut buf = String::new();
        let mut rows = 0usize;
        loop {
            match reader.read_record(&mut record) {
                Ok(true) => {}
                Ok(false) => break,
                Err(e) => return Err(e.to_string()),
            }
            if record.len() != header.len() {
                let line = record.position().map_or(0, csv::Position::line);
                return Err(format!(
                    "line {line}: {} cells, but the header has {} columns",
                    record.len(),
                    header.len()
                ));
            }
            for (b, cell) in builders.iter_mut().zip(record.iter()) {
                b.push(rows, cell, &mut buf);
            }
            rows += 1;
        }
        let columns = builders
            .into_iter()
            .map(|b| match b.column {
                Column::Numbers(mut xs) => {
                    xs.shrink_to_fit();
                    Column::Numbers(xs)
                }
                Column::Texts {
                    mut values,
                    mut index,
                } => {
                    values.shrink_to_fit();
                    index.shrink_to_fit();
                    Column::Texts { values, index }
                }
                same => same,
            })
            .collect();
        Ok(Self {
            header,
            columns,
            rows,
        })
    }

    /// The number of rows.
    pub fn len(&self) -> usize {
        self.rows
    }

    /// Whether the table has no rows.
    pub fn is_empty(&self) -> bool {
        self.rows == 0
    }

    /// Index of the column called `name`.
    pub fn column(&self, name: &str) -> Option<usize> {
        self.header.iter().position(|h| h == name)
    }

    /// The cell of row `row` in column `name`, as written.
    pub fn cell(&self, row: usize, name: &str) -> Option<Cow<'_, str>> {
        if row >= self.rows {
            return None;
        }
        Some(match &self.columns[self.column(name)?] {
            Column::Same(text) => Cow::Borrowed(text.as_str()),
            Column::Numbers(xs) => Cow::Owned(xs[row].to_string()),
            Column::Texts { values, index } => Cow::Borrowed(values[index[row] as usize].as_str()),
        })
    }

    /// The cell of row `row` in column `name` as a number (`inf` included).
    pub fn num(&self, row: usize, name: &str) -> Option<f64> {
        if row >= self.rows {
            return None;
        }
        match &self.columns[self.column(name)?] {
            Column::Same(text) => number(text),
            Column::Numbers(xs) => Some(xs[row]),
            Column::Texts { values, index } => number(&values[index[row] as usize]),
        }
    }

    /// The `run` column of row `row` as an index.
    pub fn run_id(&self, row: usize) -> Option<usize> {
        self.cell(row, "run").and_then(|c| c.parse().ok())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::input::runs_table::RunsTable;

    /// Every cell and every number of `text` read back as the text table reads it.
    fn same_as_text_table(text: &str) {
        let t = RunsTable::parse(text).expect("parses");
        let c = RunsColumns::parse(text).expect("parses");
        assert_eq!(c.header, t.header);
        assert_eq!(c.len(), t.rows.len());
        for (i, row) in t.rows.iter().enumerate() {
            for (h, cell) in t.header.iter().zip(row) {
                assert_eq!(c.cell(i, h).as_deref(), Some(cell.as_str()), "row {i} {h}");
                assert_eq!(
                    c.num(i, h).map(f64::to_bits),
                    number(cell).map(f64::to_bits),
                    "row {i} {h}"
                );
            }
        }
        assert_eq!(c.cell(t.rows.len(), "run"), None);
        assert_eq!(c.cell(0, "no such column"), None);
    }

    #[test]
    fn cells_read_back_as_written_in_every_column_form() {
        // run: numbers; same: one text; profile: texts; x: numbers, then a text that is not
        // a number's shortest form (`1e-7`, `+5`, `0.10`) turns it into texts; y: a shared
        // number, then others; reason: empty, then free text with a comma.
        same_as_text_table(
            "run,same,profile,x,y,reason\n\
             0,modal,scurve,0.1,300,\n\
             1,modal,trapezoid,-0,300,\n\
             2,modal,scurve,inf,301,\"lost, 3 steps\"\n\
             3,modal,scurve,1e-7,NaN,\n\
             4,modal,scurve,+5,0.30000000000000004,\n\
             5,modal,pvt,0.10,5e-324,\n",
        );
        same_as_text_table("run,a\n");
        same_as_text_table("run,a\n0,\n");
        // A column whose first cell is a number and whose second is text.
        same_as_text_table("a,b\n1,x\n2,1\nx,y\n");
    }

    #[test]
    fn errors_are_the_text_tables() {
        for text in ["", "a,b\n1,2\n3\n", "\n", "a\n\"x\n"] {
            assert_eq!(
                RunsColumns::parse(text).map(|_| ()),
                RunsTable::parse(text).map(|_| ()),
                "{text:?}"
            );
        }
    }
}
