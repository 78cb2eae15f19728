//! The streaming reader: lines in, events out, in file order.

use std::collections::{BTreeMap, VecDeque};
use std::fmt::Write as _;
use std::io::{BufRead, BufReader};
use std::path::Path;
use std::sync::Arc;

use crate::error::{GcodeError, Location};
use crate::read::arc::Plane;
use crate::read::cmd::{Check, Cmd, CmdName};
use crate::read::dialect::Dialect;
use crate::read::event::{Event, EventKind, Note};
use crate::read::geometry::{Move, Point};
use crate::read::grbl::GrblState;
use crate::read::grbl::dollar::{self, Dollar};
use crate::read::grbl::words;
use crate::read::layers::{LayerMode, Layers};
use crate::read::lex::{self, LexError, LineKind, lex};
use crate::read::limit_parse::{self, Outcome};
use crate::read::motion::Motion;
use crate::read::params::{KeyValues, Params};
use crate::read::setting_parse;
use settle_files::lines::{BoundedLines as Lines, LineStatus};
use settle_files::looks::Looks;

/// How the reader reads.
#[derive(Debug, Clone, PartialEq)]
pub struct ReaderOptions {
    /// Whose conventions to follow.
    pub dialect: Dialect,
    /// Count and skip bad lines (see [`Reader::skipped`]) instead of ending with an error.
    pub skip_bad_lines: bool,
    /// Longest line read, bytes (64 KiB by default: slicers write lines under 1 KiB; a
    /// longer one is binary data or a corrupt file, and is skipped unread).
    pub max_line_bytes: usize,
    /// Where layer changes come from (at most [`crate::MAX_LAYERS`] of them).
    pub layers: LayerMode,
    /// Largest |X|, |Y|, |Z| accepted, mm (1e5: no printer or gantry spans 100 m; larger
    /// values are typing errors or garbage).
    pub max_coordinate_mm: f64,
    /// Largest |E| accepted, mm (1e9: a kilometre of filament is ~1e6 mm).
    pub max_extruder_mm: f64,
    /// How many skipped-line errors to keep for reporting (the rest are only counted).
    pub kept_errors: usize,
    /// GRBL: the laser mode (`$32=1`) at the start of the file (off by default, as GRBL
    /// ships; the file's own `$32` lines change it).
    pub laser_mode: bool,
    /// GRBL: `$31` and `$30`, the `S` of the least and of full spindle speed or laser
    /// power, at the start of the file (0 and 1000, GRBL's defaults.h; the file's own
    /// `$30`/`$31` lines change them). An `S` outside them is noted: GRBL runs it at the
    /// nearer end.
    pub spindle_range: [f64; 2],
}

impl ReaderOptions {
    /// The defaults for `dialect`.
    pub fn new(dialect: Dialect) -> Self {
        ReaderOptions {
            dialect,
            skip_bad_lines: false,
            max_line_bytes: 64 * 1024,
            layers: LayerMode::Auto,
            max_coordinate_mm: 1e5,
            max_extruder_mm: 1e9,
            kept_errors: 20,
            laser_mode: false,
            spindle_range: [0.0, 1000.0],
        }
    }
}

/// Lines skipped under [`ReaderOptions::skip_bad_lines`].
#[derive(Debug, Default)]
pub struct Skipped {
    /// How many.
    pub count: u64,
    /// The first [`ReaderOptions::kept_errors`] of them.
    pub first: Vec<GcodeError>,
}

/// Distinct ignored command names kept; more are counted under `(other)`.
const MAX_IGNORED_NAMES: usize = 256;

/// Distinct slicer feature types kept (a slicer writes some 15); more share the last,
/// `(other)`.
pub const MAX_FEATURES: usize = 64;

