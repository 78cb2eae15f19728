//! settle-gcode: what firmware reads — G-code jobs and firmware configuration files.
//!
//! Three parts, a folder each:
//! - `read/`: the streaming G-code reader (below);
//! - [`config`]: Klipper's `printer.cfg` and RepRapFirmware's `config.g` read into plain
//!   data with the values the firmware would use (includes, SAVE_CONFIG, macros, defaults),
//!   and input shaper settings written back in each firmware's syntax;
//! - [`job`]: a G-code file replayed through a firmware's planner (settle-planner's
//!   `firmware` planners) into per-axis motion, streaming.
//!
//! [`Reader`] turns any `BufRead` (or a file, [`Reader::open`]) into [`Event`]s in file
//! order, each with its 1-based line and its layer: moves ([`Move`]: start and end in a
//! continuous machine frame, requested feed in mm/s, print/travel/extruder-only, exact arc
//! geometry), dwells, layer changes, motion-limit changes ([`LimitChange`], in mm/s and
//! mm/s^2 whatever the firmware's units) and notes. The conventions of the firmware
//! dialect the caller chooses ([`Dialect`]: Klipper, Marlin, RepRapFirmware) decide units
//! and modes; [`Move::segments_for`] cuts an arc into the exact points each firmware plans.
//! In the RepRapFirmware dialect the configuration commands (`M92`, `M350`, `M906`,
//! `M208`, `M669`) arrive as [`Setting`]s and macro calls (`M98`, `M501`) as notes.
//!
//! The reader holds one line at a time (at most [`ReaderOptions::max_line_bytes`]), so a
//! file of any size reads in bounded memory. Bad lines (binary data, NaN or huge
//! coordinates, a zero feed, inconsistent arcs, ...) are errors that name the file, line,
//! column and parameter; [`ReaderOptions::skip_bad_lines`] counts and skips them instead.
//! Commands without effect on motion (temperatures, fans, macros) are counted in
//! [`Reader::ignored_commands`]. [`Summary`] gathers the statistics a user wants before
//! planning; [`CanonicalWriter`] writes events back as G-code.
//!
//! ```
//! use settle_gcode::{ArcSegmentation, Dialect, EventKind, MoveKind, Reader, ReaderOptions};
//!
//! let text = "G1 X10 Y0 F6000\n;LAYER:0\nG3 X0 Y10 I-10 J0 E1.5 ; a quarter circle\nM104 S200\n";
//! let mut reader = Reader::new(text.as_bytes(), ReaderOptions::new(Dialect::Klipper));
//! let mut arcs = 0;
//! for event in reader.by_ref() {
//!     let event = event?;
//!     if let EventKind::Move(mv) = &event.kind {
//!         // Klipper cuts arcs into floor(length / 1 mm) segments.
//!         let points = mv.segments_for(&ArcSegmentation::default_for(Dialect::Klipper));
//!         if mv.kind == MoveKind::Print {
//!             assert_eq!((event.line, event.layer, points.len()), (3, 1, 15));
//!             assert!((mv.length_mm() - 5.0 * std::f64::consts::PI).abs() < 1e-12);
//!             assert_eq!(mv.feed_mm_s, 100.0);
//!             arcs += 1;
//!         }
//!     }
//! }
//! assert_eq!(arcs, 1);
//! assert_eq!(reader.ignored_commands()["M104"], 1);
//! # Ok::<(), settle_gcode::GcodeError>(())
//! ```

// `!(x >= 0.0)`-style comparisons reject NaN together with out-of-range values.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod config;
mod error;
pub mod job;
mod read;

pub use error::{GcodeError, Location, QUOTED_CHARS, excerpt};

/// The longest move (its length at its feed) or dwell a job may hold (s): an hour. A real
/// one lasts seconds (a slow CNC finishing pass minutes); longer is a unit mistake that
/// would keep the replay busy for weeks ([`GcodeError::TooLong`]).
pub const MAX_STEP_DURATION_S: f64 = 3600.0;

/// The largest value of a motion setting a G-code file may set (mm, mm/s, mm/s^2, mm/min,
/// Hz, s, in the command's own units; `SET_VELOCITY_LIMIT`, `M201`-`M205`, `M566`,
/// `M593`, `G1 F`, GRBL's `$` lines): none comes near it; larger is a typing error.
pub const MAX_LIMIT_VALUE: f64 = 1e9;

/// The least value of a motion setting that must be above 0 (a velocity, acceleration,
/// feed, junction deviation): the other end of [`MAX_LIMIT_VALUE`]. Below it the
/// planners' arithmetic leaves the range of `f64` (`SET_VELOCITY_LIMIT VELOCITY=1e-200`
/// planned a segment of infinite duration), and a move at 1e-9 already lasts longer than
/// [`MAX_STEP_DURATION_S`].
pub const MIN_LIMIT_VALUE: f64 = 1e-9;

/// The most straight segments one arc may be cut into: 100,000 (a 100 m arc at Klipper's
/// 1 mm resolution). The replay holds an arc's planned and shaped segments until the arc
/// ends (a move's timing is complete only then), a few KB each with a shaper; a longer
/// arc is refused ([`GcodeError::ArcTooManySegments`]) rather than held in gigabytes.
pub const MAX_ARC_SEGMENTS: usize = 100_000;

/// The most layers a job may have: 50,000 (2.5 m of print at 0.05 mm; a real print has a
/// few thousand). Each layer is a row that every consumer keeps and writes (`settle
/// gcode`'s layers.csv, summary.md and report.html), so their number bounds memory and
/// output; a file that opens one more is refused ([`GcodeError::TooManyLayers`]). Without
/// slicer markers a layer starts at every planar working move at a new Z, and a CNC
/// finishing toolpath changes Z all the time: [`LayerMode::Comments`] takes no layers from
/// Z.
pub const MAX_LAYERS: u32 = 50_000;
pub use read::arc::{
    Arc, FULL_CIRCLE_TOLERANCE_MM, Plane, RADIUS_TOLERANCE_MAX_MM, RADIUS_TOLERANCE_MM,
    RADIUS_TOLERANCE_REL,
};
pub use read::bgcode::{Bgcode, BgcodeError};
pub use read::canonical::CanonicalWriter;
pub use read::dialect::Dialect;
pub use read::event::{Event, EventKind, LayerChange, LayerSource, Note};
pub use read::geometry::{Bounds, Move, MoveKind, Path, Point, Tool};
pub use read::layers::LayerMode;
pub use read::limits::{AxisFlags, AxisValues, FtShaper, LimitChange};
pub use read::reader::{FileInput, MAX_FEATURES, Reader, ReaderOptions, Skipped};
pub use read::segments::{ArcSegmentation, GrblArcs, KlipperArcs, MarlinArcs, PrusaArcs, RrfArcs};
pub use read::setting::Setting;
pub use read::summary::{LimitSeen, Summary};
