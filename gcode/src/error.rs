//! The crate's one error type, and where in a file an error is.

use std::fmt;
use std::sync::Arc;

/// A place in the input: the source's name (a path, or `<input>`), the 1-based line and,
/// where it is known, the 1-based byte column.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Location {
    /// The path given to [`crate::Reader::open`], or the name given to
    /// [`crate::Reader::with_name`] (`<input>` by default).
    pub source_name: Arc<str>,
    /// 1-based line number.
    pub line: u64,
    /// 1-based byte column of the offending text, when known.
    pub column: Option<usize>,
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}", self.source_name, self.line)?;
        if let Some(c) = self.column {
            write!(f, ":{c}")?;
        }
        Ok(())
    }
}

/// Everything that can go wrong reading G-code or a firmware configuration file. Every
/// variant about a line names the file, the line (and column where known), the command,
/// option or parameter and what is allowed.
#[derive(Debug, thiserror::Error)]
pub enum GcodeError {
    /// The input could not be opened or read.
    #[error("{source_name}: cannot read: {source}")]
    Io {
        /// The path or input name.
        source_name: Arc<str>,
        /// The underlying error.
        source: std::io::Error,
    },
    /// A file that is not a regular file, larger than its limit, or not text (settle-files'
    /// reader).
    #[error(transparent)]
    File(Box<settle_files::FileError>),
    /// A binary G-code file that cannot be decoded (gcode/src/read/bgcode.rs): truncated,
    /// a bad checksum, an unknown block type, compression or encoding, or text past the
    /// limit on a G-code file.
    #[error("{source_name}: binary G-code, {source}")]
    Bgcode {
        /// The path.
        source_name: Arc<str>,
        /// The byte offset and what is wrong.
        source: crate::read::bgcode::BgcodeError,
    },
    /// A file an `[include]` (or RepRapFirmware `M98 P`) names cannot be read.
    #[error("{at}: {what}: {source}")]
    Include {
        /// The include line.
        at: Location,
        /// The include as written (`[include macros/*.cfg]`).
        what: String,
        /// Why the file cannot be read (boxed: it is large and rare).
        source: Box<settle_files::FileError>,
    },
    /// A line is longer than the reader's limit; it was not read into memory.
    #[error("{at}: line longer than {limit_bytes} bytes (binary data or a corrupt file?)")]
    LineTooLong {
        /// Where.
        at: Location,
        /// The limit ([`crate::ReaderOptions::max_line_bytes`]).
        limit_bytes: usize,
    },
    /// The file is not G-code text but a format a slicer writes G-code into
    /// (gcode/src/read/packaged.rs: binary G-code, a gzip stream, a zip archive, a zstd
    /// frame; or UTF-16 text), known by
    /// its first bytes. Not a bad line: even skipping bad lines, no line of it is G-code text.
    #[error("{at}: {what}; settle reads G-code text: {instead}")]
    Packaged {
        /// Where (line 1, column 1).
        at: Location,
        /// What the file is.
        what: &'static str,
        /// How to get its G-code as text.
        instead: &'static str,
    },
    /// The line is not valid UTF-8.
    #[error("{at}: invalid UTF-8 (binary data?); G-code is text")]
    InvalidUtf8 {
        /// Where (column = first invalid byte).
        at: Location,
    },
    /// A control character other than tab (or a trailing carriage return); a carriage
    /// return inside a line is named as such.
    #[error("{at}: {}", control_words(*.byte))]
    ControlCharacter {
        /// Where.
        at: Location,
        /// The byte.
        byte: u8,
    },
    /// Text that is not G-code syntax.
    #[error("{at}: {what}")]
    Syntax {
        /// Where.
        at: Location,
        /// What was expected.
        what: &'static str,
    },
    /// A parameter value that is not a number.
    #[error(
        "{at}: `{command}` parameter {param}: `{text}` is not a number (allowed: decimal like -12.5)"
    )]
    NotANumber {
        /// Where.
        at: Location,
        /// The command (`G1`, `SET_VELOCITY_LIMIT`).
        command: String,
        /// The parameter (`X`, `ACCEL`).
        param: String,
        /// The text found.
        text: String,
    },
    /// A number outside the range the parameter allows (also NaN and infinity).
    #[error("{at}: `{command}` parameter {param} = {value}: out of range (allowed: {allowed})")]
    OutOfRange {
        /// Where.
        at: Location,
        /// The command.
        command: String,
        /// The parameter.
        param: String,
        /// The value (after unit conversion and, for coordinates, after adding the
        /// position for relative moves).
        value: f64,
        /// What is allowed.
        allowed: &'static str,
    },
    /// The same parameter twice on one line.
    #[error("{at}: `{command}` has parameter {param} twice")]
    DuplicateParameter {
        /// Where.
        at: Location,
        /// The command.
        command: String,
        /// The parameter.
        param: String,
    },
    /// A parameter the command does not take.
    #[error("{at}: `{command}` does not take parameter {param} (allowed: {allowed})")]
    UnknownParameter {
        /// Where.
        at: Location,
        /// The command.
        command: String,
        /// The parameter.
        param: String,
        /// The parameters it takes.
        allowed: &'static str,
    },
    /// A parameter given without the value it needs (`G1 X`).
    #[error("{at}: `{command}` parameter {param} needs a value")]
    MissingValue {
        /// Where.
        at: Location,
        /// The command.
        command: String,
        /// The parameter.
        param: String,
    },
    /// A `*nn` checksum that does not match the line (the XOR of its bytes before `*`).
    #[error("{at}: checksum *{found} does not match the line (computed {computed})")]
    Checksum {
        /// Where.
        at: Location,
        /// The checksum written in the line.
        found: u32,
        /// The XOR of the bytes before `*`.
        computed: u8,
    },
    /// A command the chosen firmware dialect (or this reader) does not support.
    #[error("{at}: `{command}` is not supported: {why}")]
    Unsupported {
        /// Where.
        at: Location,
        /// The command.
        command: String,
        /// Why, and what to do instead.
        why: &'static str,
    },
    /// An arc command without the centre or radius it needs.
    #[error("{at}: `{command}` needs a centre offset I/J (not both zero) or a radius R")]
    ArcWithoutCentre {
        /// Where.
        at: Location,
        /// `G2` or `G3`.
        command: String,
    },
    /// An arc command with both I/J and R.
    #[error("{at}: `{command}` has both a centre offset (I/J) and a radius (R); give one form")]
    ArcMixedForms {
        /// Where.
        at: Location,
        /// `G2` or `G3`.
        command: String,
    },
    /// An I/J arc whose end point is not on the circle through its start point.
    #[error(
        "{at}: `{command}` start radius {start_radius_mm} mm and end radius {end_radius_mm} mm differ too much (allowed: up to 0.005 mm, or up to 0.1 % of the radius and 0.5 mm)"
    )]
    ArcRadiusMismatch {
        /// Where.
        at: Location,
        /// `G2` or `G3`.
        command: String,
        /// Distance from the centre to the start point.
        start_radius_mm: f64,
        /// Distance from the centre to the end point.
        end_radius_mm: f64,
    },
    /// An R-form arc whose radius is shorter than half the chord.
    #[error(
        "{at}: `{command}` radius {radius_mm} mm cannot reach the end point {chord_mm} mm away (needs at least half the chord, 1 % slack)"
    )]
    ArcRadiusTooSmall {
        /// Where.
        at: Location,
        /// `G2` or `G3`.
        command: String,
        /// |R|.
        radius_mm: f64,
        /// Distance from start to end.
        chord_mm: f64,
    },
    /// A line of a firmware configuration file that is not what the format allows there.
    #[error("{at}: {what}")]
    ConfigSyntax {
        /// Where.
        at: Location,
        /// What was found and what is allowed.
        what: String,
    },
    /// A configuration value that is malformed or out of the range the firmware accepts.
    #[error(
        "{at}: {} = `{}`: not allowed (allowed: {allowed})",
        config_setting(section, key),
        excerpt(value, QUOTED_CHARS)
    )]
    ConfigValue {
        /// Where the option (or command) is.
        at: Location,
        /// The section (Klipper), command (RepRapFirmware, `M350`) or `$` (a GRBL
        /// setting `$N`, `key` its number).
        section: String,
        /// The option (Klipper) or parameter (RepRapFirmware).
        key: String,
        /// The value as written.
        value: Box<str>,
        /// What is allowed.
        allowed: Box<str>,
    },
    /// An option the firmware requires is not set.
    #[error("{source_name}: [{section}] has no `{key}` ({why})")]
    ConfigMissing {
        /// The configuration file (the main one when the whole section is missing).
        source_name: Arc<str>,
        /// The section.
        section: String,
        /// The option.
        key: String,
        /// Why it is needed (and, when includes were skipped, that one of them may set it).
        why: String,
    },
    /// A section the firmware requires is not in the configuration at all: the file is a
    /// fragment (a board's pins, a macro collection) rather than a whole configuration.
    #[error("{source_name}: no [{section}] section: {why}")]
    ConfigNoSection {
        /// The main configuration file.
        source_name: Arc<str>,
        /// The section.
        section: String,
        /// What the section must hold, and what to give instead.
        why: String,
    },
    /// A file that includes itself, directly or through others.
    #[error("{at}: `{path}` is already being read (include cycle: {chain})")]
    IncludeCycle {
        /// The include line that closes the cycle.
        at: Location,
        /// The file included again.
        path: String,
        /// The files being read, outermost first, joined by ` -> `.
        chain: String,
    },
    /// An exporter was given a value the firmware would not accept.
    #[error("cannot export {key} = {value} (allowed: {allowed})")]
    ExportValue {
        /// The setting (`shaper_type_x`, `M593 F`).
        key: String,
        /// The value given.
        value: String,
        /// What is allowed.
        allowed: String,
    },
    /// An R-form arc that ends where it starts, or an arc of zero sweep.
    #[error("{at}: `{command}`: {why}")]
    ArcDegenerate {
        /// Where.
        at: Location,
        /// `G2` or `G3`.
        command: String,
        /// What is degenerate.
        why: &'static str,
    },
    /// An arc the firmware would cut into more than [`crate::MAX_ARC_SEGMENTS`] segments.
    #[error(
        "{at}: `{command}`: {firmware} cuts this arc ({length_mm:.0} mm long) into {segments} straight segments; settle replays an arc of at most {max} (a 100 m arc at 1 mm): split it into several {command}s, or check the units (I, J, R in mm)"
    )]
    ArcTooManySegments {
        /// Where.
        at: Location,
        /// `G2` or `G3`.
        command: String,
        /// The firmware whose segmentation was used.
        firmware: String,
        /// The arc's length (mm).
        length_mm: f64,
        /// How many segments the firmware cuts it into.
        segments: usize,
        /// [`crate::MAX_ARC_SEGMENTS`].
        max: usize,
    },
    /// The firmware's planner or shaper refuses what a line asks for (a move, a limit, a
    /// shaper setting).
    #[error("{at}: `{command}`: {source}")]
    Plan {
        /// Where.
        at: Location,
        /// The command (`G1`, `SET_INPUT_SHAPER`, `M593`).
        command: String,
        /// What the planner says (boxed: it is large and rare).
        source: Box<settle_planner::PlanError>,
    },
    /// A move the firmware refuses because it leaves the machine's travel, in the
    /// firmware's words (Klipper's `Move out of range: x y z [e]`, GRBL's soft-limit
    /// alarm): the print stops there.
    #[error("{at}: {command}: {message}")]
    OutOfTravel {
        /// The move's line.
        at: Location,
        /// The command (`G1`).
        command: String,
        /// What the firmware says, and the travel.
        message: String,
    },
    /// A move or a dwell longer than [`crate::MAX_STEP_DURATION_S`]: a unit mistake (a feed
    /// of 0.0001 mm/min, a dwell of 1e9 ms), which would keep the replay busy for weeks.
    #[error(
        "{at}: `{command}` would last {duration_s:.4e} s ({what}): settle replays a move or a dwell of at most 3600 s (an hour), a real one lasts seconds: check the units (F is in mm/min; G4's P and S; the velocity and acceleration limits)"
    )]
    TooLong {
        /// The line.
        at: Location,
        /// The command (`G1`, `G4`).
        command: String,
        /// How long it would last (s).
        duration_s: f64,
        /// Its length and feed, or "a dwell".
        what: String,
    },
    /// A layer change past [`crate::MAX_LAYERS`]: the line that would open it.
    #[error(
        "{at}: this line opens layer {layer} ({}), past the {max} layers settle reads in a job (2.5 m of print at 0.05 mm): each layer is a row kept in memory and written to layers.csv, summary.md and report.html; {}",
        layer_cause(*from),
        layer_way_out(*from)
    )]
    TooManyLayers {
        /// The line of the layer change (the marker comment, or the move at a new Z).
        at: Location,
        /// The layer it would open ([`crate::MAX_LAYERS`] + 1).
        layer: u32,
        /// [`crate::MAX_LAYERS`].
        max: u32,
        /// How the layer change was found.
        from: crate::LayerSource,
    },
    /// A Prusa job for a printer settle has no Prusa-Firmware-Buddy settings for
    /// (`M862.3 P "MK3S"`): planning it with another printer's would be a guess.
    #[error(
        "{at}: `M862.3 P \"{name}\"`: settle has no Prusa-Firmware-Buddy settings for this printer, so --firmware prusa cannot plan the file as it would run (allowed: {known})"
    )]
    UnknownPrinter {
        /// The `M862.3` line.
        at: Location,
        /// The printer's name as written.
        name: String,
        /// The names settle knows.
        known: String,
    },
    /// A setting of a configuration file that the job cannot use, at the line that set
    /// it (a shaper settle refuses, limits the planner refuses).
    #[error("{at}: key `{key}`: {reason}")]
    ConfigSetting {
        /// The line that set it (the last one, where several did).
        at: Location,
        /// The setting as its firmware names it (`M593`, `input_shaper.shaper_freq_x`).
        key: String,
        /// What is wrong and what is allowed.
        reason: String,
    },
    /// A job setting (not from the file) that cannot be used.
    #[error("job setting `{key}`: {reason}")]
    JobSetting {
        /// The setting (`layers`, `shaper_x`, `firmware`, ...).
        key: &'static str,
        /// What is wrong and what is allowed.
        reason: String,
    },
}