/// A streaming G-code reader: an iterator of events (or the error that ended it).
///
/// Memory is bounded by [`ReaderOptions::max_line_bytes`] plus the input's buffer; the
/// file is never held whole. After an error the iterator ends, unless
/// [`ReaderOptions::skip_bad_lines`] is set; a layer past [`crate::MAX_LAYERS`] ends it
/// always ([`GcodeError::TooManyLayers`]).
#[derive(Debug)]
pub struct Reader<R> {
    lines: Lines<R>,
    source_name: Arc<str>,
    scratch: String,
    interp: Interp,
    error: Option<GcodeError>,
    finished: bool,
    /// What the file looks like when it is text of another kind than G-code (a
    /// printer.cfg, a scenario: [`Looks`]), as [`Reader::open`] found: its first error is
    /// reported as that until a move has been read (a file with moves is a job, whatever
    /// its first lines look like).
    foreign: Option<Looks>,
    /// A move has been yielded.
    moved: bool,
}

#[derive(Debug)]
struct Interp {
    opts: ReaderOptions,
    motion: Motion,
    layers: Layers,
    params: Params,
    kv: KeyValues,
    queue: VecDeque<Event>,
    layer_buf: Vec<(u64, u32, crate::read::event::LayerChange)>,
    ignored: BTreeMap<String, u64>,
    name_buf: String,
    skipped: Skipped,
    /// GRBL's modal state (the GRBL dialect only).
    grbl: GrblState,
    /// GRBL: the line with its commands blanked, for the value words.
    words_buf: String,
    /// GRBL: events of the block being run.
    block_out: Vec<EventKind>,
    /// Feature types named so far; index 0 is "none".
    features: Vec<String>,
    /// The feature type in force (index into `features`).
    feature: u16,
}

/// A G-code file open for reading (settle-files' reader: a regular file of at most
/// [`settle_files::limit::GCODE`]): its text, or, for a binary G-code file (it starts with
/// `GCDE`), the text its G-code blocks decode to ([`crate::Bgcode`]).
#[derive(Debug)]
pub enum FileInput {
    /// A text file.
    Text(BufReader<settle_files::read::Input>),
    /// A binary G-code file, decoded block by block.
    Binary(super::bgcode::Bgcode<BufReader<settle_files::read::Input>>),
}

impl std::io::Read for FileInput {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        match self {
            FileInput::Text(r) => r.read(buf),
            FileInput::Binary(r) => r.read(buf),
        }
    }
}

impl BufRead for FileInput {
    fn fill_buf(&mut self) -> std::io::Result<&[u8]> {
        match self {
            FileInput::Text(r) => r.fill_buf(),
            FileInput::Binary(r) => r.fill_buf(),
        }
    }

    fn consume(&mut self, amt: usize) {
        match self {
            FileInput::Text(r) => r.consume(amt),
            FileInput::Binary(r) => r.consume(amt),
        }
    }
}

impl Reader<FileInput> {
    /// Opens a file (a regular file, links followed, of at most
    /// [`settle_files::limit::GCODE`]); a binary G-code file is read as its G-code text.
    pub fn open(path: impl AsRef<Path>, options: ReaderOptions) -> Result<Self, GcodeError> {
        let path = path.as_ref();
        let name: Arc<str> = Arc::from(path.display().to_string());
        let file = settle_files::read::open(path, settle_files::limit::GCODE)?;
        let len = file.len();
        let mut buffered = BufReader::with_capacity(settle_files::looks::HEAD, file);
        let head = buffered.fill_buf().map_err(|e| GcodeError::io(&name, e))?;
        let binary = head.starts_with(b"GCDE");
        // A model, a slicer's package or binary data is no G-code at all; text of another
        // kind (a printer.cfg, a scenario) is named if the reader refuses it.
        let foreign = match Looks::of(head, &name, len) {
            Some(
                l @ (Looks::SlicedThreeMf
                | Looks::ThreeMf
                | Looks::Ufp
                | Looks::StlBinary
                | Looks::StlAscii
                | Looks::Binary),
            ) => {
                return Err(GcodeError::Packaged {
                    at: Location {
                        source_name: name,
                        line: 1,
                        column: Some(1),
                    },
                    what: l.what(),
                    instead: l.then(),
                });
            }
            // G-code, and what the first line names (gzip, zip, UTF-16: `packaged`).
            Some(Looks::GcodeJob | Looks::Bgcode | Looks::Packed(_)) | None => None,
            other => other,
        };
        let input = if binary {
            FileInput::Binary(
                super::bgcode::Bgcode::new(buffered).map_err(|e| GcodeError::io(&name, e))?,
            )
        } else {
            FileInput::Text(buffered)
        };
        let mut reader = Reader::new(input, options).with_name(name);
        reader.foreign = foreign;
        Ok(reader)
    }
}

