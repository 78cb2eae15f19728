//! The modal motion state (position, G92 offsets, absolute/relative modes, units, feed
//! rate and its `M220` factor, the `M221` extrusion factor, arc plane) and the commands
//! that move or rename the position: G0-G4, G17-G21, G28, G90, G91, G92, M82, M83.

use crate::error::GcodeError;
use crate::read::arc::{Arc, ArcProblem, Plane};
use crate::read::cmd::{Check, Cmd, FINITE, NON_NEGATIVE, POSITIVE};
use crate::read::dialect::Dialect;
use crate::read::geometry::{Move, MoveKind, Path, Point, Tool};
use crate::read::limits::AxisFlags;
use crate::read::params::Params;

const AXES: [u8; 4] = [b'X', b'Y', b'Z', b'E'];

#[derive(Debug, Clone)]
pub(crate) struct Motion {
    dialect: Dialect,
    /// Machine position X Y Z E, mm.
    pos: [f64; 4],
    /// Machine minus file coordinates (set by G92), mm.
    offset: [f64; 4],
    /// G91 in force.
    axes_relative: bool,
    /// M83 in force (Marlin: also set by G90/G91).
    e_relative: bool,
    /// The modal F, mm/min.
    feed_mm_min: f64,
    /// The arc plane (G17, G18, G19).
    plane: Plane,
    max_coordinate_mm: f64,
    max_extruder_mm: f64,
    /// Millimetres per unit of X, Y, Z, I, J, R and F: 1 (G21) or 25.4 (G20).
    unit_mm: f64,
    /// `M220`: the feed of every move is multiplied by this.
    speed_factor: f64,
    /// `M221`: extrusion is multiplied by this.
    extrude_factor: f64,
    /// GRBL's `G53`: this block's coordinates are machine coordinates.
    machine_coordinates: bool,
}

impl Motion {
    pub(crate) fn new(dialect: Dialect, max_coordinate_mm: f64, max_extruder_mm: f64) -> Self {
        Motion {
            dialect,
            pos: [0.0; 4],
            offset: [0.0; 4],
            axes_relative: false,
            e_relative: false,
            feed_mm_min: dialect.initial_feed_mm_s() * 60.0,
            plane: Plane::Xy,
            max_coordinate_mm,
            max_extruder_mm,
            unit_mm: 1.0,
            speed_factor: 1.0,
            extrude_factor: 1.0,
            machine_coordinates: false,
        }
    }

    /// G20 (true: inches) / G21.
    pub(crate) fn set_inches(&mut self, inches: bool) {
        self.unit_mm = if inches { 25.4 } else { 1.0 };
    }

    /// Millimetres per unit of the coordinates and feeds written (25.4 after G20).
    pub(crate) fn unit_mm(&self) -> f64 {
        self.unit_mm
    }

    /// `M220 S`: the feed factor (1 = 100 %).
    pub(crate) fn set_speed_factor(&mut self, factor: f64) {
        self.speed_factor = factor;
    }

    /// `M221 S`: the extrusion factor (1 = 100 %) for the extrusion from here on (as
    /// Klipper's `cmd_M221` keeps the file's E position continuous).
    pub(crate) fn set_extrude_factor(&mut self, factor: f64) {
        let file_e = (self.pos[3] - self.offset[3]) / self.extrude_factor;
        self.offset[3] = self.pos[3] - file_e * factor;
        self.extrude_factor = factor;
    }

    /// The modal feed (mm/min as written, before `M220`); 0 when none was set (GRBL).
    pub(crate) fn feed_mm_min(&self) -> f64 {
        self.feed_mm_min
    }

    /// Sets the modal feed (mm/min as written).
    pub(crate) fn set_feed_mm_min(&mut self, feed: f64) {
        self.feed_mm_min = feed;
    }

    /// Sets machine minus file coordinates of X, Y, Z (GRBL's work offsets).
    pub(crate) fn set_offsets(&mut self, offsets: [f64; 3]) {
        self.offset[..3].copy_from_slice(&offsets);
    }