/// A configuration setting as its firmware writes it: `[section] key` (Klipper's option,
/// RepRapFirmware's command and parameter), `$N` for GRBL's setting N.
/// The most characters of a line or value a note or an error quotes.
pub const QUOTED_CHARS: usize = 120;

/// `text` as a message quotes it: whole up to `chars` characters, else its first `chars`
/// and `...` (the file and line named hold the rest).
pub fn excerpt(text: &str, chars: usize) -> std::borrow::Cow<'_, str> {
    match text.char_indices().nth(chars) {
        Some((end, _)) => format!("{}...", &text[..end]).into(),
        None => text.into(),
    }
}

/// What opened a layer, for [`GcodeError::TooManyLayers`].
fn layer_cause(from: crate::LayerSource) -> &'static str {
    match from {
        crate::LayerSource::ZChange => "a working move at a new Z, in a file with no layer markers",
        _ => "a slicer's layer marker",
    }
}

/// How to read a file of more layers than [`crate::MAX_LAYERS`]: from the other source.
fn layer_way_out(from: crate::LayerSource) -> &'static str {
    match from {
        crate::LayerSource::ZChange => {
            "a milling or engraving job's changes of Z are not printed layers: give --layer-source markers (in a scenario, [gcode] layer_source = \"markers\") to take no layers from Z"
        }
        _ => {
            "if the file's layer markers are not its printed layers, give --layer-source z (in a scenario, [gcode] layer_source = \"z\") to take layers from Z only"
        }
    }
}