impl<R: BufRead> Reader<R> {
    /// A reader over any buffered input.
    pub fn new(input: R, options: ReaderOptions) -> Self {
        let interp = Interp {
            motion: Motion::new(
                options.dialect,
                options.max_coordinate_mm,
                options.max_extruder_mm,
            ),
            layers: Layers::new(options.layers),
            params: if options.dialect == Dialect::Rrf {
                Params::with_exponents()
            } else {
                Params::default()
            },
            kv: KeyValues::default(),
            queue: VecDeque::new(),
            layer_buf: Vec::new(),
            ignored: BTreeMap::new(),
            name_buf: String::new(),
            skipped: Skipped::default(),
            grbl: GrblState::new(options.laser_mode, options.spindle_range),
            words_buf: String::new(),
            block_out: Vec::new(),
            features: vec![String::new()],
            feature: 0,
            opts: options,
        };
        Reader {
            lines: Lines::new(input, interp.opts.max_line_bytes),
            source_name: Arc::from("<input>"),
            scratch: String::new(),
            interp,
            error: None,
            finished: false,
            foreign: None,
            moved: false,
        }
    }

    /// Names the input in error messages.
    pub fn with_name(mut self, name: impl Into<Arc<str>>) -> Self {
        self.source_name = name.into();
        self
    }

    /// The input's name in error messages ([`Reader::with_name`]).
    pub fn source_name(&self) -> &Arc<str> {
        &self.source_name
    }

    /// The options in use.
    pub fn options(&self) -> &ReaderOptions {
        &self.interp.opts
    }

    /// Commands ignored so far (not motion, or not known in this dialect), by name
    /// (`M104`, `T0`, `PRINT_START`), with how often.
    pub fn ignored_commands(&self) -> &BTreeMap<String, u64> {
        &self.interp.ignored
    }

    /// The slicer feature types named so far (`;TYPE:` comments): [`crate::Move::feature`]
    /// indexes it; index 0 is the empty name (no feature named).
    pub fn features(&self) -> &[String] {
        &self.interp.features
    }

    /// Lines skipped so far under [`ReaderOptions::skip_bad_lines`].
    pub fn skipped(&self) -> &Skipped {
        &self.interp.skipped
    }

    /// Lines read so far.
    pub fn lines_read(&self) -> u64 {
        self.lines.line_no()
    }

    /// Bytes read so far.
    pub fn bytes_read(&self) -> u64 {
        self.lines.bytes_read()
    }

    /// The machine position after the events yielded so far, mm.
    pub fn position(&self) -> Point {
        self.interp.motion.position()
    }

    /// Ends the read at a layer past [`crate::MAX_LAYERS`], with or without
    /// [`ReaderOptions::skip_bad_lines`]: the line is not bad, the job has too many layers
    /// (skipping the change would only refuse the next).
    fn check_layers(&mut self) {
        if let Some((line, from)) = self.interp.layers.refused() {
            // A line error of the same line is reported first.
            self.error.get_or_insert(GcodeError::TooManyLayers {
                at: Location {
                    source_name: self.source_name.clone(),
                    line,
                    column: None,
                },
                layer: crate::MAX_LAYERS + 1,
                max: crate::MAX_LAYERS,
                from,
            });
            self.finished = true;
        }
    }

