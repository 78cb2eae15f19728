//! The fly-axis error of a raster job: a laser engraving an image scans lines back and
//! forth along one axis (the fly axis) with the power set per pixel; a pixel lands where
//! the toolhead is when the firmware sets its power, so what misplaces it is the error
//! **along** the scan line, toolhead minus command on the fly axis, inside the scan
//! region (the laser on). The contour error, across the line, does not see it.
//!
//! Every laser move (working, [`settle_gcode::Tool::Laser`]) straight along X (or along Y)
//! counts: its samples' along-axis error (toolhead minus the command the machine receives
//! on that axis) goes to that axis's histogram. A laser job is a raster when more than
//! half of its working length is such lines along one axis and its lines along the other
//! axis are at most a tenth as long ([`FlyAxis::raster`]); that axis is its fly axis. A
//! raster's scan lines all run one way (its step-overs are short, or run with the laser
//! off); a vector job's straight lines run both ways, a rectangle's sides as long along X
//! as along Y, and its along-line error misplaces no pixel. Printers and mills draw
//! contours, not rasters: their moves are not counted.

use super::stats::{Histogram, Split, Spot};
use settle_gcode::job::{MoveGeometry, MoveInfo};

/// A line is along an axis when its other components are below this fraction of its
/// length.
const ALONG: f64 = 1e-6;

/// A raster's lines along the other axis are at most this fraction of its lines along
/// the fly axis (module doc).
const ACROSS: f64 = 0.1;

/// The along-line errors of the scan lines along X and along Y.
#[derive(Debug, Clone, Default)]
pub struct FlyAxis {
    /// X, Y: the errors (um) of samples on working lines along that axis.
    pub errors: [Histogram; 2],
    /// X, Y: the largest |error| and where.
    pub worst: [Option<Spot>; 2],
    /// X, Y: working length on lines along that axis (mm).
    pub length_mm: [f64; 2],
    /// Working length of every kind (mm).
    pub working_mm: f64,
    last_move: Option<u64>,
}

/// The axis (0 X, 1 Y) a straight move runs along, if it runs along one.
fn along(m: &MoveInfo) -> Option<(usize, f64)> {
    let MoveGeometry::Line { from_mm, to_mm } = &m.geometry else {
        return None;
    };
    let d = [to_mm[0] - from_mm[0], to_mm[1] - from_mm[1], to_mm[2] - from_mm[2]];
    let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    (0..2).find_map(|a| {
        let others = (0..3).filter(|&k| k != a).map(|k| d[k].abs()).fold(0.0, f64::max);
        (l > 0.0 && others <= ALONG * l).then_some((a, l))
    })
}

impl FlyAxis {
    /// A working sample of move `m` at `t`: commanded and toolhead X, Y (mm).
    pub fn sample(&mut self, m: &MoveInfo, t: f64, cmd_mm: [f64; 2], head_mm: [f64; 2]) {
        if !matches!(m.tool, settle_gcode::Tool::Laser { .. }) {
            return;
        }
        let first = self.last_move != Some(m.index);
        self.last_move = Some(m.index);
        let line = along(m);
        if first {
            let len = match &m.geometry {
                MoveGeometry::Line { .. } => line.map_or_else(|| m.start_mm.distance_xyz_mm(&m.end_mm), |(_, l)| l),
                MoveGeometry::Arc { .. } => m.start_mm.distance_xyz_mm(&m.end_mm),
            };
            self.working_mm += len;
            if let Some((a, l)) = line {
                self.length_mm[a] += l;
            }
        }
        let Some((a, _)) = line else {
            return;
        };
        let e_um = (head_mm[a] - cmd_mm[a]).abs() * 1e3;
        self.errors[a].push(e_um);
        if self.worst[a].as_ref().is_none_or(|w| e_um > w.error_um) {
            self.worst[a] = Some(Spot {
                error_um: e_um,
                time_s: t,
                x_mm: head_mm[0],
                y_mm: head_mm[1],
                line: m.line,
                layer: m.layer,
                move_index: m.index,
                // The split is the contour error's; the along-line error has none.
                split: Split::default(),
            });
        }
    }

    /// The fly axis (0 X, 1 Y) when the job is a raster (module doc): more than half of
    /// the working length on lines along it, and at most a tenth of that along the other
    /// axis.
    pub fn raster(&self) -> Option<usize> {
        let a = if self.length_mm[0] >= self.length_mm[1] { 0 } else { 1 };
        let across = self.length_mm[1 - a];
        (self.working_mm > 0.0
            && self.length_mm[a] > 0.5 * self.working_mm
            && across <= ACROSS * self.length_mm[a])
            .then_some(a)
    }
}
