//! Moves: where they start and end, how fast they were asked to go, whether they print.

use crate::read::arc::Arc;

/// A machine position, mm: X Y Z and the extruder's E.
///
/// "Machine" means continuous: `G92` renames the current position without moving, so the
/// reader keeps its own frame in which no `G92` ever makes the head jump (the file's first
/// coordinates are taken as written; `G28` puts the homed axes at 0).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Point {
    /// X, mm.
    pub x_mm: f64,
    /// Y, mm.
    pub y_mm: f64,
    /// Z, mm.
    pub z_mm: f64,
    /// Extruder position, mm of filament (cumulative over the file).
    pub e_mm: f64,
}

impl Point {
    /// A point from its four coordinates, mm.
    pub fn new(x_mm: f64, y_mm: f64, z_mm: f64, e_mm: f64) -> Self {
        Point {
            x_mm,
            y_mm,
            z_mm,
            e_mm,
        }
    }

    /// Straight-line XYZ distance to `other`, mm (E is not a distance in space).
    pub fn distance_xyz_mm(&self, other: &Point) -> f64 {
        let (dx, dy, dz) = (
            other.x_mm - self.x_mm,
            other.y_mm - self.y_mm,
            other.z_mm - self.z_mm,
        );
        (dx * dx + dy * dy + dz * dz).sqrt()
    }

    /// X, Y and Z, mm.
    pub fn xyz(&self) -> [f64; 3] {
        [self.x_mm, self.y_mm, self.z_mm]
    }
}

/// What a move does, from its XYZ travel and its extrusion.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum MoveKind {
    /// XYZ travel with positive extrusion.
    Print,
    /// XYZ travel without positive extrusion (a retract during a travel counts here).
    Travel,
    /// No XYZ travel, only E (retract, unretract, purge in place).
    Extruder,
}

/// What a spindle or laser does over a move (GRBL's `M3`/`M4`/`M5` and `S`); a printer's
/// tool is its extruder, which [`MoveKind`] describes.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Tool {
    /// Nothing turns or fires: printers, `M5`, or a laser during a `G0` (GRBL's laser mode
    /// turns the laser off for rapids, grbl/gcode.c `GC_PARSER_LASER_DISABLE`).
    #[default]
    Off,
    /// A laser in GRBL's laser mode (`$32=1`) at power `S`: `M3` constant power, `M4`
    /// (`dynamic`) power scaled by the current speed over the programmed rate
    /// (grbl/stepper.c `is_pwm_rate_adjusted`).
    Laser {
        /// The `S` value in force (the firmware's scale, `$30` at full power).
        s: f64,
        /// `M4`: dynamic power.
        dynamic: bool,
    },
    /// A spindle turning at `S` (`M3` clockwise, `M4` counter-clockwise), laser mode off.
    Spindle {
        /// The `S` value in force (rpm).
        s: f64,
    },
}

impl Tool {
    /// Whether the tool works the material during a feed move: a laser or spindle on at
    /// `S > 0`.
    pub fn is_on(&self) -> bool {
        match *self {
            Tool::Off => false,
            Tool::Laser { s, .. } | Tool::Spindle { s } => s > 0.0,
        }
    }
}

/// The geometry of a move between its start and end points.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Path {
    /// A straight line (G0, G1).
    Line,
    /// A circular or helical arc in the XY plane (G2, G3); Z and E change linearly with
    /// the angle.
    Arc(Arc),
}

/// One move as the file asks for it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Move {
    /// Where the move starts, mm (machine frame, see [`Point`]).
    pub start: Point,
    /// Where it ends, mm.
    pub end: Point,
    /// Requested feed rate along the path, mm/s (the file's `F`, mm/min, divided by 60;
    /// each firmware caps it by its own limits).
    pub feed_mm_s: f64,
    /// Print, travel or extruder-only.
    pub kind: MoveKind,
    /// `G0` (rapid) rather than `G1`/`G2`/`G3`. Klipper, Marlin and RepRapFirmware in
    /// printer mode plan G0 like G1; CNC planners may not.
    pub rapid: bool,
    /// Line or arc.
    pub path: Path,
    /// The spindle or laser over the move ([`Tool::Off`] on a printer).
    pub tool: Tool,
    /// The slicer's feature type of the move (`;TYPE:` comments): an index into
    /// [`crate::Reader::features`], 0 when the file names none.
    pub feature: u16,
}