    /// What [`Reader::open`] found the file to be when it is text of another kind than
    /// G-code (a printer.cfg, a scenario, a recording), with the command that reads it.
    pub fn looks(&self) -> Option<Looks> {
        self.foreign
    }

    fn fail(&mut self, e: GcodeError) {
        if let Some(l) = self.foreign.filter(|_| !self.moved) {
            // Not a bad line of a job: no line of it is G-code, skipped or not.
            self.error = Some(GcodeError::Packaged {
                at: Location {
                    source_name: self.source_name.clone(),
                    line: 1,
                    column: Some(1),
                },
                what: l.what(),
                instead: l.then(),
            });
            return;
        }
        if self.interp.opts.skip_bad_lines {
            let s = &mut self.interp.skipped;
            s.count += 1;
            if s.first.len() < self.interp.opts.kept_errors {
                s.first.push(e);
            }
        } else {
            self.error = Some(e);
        }
    }
}

impl<R: BufRead> Iterator for Reader<R> {
    type Item = Result<Event, GcodeError>;

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            if let Some(e) = self.interp.queue.pop_front() {
                self.moved |= matches!(e.kind, EventKind::Move(_));
                return Some(Ok(e));
            }
            if let Some(e) = self.error.take() {
                self.finished = true;
                return Some(Err(e));
            }
            if self.finished {
                return None;
            }
            match self.lines.next_line() {
                Err(source) => {
                    self.finished = true;
                    return Some(Err(GcodeError::io(&self.source_name, source)));
                }
                Ok(None) => {
                    self.finished = true;
                    self.interp.flush_layer();
                    self.check_layers();
                }
                Ok(Some(LineStatus::TooLong)) => {
                    let at = Location {
                        source_name: self.source_name.clone(),
                        line: self.lines.line_no(),
                        column: None,
                    };
                    self.fail(GcodeError::LineTooLong {
                        at,
                        limit_bytes: self.interp.opts.max_line_bytes,
                    });
                }
                Ok(Some(LineStatus::Complete)) => {
                    let line_no = self.lines.line_no();
                    let mut bytes = self.lines.bytes();
                    if line_no == 1 {
                        // A byte-order mark (editors on Windows write one) is not G-code.
                        bytes = bytes.strip_prefix(b"\xef\xbb\xbf").unwrap_or(bytes);
                        if let Some((what, instead)) = super::packaged::packaged(bytes) {
                            let at = Location {
                                source_name: self.source_name.clone(),
                                line: 1,
                                column: Some(1),
                            };
                            self.error = Some(GcodeError::Packaged { at, what, instead });
                            continue;
                        }
                    }
                    let result =
                        self.interp
                            .line(&self.source_name, line_no, bytes, &mut self.scratch);
                    if let Err(e) = result {
                        self.fail(e);
                    }
                    self.check_layers();
                }
            }
        }
    }
}

/// The printer `M862.3` names with `P`, as Prusa-Firmware-Buddy reads it
/// (src/marlin_stubs/M862_2_3.cpp, `M862_3`): after the `P`, spaces and double quotes are
/// skipped, then letters, digits and dots make the name (`P "MK4S"`, `P"MK4S"`, `P MK4S`).
/// `None` without `P` (`M862.3 Q` asks the printer for its name).
fn printer_model(args: &str) -> Option<String> {
    let at = args.find('P')?;
    let rest = args[at + 1..].trim_start_matches([' ', '"']);
    let end = rest
        .find(|c: char| !(c.is_ascii_alphanumeric() || c == '.'))
        .unwrap_or(rest.len());
    Some(rest[..end].to_string())
}

/// RepRapFirmware's configuration commands ([`setting_parse`]).
fn is_rrf_setting(number: u32) -> bool {
    matches!(number, 92 | 350 | 906 | 208 | 669 | 665 | 98 | 501)
}

