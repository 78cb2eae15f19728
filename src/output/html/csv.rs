//! A CSV file (e.g. `runs.csv`) read into a [`Table`]: every column, cells typed so that a
//! column of numbers sorts as numbers.

use super::model::{Cell, Table};

/// Why CSV text could not be read as a table. Lines are 1-based.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum CsvError {
    /// No header line.
    Empty,
    /// A row whose cell count differs from the header's.
    Ragged {
        /// The row's line.
        line: usize,
        /// Its cell count.
        cells: usize,
        /// The header's column count.
        columns: usize,
    },
    /// A quoted cell that never closes.
    UnclosedQuote {
        /// The line where the quote opens.
        line: usize,
    },
}

impl std::fmt::Display for CsvError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            CsvError::Empty => write!(f, "empty file: expected a header line"),
            CsvError::Ragged {
                line,
                cells,
                columns,
            } => write!(
                f,
                "line {line}: {cells} cells, but the header has {columns} columns"
            ),
            CsvError::UnclosedQuote { line } => {
                write!(f, "line {line}: a quoted cell is not closed")
            }
        }
    }
}

impl std::error::Error for CsvError {}

/// Split CSV text into records of cells, each with the line it starts on. Cells may be
/// quoted (`"a,b"`, `""` for a quote inside); line ends are `\n` or `\r\n`; empty lines are
/// skipped.
fn records(text: &str) -> Result<Vec<(usize, Vec<String>)>, CsvError> {
    Records::new(text).collect()
}

/// The records of CSV text one at a time (see [`records`]): a quote left open is an error
/// after the last record.
pub(crate) struct Records<'a> {
    chars: std::iter::Peekable<std::str::Chars<'a>>,
    line: usize,
    done: bool,
}

impl<'a> Records<'a> {
    /// The records of `text`.
    pub(crate) fn new(text: &'a str) -> Self {
        Self {
            chars: text.chars().peekable(),
            line: 1,
            done: false,
        }
    }
}

impl Iterator for Records<'_> {
    type Item = Result<(usize, Vec<String>), CsvError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.done {
            return None;
        }
        let mut record: Vec<String> = Vec::new();
        let mut cell = String::new();
        let mut start_line = self.line;
        let mut quoted = false;
        while let Some(c) = self.chars.next() {
            match (quoted, c) {
                (true, '"') if self.chars.peek() == Some(&'"') => {
                    self.chars.next();
                    cell.push('"');
                }
                (true, '"') => quoted = false,
                (true, c) => {
                    if c == '\n' {
                        self.line += 1;
                    }
                    cell.push(c);
                }
                (false, '"') if cell.is_empty() => quoted = true,
                (false, ',') => record.push(std::mem::take(&mut cell)),
                (false, '\r') if self.chars.peek() == Some(&'\n') => {}
                (false, '\n') => {
                    record.push(std::mem::take(&mut cell));
                    self.line += 1;
                    if !(record.len() == 1 && record[0].is_empty()) {
                        return Some(Ok((start_line, record)));
                    }
                    record.clear();
                    start_line = self.line;
                }
                (false, c) => cell.push(c),
            }
        }
        self.done = true;
        if quoted {
            return Some(Err(CsvError::UnclosedQuote { line: start_line }));
        }
        if !cell.is_empty() || !record.is_empty() {
            record.push(cell);
            return Some(Ok((start_line, record)));
        }
        None
    }
}