    /// GRBL's `G53` for the next move (cleared by it).
    pub(crate) fn set_machine_coordinates(&mut self, on: bool) {
        self.machine_coordinates = on;
    }

    /// Whether G91 is in force.
    pub(crate) fn is_relative(&self) -> bool {
        self.axes_relative
    }

    /// A straight move to a point given in machine coordinates (GRBL's `G28`/`G30`
    /// travel), `None` when it goes nowhere.
    pub(crate) fn line_to_machine(&mut self, xyz: [f64; 3], rapid: bool) -> Option<Move> {
        let mut t = self.pos;
        t[..3].copy_from_slice(&xyz);
        (t != self.pos).then(|| self.finish(t, rapid, Path::Line))
    }

    /// The machine position, mm.
    pub(crate) fn position(&self) -> Point {
        Point::new(self.pos[0], self.pos[1], self.pos[2], self.pos[3])
    }

    fn e_is_relative(&self) -> bool {
        self.e_relative || (self.dialect == Dialect::Klipper && self.axes_relative)
    }

    /// G90 (false) / G91 (true).
    pub(crate) fn set_relative(&mut self, relative: bool) {
        self.axes_relative = relative;
        if self.dialect.is_marlin() {
            self.e_relative = relative;
        }
    }

    /// M82 (false) / M83 (true).
    pub(crate) fn set_e_relative(&mut self, relative: bool) {
        self.e_relative = relative;
    }

    /// G17, G18 or G19.
    pub(crate) fn set_plane(&mut self, plane: Plane) {
        self.plane = plane;
    }

    /// Reads F and X Y Z E: the target machine position and the feed, mm/min (committed
    /// by the caller once the whole line is good).
    fn target(&self, cmd: &Cmd, p: &Params) -> Result<([f64; 4], f64), GcodeError> {
        let feed = match cmd.num(p, b'F', POSITIVE)? {
            Some(f) => f * self.unit_mm,
            None => self.feed_mm_min,
        };
        let mut t = self.pos;
        for (k, &letter) in AXES.iter().enumerate() {
            let Some(v) = cmd.num(p, letter, FINITE)? else {
                continue;
            };
            let (relative, v) = if k == 3 {
                (self.e_is_relative(), v * self.extrude_factor)
            } else {
                (self.axes_relative, v * self.unit_mm)
            };
            t[k] = if self.machine_coordinates && k < 3 {
                v
            } else if relative {
                self.pos[k] + v
            } else {
                v + self.offset[k]
            };
            let (limit, allowed) = if k == 3 {
                (
                    self.max_extruder_mm,
                    "an extruder position within the reader's limit (+-1e9 mm by default)",
                )
            } else {
                (
                    self.max_coordinate_mm,
                    "a position within the reader's limit (+-1e5 mm by default: 100 m, larger than any machine)",
                )
            };
            if t[k].abs() > limit {
                return Err(cmd.out_of_range(
                    Some(p.at(letter)),
                    &char::from(letter).to_string(),
                    t[k],
                    allowed,
                ));
            }
        }
        Ok((t, feed))
    }

    fn finish(&mut self, target: [f64; 4], rapid: bool, path: Path) -> Move {
        let start = self.position();
        self.pos = target;
        let end = self.position();
        self.machine_coordinates = false;
        let mut mv = Move {
            start,
            end,
            feed_mm_s: self.feed_mm_min * self.speed_factor / 60.0,
            kind: MoveKind::Travel,
            rapid,
            path,
            tool: Tool::Off,
            feature: 0,
        };
        let moves_xyz = match path {
            Path::Line => {
                start.x_mm != end.x_mm || start.y_mm != end.y_mm || start.z_mm != end.z_mm
            }
            Path::Arc(_) => true,
        };
        mv.kind = match (moves_xyz, mv.extrusion_mm() > 0.0) {
            (true, true) => MoveKind::Print,
            (true, false) => MoveKind::Travel,
            (false, _) => MoveKind::Extruder,
        };
        mv
    }

