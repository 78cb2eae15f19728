//! What the reader yields: events in file order, each with its line and layer.

use crate::read::geometry::Move;
use crate::read::limits::{AxisFlags, LimitChange};
use crate::read::setting::Setting;

/// One thing the file asks for.
#[derive(Debug, Clone, PartialEq)]
pub struct Event {
    /// 1-based line of the command (of the marker comment, for a layer change).
    pub line: u64,
    /// Layer index: 0 before the first layer change, then 1, 2, ... (a layer change event
    /// carries the index of the layer it starts).
    pub layer: u32,
    /// What it is.
    pub kind: EventKind,
}

/// The kinds of event.
#[derive(Debug, Clone, PartialEq)]
pub enum EventKind {
    /// A move (G0/G1 line, G2/G3 arc). Moves that change nothing are not reported.
    Move(Move),
    /// The planner must drain and stand still for this long, s: `G4` (0 = just wait
    /// for the queued moves, as `G4 P0`) and `M400` (0).
    Dwell {
        /// Dwell time after the machine stops, s.
        duration_s: f64,
    },
    /// A new layer starts.
    Layer(LayerChange),
    /// Motion limits or shaping change from here on.
    Limits(LimitChange),
    /// A machine setting (steps per mm, microstepping, current, travel, kinematics) changes
    /// from here on; configuration-file commands, RepRapFirmware only.
    Setting(Setting),
    /// Something the reader does not simulate but a user should know about.
    Note(Note),
}

/// Where a layer change was found.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum LayerSource {
    /// Cura (and ideaMaker): `;LAYER:n`, n from 0 (negative for raft layers).
    Cura,
    /// PrusaSlicer, SuperSlicer, OrcaSlicer (non-Bambu printers): `;LAYER_CHANGE`,
    /// then `;Z:z`.
    LayerChange,
    /// OrcaSlicer / BambuStudio for Bambu printers: `; CHANGE_LAYER`, then
    /// `; Z_HEIGHT: z` (OrcaSlicer `GCodeProcessor::Reserved_Tags`).
    ChangeLayer,
    /// Simplify3D (and old Slic3r): `; layer n, Z = z`, n from 1.
    Simplify3d,
    /// No slicer marker: a planar printing move at a new Z.
    ZChange,
}

/// A layer change.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LayerChange {
    /// How it was found.
    pub source: LayerSource,
    /// The slicer's own layer number, where the marker has one.
    pub slicer_number: Option<i64>,
    /// The layer's Z, mm (the marker's value, or the printing move's Z), where known.
    pub z_mm: Option<f64>,
}

/// Notes about commands the reader does not turn into motion.
#[derive(Debug, Clone, PartialEq)]
pub enum Note {
    /// `G28`: homing is not simulated; the homed axes are taken to be at 0 afterwards
    /// (and any `G92` offset on them is cleared, as Marlin's `set_axis_is_at_home` does).
    Homed {
        /// The axes homed (all of X, Y, Z when the command names none).
        axes: AxisFlags,
    },
    /// A command the chosen firmware reads but ignores with a message (for example
    /// Klipper's `M204` with `P` but no `T`, `klippy/toolhead.py` `cmd_M204`).
    IgnoredByFirmware {
        /// The command as written.
        command: String,
        /// What the firmware says.
        reason: &'static str,
    },
    /// Prusa-Firmware-Buddy's printer-model check, `M862.3 P "MK4S"` (Prusa dialect):
    /// the name as Buddy reads it (src/marlin_stubs/M862_2_3.cpp: after `P`, spaces and
    /// quotes skipped, then letters, digits and dots). The command is also counted among
    /// [`crate::Reader::ignored_commands`] (it moves nothing).
    PrinterModel {
        /// The printer's name (`MINI`, `MK4S`, `COREONE`).
        name: String,
    },
    /// RepRapFirmware runs another file here (`M98 P"file"`, or `M501`, which runs
    /// `config-override.g`); the reader does not open it
    /// ([`crate::config::RrfConfig`] does).
    MacroCall {
        /// `M98` or `M501`.
        command: &'static str,
        /// The file as written (relative names are relative to the firmware's `/sys`
        /// folder).
        path: String,
    },
}
