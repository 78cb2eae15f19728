//! The runs table: `runs.csv` read back as named columns of text cells, and the text of a
//! table (the one place a CSV record is written, with the `csv` crate's quoting).
//!
//! Everything a sweep leaves besides the recordings is a function of this table (and the
//! scenario): the summary, the plots, the regression gate (`settle check`) and the merge of
//! sharded sweeps. Working on the table rather than on metrics structs keeps those outputs
//! generic: a column added to `runs.csv` is carried, compared and merged without more code.
//!
//! Cells are kept as the exact text written; numbers are written by Rust's shortest
//! round-trip formatting, so parsing a cell gives back the very `f64` that was written.
//! Free text (a failed run's reason) is quoted where it holds a comma or a quote.

/// A CSV table of text cells.
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

/// One CSV record with its newline: cells separated by commas, a cell quoted when it holds
/// a comma, a quote or a line break (a record of one empty cell is `""`).
pub fn record<S: AsRef<[u8]>>(cells: &[S]) -> String {
    let mut w = csv::WriterBuilder::new().from_writer(Vec::new());
    // Writing to memory cannot fail.
    let _ = w.write_record(cells);
    let bytes = w.into_inner().unwrap_or_default();
    String::from_utf8(bytes).unwrap_or_default()
}

impl RunsTable {
    /// Parse CSV text. Errors name the 1-based line.
    pub fn parse(text: &str) -> Result<Self, String> {
        let mut reader = csv::ReaderBuilder::new()
            .has_headers(false)
            .flexible(true)
            .from_reader(text.as_bytes());
        let mut records = reader.records();
        let header: Vec<String> = match records.next() {
            Some(Ok(h)) if !(h.len() == 1 && h[0].trim().is_empty()) => {
                h.iter().map(str::to_string).collect()
            }
            Some(Err(e)) => return Err(e.to_string()),
            _ => return Err("empty file: expected a header line".into()),
        };
        let mut rows = Vec::new();
        for r in records {
            let r = r.map_err(|e| e.to_string())?;
            if r.len() != header.len() {
                let line = r.position().map_or(0, csv::Position::line);
                return Err(format!(
                    "line {line}: {} cells, but the header has {} columns",
                    r.len(),
                    header.len()
                ));
            }
            rows.push(r.iter().map(str::to_string).collect());
        }
        Ok(Self { header, rows })
    }

    /// The CSV text (header, then one line per row, each ending in a newline).
    pub fn to_csv(&self) -> String {
        let mut out = record(&self.header);
        for r in &self.rows {
            out.push_str(&record(r));
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

    #[test]
    fn free_text_with_commas_and_quotes_is_quoted_and_read_back() {
        let reason = "the backend failed at t = 0.1 s: \"step\" rejected, h = 2e-3";
        let t = RunsTable {
            header: vec!["run".into(), "reason".into(), "empty".into()],
            rows: vec![vec!["0".into(), reason.into(), String::new()]],
        };
        let text = t.to_csv();
        assert_eq!(
            text,
            "run,reason,empty\n0,\"the backend failed at t = 0.1 s: \"\"step\"\" rejected, h = 2e-3\",\n"
        );
        assert_eq!(RunsTable::parse(&text).expect("parses"), t);
        assert_eq!(record(&["a", "b"]), "a,b\n");
    }
}