impl Move {
    /// Whether the move works the material, the one notion of a "working" move every
    /// metric counts: a printing (extruding) move on a printer, a feed move (`G1`, `G2`,
    /// `G3`, not a rapid) with the laser or spindle on at `S > 0` on a laser or a mill.
    pub fn is_working(&self) -> bool {
        match self.tool {
            Tool::Off => self.kind == MoveKind::Print,
            tool => tool.is_on() && !self.rapid,
        }
    }

    /// Length of the XYZ path, mm: the straight distance for a line, the exact helical
    /// length `sqrt((r |sweep|)^2 + dz^2)` for an arc (`dz` along its plane's linear axis).
    pub fn length_mm(&self) -> f64 {
        match &self.path {
            Path::Line => self.start.distance_xyz_mm(&self.end),
            Path::Arc(a) => {
                let linear = a.plane.axes()[2];
                a.length_mm(self.end.xyz()[linear] - self.start.xyz()[linear])
            }
        }
    }

    /// Extruder travel, mm (negative for a retract).
    pub fn extrusion_mm(&self) -> f64 {
        self.end.e_mm - self.start.e_mm
    }

    /// The point a fraction `s` (0..=1) of the way along the path (angle-proportional on an
    /// arc, so also length-proportional); `s = 1` returns `end` exactly.
    pub fn point_at(&self, s: f64) -> Point {
        if s >= 1.0 {
            return self.end;
        }
        let lerp = |a: f64, b: f64| a + (b - a) * s;
        let (a, b) = (self.start.xyz(), self.end.xyz());
        let mut p = [lerp(a[0], b[0]), lerp(a[1], b[1]), lerp(a[2], b[2])];
        if let Path::Arc(arc) = &self.path {
            let [first, second, _] = arc.plane.axes();
            (p[first], p[second]) = arc.xy_at(s);
        }
        Point {
            x_mm: p[0],
            y_mm: p[1],
            z_mm: p[2],
            e_mm: lerp(self.start.e_mm, self.end.e_mm),
        }
    }

    /// The bounding box of the path (exact for arcs: it includes the quadrant points the
    /// arc passes in its plane), with the arc plane's linear axis (Z in the XY plane) from
    /// the end points.
    pub fn bounds(&self) -> Bounds {
        let mut b = Bounds::empty();
        b.include(&self.start);
        b.include(&self.end);
        if let Path::Arc(a) = &self.path {
            let [first, second, _] = a.plane.axes();
            for [u, v] in a.extremes_xy() {
                let mut p = self.start.xyz();
                (p[first], p[second]) = (u, v);
                b.include_xyz(p);
            }
        }
        b
    }
}

/// An axis-aligned box, mm. Empty until a point is included.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bounds {
    /// Smallest X, Y, Z seen, mm.
    pub min_mm: [f64; 3],
    /// Largest X, Y, Z seen, mm.
    pub max_mm: [f64; 3],
}

impl Bounds {
    /// The empty box (min = +inf, max = -inf).
    pub fn empty() -> Self {
        Bounds {
            min_mm: [f64::INFINITY; 3],
            max_mm: [f64::NEG_INFINITY; 3],
        }
    }

    /// Whether nothing has been included.
    pub fn is_empty(&self) -> bool {
        self.min_mm[0] > self.max_mm[0]
    }

    /// Grows the box to hold `p`.
    pub fn include(&mut self, p: &Point) {
        self.include_xyz([p.x_mm, p.y_mm, p.z_mm]);
    }

    /// Grows the box to hold a point given as X, Y, Z.
    pub fn include_xyz(&mut self, p: [f64; 3]) {
        for ((lo, hi), v) in self.min_mm.iter_mut().zip(self.max_mm.iter_mut()).zip(p) {
            *lo = lo.min(v);
            *hi = hi.max(v);
        }
    }

    /// Grows the box to hold `other`.
    pub fn union(&mut self, other: &Bounds) {
        if !other.is_empty() {
            self.include_xyz(other.min_mm);
            self.include_xyz(other.max_mm);
        }
    }
}
