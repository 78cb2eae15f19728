//! The runs table: `runs.csv` read back as named columns of text cells.
//!
//! Everything a sweep leaves besides the recordings is a function of this table (and the
//! scenario): the summary, the plots, the regression gate (`settle check`) and the merge of
//! sharded sweeps. Working on the table rather than on [`crate::Metrics`] keeps those outputs
//! generic: a column added to `runs.csv` is carried, compared and merged without more code.
//!
//! Cells are kept as the exact text written; numbers are written by Rust's shortest
//! round-trip formatting, so parsing a cell gives back the very `f64` that was written.

use std::fmt::Write as _;

/// A CSV table of plain cells (no quoting: settle never writes commas inside a cell).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RunsTable {
    /// Column names, in order.
    pub header: Vec<String>,
    /// Rows, each as long as the header.
    pub rows: Vec<Vec<String>>,
}

/// A cell read as a number: `inf` (not settled) is `f64::INFINITY`.
pub fn number(cell: &str) -> Option<f64> {
    cell.parse::<f64>().ok()
}

impl RunsTable {
    /// Parse CSV text. Errors name the 1-based line.
    pub fn parse(text: &str) -> Result<Self, String> {
        let mut lines = text.lines();
        let header: Vec<String> = match lines.next() {
            Some(h) if !h.trim().is_empty() => h.split(',').map(str::to_string).collect(),
            _ => return Err("empty file: expected a header line".into()),
        };
        let mut rows = Vec::new();
        for (i, line) in lines.enumerate() {
            if line.is_empty() {
                continue;
            }
            let row: Vec<String> = line.split(',').map(str::to_string).collect();
            if row.len() != header.len() {
                return Err(format!(
                    "line {}: {} cells, but the header has {} columns",
                    i + 2,
                    row.len(),
                    header.len()
                ));
            }
            rows.push(row);
        }
        Ok(Self { header, rows })
    }

    /// The CSV text (header, then one line per row, each ending in a newline).
    pub fn to_csv(&self) -> String {
        let mut out = String::new();
        let _ = writeln!(out, "{}", self.header.join(","));
        for r in &self.rows {
            let _ = writeln!(out, "{}", r.join(","));
        }
        out
    }

    /// Index of the column called `name`.
    pub fn column(&self, name: &str) -> Option<usize> {
        self.header.iter().position(|h| h == name)
    }

    /// The cell of row `row` in column `name`.
    pub fn cell(&self, row: usize, name: &str) -> Option<&str> {
        let c = self.column(name)?;
        self.rows.get(row).map(|r| r[c].as_str())
    }

    /// The cell of row `row` in column `name` as a number (`inf` included).
    pub fn num(&self, row: usize, name: &str) -> Option<f64> {
        self.cell(row, name).and_then(number)
    }

    /// The `run` column of row `row` as an index.
    pub fn run_id(&self, row: usize) -> Option<usize> {
        self.cell(row, "run").and_then(|c| c.parse().ok())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_text_and_numbers() {
        let text = "run,profile,settle_time_s_10um\n0,scurve,0.1\n1,trapezoid,inf\n";
        let t = RunsTable::parse(text).expect("parses");
        assert_eq!(t.to_csv(), text);
        assert_eq!(t.num(0, "settle_time_s_10um"), Some(0.1));
        assert_eq!(t.num(1, "settle_time_s_10um"), Some(f64::INFINITY));
        assert_eq!(t.cell(1, "profile"), Some("trapezoid"));
        assert_eq!(t.run_id(1), Some(1));
        // Rust's shortest formatting round-trips every f64 exactly.
        for x in [0.1f64 + 0.2, 1e-300, 123456.789e10, -0.0, 5e-324] {
            assert_eq!(number(&x.to_string()).map(f64::to_bits), Some(x.to_bits()));
        }
    }

    #[test]
    fn ragged_rows_are_errors_with_the_line() {
        let e = RunsTable::parse("a,b\n1,2\n3\n").expect_err("ragged");
        assert!(e.contains("line 3"), "{e}");
        assert!(RunsTable::parse("").is_err());
    }
}
