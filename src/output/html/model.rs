//! What a report says, as plain data: the caller fills a [`Report`], [`super::render`]
//! turns it into one HTML file. Every string here is text (escaped on output) except
//! [`Image::Svg`], which is SVG markup embedded as is.

/// One report: a sweep's, a tune's or a G-code job's.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Report {
    /// The page title and first heading (e.g. the scenario's name).
    pub title: String,
    /// Paragraphs under the title (what was swept, on which machine, how to read the page).
    pub intro: Vec<String>,
    /// The winner per settling band, shown first.
    pub winners: Vec<BandWinner>,
    /// Named tables (e.g. move-and-settle per swept point), in order.
    pub tables: Vec<Table>,
    /// Sections after the tables, each with its own tables, figures and texts (e.g. one
    /// per tuned axis).
    pub sections: Vec<Section>,
    /// Figures, in order.
    pub figures: Vec<Figure>,
    /// Every run (e.g. `runs.csv` read by [`Table::from_csv`]): sortable and filterable.
    pub runs: Option<Table>,
    /// Runs that failed (lost steps, a broken-down simulation), with their reasons.
    pub failed: Vec<FailedRun>,
    /// Where the numbers come from.
    pub provenance: Provenance,
}

/// A part of the page under its own heading: a paragraph or two, its tables, its figures
/// and preformatted texts (e.g. an exported configuration file).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Section {
    /// The element id (letters, digits, `-`), e.g. `axis-x`.
    pub id: String,
    /// The heading.
    pub title: String,
    /// Paragraphs under the heading.
    pub intro: Vec<String>,
    /// Its tables, in order.
    pub tables: Vec<Table>,
    /// Its figures, in order.
    pub figures: Vec<Figure>,
    /// Preformatted texts: a name and the text, shown as is.
    pub texts: Vec<InputFile>,
}

/// The fastest candidate for one settling band.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct BandWinner {
    /// The band, as shown (e.g. `within 10 um`).
    pub band: String,
    /// The winning candidate's label (e.g. `scurve jmax 1e5`).
    pub winner: String,
    /// The winner's numbers, as shown (e.g. `move and settle` = `71.2 ms`).
    pub numbers: Vec<Stat>,
    /// The gain over the reference; `None` when there is nothing to compare with.
    pub gain: Option<Gain>,
}

/// A labelled value, already formatted with its unit.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Stat {
    /// What the value is (e.g. `move and settle`).
    pub label: String,
    /// The value with its unit (e.g. `71.2 ms`).
    pub value: String,
}

/// How much the winner gains over a reference candidate.
#[derive(Debug, Clone, PartialEq)]
pub struct Gain {
    /// What the winner is compared with.
    pub reference: Reference,
    /// The reference's time divided by the winner's (e.g. move-and-settle, both in s):
    /// 1.38 means the reference takes 38 % longer. Infinite when the reference never enters
    /// the band; 1 or less when the reference itself is (as good as) the winner.
    pub ratio: f64,
    /// Free text shown under the gain (e.g. `move and settle 71.2 ms vs 98.3 ms`).
    pub detail: String,
}

/// The candidate a gain is measured against.
#[derive(Debug, Clone, PartialEq)]
pub enum Reference {
    /// The user's current settings: the candidate named `current` in the scenario.
    Current {
        /// The candidate's label.
        label: String,
    },
    /// The slowest candidate, used when the scenario names no `current` candidate.
    Slowest {
        /// The candidate's label.
        label: String,
    },
}

/// A table: a header and rows of typed cells. A column whose cells are all numbers (or
/// empty) sorts numerically; non-finite numbers (`inf` = not settled) and empty cells sort
/// last in both directions.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Table {
    /// The heading above the table.
    pub title: String,
    /// A line under the heading (units, how to read it); empty for none.
    pub note: String,
    /// Column names.
    pub header: Vec<String>,
    /// Rows; each as long as the header (shorter rows are padded with empty cells).
    pub rows: Vec<Vec<Cell>>,
}

/// Rows made as the page is written, for the tables of a [`Report`] given without rows
/// (a ranking of 100,000 runs is never held as cells): `row(t, k)` is row `k` of table
/// `t` (its index in [`Report::tables`]), `None` past the last row or for a table it does
/// not make.
pub trait Rows {
    /// Row `k` of table `table`.
    fn row(&self, table: usize, k: usize) -> Option<Vec<Cell>>;
}

/// No rows made: every table has its own.
impl Rows for () {
    fn row(&self, _: usize, _: usize) -> Option<Vec<Cell>> {
        None
    }
}

/// One table cell.
#[derive(Debug, Clone, PartialEq)]
pub enum Cell {
    /// A number: `text` is shown, `value` is the sort key (non-finite sorts last).
    Number {
        /// The value.
        value: f64,
        /// How it is shown (e.g. `71.2` or `inf`).
        text: String,
    },
    /// Text, sorted as text.
    Text(String),
    /// A link (e.g. to a run's recording beside the report), sorted by its text.
    Link {
        /// What is shown.
        text: String,
        /// Where it points (a relative path or URL; escaped, never fetched by the page).
        href: String,
    },
}

impl Cell {
    /// A number shown by Rust's shortest round-trip formatting (`inf` when infinite).
    pub fn number(value: f64) -> Self {
        Cell::Number {
            value,
            text: value.to_string(),
        }
    }

    /// A text cell.
    pub fn text(text: impl Into<String>) -> Self {
        Cell::Text(text.into())
    }

    /// What the cell shows.
    pub fn shown(&self) -> &str {
        match self {
            Cell::Number { text, .. } => text,
            Cell::Text(text) => text,
            Cell::Link { text, .. } => text,
        }
    }
}

/// A figure: a title and an image.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// The caption (also the image's alternative text).
    pub title: String,
    /// The image.
    pub image: Image,
}

/// An image embedded in the page.
#[derive(Debug, Clone, PartialEq)]
pub enum Image {
    /// SVG markup (e.g. from the crate's plots), embedded inline as is: it must be trusted
    /// markup, not user text. A leading XML declaration or doctype is dropped.
    Svg(String),
    /// An SVG file, read and embedded as [`Image::Svg`] when the page is written (so a
    /// report holds no figure's markup until then).
    SvgFile(std::path::PathBuf),
    /// PNG bytes, embedded as a base64 `data:` URI.
    Png(Vec<u8>),
}

/// A run that produced no numbers.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FailedRun {
    /// The run (its id or label).
    pub run: String,
    /// Its status (e.g. `lost_steps`, `fault`).
    pub status: String,
    /// Why it failed.
    pub reason: String,
}

/// Where the numbers come from. The renderer reads no clock: the caller passes the date,
/// so the same report data always gives the same bytes.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Provenance {
    /// The settle version that produced the numbers.
    pub settle_version: String,
    /// The simulation backend (`modal`, `rapier`, `mujoco`).
    pub backend: String,
    /// The command line, as typed.
    pub command_line: String,
    /// When the numbers were produced, as the caller formats it.
    pub date: String,
    /// More facts about the inputs, shown after the date (e.g. a G-code file's digest,
    /// the machine, the firmware).
    pub facts: Vec<Stat>,
    /// Input files (scenario, machine, firmware config) with their text, each shown in a
    /// collapsible block.
    pub inputs: Vec<InputFile>,
}

/// An input file's name and text.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct InputFile {
    /// The file's name or path, as given.
    pub name: String,
    /// Its text.
    pub text: String,
}