fn config_setting(section: &str, key: &str) -> String {
    if section == "$" {
        format!("${key}")
    } else {
        format!("[{section}] {key}")
    }
}

impl From<settle_files::FileError> for GcodeError {
    fn from(e: settle_files::FileError) -> Self {
        GcodeError::File(Box::new(e))
    }
}

impl GcodeError {
    /// A failed read of the stream named `source_name`: the reader's own error when the
    /// file grew past its limit, else the operating system's.
    pub(crate) fn io(source_name: &Arc<str>, source: std::io::Error) -> Self {
        if source
            .get_ref()
            .is_some_and(|e| e.is::<settle_files::FileError>())
        {
            return settle_files::read::unwrap_io(std::path::Path::new(&**source_name), source)
                .into();
        }
        let source = match source.downcast::<crate::read::bgcode::BgcodeError>() {
            Ok(b) => {
                return GcodeError::Bgcode {
                    source_name: source_name.clone(),
                    source: b,
                };
            }
            Err(source) => source,
        };
        GcodeError::Io {
            source_name: source_name.clone(),
            source,
        }
    }

    /// The location of a line error (`None` for I/O errors).
    pub fn location(&self) -> Option<&Location> {
        match self {
            GcodeError::Io { .. }
            | GcodeError::Bgcode { .. }
            | GcodeError::File(_)
            | GcodeError::ConfigMissing { .. }
            | GcodeError::ConfigNoSection { .. }
            | GcodeError::ExportValue { .. }
            | GcodeError::JobSetting { .. } => None,
            GcodeError::LineTooLong { at, .. }
            | GcodeError::Packaged { at, .. }
            | GcodeError::InvalidUtf8 { at }
            | GcodeError::ControlCharacter { at, .. }
            | GcodeError::Syntax { at, .. }
            | GcodeError::NotANumber { at, .. }
            | GcodeError::OutOfRange { at, .. }
            | GcodeError::DuplicateParameter { at, .. }
            | GcodeError::UnknownParameter { at, .. }
            | GcodeError::MissingValue { at, .. }
            | GcodeError::Checksum { at, .. }
            | GcodeError::Unsupported { at, .. }
            | GcodeError::ArcWithoutCentre { at, .. }
            | GcodeError::ArcMixedForms { at, .. }
            | GcodeError::ArcRadiusMismatch { at, .. }
            | GcodeError::ArcRadiusTooSmall { at, .. }
            | GcodeError::ArcDegenerate { at, .. }
            | GcodeError::ArcTooManySegments { at, .. }
            | GcodeError::ConfigSyntax { at, .. }
            | GcodeError::ConfigValue { at, .. }
            | GcodeError::ConfigSetting { at, .. }
            | GcodeError::IncludeCycle { at, .. }
            | GcodeError::Include { at, .. }
            | GcodeError::Plan { at, .. }
            | GcodeError::OutOfTravel { at, .. }
            | GcodeError::TooLong { at, .. }
            | GcodeError::TooManyLayers { at, .. }
            | GcodeError::UnknownPrinter { at, .. } => Some(at),
        }
    }

    /// The 1-based line number of a line error.
    pub fn line(&self) -> Option<u64> {
        self.location().map(|l| l.line)
    }
}

/// What a control character `byte` inside a line means: a carriage return there is most
/// likely a line end (a file whose lines end in CR alone, as classic Mac OS wrote them;
/// GRBL ends a line at CR as at LF, grbl/protocol.c), which the reader does not take as
/// one; anything else is binary data.
fn control_words(byte: u8) -> String {
    if byte == b'\r' {
        "carriage return (0x0d) inside the line: lines end at LF here (a CR before it is \
         dropped), and this file seems to end its lines in CR alone, which GRBL also takes \
         as a line end (grbl/protocol.c); convert them to LF (tr '\\r' '\\n')"
            .to_owned()
    } else {
        format!("control character 0x{byte:02x} (binary data?); G-code is text")
    }
}
