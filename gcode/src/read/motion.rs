//! The modal motion state (position, G92 offsets, absolute/relative modes, feed rate, arc
//! plane) and the commands that move or rename the position: G0-G4, G17-G19, G28, G90,
//! G91, G92, M82, M83.

use crate::error::GcodeError;
use crate::read::arc::{Arc, ArcProblem};
use crate::read::cmd::{Check, Cmd, FINITE, NON_NEGATIVE, POSITIVE};
use crate::read::dialect::Dialect;
use crate::read::geometry::{Move, MoveKind, Path, Point};
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
    /// G17 (XY) is the arc plane.
    plane_xy: bool,
    max_coordinate_mm: f64,
    max_extruder_mm: f64,
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
            plane_xy: true,
            max_coordinate_mm,
            max_extruder_mm,
        }
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
        if self.dialect == Dialect::Marlin {
            self.e_relative = relative;
        }
    }

    /// M82 (false) / M83 (true).
    pub(crate) fn set_e_relative(&mut self, relative: bool) {
        self.e_relative = relative;
    }

    /// G17 (true) or G18/G19 (false).
    pub(crate) fn set_plane_xy(&mut self, xy: bool) {
        self.plane_xy = xy;
    }

    /// Reads F and X Y Z E: the target machine position and the feed, mm/min (committed
    /// by the caller once the whole line is good).
    fn target(&self, cmd: &Cmd, p: &Params) -> Result<([f64; 4], f64), GcodeError> {
        let feed = cmd.num(p, b'F', POSITIVE)?.unwrap_or(self.feed_mm_min);
        let mut t = self.pos;
        for (k, &letter) in AXES.iter().enumerate() {
            let Some(v) = cmd.num(p, letter, FINITE)? else {
                continue;
            };
            let relative = if k == 3 {
                self.e_is_relative()
            } else {
                self.axes_relative
            };
            t[k] = if relative {
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
        let mut mv = Move {
            start,
            end,
            feed_mm_s: self.feed_mm_min / 60.0,
            kind: MoveKind::Travel,
            rapid,
            path,
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
        if !self.plane_xy {
            return Err(
                cmd.unsupported("arcs are read in the XY plane only (G17); G18/G19 arcs are not")
            );
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
        cmd.allow(p, b"XYZEFIJR", "X Y Z E F I J R")?;
        let offset_check = Check {
            ok: |v| v.abs() <= 1e5,
            allowed: "within 1e5 mm",
        };
        let i = cmd.num(p, b'I', offset_check)?;
        let j = cmd.num(p, b'J', offset_check)?;
        let r = cmd.num(p, b'R', offset_check)?;
        if r.is_some() && (i.is_some() || j.is_some()) {
            return Err(GcodeError::ArcMixedForms {
                at: cmd.at(None),
                command: cmd.name(),
            });
        }
        let (target, feed) = self.target(cmd, p)?;
        let (start, end) = ([self.pos[0], self.pos[1]], [target[0], target[1]]);
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
        let arc = built.map_err(|e| arc_error(cmd, e))?;
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
        for (k, homed) in [axes.x, axes.y, axes.z].into_iter().enumerate() {
            if homed {
                self.pos[k] = 0.0;
                self.offset[k] = 0.0;
            }
        }
        axes
    }

    /// G4: the dwell time, s, and whether Klipper ignored an `S`.
    pub(crate) fn dwell(&self, cmd: &Cmd, p: &Params) -> Result<(f64, bool), GcodeError> {
        cmd.allow(p, b"PS", "P (ms) S (s)")?;
        let ms = cmd.num(p, b'P', NON_NEGATIVE)?;
        let s = cmd.num(p, b'S', NON_NEGATIVE)?;
        Ok(match self.dialect {
            Dialect::Klipper => (ms.unwrap_or(0.0) / 1000.0, s.is_some()),
            Dialect::Marlin | Dialect::Rrf => (s.unwrap_or(ms.unwrap_or(0.0) / 1000.0), false),
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