    /// G0 / G1. `None` when the position does not change (F alone).
    pub(crate) fn line(
        &mut self,
        cmd: &Cmd,
        p: &Params,
        rapid: bool,
    ) -> Result<Option<Move>, GcodeError> {
        cmd.allow(p, b"XYZEF", "X Y Z E F")?;
        let (target, feed) = self.target(cmd, p)?;
        self.feed_mm_min = feed;
        if target == self.pos {
            self.machine_coordinates = false;
            return Ok(None);
        }
        Ok(Some(self.finish(target, rapid, Path::Line)))
    }

    /// G2 (clockwise) / G3.
    pub(crate) fn arc(
        &mut self,
        cmd: &Cmd,
        p: &Params,
        clockwise: bool,
    ) -> Result<Move, GcodeError> {
        let grbl = self.dialect == Dialect::Grbl;
        if self.plane != Plane::Xy && !grbl {
            return Err(cmd.unsupported(
                "arcs are read in the XY plane only (G17) under this firmware; G18/G19 arcs are read under GRBL (--firmware grbl)",
            ));
        }
        if self.dialect == Dialect::Klipper {
            if self.axes_relative {
                return Err(cmd.unsupported(
                    "Klipper refuses G2/G3 in relative mode (klippy/extras/gcode_arcs.py)",
                ));
            }
            if p.has(b'R') {
                return Err(cmd.unsupported(
                    "Klipper refuses the R form of G2/G3 (klippy/extras/gcode_arcs.py); give I/J",
                ));
            }
        }
        if grbl {
            // GRBL takes K (grbl/gcode.c reads I, J and K in every plane and uses the
            // plane's two).
            cmd.allow(p, b"XYZFIJKR", "X Y Z F I J K R")?;
        } else if self.dialect == Dialect::Klipper {
            // Klipper reads X Y Z E F I J (and K in G18/G19) and passes over any other
            // word: OrcaSlicer's spiral lift writes `P1` (the caller notes it).
            cmd.allow(
                p,
                b"XYZEFIJRP",
                "X Y Z E F I J, and P, which Klipper passes over",
            )?;
        } else if self.dialect.is_marlin() {
            // Marlin reads `P` (extra full turns) only in a build with ARC_P_CIRCLES and
            // passes over it otherwise (Marlin/src/gcode/motion/G2_G3.cpp): the turns
            // such an arc makes depend on the build, which settle does not know.
            cmd.allow(
                p,
                b"XYZEFIJR",
                "X Y Z E F I J R; P (full turns, as in the spiral lift Bambu Studio and OrcaSlicer write) is read only by a Marlin built with ARC_P_CIRCLES and passed over by others, so the turns depend on the build",
            )?;
        } else {
            cmd.allow(p, b"XYZEFIJR", "X Y Z E F I J R")?;
        }
        let [first, second, _] = self.plane.axes();
        if grbl && !p.has(b"XYZ"[first]) && !p.has(b"XYZ"[second]) {
            return Err(cmd.unsupported(
                "no axis word in the arc's plane (G17 X Y, G18 Z X, G19 Y Z): GRBL refuses the line (error:32, grbl/gcode.c)",
            ));
        }
        let offset_check = Check {
            ok: |v| v.abs() <= 1e5,
            allowed: "within 1e5 mm",
        };
        let unit = |v: Option<f64>| v.map(|v| v * self.unit_mm);
        let [word_i, word_j] = self.plane.offset_words();
        let i = unit(cmd.num(p, word_i, offset_check)?);
        let j = unit(cmd.num(p, word_j, offset_check)?);
        let r = unit(cmd.num(p, b'R', offset_check)?);
        if r.is_some() && (i.is_some() || j.is_some()) {
            return Err(GcodeError::ArcMixedForms {
                at: cmd.at(None),
                command: cmd.name(),
            });
        }
        let (target, feed) = self.target(cmd, p)?;
        let (start, end) = (
            [self.pos[first], self.pos[second]],
            [target[first], target[second]],
        );
        let built = match r {
            Some(r) if r != 0.0 => Arc::from_radius(start, end, r, clockwise),
            Some(_) => Err(ArcProblem::NoCentre),
            None => Arc::from_offsets(
                start,
                end,
                i.unwrap_or(0.0),
                j.unwrap_or(0.0),
                clockwise,
                true,
            ),
        };
        let arc = built.map_err(|e| arc_error(cmd, e))?.in_plane(self.plane);
        self.feed_mm_min = feed;
        Ok(self.finish(target, false, Path::Arc(arc)))
    }