impl Interp {
    fn push(&mut self, line: u64, kind: EventKind) {
        self.queue.push_back(Event {
            line,
            layer: self.layers.index,
            kind,
        });
    }

    /// A move, after the layer change it may start (Z fallback: a working move at a new
    /// Z), tagged with the feature type in force.
    fn push_move(&mut self, line: u64, mut mv: Move) {
        mv.feature = self.feature;
        if let Some(c) = self.layers.before_move(line, &mv, mv.is_working()) {
            self.push(line, EventKind::Layer(c));
        }
        self.push(line, EventKind::Move(mv));
    }

    /// A comment line: a layer marker, or a slicer feature type.
    fn comment(&mut self, line_no: u64, t: &str) {
        self.layers.comment(line_no, t, &mut self.layer_buf);
        for (line, layer, c) in self.layer_buf.drain(..) {
            self.queue.push_back(Event {
                line,
                layer,
                kind: EventKind::Layer(c),
            });
        }
        if let Some(name) = feature_name(t) {
            self.feature = match self.features.iter().position(|f| f == name) {
                Some(i) => i as u16,
                None if self.features.len() < MAX_FEATURES - 1 => {
                    self.features.push(name.to_string());
                    (self.features.len() - 1) as u16
                }
                None => {
                    if self.features.len() < MAX_FEATURES {
                        self.features.push("(other)".to_string());
                    }
                    (MAX_FEATURES - 1) as u16
                }
            };
        }
    }

    fn flush_layer(&mut self) {
        if let Some((line, layer, c)) = self.layers.flush() {
            self.queue.push_back(Event {
                line,
                layer,
                kind: EventKind::Layer(c),
            });
        }
    }

    fn ignore(&mut self, name: CmdName) {
        self.name_buf.clear();
        match name {
            CmdName::Code {
                letter,
                number,
                sub,
            } => {
                let _ = write!(self.name_buf, "{}{number}", char::from(letter));
                if let Some(s) = sub {
                    let _ = write!(self.name_buf, ".{s}");
                }
            }
            CmdName::Named(n) | CmdName::Block(n) => {
                self.name_buf.push_str(&n.to_ascii_uppercase());
            }
        }
        if let Some(c) = self.ignored.get_mut(self.name_buf.as_str()) {
            *c += 1;
        } else if self.ignored.len() < MAX_IGNORED_NAMES {
            self.ignored.insert(self.name_buf.clone(), 1);
        } else {
            *self.ignored.entry("(other)".to_string()).or_insert(0) += 1;
        }
    }

    fn line(
        &mut self,
        source: &Arc<str>,
        line_no: u64,
        bytes: &[u8],
        scratch: &mut String,
    ) -> Result<(), GcodeError> {
        let at = |column: Option<usize>| Location {
            source_name: source.clone(),
            line: line_no,
            column,
        };
        let text = std::str::from_utf8(bytes).map_err(|e| GcodeError::InvalidUtf8 {
            at: at(Some(e.valid_up_to() + 1)),
        })?;
        let lex_error = |e: LexError| match e {
            LexError::Control { at: c, byte } => GcodeError::ControlCharacter {
                at: at(Some(c + 1)),
                byte,
            },
            LexError::Syntax { at: c, what } => GcodeError::Syntax {
                at: at(Some(c + 1)),
                what,
            },
            LexError::Checksum {
                at: c,
                found,
                computed,
            } => GcodeError::Checksum {
                at: at(Some(c + 1)),
                found,
                computed,
            },
        };
        if self.opts.dialect == Dialect::Grbl {
            let code = lex::code(text, scratch).map_err(lex_error)?;
            return self.grbl_line(source, line_no, code, &at);
        }
        let kind = lex(text, scratch).map_err(lex_error)?;
        match kind {
            LineKind::Blank | LineKind::Percent => Ok(()),
            LineKind::Comment(t) => {
                self.comment(line_no, t);
                Ok(())
            }
            LineKind::Code {
                letter,
                number,
                sub,
                args,
                args_at,
            } => {
                self.flush_layer();
                let cmd = Cmd {
                    name: CmdName::Code {
                        letter,
                        number,
                        sub,
                    },
                    source,
                    line: line_no,
                    args_at,
                    args,
                };
                self.code(&cmd, letter, number, sub)
            }
            LineKind::Extended {
                name,
                args,
                args_at,
            } => {
                self.flush_layer();
                let cmd = Cmd {
                    name: CmdName::Named(name),
                    source,
                    line: line_no,
                    args_at,
                    args,
                };
                self.named(&cmd, name)
            }
        }
    }

