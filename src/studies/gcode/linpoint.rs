//! Where the modal backend linearises a G-code job: one point for the whole file, the
//! same for the whole run and for any layer range of it (`settle gcode` and the `[gcode]`
//! study alike), found by one streaming pass of the reader over the whole file
//! (bounded memory: the running box only).
//!
//! The point is the centre of the XY(Z) bounding box of the file's **working** moves
//! ([`settle_gcode::Move::is_working`]: extruding on a printer, the laser or spindle on in
//! a feed move on a laser or a mill; arcs with the quadrant points they pass,
//! [`settle_gcode::Move::bounds`]), in the G-code's
//! coordinates after G90/G91, G92 and homing as the reader resolves them. A physical
//! machine's stiffness depends on where the carriage is (a belt's spans); the print is
//! where the ringing is measured, and its box centre is at most half the part's size from
//! any printed point. The first printing move would be the alternative, but a skirt or a
//! purge line is printed first and often far from the part (a purge line at the bed's
//! edge), and the job's start (the origin, where every planner starts) is where nothing is
//! printed. Travel moves do not count: they go to and from the part (and the first one
//! starts at the origin).
//!
//! A file with no working move (a path without extrusion and without a laser or spindle
//! command) takes the box of its feed moves (G1, G2, G3; G0 rapids go to and from the
//! work), and a file without those the origin; the outputs say which
//! ([`PointSource`]).

use std::io::BufRead;

use settle_gcode::{Bounds, EventKind, GcodeError, MoveKind, Reader};

/// What the point is the centre of.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PointSource {
    /// The box of the working moves (extruding, or the laser or spindle on).
    Working,
    /// No working move: the box of the feed moves (G1, G2, G3).
    Feed,
    /// No feed move either: the origin, where the job starts.
    Origin,
}

impl PointSource {
    /// In words, for the outputs.
    pub fn describe(self) -> &'static str {
        match self {
            PointSource::Working => "the centre of the working moves' bounding box",
            PointSource::Feed => {
                "the centre of the feed moves' bounding box (the file has no working move)"
            }
            PointSource::Origin => "the origin (the file has no working or feed move)",
        }
    }
}

/// The linearisation point of a G-code job.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinPoint {
    /// X, Y, Z (mm, G-code coordinates).
    pub xyz_mm: [f64; 3],
    /// What it is the centre of.
    pub source: PointSource,
}

impl LinPoint {
    /// The point's position (m) on each machine axis, named `x`, `y` or `z` (other names
    /// get 0: the G-code job refuses them before it runs).
    pub fn on_axes(&self, names: &[String]) -> Vec<f64> {
        names
            .iter()
            .map(|n| match n.as_str() {
                "x" => self.xyz_mm[0] * 1e-3,
                "y" => self.xyz_mm[1] * 1e-3,
                "z" => self.xyz_mm[2] * 1e-3,
                _ => 0.0,
            })
            .collect()
    }

    /// `X 110.00 Y 110.00 Z 0.60 mm, the centre of ...`.
    pub fn describe(&self) -> String {
        let [x, y, z] = self.xyz_mm;
        format!(
            "X {x:.2} Y {y:.2} Z {z:.2} mm, {}",
            self.source.describe()
        )
    }
}

/// The point of the file `reader` reads (module doc), reading it to its end. Errors are
/// the reader's (a bad line, unless the reader skips them).
pub fn linearisation_point<R: BufRead>(reader: Reader<R>) -> Result<LinPoint, GcodeError> {
    let (mut print, mut feed) = (Bounds::empty(), Bounds::empty());
    for ev in reader {
        if let EventKind::Move(mv) = &ev?.kind {
            let b = mv.bounds();
            if mv.is_working() {
                print.union(&b);
            } else if !mv.rapid && mv.kind == MoveKind::Travel {
                feed.union(&b);
            }
        }
    }
    let centre = |b: &Bounds| std::array::from_fn(|i| 0.5 * (b.min_mm[i] + b.max_mm[i]));
    Ok(if !print.is_empty() {
        LinPoint {
            xyz_mm: centre(&print),
            source: PointSource::Working,
        }
    } else if !feed.is_empty() {
        LinPoint {
            xyz_mm: centre(&feed),
            source: PointSource::Feed,
        }
    } else {
        LinPoint {
            xyz_mm: [0.0; 3],
            source: PointSource::Origin,
        }
    })
}

/// Whether a position-dependent stiffness makes the linearisation point matter on any of
/// these axes.
pub fn depends_on_position(axes: &[settle_sim::AxisModel]) -> bool {
    axes.iter().any(|a| {
        a.lumped
            .couplings
            .iter()
            .any(|c| c.stiffness.depends_on().is_some())
    })
}