    /// G92: renames the position without moving.
    pub(crate) fn set_position(&mut self, cmd: &Cmd, p: &Params) -> Result<(), GcodeError> {
        cmd.allow(p, b"XYZE", "X Y Z E")?;
        if p.is_empty() {
            if self.dialect == Dialect::Klipper {
                self.offset = self.pos;
            }
            return Ok(());
        }
        for (k, &letter) in AXES.iter().enumerate() {
            if let Some(v) = cmd.num(p, letter, FINITE)? {
                let v = if k == 3 {
                    v * self.extrude_factor
                } else {
                    v * self.unit_mm
                };
                self.offset[k] = self.pos[k] - v;
            }
        }
        Ok(())
    }

    /// G28: the named axes (all of X Y Z when none is named) go to 0. Other parameters
    /// (Marlin's `O`, `R`, Prusa's `W`) are accepted and have no effect here.
    pub(crate) fn home(&mut self, p: &Params) -> AxisFlags {
        let named = AxisFlags {
            x: p.has(b'X'),
            y: p.has(b'Y'),
            z: p.has(b'Z'),
            e: false,
        };
        let axes = if named.x || named.y || named.z {
            named
        } else {
            AxisFlags {
                x: true,
                y: true,
                z: true,
                e: false,
            }
        };
        self.home_axes(axes);
        axes
    }

    /// Homing of `axes` (GRBL's `$H`): they go to 0 and lose their offsets.
    pub(crate) fn home_axes(&mut self, axes: AxisFlags) {
        for (k, homed) in [axes.x, axes.y, axes.z].into_iter().enumerate() {
            if homed {
                self.pos[k] = 0.0;
                self.offset[k] = 0.0;
            }
        }
    }

    /// G4: the dwell time, s, and whether Klipper ignored an `S`.
    pub(crate) fn dwell(&self, cmd: &Cmd, p: &Params) -> Result<(f64, bool), GcodeError> {
        cmd.allow(p, b"PS", "P (ms) S (s)")?;
        let ms = cmd.num(p, b'P', NON_NEGATIVE)?;
        let s = cmd.num(p, b'S', NON_NEGATIVE)?;
        Ok(match self.dialect {
            Dialect::Klipper => (ms.unwrap_or(0.0) / 1000.0, s.is_some()),
            Dialect::Marlin | Dialect::Prusa | Dialect::Rrf => {
                (s.unwrap_or(ms.unwrap_or(0.0) / 1000.0), false)
            }
            // GRBL's P is in seconds (grbl/gcode.c `mc_dwell(gc_block.values.p)`).
            Dialect::Grbl => (ms.unwrap_or(0.0), false),
        })
    }
}

fn arc_error(cmd: &Cmd, e: ArcProblem) -> GcodeError {
    let (at, command) = (cmd.at(None), cmd.name());
    match e {
        ArcProblem::NoCentre => GcodeError::ArcWithoutCentre { at, command },
        ArcProblem::RadiusMismatch { start_mm, end_mm } => GcodeError::ArcRadiusMismatch {
            at,
            command,
            start_radius_mm: start_mm,
            end_radius_mm: end_mm,
        },
        ArcProblem::RadiusTooSmall {
            radius_mm,
            chord_mm,
        } => GcodeError::ArcRadiusTooSmall {
            at,
            command,
            radius_mm,
            chord_mm,
        },
        ArcProblem::ZeroChord => GcodeError::ArcDegenerate {
            at,
            command,
            why: "the R form needs an end point away from the start",
        },
        ArcProblem::ZeroSweep => GcodeError::ArcDegenerate {
            at,
            command,
            why: "the end point lies on the start radius: the arc sweeps no angle",
        },
    }
}