    fn code(
        &mut self,
        cmd: &Cmd,
        letter: u8,
        number: u32,
        sub: Option<u32>,
    ) -> Result<(), GcodeError> {
        let known = sub.is_none()
            && match letter {
                b'G' => matches!(number, 0..=4 | 17..=21 | 28 | 90..=92),
                b'M' => {
                    matches!(
                        number,
                        82 | 83 | 400 | 201 | 203 | 204 | 205 | 566 | 593 | 493 | 494 | 220 | 221
                    ) || (self.opts.dialect == Dialect::Rrf && is_rrf_setting(number))
                        || (self.opts.dialect.is_marlin() && number == 92)
                }
                _ => false,
            };
        if !known {
            if self.opts.dialect == Dialect::Prusa
                && (letter, number, sub) == (b'M', 862, Some(3))
                && let Some(name) = printer_model(cmd.args)
            {
                self.push(cmd.line, EventKind::Note(Note::PrinterModel { name }));
            }
            self.ignore(cmd.name);
            return Ok(());
        }
        self.params
            .parse(cmd.args)
            .map_err(|e| cmd.param_error(e))?;
        let p = &self.params;
        let line = cmd.line;
        match (letter, number) {
            (b'G', 0 | 1) => {
                if let Some(mv) = self.motion.line(cmd, p, number == 0)? {
                    self.push_move(line, mv);
                }
            }
            (b'G', 2 | 3) => {
                let mv = self.motion.arc(cmd, p, number == 2)?;
                if self.opts.dialect == Dialect::Klipper && p.has(b'P') {
                    // OrcaSlicer's spiral lift (`G3 Z.8 I.044 J-1.216 P1 F30000`): one
                    // turn that ends where it starts, which Klipper traces as a full
                    // circle whatever P says (Marlin's ARC_P_CIRCLES reads P as extra
                    // turns).
                    let turns = match p.get(b'P') {
                        crate::read::params::Value::Num(v) => v.to_string(),
                        _ => String::new(),
                    };
                    let note = Note::IgnoredByFirmware {
                        command: format!("G{number} P{turns}"),
                        reason: "Klipper's G2/G3 reads no P, the count of turns Marlin's ARC_P_CIRCLES reads; an arc that ends where it starts is one full turn (klippy/extras/gcode_arcs.py)",
                    };
                    self.push(line, EventKind::Note(note));
                }
                self.push_move(line, mv);
            }
            (b'G', 4) => {
                let (duration_s, s_ignored) = self.motion.dwell(cmd, p)?;
                if s_ignored {
                    let note = Note::IgnoredByFirmware {
                        command: format!("G4{}", cmd.args.trim_end()),
                        reason: "Klipper's G4 reads only P, in milliseconds (klippy/toolhead.py cmd_G4)",
                    };
                    self.push(line, EventKind::Note(note));
                }
                self.push(line, EventKind::Dwell { duration_s });
            }
            (b'G', 17..=19) => {
                cmd.allow(p, b"", "none")?;
                self.motion.set_plane(match number {
                    17 => Plane::Xy,
                    18 => Plane::Zx,
                    _ => Plane::Yz,
                });
            }
            (b'G', 20 | 21) => {
                cmd.allow(p, b"", "none")?;
                match self.opts.dialect {
                    Dialect::Klipper if number == 20 => {
                        return Err(cmd.unsupported(
                            "Klipper refuses inch units (klippy/extras/gcode_move.py cmd_G20: \"Machine does not support G20\"); convert the file to millimetres",
                        ));
                    }
                    Dialect::Marlin | Dialect::Prusa if number == 20 => {
                        return Err(cmd.unsupported(
                            "Marlin reads G20 only when built with INCH_MODE_SUPPORT (off in its example configuration); convert the file to millimetres",
                        ));
                    }
                    _ => self.motion.set_inches(number == 20),
                }
            }
            (b'G', 28) => {
                let axes = self.motion.home(p);
                self.push(line, EventKind::Note(Note::Homed { axes }));
            }
            (b'G', 90 | 91) => {
                cmd.allow(p, b"", "none")?;
                self.motion.set_relative(number == 91);
            }
            (b'G', 92) => self.motion.set_position(cmd, p)?,
            (b'M', 82 | 83) => {
                cmd.allow(p, b"", "none")?;
                self.motion.set_e_relative(number == 83);
            }
            (b'M', 400) => self.push(line, EventKind::Dwell { duration_s: 0.0 }),
            (b'M', 220 | 221) => {
                if let Some(note) = factor(&mut self.motion, self.opts.dialect, cmd, number, p)? {
                    self.push(line, EventKind::Note(note));
                }
            }
            // Marlin's steps per mm: checked, not followed (the configuration's hold).
            (b'M', 92) if self.opts.dialect.is_marlin() => {
                limit_parse::marlin_steps(cmd, p)?;
                self.ignore(cmd.name);
            }
            (b'M', n) if is_rrf_setting(n) => {
                match setting_parse::m_code(self.opts.dialect, cmd, number, p)? {
                    setting_parse::Outcome::Setting(s) => self.push(line, EventKind::Setting(s)),
                    setting_parse::Outcome::Note(n) => self.push(line, EventKind::Note(n)),
                    setting_parse::Outcome::Nothing => {}
                    setting_parse::Outcome::Unknown => self.ignore(cmd.name),
                }
            }
            (b'M', _) => match limit_parse::m_code(self.opts.dialect, cmd, number, p)? {
                Outcome::Limits(c) => self.push(line, EventKind::Limits(c)),
                Outcome::Note(n) => self.push(line, EventKind::Note(n)),
                Outcome::Nothing => {}
                Outcome::Unknown => self.ignore(cmd.name),
            },
            _ => self.ignore(cmd.name),
        }
        Ok(())
    }

