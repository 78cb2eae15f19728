//! What a job yields: shaped per-axis motion in chunks, each with the moves it carries,
//! and the print-time account.

use std::collections::BTreeMap;
use std::sync::Arc;

use settle_planner::Trajectory;

use crate::read::geometry::{MoveKind, Point};
use settle_planner::firmware::Firmware;

/// The path a move commands, for measuring contour error against it (mm, machine frame).
#[derive(Debug, Clone, PartialEq)]
pub enum MoveGeometry {
    /// A straight line.
    Line {
        /// Start X, Y, Z (mm).
        from_mm: [f64; 3],
        /// End X, Y, Z (mm).
        to_mm: [f64; 3],
    },
    /// An arc, as written and as the firmware cuts it.
    Arc {
        /// The exact arc (centre, radius, sweep).
        arc: crate::Arc,
        /// The corners of the straight segments the firmware plans, X, Y, Z (mm), the
        /// start first and the end last: the path the machine is commanded along.
        points_mm: Vec<[f64; 3]>,
    },
}

/// One G-code move and when the planner runs it.
#[derive(Debug, Clone, PartialEq)]
pub struct MoveInfo {
    /// 0-based index among the file's moves (every G0/G1/G2/G3 that moves something, and
    /// the travel home a `G28` after motion stands for).
    pub index: u64,
    /// 1-based line in the file.
    pub line: u64,
    /// Layer index (0 before the first layer change; see [`crate::Event::layer`]).
    pub layer: u32,
    /// Print, travel or extruder-only.
    pub kind: MoveKind,
    /// Whether it works the material ([`crate::Move::is_working`]): the moves whose error
    /// counts.
    pub working: bool,
    /// The spindle or laser over it ([`crate::Tool::Off`] on a printer).
    pub tool: crate::Tool,
    /// The slicer's feature type: an index into [`JobSummary::features`] (0: none named).
    pub feature: u16,
    /// When the planner starts it (s, print clock): the start of its first planned
    /// segment (settle's planner: the middle of the corner transition at its start).
    pub start_time_s: f64,
    /// How long it runs (s); 0 for a move the firmware merged into the next one.
    pub duration_s: f64,
    /// Where it starts (mm, E included).
    pub start_mm: Point,
    /// Where it ends (mm).
    pub end_mm: Point,
    /// The requested feed rate (mm/s).
    pub feed_mm_s: f64,
    /// The commanded path.
    pub geometry: MoveGeometry,
}

impl MoveInfo {
    /// When the planner is done with it (s).
    pub fn end_time_s(&self) -> f64 {
        self.start_time_s + self.duration_s
    }
}

/// A stretch of shaped motion.
#[derive(Debug, Clone)]
pub struct JobChunk {
    /// Print-clock time of the profiles' `t = 0` (s).
    pub start_time_s: f64,
    /// X, Y, Z and E (m; E in m of filament), each axis shaped by the shaper in force.
    /// Consecutive chunks join continuously.
    pub trajectory: Trajectory,
    /// Every move whose planned time span meets the chunk's, in order.
    pub moves: Vec<Arc<MoveInfo>>,
}

impl JobChunk {
    /// Print-clock time of the chunk's end (s).
    pub fn end_time_s(&self) -> f64 {
        self.start_time_s + self.trajectory.duration_s()
    }
}

/// One layer's share of the print time.
#[derive(Debug, Clone, PartialEq)]
pub struct LayerTime {
    /// Layer index.
    pub layer: u32,
    /// The layer's Z (mm): where the file says (PrusaSlicer's `;Z:`, Simplify3D's layer
    /// comment, a change of Z), else where the layer's first working move in a plane of
    /// constant Z runs (Cura's `;LAYER:n` names no Z); none for a layer without one.
    pub z_mm: Option<f64>,
    /// When its first move starts (s; the first layer counted starts at 0).
    pub start_time_s: f64,
    /// Until the next layer's first move, or the end of the print (s): its moves and the
    /// dwells and pauses between them.
    pub duration_s: f64,
    /// Moves in it.
    pub moves: u64,
    /// Time spent in its working moves (s): extruding on a printer, the laser or spindle
    /// on in a feed move on a laser or mill ([`crate::Move::is_working`]).
    pub working_s: f64,
    /// The lowest and the highest Z (mm) of its extruding moves (a printer's working
    /// moves), where it has any: one value in a planar layer; a spiral vase in a file that
    /// marks no layer is one layer from its bottom to its top.
    pub print_z_mm: Option<[f64; 2]>,
    /// What opened it: a slicer's layer marker or a change of Z; `None` for the moves
    /// before the first (a start G-code's).
    pub opened_by: Option<crate::LayerSource>,
}

/// A limit the file raises above the configuration it started with.
#[derive(Debug, Clone, PartialEq)]
pub struct LimitOverride {
    /// The line of the command.
    pub line: u64,
    /// The command (`M204`, `SET_VELOCITY_LIMIT`, `$120`).
    pub command: String,
    /// The limit, by the firmware's name and unit (`max_accel (mm/s^2)`).
    pub limit: &'static str,
    /// The configuration's value.
    pub configured: f64,
    /// The file's, the first time it raises the limit.
    pub file: f64,
    /// The highest value the file sets it to.
    pub highest: f64,
    /// How many commands change it to a value above the configuration's (this one
    /// counted).
    pub raises: u64,
}

/// What a job did, for reports.
#[derive(Debug, Clone, Default)]
pub struct JobSummary {
    /// The planner used.
    pub firmware: Option<Firmware>,
    /// The print clock at the end: the planner's own sum of move and dwell times (s).
    /// Complete once the whole file is planned ([`super::Job::run_to_end`]).
    pub print_time_s: f64,
    /// The account per layer, in order.
    pub layers: Vec<LayerTime>,
    /// G-code moves read.
    pub moves: u64,
    /// Straight moves given to the planner (arcs count their segments).
    pub segments: u64,
    /// Limit commands applied.
    pub limit_changes: u64,
    /// Shaper changes applied.
    pub shaper_changes: u64,
    /// Commands read but not followed, with why, and how often.
    pub ignored: BTreeMap<String, u64>,
    /// The slicer feature types the file names, as [`crate::Reader::features`].
    pub features: Vec<String>,
    /// The file's limit commands that raise a limit above the configuration's (a
    /// slicer's `M204 S15000` against `max_accel: 7000`): the first of each limit, in
    /// file order.
    pub overrides: Vec<LimitOverride>,
    /// Whether every line of the file has been planned.
    pub complete: bool,
}
