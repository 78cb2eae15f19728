//! The identify crate's one error type.
//!
//! Errors about a file name the file (as the caller named it) and, where one line is to
//! blame, its 1-based line number (for a `.stdata` file: the line of the decompressed JSON
//! text).

/// What can go wrong reading a recording or identifying modes from it.
#[derive(Debug, thiserror::Error)]
pub enum IdentifyError {
    /// The file is not a regular file, is larger than a recording can be, or decompresses
    /// to more (settle-files' reader).
    #[error(transparent)]
    File(#[from] settle_files::FileError),
    /// The file could not be read.
    #[error("{file}: cannot read: {source}")]
    Io {
        /// The file.
        file: String,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// A line does not have the form the format requires.
    #[error("{file}:{line}: {found}; expected {expected}")]
    Format {
        /// The file.
        file: String,
        /// 1-based line number.
        line: usize,
        /// What the line holds (or what is wrong with it).
        found: String,
        /// What the format allows there.
        expected: String,
    },
    /// A value is NaN or infinite.
    #[error("{file}:{line}: column `{column}` is {value}; expected a finite number")]
    NotFinite {
        /// The file.
        file: String,
        /// 1-based line number.
        line: usize,
        /// The column's name in the header.
        column: String,
        /// The value as read.
        value: f64,
    },
    /// Time stamps must increase from one sample to the next.
    #[error(
        "{file}:{line}: time {time_s} s does not increase (the line before holds {previous_s} s); expected strictly increasing time stamps"
    )]
    NotMonotonic {
        /// The file.
        file: String,
        /// 1-based line number of the offending sample.
        line: usize,
        /// Its time (s).
        time_s: f64,
        /// The previous sample's time (s).
        previous_s: f64,
    },
    /// An input the readers do not take: not a regular file, or more than they read
    /// (every input is bounded before it is read, so that identifying it stays within the
    /// memory `docs/performance.md` states).
    #[error("{file}: {found}; the readers take {allowed}")]
    NotAccepted {
        /// The file.
        file: String,
        /// What it is or holds.
        found: String,
        /// What the readers take.
        allowed: String,
    },
    /// Too few samples (or frequency rows) to analyse.
    #[error("{file}{}: the data end after {found} {what}; at least {needed} are needed", at_line(*line))]
    TooFewSamples {
        /// The file.
        file: String,
        /// 1-based number of the last line read (0: about the whole file, no line named).
        line: usize,
        /// What was counted (`samples`, `frequency rows`).
        what: &'static str,
        /// How many there are.
        found: usize,
        /// How many the analysis needs.
        needed: usize,
    },
    /// The recording holds no resonance: nothing in the band stands out of the noise.
    #[error(
        "{file}: no resonance peak above the noise between {band_lo_hz:.1} and {band_hi_hz:.1} Hz ({measure} is {ratio:.2}; at least {needed:.1} is needed)"
    )]
    NoPeak {
        /// The file.
        file: String,
        /// Lower edge of the band searched (Hz).
        band_lo_hz: f64,
        /// Upper edge of the band searched (Hz).
        band_hi_hz: f64,
        /// What was compared (`largest PSD / noise floor`, `largest response / median
        /// response`).
        measure: &'static str,
        /// The ratio found.
        ratio: f64,
        /// The ratio required.
        needed: f64,
    },
    /// The recording holds no vibration to identify: every sensor axis reads one value
    /// throughout (a sensor that is not read, a file of zeros), or the values vary by less
    /// than any accelerometer resolves.
    #[error("{file}: no vibration to identify: {reason}")]
    NoVibration {
        /// The file.
        file: String,
        /// What the recording holds, and what is needed.
        reason: String,
    },
    /// A sensor axis the recording holds reads one value throughout while another varies:
    /// the axis was not measured.
    #[error("{file}: a sensor axis that does not measure: {reason}")]
    AxisNotMeasured {
        /// The file.
        file: String,
        /// Which axis, what it reads, and what to check.
        reason: String,
    },
    /// No free decay (ring-down) could be found in the recording.
    #[error("{file}: {reason}")]
    NoRingDown {
        /// The file.
        file: String,
        /// Why not.
        reason: String,
    },
    /// The recording needs the resonance test's parameters, which were not given and which
    /// the file does not record.
    #[error("{file}: {reason}")]
    NeedsTestParameters {
        /// The file.
        file: String,
        /// Which parameters, and why.
        reason: String,
    },
    /// A fit ran but its result cannot be stood behind: a frequency at or above Nyquist or
    /// outside the band the data cover, a value that is not a number, an uncertainty larger
    /// than the value, a fit that did not converge.
    #[error("{file}: the fit cannot be trusted: {reason}")]
    Unreliable {
        /// The file.
        file: String,
        /// What is wrong with it.
        reason: String,
    },
    /// An option passed by the caller is out of range.
    #[error("option `{name}` = {value} is invalid: allowed {allowed}")]
    InvalidOption {
        /// The option's name.
        name: &'static str,
        /// The offending value.
        value: f64,
        /// What is allowed.
        allowed: &'static str,
    },
}

/// `:LINE`, or nothing for line 0 (a count over the whole file, not a line of it).
fn at_line(line: usize) -> String {
    if line == 0 {
        String::new()
    } else {
        format!(":{line}")
    }
}

impl IdentifyError {
    /// A [`IdentifyError::NotAccepted`] error.
    pub(crate) fn not_accepted(
        file: &str,
        found: impl Into<String>,
        allowed: impl Into<String>,
    ) -> Self {
        IdentifyError::NotAccepted {
            file: file.to_string(),
            found: found.into(),
            allowed: allowed.into(),
        }
    }

    /// A [`IdentifyError::Format`] error.
    pub(crate) fn format(
        file: &str,
        line: usize,
        found: impl Into<String>,
        expected: impl Into<String>,
    ) -> Self {
        IdentifyError::Format {
            file: file.to_string(),
            line,
            found: found.into(),
            expected: expected.into(),
        }
    }
}