    /// A line of GRBL G-code: a `$` command, or a block ([`crate::read::grbl`]).
    fn grbl_line(
        &mut self,
        source: &Arc<str>,
        line_no: u64,
        code: lex::Code<'_>,
        at: &dyn Fn(Option<usize>) -> Location,
    ) -> Result<(), GcodeError> {
        if code.is_empty() {
            if let Some(t) = code.comment {
                self.comment(line_no, t);
            }
            return Ok(());
        }
        self.flush_layer();
        let text = &code.text[code.at..];
        self.block_out.clear();
        let mut out = std::mem::take(&mut self.block_out);
        let result = if text.starts_with('$') {
            match dollar::line(&mut self.grbl, &mut self.motion, text, at, &mut out) {
                Ok(Dollar::Events) => Ok(()),
                Ok(Dollar::Ignored(name)) => {
                    *self.ignored.entry(name.to_string()).or_insert(0) += 1;
                    Ok(())
                }
                Err(e) => Err(e),
            }
        } else {
            let cmd = Cmd {
                name: CmdName::Block(text),
                source,
                line: line_no,
                args_at: code.at,
                args: text,
            };
            let mut rest = std::mem::take(&mut self.words_buf);
            let r = words::read(&cmd, text, &mut rest).and_then(|w| {
                self.params.parse(&rest).map_err(|e| cmd.param_error(e))?;
                let cmd = Cmd { args: &rest, ..cmd };
                self.grbl
                    .block(&mut self.motion, &cmd, &w, &self.params, &mut out)
            });
            self.words_buf = rest;
            r
        };
        for kind in out.drain(..) {
            match kind {
                EventKind::Move(mv) => self.push_move(line_no, mv),
                other => self.push(line_no, other),
            }
        }
        self.block_out = out;
        result
    }