impl Table {
    /// Read CSV text (header line, then one line per row) into a table titled `title`.
    /// A column is numeric when every non-empty cell parses as a number (`inf`, `NaN`
    /// included); its cells keep their exact text and sort by value. Other columns are text.
    pub fn from_csv(title: &str, text: &str) -> Result<Table, CsvError> {
        let mut records = records(text)?.into_iter();
        let header = match records.next() {
            Some((_, header)) => header,
            None => return Err(CsvError::Empty),
        };
        let mut raw = Vec::new();
        for (line, row) in records {
            if row.len() != header.len() {
                return Err(CsvError::Ragged {
                    line,
                    cells: row.len(),
                    columns: header.len(),
                });
            }
            raw.push(row);
        }
        let numeric: Vec<bool> = (0..header.len())
            .map(|c| {
                let mut cells = raw.iter().map(|r| r[c].as_str()).filter(|s| !s.is_empty());
                let mut any = false;
                let all = cells.all(|s| {
                    any = true;
                    s.parse::<f64>().is_ok()
                });
                any && all
            })
            .collect();
        let rows = raw.into_iter().map(|row| typed(row, &numeric)).collect();
        Ok(Table {
            title: title.to_string(),
            note: String::new(),
            header,
            rows,
        })
    }
}

/// The cells of a record: a cell of a numeric column that parses is a number (its exact
/// text kept), every other cell text.
pub(crate) fn typed(row: Vec<String>, numeric: &[bool]) -> Vec<Cell> {
    row.into_iter()
        .zip(numeric)
        .map(|(text, &numeric)| match text.parse::<f64>() {
            Ok(value) if numeric => Cell::Number { value, text },
            _ => Cell::Text(text),
        })
        .collect()
}

/// What [`Table::from_csv`] finds in CSV text, read one record at a time (nothing but the
/// header kept): the header, which columns are numeric, and the number of rows; `None`
/// when `from_csv` would fail.
pub(crate) fn shape(text: &str) -> Option<(Vec<String>, Vec<bool>, usize)> {
    let mut records = Records::new(text);
    let header = match records.next()? {
        Ok((_, header)) => header,
        Err(_) => return None,
    };
    let mut any = vec![false; header.len()];
    let mut all = vec![true; header.len()];
    let mut rows = 0;
    for r in records {
        let (_, row) = r.ok()?;
        if row.len() != header.len() {
            return None;
        }
        for (c, cell) in row.iter().enumerate() {
            if !cell.is_empty() {
                any[c] = true;
                all[c] &= cell.parse::<f64>().is_ok();
            }
        }
        rows += 1;
    }
    let numeric = any.iter().zip(&all).map(|(a, b)| *a && *b).collect();
    Some((header, numeric, rows))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn typed_columns_quotes_and_errors() {
        let t = Table::from_csv("runs", "run,name,t_s\r\n0,\"a,\"\"b\"\"\",inf\n\n1,c,0.5\n")
            .expect("valid CSV");
        assert_eq!(t.header, ["run", "name", "t_s"]);
        assert_eq!(
            t.rows[0],
            [
                Cell::Number {
                    value: 0.0,
                    text: "0".into()
                },
                Cell::text("a,\"b\""),
                Cell::Number {
                    value: f64::INFINITY,
                    text: "inf".into()
                },
            ]
        );
        assert_eq!(t.rows[1][1], Cell::text("c"));
        assert_eq!(
            Table::from_csv("x", "a,b\n1,2\n3\n"),
            Err(CsvError::Ragged {
                line: 3,
                cells: 1,
                columns: 2
            })
        );
        assert_eq!(
            Table::from_csv("x", "a\n\"open\n"),
            Err(CsvError::UnclosedQuote { line: 2 })
        );
        assert_eq!(Table::from_csv("x", "\n"), Err(CsvError::Empty));
    }

    #[test]
    fn a_column_with_one_word_is_text() {
        let t = Table::from_csv("x", "v\n1\nn/a\n\n").expect("valid CSV");
        assert_eq!(t.rows, [vec![Cell::text("1")], vec![Cell::text("n/a")]]);
        let t = Table::from_csv("x", "v,w\n1,\n2,\n").expect("valid CSV");
        assert_eq!(t.rows[0][1], Cell::text(""));
        assert!(matches!(t.rows[1][0], Cell::Number { value: 2.0, .. }));
    }
}