    fn named(&mut self, cmd: &Cmd, name: &str) -> Result<(), GcodeError> {
        let limit_command = name.eq_ignore_ascii_case("SET_VELOCITY_LIMIT")
            || name.eq_ignore_ascii_case("SET_INPUT_SHAPER");
        if self.opts.dialect != Dialect::Klipper || !limit_command {
            self.ignore(cmd.name);
            return Ok(());
        }
        self.kv.parse(cmd.args).map_err(|e| cmd.param_error(e))?;
        match limit_parse::named(self.opts.dialect, cmd, name, &self.kv)? {
            Outcome::Limits(c) => self.push(cmd.line, EventKind::Limits(c)),
            Outcome::Note(n) => self.push(cmd.line, EventKind::Note(n)),
            Outcome::Nothing => {}
            Outcome::Unknown => self.ignore(cmd.name),
        }
        Ok(())
    }
}

/// The feature type a comment names: PrusaSlicer, SuperSlicer, OrcaSlicer and Cura write
/// `;TYPE:External perimeter` / `;TYPE:WALL-OUTER`; OrcaSlicer and BambuStudio for Bambu
/// printers `; FEATURE: Outer wall` (OrcaSlicer `GCodeProcessor::Reserved_Tags`).
fn feature_name(comment: &str) -> Option<&str> {
    let t = comment.trim();
    let name = t
        .strip_prefix("TYPE:")
        .or_else(|| t.strip_prefix("FEATURE:"))?
        .trim();
    (!name.is_empty() && name.len() <= 64).then_some(name)
}

/// `M220 S` (feed factor) and `M221 S` (extrusion factor), percent: Klipper
/// `cmd_M220`/`cmd_M221` (klippy/extras/gcode_move.py; without `S` they reset to
/// 100 %), Marlin `M220.cpp`/`M221.cpp` (whole percent; without `S` they report),
/// RepRapFirmware (`GCodes2.cpp`; without `S` they report; below 1 % they change nothing,
/// returned as a note).
fn factor(
    motion: &mut Motion,
    dialect: Dialect,
    cmd: &Cmd,
    number: u32,
    p: &Params,
) -> Result<Option<Note>, GcodeError> {
    let allowed: &[u8] = match dialect {
        Dialect::Marlin | Dialect::Prusa => b"SBRT",
        Dialect::Rrf => b"SD",
        _ => b"S",
    };
    cmd.allow(p, allowed, "S (percent)")?;
    let check = Check {
        ok: |v| v > 0.0 && v <= 1e4,
        allowed: "a percentage above 0, up to 10000",
    };
    let percent = match (cmd.num(p, b'S', check)?, dialect) {
        (Some(s), Dialect::Marlin | Dialect::Prusa) => s.trunc().max(1.0),
        // RepRapFirmware takes a factor of 0.01 or more: M220 answers "Invalid speed
        // factor", M221 keeps its factor without a word (src/GCodes/GCodes2.cpp cases 220
        // and 221).
        (Some(s), Dialect::Rrf) if s < 1.0 => {
            return Ok(Some(Note::IgnoredByFirmware {
                command: format!("M{number}{}", cmd.args.trim_end()),
                reason: "RepRapFirmware keeps its factor for S below 1 % (src/GCodes/GCodes2.cpp cases 220 and 221)",
            }));
        }
        (Some(s), _) => s,
        (None, Dialect::Klipper) => 100.0,
        (None, _) => return Ok(None),
    };
    if number == 220 {
        motion.set_speed_factor(percent / 100.0);
    } else {
        motion.set_extrude_factor(percent / 100.0);
    }
    Ok(None)
}
